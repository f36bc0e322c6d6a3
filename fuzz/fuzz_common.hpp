// Shared by the fuzz targets: the libFuzzer entry point's signature, and how a target
// says "this input broke a promise" (abort, which libFuzzer and the replay both report).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);
// Optional one-time setup (libFuzzer calls it before the first input; so does the replay).
extern "C" __attribute__((weak)) int LLVMFuzzerInitialize(int* argc, char*** argv);

namespace boxes::fuzz {

// A broken promise (not a refused input): print it and abort so the input is kept.
[[noreturn]] inline void fail(const std::string& what) {
    std::fprintf(stderr, "fuzz: broken promise: %s\n", what.c_str());
    std::abort();
}

// The one-line rule of runMain: an error message is a single, non-empty line.
inline void checkMessage(const char* what) {
    std::string m = what;
    if (m.empty()) fail("empty error message");
    if (m.find('\n') != std::string::npos) fail("error message of several lines: " + m);
}

}  // namespace boxes::fuzz
