// Step 04: bounding volume hierarchies. Renders a mesh through the hierarchy, shows which
// of its boxes frustum culling keeps, measures builders and traversal, and traces batches
// of rays from files (`trace`) so any tracer can be compared with this one ray by ray.
#include <SDL2/SDL_keycode.h>
#include <imgui.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <nlohmann/json.hpp>

#include "04_bvh/bvh4.hpp"
#include "04_bvh/measure.hpp"
#include "core/app.hpp"
#include "core/orbit.hpp"
#include "core/render.hpp"
#include "core/timing.hpp"

using namespace boxes;

namespace {

// CPU time of the process (all threads): on a loaded machine the wall time includes the
// time other processes held the core; the CPU time of one thread does not.
double processCpuSeconds() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

struct TraceOptions {
    std::string mesh, rays, hits, builder = "sah";
    int threads = 1, repeat = 1, bins = BvhBuildOptions{}.bins, width = 2;
    bool count = false;
};

// `trace`: build, trace every ray (median of --repeat), write HITS.bin, one JSON line.
int runTrace(const TraceOptions& o) {
    Mesh mesh = loadObj(o.mesh);
    std::vector<Ray> rays = readRays(o.rays);
    BvhBuildOptions build;
    build.builder = parseBvhBuilder(o.builder);
    build.bins = o.bins;
    BvhBuildStats stats;
    double buildCpuStart = processCpuSeconds();
    Bvh bvh = buildBvh(mesh, build, &stats);
    // --width 4 or 8: the binary tree collapsed to 4- or 8-wide nodes (bvh4.hpp); the
    // collapse counts as build time.
    Stopwatch collapseWatch;
    Bvh4 wide = o.width == 4 ? collapseToBvh4(bvh) : Bvh4{};
    Bvh8 wide8 = o.width == 8 ? collapseToBvh8(bvh) : Bvh8{};
    if (o.width != 2) stats.buildMs += collapseWatch.seconds() * 1e3;
    double buildCpuSeconds = processCpuSeconds() - buildCpuStart;
    std::vector<TraceHit> hits;
    std::vector<double> seconds, cpuSeconds;
    for (int i = 0; i < o.repeat; ++i) {
        Stopwatch watch;
        double cpuStart = processCpuSeconds();
        if (o.width == 4)
            traceBatch(wide, rays, hits, o.threads);
        else if (o.width == 8)
            traceBatch(wide8, rays, hits, o.threads);
        else
            traceBatch(bvh, rays, hits, o.threads);
        seconds.push_back(watch.seconds());
        cpuSeconds.push_back(processCpuSeconds() - cpuStart);
    }
    double traceSeconds = summarize(seconds).median;
    size_t hitCount = 0;
    for (const TraceHit& h : hits) hitCount += h.triangle != kNoPrimitive;
    writeHits(o.hits, hits);
    nlohmann::json j = {{"tris", mesh.triangleCount()},
                        {"rays", rays.size()},
                        {"build_ms", stats.buildMs},
                        {"build_cpu_ms", buildCpuSeconds * 1e3},
                        {"trace_ms", traceSeconds * 1e3},
                        {"trace_cpu_ms", summarize(cpuSeconds).median * 1e3},
                        {"mrays_per_s", double(rays.size()) / traceSeconds / 1e6},
                        {"hits", hitCount},
                        {"threads", o.threads},
                        {"builder", bvhBuilderName(build.builder)},
                        {"width", o.width},
                        {"isa", traceUsesAvx2() ? "avx2" : "baseline"},
                        {"bins", o.bins},
                        {"repeat", o.repeat},
                        {"nodes", stats.nodes},
                        {"references", bvh.primitiveIndices.size()},
                        {"depth", stats.depth},
                        {"sah_cost", stats.sahCost}};
    // --width 4 or 8: the traced tree's own figures; nodes, depth and SAH cost stay the
    // binary's.
    if (o.width != 2) {
        BvhWideStats wideStats = o.width == 4 ? bvhWideStats(wide) : bvhWideStats(wide8);
        std::string suffix = "_" + std::to_string(o.width) + "wide";
        j["nodes" + suffix] = wideStats.nodes;
        j["depth" + suffix] = wideStats.depth;
        j["sah_cost" + suffix] = wideStats.nodeSahCost + wideStats.leafSahCost;
    }
    // --count: the work per ray, from one more pass outside the timed ones.
    if (o.count) {
        TraversalCounts c = o.width == 4   ? countWork(wide, rays)
                            : o.width == 8 ? countWork(wide8, rays)
                                           : countWork(bvh, rays);
        double perRay = rays.empty() ? 0.0 : 1.0 / double(rays.size());
        j["triangles_per_ray"] = double(c.triangles) * perRay;
        if (o.width != 2) {
            j["nodes_per_ray"] = double(c.nodes) * perRay;
            j["leaves_per_ray"] = double(c.leaves) * perRay;
            j["packets_per_ray"] = double(c.packets) * perRay;
        }
    }
    std::cout << j.dump() << "\n";
    return 0;
}

struct CheckOptions {
    std::string mesh, rays, kind = "random";
    size_t count = 10000, cracks = 0;
    int threads = 0;
    uint64_t seed = 1;
};

// `check`: every builder's nearest hits against brute force over all triangles, and
// optionally rays aimed at shared edges and vertices. Exit 1 on any difference.
int runCheck(const CheckOptions& o) {
    Mesh mesh = loadObj(o.mesh);
    std::vector<Ray> rays;
    if (!o.rays.empty()) {
        rays = readRays(o.rays);
    } else {
        RayKind kind = o.kind == "primary"   ? RayKind::Primary
                       : o.kind == "diffuse" ? RayKind::Diffuse
                                             : RayKind::Random;
        rays = makeRays(mesh, kind, o.count, o.seed);
    }
    Stopwatch watch;
    std::vector<TraceHit> reference;
    traceBatchBruteForce(mesh, rays, reference, o.threads);
    double bruteSeconds = watch.seconds();
    nlohmann::json j = {{"mesh", o.mesh}, {"rays", rays.size()}, {"brute_force_s", bruteSeconds}};
    size_t total = 0;
    // The exercises' builders, and the SAH with spatial splits (its leaves share triangles).
    for (BvhBuilder builder : {BvhBuilder::Midpoint, BvhBuilder::Median, BvhBuilder::BinnedSah,
                               BvhBuilder::SpatialSah}) {
        BvhBuildOptions build;
        build.builder = builder;
        Bvh bvh = buildBvh(mesh, build);
        std::vector<TraceHit> hits;
        traceBatch(bvh, rays, hits, o.threads);
        size_t differ = 0, hit = 0;
        for (size_t i = 0; i < rays.size(); ++i) {
            differ += !hitsAgree(hits[i], reference[i]);
            hit += hits[i].triangle != kNoPrimitive;
        }
        j[bvhBuilderName(builder)] = {{"differ", differ}, {"hits", hit}};
        total += differ;
        // The SAH trees' 4- and 8-wide collapses (bvh4.hpp).
        if (builder == BvhBuilder::BinnedSah || builder == BvhBuilder::SpatialSah) {
            auto countDiffering = [&] {
                size_t n = 0;
                for (size_t i = 0; i < rays.size(); ++i) n += !hitsAgree(hits[i], reference[i]);
                total += n;
                return n;
            };
            std::string name = bvhBuilderName(builder);
            traceBatch(collapseToBvh4(bvh), rays, hits, o.threads);
            j[name + "-4wide"] = {{"differ", countDiffering()}};
            traceBatch(collapseToBvh8(bvh), rays, hits, o.threads);
            j[name + "-8wide"] = {{"differ", countDiffering()}};
        }
    }
    if (o.cracks > 0) {
        Table t = measureBvhCracks({{o.mesh, &mesh}}, o.cracks, o.seed);
        t.print(std::cerr);
        size_t cracks = 0;
        for (const auto& row : t.rows) cracks += size_t(std::get<long long>(row[4]));
        j["crack_rays"] = o.cracks;
        j["cracks"] = cracks;
        total += cracks;
    }
    j["ok"] = total == 0;
    std::cout << j.dump() << "\n";
    return total == 0 ? 0 : 1;
}

const char* testName(CullTest test) {
    return test == CullTest::Planes ? "planes (p-vertex)" : "planes + frustum corners";
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
        int bins = BvhBuildOptions{}.bins;
        app.add_option("--bins", bins, "binned SAH: bins per axis")
            ->check(CLI::Range(2, 256))
            ->capture_default_str();
        bool measure = false;
        app.add_flag("--measure", measure, "also measure builders, traversal, cracks and culling");
        size_t measureRays = 100000;
        app.add_option("--measure-rays", measureRays, "rays per kind in the speed table")
            ->check(CLI::Range(size_t(100), size_t(10000000)));
        size_t crackRays = 5000;
        app.add_option("--crack-rays", crackRays, "rays per mesh and feature for the crack count")
            ->check(CLI::Range(size_t(1), size_t(10000000)));

        TraceOptions trace;
        CLI::App* traceCommand = app.add_subcommand(
            "trace", "trace RAYS.bin against MESH.obj, write HITS.bin, print one JSON line");
        traceCommand->add_option("--mesh", trace.mesh, "the mesh (OBJ)")->required();
        traceCommand
            ->add_option("--rays", trace.rays, "float32 ox oy oz tmin dx dy dz tmax per ray")
            ->required();
        traceCommand
            ->add_option("--hits", trace.hits, "written: float32 t, uint32 triangle per ray")
            ->required();
        traceCommand
            ->add_option("--builder", trace.builder,
                         "midpoint, median, sah, sweep-sah or sbvh (SAH with spatial splits)")
            ->check(CLI::IsMember({"midpoint", "median", "sah", "sweep-sah", "sbvh"}))
            ->capture_default_str();
        traceCommand->add_option("--threads", trace.threads, "threads")
            ->check(CLI::Range(1, 256))
            ->capture_default_str();
        traceCommand->add_option("--repeat", trace.repeat, "trace runs; the median is reported")
            ->check(CLI::Range(1, 1000))
            ->capture_default_str();
        traceCommand
            ->add_option("--width", trace.width,
                         "2: the binary tree; 4 or 8: its collapse to 4- or 8-wide nodes, SIMD "
                         "traversal")
            ->check(CLI::IsMember({2, 4, 8}))
            ->capture_default_str();
        traceCommand->add_option("--bins", trace.bins, "binned SAH: bins per axis")
            ->check(CLI::Range(2, 256))
            ->capture_default_str();
        traceCommand->add_flag("--count", trace.count,
                               "also count the work per ray (one more, untimed pass): "
                               "triangles tested; with --width 4 or 8 also nodes, leaves "
                               "and packets");

        CheckOptions check;
        CLI::App* checkCommand = app.add_subcommand(
            "check",
            "compare every builder's nearest hits with brute force; exit 1 on a difference");
        checkCommand->add_option("--mesh", check.mesh, "the mesh (OBJ)")->required();
        checkCommand->add_option("--rays", check.rays, "a rays file (else --kind and --count)");
        checkCommand->add_option("--kind", check.kind, "generated rays: primary, diffuse, random")
            ->check(CLI::IsMember({"primary", "diffuse", "random"}));
        checkCommand->add_option("--count", check.count, "generated rays")
            ->check(CLI::Range(size_t(1), size_t(100000000)));
        checkCommand->add_option("--cracks", check.cracks,
                                 "also this many rays per feature at shared edges and vertices");
        checkCommand->add_option("--threads", check.threads, "threads (0: all)");
        checkCommand->add_option("--seed", check.seed, "seed of generated rays");
        app.require_subcommand(0, 1);
        parseCommandLine(app, argc, argv);

        if (*traceCommand) return runTrace(trace);
        if (*checkCommand) return runCheck(check);

        BvhBuildOptions buildOptions;
        buildOptions.builder = parseBvhBuilder(builderName);
        buildOptions.bins = bins;
        Scene scene = sceneFromOptions(opts);
        std::shared_ptr<MeshBvhGeometry> geometry;
        if (scene.hasMesh()) {
            geometry =
                std::make_shared<MeshBvhGeometry>(scene.mesh, scene.meshMaterial, buildOptions);
            scene.geometries.push_back(geometry);
        }
        Vec3 sceneUp = scene.camera.up;
        RenderSettings settings = opts.renderSettings();

        if (opts.headless) {
            Report report;
            report.program = "04_bvh";
            std::string out = headlessPath(opts, report.program);
            renderHeadlessImage(scene, scene.camera, settings, out,
                                "scene '" + scene.name + "' through the " +
                                    bvhBuilderName(buildOptions.builder) + " hierarchy",
                                report);
            if (geometry) {
                const BvhBuildStats& s = geometry->stats();
                report.facts["build_ms"] = s.buildMs;
                report.facts["nodes"] = s.nodes;
                report.facts["sah_cost"] = s.sahCost;
                // The culling map: the hierarchy from above, for the first measuring view.
                CullingView v = cullingView(geometry->bvh().bounds(), 1, 8, opts.aspect());
                Frustum f = makeFrustum(v.camera, v.nearDistance, v.farDistance);
                Image map(opts.width, opts.height);
                drawCullingMap(map, 0, opts.width, geometry->bvh(), f, CullTest::Planes, 6,
                               sceneUp);
                std::string mapPath = pngWithSuffix(out, "-cull");
                map.writePng(mapPath);
                report.images.push_back(
                    {mapPath,
                     "the hierarchy from above (depth 6): grey culled, green kept, red "
                     "wrongly kept by the plane test; the frustum in blue"});
            }
            if (measure && geometry) {
                NamedMesh named{scene.name, &scene.mesh};
                std::cerr << "04_bvh: measuring builds...\n";
                report.add(measureBuilds(named, bins, 5));
                std::cerr << "04_bvh: measuring traversal...\n";
                report.add(measureTraceSpeed(named, measureRays, 1000, 5, opts.seed, bins));
                report.add(measureThreads(named, measureRays, 5, opts.seed));
                std::cerr << "04_bvh: counting cracks...\n";
                Mesh sh1 = loadObj(opts.dataDir + "/meshes/sh1.obj");
                Mesh bunny = scene.name == "bunny" ? scene.mesh
                                                   : loadObj(opts.dataDir + "/meshes/bunny.obj");
                report.add(
                    measureBvhCracks({{"bunny", &bunny}, {"sh1", &sh1}}, crackRays, opts.seed));
                std::cerr << "04_bvh: culling...\n";
                report.add(measureCulling(named, geometry->bvh(), 8));
                // Build time against trace speed, one point per builder (primary rays).
                Table tradeoff;
                tradeoff.id = "bvh_tradeoff";
                tradeoff.title = "Build time against trace speed (primary rays, one thread)";
                tradeoff.columns = {"builder", "build ms", "Mrays/s"};
                for (const auto& row : report.tables[1].rows) {
                    std::string name = std::get<std::string>(row[0]);
                    if (!name.ends_with(" primary")) continue;
                    tradeoff.row({name.substr(0, name.size() - 8), std::get<double>(row[3]),
                                  std::get<double>(row[2])});
                }
                report.add(tradeoff);
                report.plots.push_back({{"table", "bvh_tradeoff"},
                                        {"x", "build ms"},
                                        {"y", "Mrays/s"},
                                        {"series", "builder"},
                                        {"title", "Builders: build time against trace speed"}});
            }
            writeReport(report, opts);
            return 0;
        }

        // The window: left the view through the hierarchy, right the hierarchy from above,
        // its boxes coloured by the culling test of the left view's frustum.
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
        CullCounts planeCounts, cornerCounts;
        WindowCallbacks cb;
        cb.keys = {
            {SDLK_b, "next builder (midpoint / median / binned SAH / spatial splits), rebuilds"},
            {SDLK_c, "culling test: planes / planes + frustum corners"},
            {SDLK_l, "show deeper boxes in the map"},
            {SDLK_k, "show shallower boxes in the map"},
            {SDLK_f, "far plane: through the target / 3x further"}};
        cb.onKey = [&](int key) {
            if (key == SDLK_b && geometry) {
                constexpr BvhBuilder cycle[] = {BvhBuilder::Midpoint, BvhBuilder::Median,
                                                BvhBuilder::BinnedSah, BvhBuilder::SpatialSah};
                const BvhBuilder* at =
                    std::find(std::begin(cycle), std::end(cycle), buildOptions.builder);
                bool last = at == std::end(cycle) || at + 1 == std::end(cycle);
                buildOptions.builder = last ? cycle[0] : at[1];
                scene.geometries.clear();
                geometry =
                    std::make_shared<MeshBvhGeometry>(scene.mesh, scene.meshMaterial, buildOptions);
                scene.geometries.push_back(geometry);
                return dirty = true;
            }
            if (key == SDLK_c) {
                test = test == CullTest::Planes ? CullTest::PlanesAndCorners : CullTest::Planes;
                return dirty = true;
            }
            if (key == SDLK_l || key == SDLK_k) {
                level = std::clamp(level + (key == SDLK_l ? 1 : -1), 0, 64);
                return dirty = true;
            }
            if (key == SDLK_f) {
                farScale = farScale == 1.0f ? 3.0f : 1.0f;
                return dirty = true;
            }
            return false;
        };
        orbit.addTo(cb, [&] { dirty = true; });
        cb.frame = [&](double) -> const Image& {
            if (!dirty) return image;
            Stopwatch watch;
            Image view = renderImage(scene, orbit.camera(), settings);
            renderMs = watch.milliseconds();
            for (int y = 0; y < view.height(); ++y)
                for (int x = 0; x < view.width(); ++x) image.at(x, y) = view.at(x, y);
            if (geometry) {
                const Camera& camera = orbit.camera();
                Bounds3f bounds = geometry->bvh().bounds();
                float radius = 0.5f * glm::length(bounds.diagonal());
                // Far plane through the mesh's centre (or 3x as far): it cuts the mesh.
                float centreDistance =
                    glm::dot(bounds.centroid() - camera.eye, glm::normalize(camera.view));
                Frustum f = makeFrustum(camera, 0.01f * radius,
                                        std::max(0.02f * radius, farScale * centreDistance));
                cullHierarchy(geometry->bvh(), f, CullTest::Planes, &planeCounts);
                cullHierarchy(geometry->bvh(), f, CullTest::PlanesAndCorners, &cornerCounts);
                drawCullingMap(image, settings.width, opts.width - settings.width, geometry->bvh(),
                               f, test, level, sceneUp);
            }
            dirty = false;
            return image;
        };
        cb.panel = [&] {
            ImGui::Text("builder: %s  render: %.1f ms", bvhBuilderName(buildOptions.builder),
                        renderMs);
            if (!geometry) return;
            const BvhBuildStats& s = geometry->stats();
            ImGui::Text("build %.1f ms, %zu nodes, depth %d, SAH cost %.1f", s.buildMs, s.nodes,
                        s.depth, s.sahCost);
            ImGui::Text("map (right): %s, depth %d", testName(test), level);
            ImGui::Text("grey culled, green kept, red wrongly kept; blue: frustum");
            for (auto [name, c] : {std::pair{"planes", &planeCounts}, {"+corners", &cornerCounts}})
                ImGui::Text("%-9s visited %zu culled %zu kept %zu wrongly kept %zu", name,
                            c->visited, c->culled, c->kept, c->wronglyKept);
        };
        runWindow(opts.windowOptions("Step 04: bounding volume hierarchies"), cb);
        return 0;
    });
}
