// The command line of every step program (core/app.cpp addCommonOptions, sceneFromOptions,
// cameraFromOptions; core/command_line.cpp parseCommandLine) with the built-in scenes. The
// input is the argument list, one argument per line. Promise: a scene with a valid camera and
// sizes in range, or one of the errors runMain turns into one line and an exit code
// (UsageError, InputError, std::invalid_argument, ExitRequest for --help); never another
// exception or a crash.
#include <CLI/CLI.hpp>
#include <sstream>
#include <vector>

#include "core/app.hpp"
#include "fuzz/fuzz_common.hpp"
#include "fuzz/fuzz_scene_check.hpp"

namespace {
// The mesh scenes, read once before fuzzing: re-reading a 2 MB OBJ per input would make
// every mesh input a (false) timeout.
boxes::Scene bunny, sh1;
}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    boxes::SceneOptions so{BOXES_FUZZ_DATA, 1.0f};
    bunny = boxes::makeScene("bunny", so);
    sh1 = boxes::makeScene("sh1", so);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace boxes;
    std::vector<std::string> args{"01_triangle"};
    std::istringstream lines(std::string(reinterpret_cast<const char*>(data), size));
    for (std::string line; std::getline(lines, line);) args.push_back(line);
    if (args.size() > 64) return 0;  // a shell's argument list; more adds nothing
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());

    CLI::App app("fuzz");
    CommonOptions options;
    addCommonOptions(app, options, "spheres");
    options.dataDir = BOXES_FUZZ_DATA;
    try {
        std::ostringstream help;  // --help goes to stdout: keep the fuzzer's output readable
        auto* old = std::cout.rdbuf(help.rdbuf());
        try {
            parseCommandLine(app, int(argv.size()), argv.data());
        } catch (...) {
            std::cout.rdbuf(old);
            throw;
        }
        std::cout.rdbuf(old);
        if (options.width < 1 || options.height < 1 || options.width > 16384 ||
            options.height > 16384)
            fuzz::fail("image size out of range accepted");
        // Only built-in scenes here: paths are the OBJ target's business, and the fuzzer
        // must not read arbitrary files. Mesh scenes are parsed once per run at most.
        bool builtin = false;
        for (const auto& [name, _] : builtinScenes()) builtin |= name == options.scene;
        if (!builtin) return 0;
        if (options.scene == "bunny" || options.scene == "sh1") {
            // The mesh scene read once, its camera swapped in and back: copying (and, under
            // ASan, freeing) the 70k-triangle mesh per input made false timeouts.
            Scene& scene = options.scene == "bunny" ? bunny : sh1;
            Camera camera = cameraFromOptions(options, scene.camera);
            std::swap(scene.camera, camera);
            fuzz::checkScene(scene);
            if (scene.camera.aspect != options.aspect()) fuzz::fail("aspect not applied");
            std::swap(scene.camera, camera);
        } else {
            Scene scene = sceneFromOptions(options);
            fuzz::checkScene(scene);
            if (scene.camera.aspect != options.aspect()) fuzz::fail("aspect not applied");
        }
    } catch (const ExitRequest&) {
    } catch (const UsageError& e) {
        fuzz::checkMessage(e.what());
    } catch (const InputError& e) {
        fuzz::checkMessage(e.what());
    } catch (const std::invalid_argument& e) {
        fuzz::checkMessage(e.what());
    }
    return 0;
}
