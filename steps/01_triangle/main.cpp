// Step 01: a triangle mesh rendered with three ray/triangle tests; measures their speed and
// their cracks on shared edges and vertices.
#include <SDL2/SDL_keycode.h>
#include <imgui.h>

#include "01_triangle/measure.hpp"
#include "01_triangle/triangle_grid.hpp"
#include "core/render.hpp"
#include "core/step.hpp"

using namespace boxes;

namespace {

TriangleTest parseTest(const std::string& name) {
    if (name == "plane") return TriangleTest::PlaneTest;
    if (name == "mt") return TriangleTest::MollerTrumbore;
    return TriangleTest::Watertight;
}

}  // namespace

int main(int argc, char** argv) {
    std::string testName = "watertight";
    bool flat = false;
    size_t crackRays = 100000;
    TriangleTest test = TriangleTest::Watertight;
    std::shared_ptr<TriangleGrid> grid;  // the scene's mesh; none for a scene without one

    // What the step is, for the shell (core/step.hpp): every main fills the same fields,
    // then adds its own flags, tables and keys.
    StepProgram step;
    step.name = "01_triangle";
    step.description =
        "Step 01: ray/triangle intersection: the plane test, Moller-Trumbore and the "
        "watertight test, side by side.";
    step.title = "Step 01: triangles";
    step.defaultScene = "bunny";
    step.measures = "the tests' speed and cracks";
    step.addOptions = [&](CLI::App& app) {
        app.add_option("--test", testName, "the ray/triangle test to render with")
            ->check(CLI::IsMember({"plane", "mt", "watertight"}))
            ->capture_default_str();
        app.add_flag("--flat", flat,
                     "shade with the triangles' own normals, without interpolation (exercise 1.6)");
        app.add_option("--crack-rays", crackRays, "rays per mesh and feature for the crack count")
            ->check(CLI::Range(size_t(1), size_t(10000000)));
    };
    // The mesh goes through a uniform grid (triangle_grid.hpp) to the selected test.
    step.addGeometry = [&](StepRun& run) {
        test = parseTest(testName);
        if (!run.scene.hasMesh()) return;
        grid = std::make_shared<TriangleGrid>(run.scene.mesh, run.scene.meshMaterial, test);
        grid->setSmoothShading(!flat);
        run.scene.geometries.push_back(grid);
    };
    step.caption = [&](const StepRun& run) {
        return "scene '" + run.scene.name + "' with the " + triangleTestName(test) + " test";
    };
    step.measure = [&](StepRun& run, Report& report) {
        if (grid) measureTriangleTests(run, *grid, crackRays, report);
    };

    // The window: T switches the test, M marks where the tests disagree.
    bool marks = false;
    size_t differ = 0;
    step.keys = {{SDLK_t, "next triangle test (plane / Moller-Trumbore / watertight)"},
                 {SDLK_m, "mark pixels where the tests disagree (magenta)"}};
    step.onKey = [&](StepRun&, int key) {
        if (key == SDLK_t) test = TriangleTest((int(test) + 1) % 3);
        if (key == SDLK_m) marks = !marks;
        return key == SDLK_t || key == SDLK_m;
    };
    step.render = [&](StepRun& run) {
        if (grid) grid->setTest(test);
        Image image = renderImage(run.scene, run.camera, run.settings);
        if (marks && grid)
            differ = markDisagreements(*grid, run.camera, image, run.options.threads);
        return image;
    };
    step.panel = [&](StepRun& run) {
        ImGui::Text("test: %s", triangleTestName(test));
        ImGui::Text("render: %.1f ms (%dx%d)", run.renderMs, run.settings.width,
                    run.settings.height);
        if (marks) ImGui::Text("pixels where the tests disagree: %zu", differ);
    };
    return runStep(argc, argv, step);
}
