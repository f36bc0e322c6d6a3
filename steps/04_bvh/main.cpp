// Step 04: bounding volume hierarchies. Renders a mesh through the hierarchy (exercise 4.4
// for every ray) beside the hierarchy seen from above, its boxes coloured by frustum
// culling (4.6-4.8); `--measure` adds the tables; `trace` and `check` are the engine's.
#include <SDL2/SDL_keycode.h>
#include <imgui.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <functional>
#include <memory>
#include <optional>

#include "04_bvh/cost_map.hpp"
#include "04_bvh/culling_map.hpp"
#include "04_bvh/measure.hpp"
#include "04_bvh/trace.hpp"
#include "core/step.hpp"

using namespace boxes;

int main(int argc, char** argv) {
    std::string builderName = "sah";
    MeasureSettings measure;
    std::function<std::optional<int>()> engineCommand;  // trace, check, rays (measure.hpp)
    BvhBuildOptions build;
    std::shared_ptr<MeshBvhGeometry> geometry;  // the scene's mesh; none for a scene without one

    // What the step is, for the shell (core/step.hpp), then its own flags, tables and keys.
    StepProgram step;
    step.name = "04_bvh";
    step.description =
        "Step 04: bounding volume hierarchies: builders, traversal, frustum culling, and a "
        "trace command for ray files.";
    step.title = "Step 04: bounding volume hierarchies";
    step.defaultScene = "bunny";
    step.measures = "builders, traversal, cracks and culling";
    step.addOptions = [&](CLI::App& app) {
        app.add_option("--builder", builderName, "hierarchy builder (exercises 4.1-4.3)")
            ->check(CLI::IsMember({"midpoint", "median", "sah"}))
            ->capture_default_str();
        app.add_option("--bins", measure.bins, "binned SAH: bins per axis")
            ->check(CLI::Range(2, 256))
            ->capture_default_str();
        addMeasureOptions(app, measure);
        engineCommand = addEngineCommands(app);
    };
    step.command = [&] { return engineCommand(); };
    // The mesh through a hierarchy of the chapter's builders (trace.hpp).
    step.addGeometry = [&](StepRun& run) {
        build.builder = parseBvhBuilder(builderName);
        build.bins = measure.bins;
        geometry = addMeshBvh(run.scene, build);
    };
    step.caption = [&](const StepRun& run) {
        return "scene '" + run.scene.name + "' through the " + bvhBuilderName(build.builder) +
               " hierarchy";
    };
    step.afterImage = [&](StepRun& run, Report& report) {
        if (geometry) addTreeReport(report, run.scene, *geometry, run.png, run.options);
    };
    step.measure = [&](StepRun& run, Report& report) {
        if (geometry) measureTree(report, run.scene, *geometry, run.options, measure, run.png);
    };
    // The window: left the view through the hierarchy, right the hierarchy from above.
    CullingMapWindow map;
    bool heat = false;  // the view's tests per pixel instead of the picture and the map
    step.keys = {{SDLK_b, "next builder (midpoint / median / binned SAH), rebuilds"},
                 {SDLK_h, "heat map: box and triangle tests per pixel / the picture"}};
    for (const KeyBinding& k : CullingMapWindow::keys()) step.keys.push_back(k);
    step.openWindow = [&](StepRun& run) {
        run.settings.width = std::max(1, run.options.width / 2);
        run.scene.camera.aspect = float(run.settings.width) / float(run.settings.height);
    };
    step.onKey = [&](StepRun& run, int key) {
        if (key == SDLK_h) return heat = geometry && !heat, true;  // no mesh, no map
        if (key != SDLK_b || !geometry) return map.onKey(key);
        build.builder = BvhBuilder((int(build.builder) + 1) % std::size(kExerciseBuilders));
        geometry = addMeshBvh(run.scene, build);
        return true;
    };
    step.render = [&](StepRun& run) {
        if (heat) return viewCostMap(geometry->bvh(), run.camera, run.settings, build.builder);
        Image view = renderImage(run.scene, run.camera, run.settings);
        Image image(2 * run.settings.width, run.settings.height);
        for (int y = 0; y < view.height(); ++y)
            for (int x = 0; x < view.width(); ++x) image.at(x, y) = view.at(x, y);
        if (geometry)
            map.draw(image, run.settings.width, geometry->bvh(), run.camera, run.scene.camera.up);
        return image;
    };
    step.panel = [&](StepRun& run) {
        ImGui::Text("builder: %s  render: %.1f ms", bvhBuilderName(build.builder), run.renderMs);
        if (!geometry) return;
        const BvhBuildStats& s = geometry->stats();
        ImGui::Text("build %.1f ms, %zu nodes, depth %d, SAH cost %.1f", s.buildMs, s.nodes,
                    s.depth, s.sahCost);
        for (const std::string& line : map.status()) ImGui::TextUnformatted(line.c_str());
    };
    return runStep(argc, argv, step);
}
