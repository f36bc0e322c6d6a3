// The command line every step program shares: the common flags and the camera flags (strict
// numbers, one-line errors and exit codes: core/command_line.hpp). What the flags then do is
// the step shell's (core/step.hpp).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/command_line.hpp"
#include "core/render.hpp"
#include "core/scene.hpp"

namespace boxes {

struct CommonOptions {
    bool headless = false;
    std::string out;  // PNG written by the headless path
    int width = 640;
    int height = 480;
    std::string scene;
    uint64_t seed = 1;
    bool json = false;       // print the measurements as JSON on stdout
    std::string reportPath;  // also write them as JSON to this file
    int threads = 0;         // 0: every hardware thread
    std::string dataDir;
    std::string eye, look, up;  // "X,Y,Z"
    float fov = 0.0f;           // degrees; 0: the scene's
    // Scripted window runs (tests, CI, screenshots).
    int frames = 0;
    std::string keys;  // comma-separated SDL key names, one per frame
    std::string screenshot;

    float aspect() const { return float(width) / float(height); }
    // --width --height --threads --seed as render settings.
    RenderSettings renderSettings() const;
};

// Adds --headless --out --width --height --scene --seed --json --report --threads --data
// --eye --look --up --fov --frames --keys --screenshot.
void addCommonOptions(CLI::App& app, CommonOptions& options, const std::string& defaultScene);

// "X,Y,Z" -> vector; throws UsageError naming the flag.
Vec3 parseVec3(const std::string& text, const std::string& flag);

// The scene's camera with --eye/--look/--up/--fov applied (and the image's aspect).
Camera cameraFromOptions(const CommonOptions& options, const Camera& sceneCamera);

// The scene named by --scene, in the image's aspect ratio, data from --data.
Scene sceneFromOptions(const CommonOptions& options);

}  // namespace boxes
