#include "core/app.hpp"

#include <CLI/CLI.hpp>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <iostream>

#include "core/exercise.hpp"
#include "core/mesh.hpp"

#ifndef BOXES_DATA_DIR
#define BOXES_DATA_DIR "data"
#endif

namespace boxes {

RenderSettings CommonOptions::renderSettings() const {
    RenderSettings s;
    s.width = width;
    s.height = height;
    s.threads = threads;
    s.seed = seed;
    return s;
}

void addCommonOptions(CLI::App& app, CommonOptions& o, const std::string& defaultScene) {
    o.scene = defaultScene;
    const char* env = std::getenv("BOXES_DATA");
    o.dataDir = env && *env ? env : BOXES_DATA_DIR;
    app.add_flag("--headless", o.headless, "render without a window and exit");
    app.add_option("--out", o.out, "PNG file for the headless image");
    app.add_option("--width", o.width, "image width in pixels")->check(CLI::Range(1, 16384));
    app.add_option("--height", o.height, "image height in pixels")->check(CLI::Range(1, 16384));
    std::string names;
    for (const auto& [n, _] : builtinScenes()) names += (names.empty() ? "" : ", ") + n;
    app.add_option("--scene", o.scene, "built-in scene (" + names + ") or an OBJ file")
        ->capture_default_str();
    app.add_option("--seed", o.seed, "random seed");
    app.add_flag("--json", o.json, "print the measurements as JSON on stdout");
    app.add_option("--report", o.reportPath, "also write the measurements as JSON to this file");
    app.add_option("--threads", o.threads, "render threads (0: all)")->check(CLI::Range(0, 1024));
    app.add_option("--data", o.dataDir, "the workbook's data folder")->capture_default_str();
    app.add_option("--eye", o.eye, "camera position X,Y,Z");
    app.add_option("--look", o.look, "point the camera looks at X,Y,Z");
    app.add_option("--up", o.up, "camera up vector X,Y,Z");
    app.add_option("--fov", o.fov, "vertical field of view in degrees")
        ->check(CLI::Range(0.001, 179.999));
    app.add_option("--frames", o.frames, "window: stop after this many frames (scripted)")
        ->check(CLI::Range(0, 1000000));
    app.add_option("--keys", o.keys, "window: key names pressed one per frame, e.g. t,t,d");
    app.add_option("--screenshot", o.screenshot, "window: save the last frame to this PNG");
}

Vec3 parseVec3(const std::string& text, const std::string& flag) {
    Vec3 v(0.0f);
    std::string rest = text;
    for (int i = 0; i < 3; ++i) {
        size_t comma = rest.find(',');
        std::string field = i < 2 ? rest.substr(0, comma) : rest;
        if ((i < 2 && comma == std::string::npos) || field.empty())
            throw UsageError(flag + ": expected X,Y,Z, got '" + printable(text) + "'");
        // from_chars: decimal only, all of the field (std::stof took "0x1p3", leading blanks).
        auto [ptr, ec] = std::from_chars(field.data(), field.data() + field.size(), v[i]);
        if (ec != std::errc() || ptr != field.data() + field.size() || !std::isfinite(v[i]))
            throw UsageError(flag + ": '" + printable(field) + "' is not a finite number");
        if (i < 2) rest = rest.substr(comma + 1);
    }
    return v;
}

Camera cameraFromOptions(const CommonOptions& o, const Camera& sceneCamera) {
    Camera c = sceneCamera;
    Vec3 look = c.eye + c.view;
    if (!o.eye.empty()) c.eye = parseVec3(o.eye, "--eye");
    if (!o.look.empty()) look = parseVec3(o.look, "--look");
    if (!o.eye.empty() || !o.look.empty()) {
        c.view = look - c.eye;
        if (isZero(c.view)) throw UsageError("--look equals --eye: the view direction is zero");
    }
    if (!o.up.empty()) {
        c.up = parseVec3(o.up, "--up");
        if (isZero(c.up)) throw UsageError("--up: the up vector is zero");
    }
    if (o.fov > 0.0f) c.fovYDegrees = o.fov;
    c.aspect = o.aspect();
    c.validate();
    return c;
}

Scene sceneFromOptions(const CommonOptions& o) {
    SceneOptions so;
    so.dataDir = o.dataDir;
    so.aspect = o.aspect();
    Scene scene = makeScene(o.scene, so);
    scene.camera = cameraFromOptions(o, scene.camera);
    return scene;
}

}  // namespace boxes
