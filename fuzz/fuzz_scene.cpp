// Scene names (core/scene.cpp makeScene): a built-in name gives a renderable scene with a
// valid camera; anything else is refused with one line. Names that are paths (ending in
// .obj) are OBJ files, fuzzed by fuzz_obj; here they are kept inside an empty folder so
// the fuzzer cannot wander the file system.
#include "core/scene.hpp"
#include "fuzz/fuzz_common.hpp"
#include "fuzz/fuzz_scene_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace boxes;
    std::string name(reinterpret_cast<const char*>(data), size);
    if (name.find('/') != std::string::npos || name.find("..") != std::string::npos) return 0;
    SceneOptions options;
    options.dataDir = BOXES_FUZZ_DATA;
    options.aspect = 4.0f / 3.0f;
    try {
        Scene scene = makeScene(name, options);
        fuzz::checkScene(scene);
    } catch (const InputError& e) {
        fuzz::checkMessage(e.what());
    }
    return 0;
}
