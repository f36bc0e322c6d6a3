// Step 04: bounding volume hierarchies. Renders a mesh through the hierarchy (exercise 4.4
// for every ray) beside the hierarchy seen from above, its boxes coloured by frustum
// culling (4.6-4.8); `--measure` adds the tables; `trace` and `check` are the engine's.
#include <SDL2/SDL_keycode.h>
#include <imgui.h>

#include <algorithm>

#include "04_bvh/advanced/build.hpp"
#include "04_bvh/advanced/commands.hpp"
#include "04_bvh/measure.hpp"
#include "core/app.hpp"
#include "core/orbit.hpp"
#include "core/timing.hpp"

using namespace boxes;

namespace {

// The scene's mesh through a hierarchy of `options.builder` (the engine builds every one).
std::shared_ptr<MeshBvhGeometry> meshGeometry(Scene& scene, const BvhBuildOptions& options) {
    scene.geometries.clear();
    if (!scene.hasMesh()) return nullptr;
    BvhBuildStats stats;
    Bvh bvh = buildEngineBvh(scene.mesh, options, &stats);
    auto geometry =
        std::make_shared<MeshBvhGeometry>(scene.mesh, scene.meshMaterial, std::move(bvh), stats);
    scene.geometries.push_back(geometry);
    return geometry;
}

// The window's right half: the hierarchy from above, culled by the left view's frustum
// (far plane through the mesh's centre, or 3x as far: it cuts the mesh).
void drawMap(Image& image, int x0, const Bvh& bvh, const Camera& camera, float farScale,
             CullTest test, int level, Vec3 up, CullCounts counts[2]) {
    Bounds3f bounds = bvh.bounds();
    float radius = 0.5f * glm::length(bounds.diagonal());
    float centre = glm::dot(bounds.centroid() - camera.eye, glm::normalize(camera.view));
    Frustum f = makeFrustum(camera, 0.01f * radius, std::max(0.02f * radius, farScale * centre));
    cullHierarchy(bvh, f, CullTest::Planes, &counts[0]);
    cullHierarchy(bvh, f, CullTest::PlanesAndCorners, &counts[1]);
    drawCullingMap(image, x0, image.width() - x0, bvh, f, test, level, up);
}

}  // namespace

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
        bool measuring = false;
        app.add_flag("--measure", measuring,
                     "also measure builders, traversal, cracks and culling");
        app.add_option("--measure-rays", measure.traceRays, "rays per kind in the speed table")
            ->check(CLI::Range(size_t(100), size_t(10000000)));
        app.add_option("--crack-rays", measure.crackRays,
                       "rays per mesh and feature for the crack count")
            ->check(CLI::Range(size_t(1), size_t(10000000)));
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
            if (geometry) {
                report.facts["build_ms"] = geometry->stats().buildMs;
                report.facts["nodes"] = geometry->stats().nodes;
                report.facts["sah_cost"] = geometry->stats().sahCost;
                addCullingMap(report, geometry->bvh(), out, opts.width, opts.height,
                              scene.camera.up);
                measure.seed = opts.seed;
                measure.dataDir = opts.dataDir;
                if (measuring)
                    addMeasurements(report, {scene.name, &scene.mesh}, geometry->bvh(), measure);
            }
            writeReport(report, opts);
            return 0;
        }

        // The window: left the view through the hierarchy, right the hierarchy from above.
        settings.width = std::max(1, opts.width / 2);
        Camera start = scene.camera;
        start.aspect = float(settings.width) / float(settings.height);
        OrbitController orbit(start);
        CullTest test = CullTest::Planes;
        int level = 6;
        float farScale = 1.0f;
        bool dirty = true;
        Image image(opts.width, opts.height);
        double renderMs = 0.0;
        CullCounts counts[2];
        WindowCallbacks cb;
        cb.keys = {
            {SDLK_b, "next builder (midpoint / median / binned SAH / spatial splits), rebuilds"},
            {SDLK_c, "culling test: planes / planes + frustum corners"},
            {SDLK_l, "show deeper boxes in the map"},
            {SDLK_k, "show shallower boxes in the map"},
            {SDLK_f, "far plane: through the target / 3x further"}};
        cb.onKey = [&](int key) {
            constexpr BvhBuilder cycle[] = {BvhBuilder::Midpoint, BvhBuilder::Median,
                                            BvhBuilder::BinnedSah, BvhBuilder::SpatialSah};
            if (key == SDLK_b && geometry) {
                const BvhBuilder* at = std::find(std::begin(cycle), std::end(cycle), build.builder);
                build.builder =
                    at == std::end(cycle) || at + 1 == std::end(cycle) ? cycle[0] : at[1];
                geometry = meshGeometry(scene, build);
            } else if (key == SDLK_c) {
                test = test == CullTest::Planes ? CullTest::PlanesAndCorners : CullTest::Planes;
            } else if (key == SDLK_l || key == SDLK_k) {
                level = std::clamp(level + (key == SDLK_l ? 1 : -1), 0, 64);
            } else if (key == SDLK_f) {
                farScale = farScale == 1.0f ? 3.0f : 1.0f;
            } else {
                return false;
            }
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
                drawMap(image, settings.width, geometry->bvh(), orbit.camera(), farScale, test,
                        level, scene.camera.up, counts);
            dirty = false;
            return image;
        };
        cb.panel = [&] {
            ImGui::Text("builder: %s  render: %.1f ms", bvhBuilderName(build.builder), renderMs);
            if (!geometry) return;
            const BvhBuildStats& s = geometry->stats();
            ImGui::Text("build %.1f ms, %zu nodes, depth %d, SAH cost %.1f", s.buildMs, s.nodes,
                        s.depth, s.sahCost);
            ImGui::Text("map (right): %s, depth %d",
                        test == CullTest::Planes ? "planes (p-vertex)" : "planes + frustum corners",
                        level);
            ImGui::Text("grey culled, green kept, red wrongly kept; blue: frustum");
            for (int i = 0; i < 2; ++i)
                ImGui::Text("%-9s visited %zu culled %zu kept %zu wrongly kept %zu",
                            i == 0 ? "planes" : "+corners", counts[i].visited, counts[i].culled,
                            counts[i].kept, counts[i].wronglyKept);
        };
        runWindow(opts.windowOptions("Step 04: bounding volume hierarchies"), cb);
        return 0;
    });
}
