// Step 03: bounding boxes. A scene of thousands of spheres and triangles plus the bunny,
// rendered with and without a box pre-test; the slab tests' speed against their wrong
// answers on hard rays.
#include <SDL2/SDL_keycode.h>
#include <imgui.h>

#include <CLI/CLI.hpp>

#include "03_aabb/measure.hpp"
#include "core/step.hpp"

using namespace boxes;

int main(int argc, char** argv) {
    size_t sphereCount = 3000, triangleCount = 4000, hardRays = 5000;
    std::string pretestName = "on";
    bool pretest = true;
    int measureWidth = 64, measureHeight = 48;
    ManyObjects objects;  // the scene's objects, each with its boxes, and their test counts

    // What the step is, for the shell (core/step.hpp): every main fills the same fields,
    // then adds its own flags, tables and keys.
    StepProgram step;
    step.name = "03_aabb";
    step.description =
        "Step 03: bounding boxes: bounds, union, overlap, the robust slab test, and a scene "
        "rendered with and without a box pre-test.";
    step.title = "Step 03: bounding boxes";
    step.defaultScene = "many";
    step.measures = "the slab tests on hard rays and the pre-test";
    step.addOptions = [&](CLI::App& app) {
        app.get_option("--scene")->description(
            "'many' (this step's scene: spheres, triangles and the bunny), or a core scene / OBJ "
            "file whose spheres and mesh get boxes");
        app.add_option("--spheres", sphereCount, "spheres in the 'many' scene")
            ->check(CLI::Range(size_t(0), size_t(1000000)));
        app.add_option("--triangles", triangleCount, "small triangles in the 'many' scene")
            ->check(CLI::Range(size_t(0), size_t(1000000)));
        app.add_option("--pretest", pretestName, "the bounding-box pre-test in the headless image")
            ->check(CLI::IsMember({"on", "off"}))
            ->capture_default_str();
        app.add_option("--measure-width", measureWidth,
                       "image width of the with/without pre-test frames")
            ->check(CLI::Range(1, 4096));
        app.add_option("--measure-height", measureHeight,
                       "image height of the with/without pre-test frames")
            ->check(CLI::Range(1, 4096));
        app.add_option("--hard-rays", hardRays, "hard rays per category for the slab table")
            ->check(CLI::Range(size_t(1), size_t(1000000)));
    };
    // The scene's objects carry their own geometry (why_we_care.hpp); run.scene shares it.
    step.makeScene = [&](const CommonOptions& o) {
        if (o.scene != "many") {
            objects = wrapScene(sceneFromOptions(o));
            return objects.scene;
        }
        objects = makeManyObjects(o.dataDir, o.aspect(), sphereCount, triangleCount, true, o.seed);
        objects.scene.camera = cameraFromOptions(o, objects.scene.camera);
        return objects.scene;
    };
    step.addGeometry = [&](StepRun&) {
        pretest = pretestName == "on";
        objects.setPretest(pretest);
        objects.counts->reset();
    };
    step.caption = [&](const StepRun& run) {
        return "scene '" + run.scene.name + "', box pre-test " + pretestName;
    };
    step.afterImage = [&](StepRun& run, Report& report) {
        report.facts["primitive_tests_per_ray"] = double(objects.counts->primitiveTests.load()) /
                                                  double(std::max<uint64_t>(1, run.counts.total()));
    };
    step.measure = [&](StepRun& run, Report& report) {
        measureBoundingBoxes(run, objects, hardRays, measureWidth, measureHeight, report);
    };

    // The window: the view with or without the pre-test, its tests per ray, and per pixel.
    ManyObjects::View shown;
    int heat = 0;  // the picture, or a heat map of its tests per pixel
    step.keys = {{SDLK_b, "bounding-box pre-test on / off (off: quarter resolution)"},
                 {SDLK_h, "heat map: primitive tests / box tests per pixel / the picture"}};
    step.onKey = [&](StepRun&, int key) {
        if (key == SDLK_b) pretest = !pretest;
        if (key == SDLK_h) heat = (heat + 1) % 3;
        return key == SDLK_b || key == SDLK_h;
    };
    step.render = [&](StepRun& run) {
        shown = objects.render(run.camera, run.settings, pretest);
        return shown.show(heat);
    };
    step.panel = [&](StepRun& run) {
        ImGui::Text("pre-test: %s", pretest ? "on" : "off (quarter resolution)");
        ImGui::Text("render: %.1f ms (%dx%d)", run.renderMs, shown.image.width(),
                    shown.image.height());
        ImGui::Text("primitive tests/ray: %.1f, box tests/ray: %.1f", shown.primitiveTestsPerRay,
                    shown.boxTestsPerRay);
    };
    return runStep(argc, argv, step);
}
