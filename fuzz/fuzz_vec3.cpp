// The "X,Y,Z" parser of --eye, --look and --up (core/app.cpp parseVec3). Promise: three
// finite numbers, or an InputError of one line that names the flag.
#include "core/app.hpp"
#include "core/mesh.hpp"
#include "fuzz/fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace boxes;
    std::string text(reinterpret_cast<const char*>(data), size);
    try {
        Vec3 v = parseVec3(text, "--eye");
        if (!isFinite(v)) fuzz::fail("non-finite vector accepted from '" + text + "'");
    } catch (const InputError& e) {
        fuzz::checkMessage(e.what());
        if (std::string(e.what()).rfind("--eye", 0) != 0)
            fuzz::fail(std::string("message does not name the flag: ") + e.what());
    }
    return 0;
}
