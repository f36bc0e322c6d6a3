// Scene names (core/scene.cpp makeScene): a built-in name gives a renderable scene with a
// valid camera; anything else is refused with one line. Names that are paths (ending in
// .obj) are OBJ files, fuzzed by fuzz_obj; here they are kept inside an empty folder so
// the fuzzer cannot wander the file system.
#include "core/scene.hpp"
#include "fuzz/fuzz_common.hpp"
#include "fuzz/fuzz_scene_check.hpp"

namespace {
const boxes::SceneOptions kOptions{BOXES_FUZZ_DATA, 4.0f / 3.0f};
}  // namespace

// The mesh scenes are checked once here: re-reading a 2 MB OBJ per input made every
// "bunny" input a (false) timeout under the fuzzer's instrumentation.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
    for (const char* name : {"bunny", "sh1"})
        boxes::fuzz::checkScene(boxes::makeScene(name, kOptions));
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace boxes;
    std::string name(reinterpret_cast<const char*>(data), size);
    if (name.find('/') != std::string::npos || name.find("..") != std::string::npos) return 0;
    if (name == "bunny" || name == "sh1") return 0;  // checked once, above
    try {
        Scene scene = makeScene(name, kOptions);
        fuzz::checkScene(scene);
    } catch (const InputError& e) {
        fuzz::checkMessage(e.what());
    }
    return 0;
}
