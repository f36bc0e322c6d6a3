// Step 04: bounding volume hierarchies. Renders a mesh through the hierarchy (exercise 4.4
// for every ray) beside the hierarchy seen from above, its boxes coloured by frustum
// culling (4.6-4.8); `--measure` adds the tables; `trace` and `check` are the engine's.
#include <SDL2/SDL_keycode.h>
#include <imgui.h>

#include <algorithm>

#include "04_bvh/advanced/build.hpp"
#include "04_bvh/advanced/commands.hpp"
#include "04_bvh/culling_map.hpp"
#include "04_bvh/measure.hpp"
#include "core/app.hpp"
#include "core/orbit.hpp"
#include "core/timing.hpp"

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
    return runMain("04_bvh", [&] {
        CLI::App app{
            "Step 04: bounding volume hierarchies: builders, traversal, frustum culling, "
            "and a trace command for ray files."};
        CommonOptions opts;
        addCommonOptions(app, opts, "bunny");
        std::string builderName = "sah";
        app.add_option("--builder", builderName,
                       "hierarchy builder: midpoint, median, sah, sweep-sah, sbvh")
            ->capture_default_str();
        MeasureSettings measure;
        app.add_option("--bins", measure.bins, "binned SAH: bins per axis")
            ->check(CLI::Range(2, 256))
            ->capture_default_str();
        addMeasureOptions(app, measure);
        EngineCommands commands(app);
        parseCommandLine(app, argc, argv);
        if (std::optional<int> code = commands.run()) return *code;

        BvhBuildOptions build;
        build.builder = parseBvhBuilder(builderName);
        build.bins = measure.bins;
        Scene scene = sceneFromOptions(opts);
        std::shared_ptr<MeshBvhGeometry> geometry = meshGeometry(scene, build);
        RenderSettings settings = opts.renderSettings();
        if (opts.headless) {
            Report report;
            report.program = "04_bvh";
            std::string out = headlessPath(opts, report.program);
            renderHeadlessImage(scene, scene.camera, settings, out,
                                "scene '" + scene.name + "' through the " +
                                    bvhBuilderName(build.builder) + " hierarchy",
                                report);
            if (geometry) addTreeReport(report, scene, *geometry, out, opts, measure);
            writeReport(report, opts);
            return 0;
        }

        // The window: left the view through the hierarchy, right the hierarchy from above.
        settings.width = std::max(1, opts.width / 2);
        Camera start = scene.camera;
        start.aspect = float(settings.width) / float(settings.height);
        OrbitController orbit(start);
        CullingMapWindow map;
        bool dirty = true;
        Image image(opts.width, opts.height);
        double renderMs = 0.0;
        WindowCallbacks cb;
        cb.keys = {
            {SDLK_b, "next builder (midpoint / median / binned SAH / spatial splits), rebuilds"}};
        for (const KeyBinding& k : CullingMapWindow::keys()) cb.keys.push_back(k);
        cb.onKey = [&](int key) {
            constexpr BvhBuilder cycle[] = {BvhBuilder::Midpoint, BvhBuilder::Median,
                                            BvhBuilder::BinnedSah, BvhBuilder::SpatialSah};
            if (key == SDLK_b && geometry) {
                const BvhBuilder* at = std::find(std::begin(cycle), std::end(cycle), build.builder);
                build.builder =
                    at == std::end(cycle) || at + 1 == std::end(cycle) ? cycle[0] : at[1];
                geometry = meshGeometry(scene, build);
                return dirty = true;
            }
            if (!map.onKey(key)) return false;
            return dirty = true;
        };
        orbit.addTo(cb, [&] { dirty = true; });
        cb.frame = [&](double) -> const Image& {
            if (!dirty) return image;
            Stopwatch watch;
            Image view = renderImage(scene, orbit.camera(), settings);
            renderMs = watch.milliseconds();
            for (int y = 0; y < view.height(); ++y)
                for (int x = 0; x < view.width(); ++x) image.at(x, y) = view.at(x, y);
            if (geometry)
                map.draw(image, settings.width, geometry->bvh(), orbit.camera(), scene.camera.up);
            dirty = false;
            return image;
        };
        cb.panel = [&] {
            ImGui::Text("builder: %s  render: %.1f ms", bvhBuilderName(build.builder), renderMs);
            if (!geometry) return;
            const BvhBuildStats& s = geometry->stats();
            ImGui::Text("build %.1f ms, %zu nodes, depth %d, SAH cost %.1f", s.buildMs, s.nodes,
                        s.depth, s.sahCost);
            for (const std::string& line : map.status()) ImGui::TextUnformatted(line.c_str());
        };
        runWindow(opts.windowOptions("Step 04: bounding volume hierarchies"), cb);
        return 0;
    });
}
