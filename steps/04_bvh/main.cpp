// Step 04: bounding volume hierarchies. Renders a mesh through the hierarchy (exercise 4.4
// for every ray) beside the hierarchy seen from above, its boxes coloured by frustum
// culling (4.6-4.8); `--measure` adds the tables; `trace` and `check` are the engine's.
#include <SDL2/SDL_keycode.h>
#include <imgui.h>

#include <algorithm>
#include <memory>

#include "04_bvh/advanced/build.hpp"
#include "04_bvh/advanced/commands.hpp"
#include "04_bvh/culling_map.hpp"
#include "04_bvh/measure.hpp"
#include "core/render.hpp"
#include "core/step.hpp"

using namespace boxes;

// The scene's mesh through a hierarchy of `options.builder` (the engine builds every one).
static std::shared_ptr<MeshBvhGeometry> meshGeometry(Scene& scene, const BvhBuildOptions& options) {
    scene.geometries.clear();
    if (!scene.hasMesh()) return nullptr;
    BvhBuildStats stats;
    Bvh bvh = buildEngineBvh(scene.mesh, options, &stats);
    auto geometry =
        std::make_shared<MeshBvhGeometry>(scene.mesh, scene.meshMaterial, std::move(bvh), stats);
    scene.geometries.push_back(geometry);
    return geometry;
}

int main(int argc, char** argv) {
    std::string builderName = "sah";
    MeasureSettings measure;
    std::unique_ptr<EngineCommands> commands;  // trace and check, on the same command line
    BvhBuildOptions build;
    std::shared_ptr<MeshBvhGeometry> geometry;  // none for a scene without a mesh

    StepProgram step;
    step.name = "04_bvh";
    step.description =
        "Step 04: bounding volume hierarchies: builders, traversal, frustum culling, and a "
        "trace command for ray files.";
    step.title = "Step 04: bounding volume hierarchies";
    step.defaultScene = "bunny";
    step.addOptions = [&](CLI::App& app) {
        app.add_option("--builder", builderName,
                       "hierarchy builder: midpoint, median, sah, sweep-sah, sbvh")
            ->capture_default_str();
        app.add_option("--bins", measure.bins, "binned SAH: bins per axis")
            ->check(CLI::Range(2, 256))
            ->capture_default_str();
        addMeasureOptions(app, measure);
        commands = std::make_unique<EngineCommands>(app);
    };
    step.command = [&] { return commands->run(); };
    step.addGeometry = [&](StepRun& run) {
        build.builder = parseBvhBuilder(builderName);
        build.bins = measure.bins;
        geometry = meshGeometry(run.scene, build);
    };
    step.caption = [&](const StepRun& run) {
        return "scene '" + run.scene.name + "' through the " + bvhBuilderName(build.builder) +
               " hierarchy";
    };
    step.measure = [&](StepRun& run, Report& report) {
        if (geometry) addTreeReport(report, run.scene, *geometry, run.png, run.options, measure);
    };

    // The window: left the view through the hierarchy, right the hierarchy from above.
    CullingMapWindow map;
    step.keys = {
        {SDLK_b, "next builder (midpoint / median / binned SAH / spatial splits), rebuilds"}};
    for (const KeyBinding& k : CullingMapWindow::keys()) step.keys.push_back(k);
    step.openWindow = [&](StepRun& run) {
        run.settings.width = std::max(1, run.options.width / 2);
        run.scene.camera.aspect = float(run.settings.width) / float(run.settings.height);
    };
    step.onKey = [&](StepRun& run, int key) {
        constexpr BvhBuilder cycle[] = {BvhBuilder::Midpoint, BvhBuilder::Median,
                                        BvhBuilder::BinnedSah, BvhBuilder::SpatialSah};
        if (key != SDLK_b || !geometry) return map.onKey(key);
        const BvhBuilder* at = std::find(std::begin(cycle), std::end(cycle), build.builder);
        build.builder = at == std::end(cycle) || at + 1 == std::end(cycle) ? cycle[0] : at[1];
        geometry = meshGeometry(run.scene, build);
        return true;
    };
    step.render = [&](StepRun& run) {
        Image view = renderImage(run.scene, run.camera, run.settings);
        Image image(run.options.width, run.options.height);
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
