// doctest's main, plus floating-point traps on request: with BOXES_FP_TRAPS=1 in the
// environment an invalid operation (one that makes a NaN: 0/0, inf-inf, 0*inf, sqrt(-1))
// raises SIGFPE, which doctest reports as a crash of the running test case. .ci/run runs
// the suites that promise "no NaN" this way. A test whose code makes a NaN on purpose
// (a documented robust path) turns the traps off for its scope with test::FpTrapsOff.
#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>
#include <fenv.h>

#include <cstdlib>
#include <cstring>
#include <iostream>

int main(int argc, char** argv) {
    const char* traps = std::getenv("BOXES_FP_TRAPS");
    if (traps && std::strcmp(traps, "1") == 0) {
        feenableexcept(FE_INVALID);
        std::cerr << "[boxes] floating-point traps on: an invalid operation (NaN) stops the test\n";
    }
    doctest::Context context(argc, argv);
    return context.run();
}
