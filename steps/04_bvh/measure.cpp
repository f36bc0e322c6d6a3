#include "04_bvh/measure.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <iostream>
#include <memory>

#include "04_bvh/advanced/batch.hpp"
#include "04_bvh/advanced/build.hpp"
#include "04_bvh/advanced/commands.hpp"
#include "04_bvh/advanced/measure.hpp"
#include "04_bvh/advanced/rays.hpp"
#include "04_bvh/cost_map.hpp"
#include "04_bvh/culling_map.hpp"
#include "core/timing.hpp"

namespace boxes {

namespace {

BvhBuildOptions optionsFor(BvhBuilder builder, int bins) {
    BvhBuildOptions o;
    o.builder = builder;
    o.bins = bins;
    return o;
}

// Seconds per ray (median, min, max of the repeats).
Timing traceTiming(const Bvh& bvh, const std::vector<Ray>& rays, int repeats, int threads) {
    std::vector<TraceHit> hits;
    Timing t = measure(repeats, [&] { traceBatch(bvh, rays, hits, threads); });
    double n = double(std::max<size_t>(1, rays.size()));
    t.median /= n, t.min /= n, t.max /= n;
    return t;
}

double traceMrays(const Bvh& bvh, const std::vector<Ray>& rays, int repeats, int threads) {
    return 1e-6 / traceTiming(bvh, rays, repeats, threads).median;
}

// The machine's own parallelism at the moment: a loop that touches no memory, run once per
// thread through the tracer's own batch loop (one chunk of 1,024 "rays" each), in millions
// of iterations per second. On two idle cores it scales by 2; when it does not (cores
// shared with other work), neither can the tracer.
double busyLoopMops(int threads, int repeats) {
    constexpr long kIterations = 20'000'000;  // per thread
    Timing t = measure(repeats, [&] {
        forEachRayChunk(1024 * size_t(threads), threads, [](size_t, size_t) {
            float x = 0.0f;
            for (long k = 0; k < kIterations; ++k) x = x * 0.999f + 1.0f;  // converges
            volatile float sink = x;
            (void)sink;
        });
    });
    return double(kIterations) * threads / t.median / 1e6;
}

// Per builder: build ms (median), nodes, leaves, leaf sizes, depth, SAH cost and its
// excess over the full-sweep SAH tree. Table id "bvh_build".
Table measureBuilds(const NamedMesh& mesh, int bins, int repeats) {
    Table t("bvh_build",
            "Builders on '" + mesh.name + "' (" + std::to_string(mesh.mesh->triangleCount()) +
                " triangles): build time and tree quality",
            {"builder", "build ms", "ms/Mtri", "nodes", "leaves", "leaf min", "leaf mean",
             "leaf max", "depth", "SAH cost", "vs sweep %", "min ms", "max ms"},
            "median of " + std::to_string(repeats) +
                " builds, one thread; SAH cost with "
                "C_trav = C_isect = 1 relative to the root's area; 'vs sweep' is the excess over "
                "the full-sweep SAH tree (every centroid a candidate plane); binned SAH with " +
                std::to_string(bins) +
                " bins (the sweep and the spatial splits: one build, so no spread); the error: the "
                "SAH cost's excess over the full-sweep tree's");
    t.timeAndError("build ms", "min ms", "max ms", "vs sweep %");
    BvhBuildStats sweep;
    buildEngineBvh(*mesh.mesh, optionsFor(BvhBuilder::SweepSah, bins), &sweep);
    for (BvhBuilder builder : {BvhBuilder::Midpoint, BvhBuilder::Median, BvhBuilder::BinnedSah,
                               BvhBuilder::SweepSah, BvhBuilder::SpatialSah}) {
        std::vector<double> ms;
        BvhBuildStats s;
        int n = builder == BvhBuilder::SweepSah || builder == BvhBuilder::SpatialSah ? 1 : repeats;
        for (int i = 0; i < n; ++i) {
            buildEngineBvh(*mesh.mesh, optionsFor(builder, bins), &s);
            ms.push_back(s.buildMs);
        }
        Timing time = summarize(ms);
        double median = time.median;
        t.row({std::string(bvhBuilderName(builder)), median,
               median / (double(mesh.mesh->triangleCount()) / 1e6), (long long)s.nodes,
               (long long)s.leaves, (long long)s.minLeafSize, s.meanLeafSize,
               (long long)s.maxLeafSize, (long long)s.depth, s.sahCost,
               100.0 * (s.sahCost / sweep.sahCost - 1.0), time.min, time.max});
    }
    return t;
}

// Per builder and ray kind: Mrays/s on one thread (median of repeats), the tree's SAH cost
// and the rays whose nearest hit differs from brute force on a sample (no build time: that
// is bvh_build's). Table id "bvh_trace".
Table measureTraceSpeed(const NamedMesh& mesh, size_t rays, size_t bruteForceRays, int repeats,
                        uint64_t seed, int bins) {
    Table t("bvh_trace", "Trace speed on '" + mesh.name + "', one thread, against brute force",
            {"builder", "rays", "Mrays/s", "SAH cost", "hit %", "checked", "differ", "ns/ray",
             "min ns", "max ns"},
            std::to_string(rays) + " rays per kind, median of " + std::to_string(repeats) +
                " runs; 'differ': rays among the first " + std::to_string(bruteForceRays) +
                " whose nearest hit is neither the brute-force triangle nor at its t; ns/ray: "
                "median, min and max of the runs");
    t.timeAndError("ns/ray", "min ns", "max ns", "differ");
    std::vector<std::vector<Ray>> sets;
    std::vector<std::vector<TraceHit>> reference;
    for (RayKind kind : {RayKind::Primary, RayKind::Diffuse, RayKind::Random}) {
        sets.push_back(makeRays(*mesh.mesh, kind, rays, seed));
        std::vector<Ray> sample(
            sets.back().begin(),
            sets.back().begin() + std::ptrdiff_t(std::min(rays, bruteForceRays)));
        reference.emplace_back();
        traceBatchBruteForce(*mesh.mesh, sample, reference.back(), 0);
    }
    for (BvhBuilder builder : kExerciseBuilders) {
        BvhBuildStats stats;
        Bvh bvh = buildEngineBvh(*mesh.mesh, optionsFor(builder, bins), &stats);
        for (size_t k = 0; k < sets.size(); ++k) {
            Timing time = traceTiming(bvh, sets[k], repeats, 1);
            double mrays = 1e-6 / time.median;
            std::vector<TraceHit> hits;
            traceBatch(bvh, sets[k], hits, 1);
            size_t hit = 0, differ = 0;
            for (const TraceHit& h : hits) hit += h.triangle != kNoPrimitive;
            for (size_t i = 0; i < reference[k].size(); ++i)
                differ += !hitsAgree(hits[i], reference[k][i]);
            t.row({std::string(bvhBuilderName(builder)) + " " + rayKindName(RayKind(k)),
                   (long long)sets[k].size(), mrays, stats.sahCost,
                   100.0 * double(hit) / double(hits.size()), (long long)reference[k].size(),
                   (long long)differ, time.median * 1e9, time.min * 1e9, time.max * 1e9});
        }
    }
    return t;
}

// 1 thread against 2 (binned SAH, primary and diffuse rays). Table id "bvh_threads".
Table measureThreads(const NamedMesh& mesh, size_t rays, int repeats, uint64_t seed) {
    Table t("bvh_threads", "Threads: binned SAH on '" + mesh.name + "', 1 thread against 2",
            {"rays", "1 thread Mrays/s", "2 threads Mrays/s", "speed-up"},
            "rays handed out in chunks of 1024 through an atomic counter; median of " +
                std::to_string(repeats) +
                " runs; 'control': a loop that touches no memory, split the same way (millions of "
                "iterations per second): the speed-up two threads can have on this machine now");
    Bvh bvh = buildEngineBvh(*mesh.mesh, optionsFor(BvhBuilder::BinnedSah, 16));
    for (RayKind kind : {RayKind::Primary, RayKind::Diffuse}) {
        std::vector<Ray> set = makeRays(*mesh.mesh, kind, rays, seed);
        double one = traceMrays(bvh, set, repeats, 1), two = traceMrays(bvh, set, repeats, 2);
        t.row({std::string(rayKindName(kind)), one, two, two / one});
    }
    double one = busyLoopMops(1, repeats), two = busyLoopMops(2, repeats);
    t.row({std::string("control"), one, two, two / one});
    return t;
}

// Build time (bvh_build's median) and trace speed per builder (primary rays) beside the rays
// it loses against brute force and its cracks, from measureBuilds's, measureTraceSpeed's and
// measureBvhCracks's tables. Table id "bvh_tradeoff".
Table measureTradeoff(const Table& builds, const Table& traceSpeed, const Table& cracks) {
    Table t("bvh_tradeoff",
            "Build time, trace speed and rays lost per builder (primary rays, one thread)",
            {"builder", "build ms", "Mrays/s", "ns/ray", "min ns", "max ns", "rays lost", "cracks",
             "lost + cracks"});
    t.note =
        "build ms: the median of bvh_build's builds (the same number as there); time: a "
        "primary ray's (bvh_trace); rays lost: rays of every kind whose nearest hit "
        "differs from brute force (bvh_trace's 'differ'); cracks: crack rays the tree lets "
        "through on every mesh (bvh_cracks); the error is both together";
    t.timeAndError("ns/ray", "min ns", "max ns", "lost + cracks");
    // Cells by their column's name: the tables' columns may change order.
    auto cell = [](const Table& table, const std::vector<Cell>& row, const std::string& column) {
        size_t i = size_t(std::find(table.columns.begin(), table.columns.end(), column) -
                          table.columns.begin());
        const Cell& c = row.at(i);
        if (auto n = std::get_if<long long>(&c)) return double(*n);
        return std::get<double>(c);
    };
    auto name = [](const std::vector<Cell>& row, size_t i) {
        return std::get<std::string>(row[i]);
    };
    for (const auto& row : traceSpeed.rows) {
        if (!name(row, 0).ends_with(" primary")) continue;
        std::string builder = name(row, 0).substr(0, name(row, 0).size() - 8);
        long long lost = 0, cracked = 0;
        for (const auto& r : traceSpeed.rows)
            if (name(r, 0).starts_with(builder + " "))
                lost += (long long)cell(traceSpeed, r, "differ");
        for (const auto& r : cracks.rows)
            if (name(r, 1) == builder) cracked += (long long)cell(cracks, r, "cracks");
        // One build time per builder on the page: bvh_build's median, not another build.
        double buildMs = 0.0;
        for (const auto& r : builds.rows)
            if (name(r, 0) == builder) buildMs = cell(builds, r, "build ms");
        t.row({builder, buildMs, cell(traceSpeed, row, "Mrays/s"), cell(traceSpeed, row, "ns/ray"),
               cell(traceSpeed, row, "min ns"), cell(traceSpeed, row, "max ns"), lost, cracked,
               lost + cracked});
    }
    return t;
}

// Culled / kept / wrongly kept nodes for both tests from cameras around the mesh, close
// enough that the frustum cuts it. Table id "bvh_culling".
Table measureCulling(const NamedMesh& mesh, const Bvh& bvh, int cameras) {
    Table t("bvh_culling",
            "Frustum culling of the hierarchy on '" + mesh.name + "' (binned SAH tree)",
            {"view", "test", "visited", "culled", "kept", "wrongly kept", "kept triangles", "ms",
             "min ms", "max ms"});
    t.note =
        "views around the mesh, fov 40, far plane through the mesh's centre; 'wrongly "
        "kept': kept boxes that lie entirely outside the frustum (exact separating-axis "
        "test, the reference); 'ms': culling traversal without the exact classification, median "
        "of 5 (min, max)";
    t.timeAndError("ms", "min ms", "max ms", "wrongly kept");
    for (int i = 0; i < cameras; ++i) {
        CullingView v = cullingView(bvh.bounds(), i, cameras, 4.0f / 3.0f);
        Frustum f = makeFrustum(v.camera, v.nearDistance, v.farDistance);
        for (CullTest test : {CullTest::Planes, CullTest::PlanesAndCorners}) {
            CullCounts c;
            cullHierarchy(bvh, f, test, &c);
            Timing time = measure(5, [&] { cullHierarchy(bvh, f, test); });
            t.row({(long long)i, std::string(test == CullTest::Planes ? "planes" : "+ corners"),
                   (long long)c.visited, (long long)c.culled, (long long)c.kept,
                   (long long)c.wronglyKept, (long long)c.keptTriangles, time.median * 1e3,
                   time.min * 1e3, time.max * 1e3});
        }
    }
    return t;
}

// The whole `--measure` run on the scene's mesh and `bvh` (the program's tree), with the
// crack count on the bunny and sh1 from dataDir, and the trade-off's plot.
void addMeasurements(Report& report, const NamedMesh& mesh, const Bvh& bvh,
                     const MeasureSettings& settings) {
    std::cerr << "04_bvh: measuring builds...\n";
    Table builds = measureBuilds(mesh, settings.bins, 5);
    report.add(builds);
    std::cerr << "04_bvh: measuring traversal...\n";
    Table speed =
        measureTraceSpeed(mesh, settings.traceRays, 1000, 5, settings.seed, settings.bins);
    report.add(speed);
    report.add(measureThreads(mesh, settings.traceRays, 5, settings.seed));
    std::cerr << "04_bvh: counting cracks...\n";
    Mesh sh1 = loadObj(settings.dataDir + "/meshes/sh1.obj");
    Mesh bunny =
        mesh.name == "bunny" ? *mesh.mesh : loadObj(settings.dataDir + "/meshes/bunny.obj");
    Table cracks =
        measureBvhCracks({{"bunny", &bunny}, {"sh1", &sh1}}, settings.crackRays, settings.seed);
    report.add(cracks);
    std::cerr << "04_bvh: culling...\n";
    report.add(measureCulling(mesh, bvh, 8));
    report.add(measureTradeoff(builds, speed, cracks));
    report.plots.push_back(
        {{"table", "bvh_tradeoff"},
         {"x", "build ms"},
         {"y", "Mrays/s"},
         {"series", "builder"},
         {"title", "Builders: build time (median of 5 builds) against trace speed"}});
    report.plots.push_back({{"table", "bvh_tradeoff"},
                            {"x", "ns/ray"},
                            {"y", "lost + cracks"},
                            {"series", "builder"},
                            {"pareto", true},
                            {"title",
                             "Builders: rays lost (brute force) and cracks against time per "
                             "primary ray, with the Pareto front"}});
}

}  // namespace

void measureTree(Report& report, const Scene& scene, const MeshBvhGeometry& geometry,
                 const CommonOptions& options, const MeasureSettings& settings,
                 const std::string& png) {
    MeasureSettings run = settings;
    run.seed = options.seed;
    run.dataDir = options.dataDir;
    addMeasurements(report, {scene.name, &scene.mesh}, geometry.bvh(), run);
    // One build time per builder: the image's tree was built once; bvh_build gives each
    // builder's median of 5, which the page, the plot and the deck show.
    report.facts.erase("build_ms");
    std::cerr << "04_bvh: the cost of a ray, per pixel...\n";
    addCostMaps(report, scene, png, options.width, options.height, settings.bins, options.threads);
}

void addMeasureOptions(CLI::App& app, MeasureSettings& settings) {
    app.add_option("--measure-rays", settings.traceRays, "rays per kind in the speed table")
        ->check(CLI::Range(size_t(100), size_t(10000000)));
    app.add_option("--crack-rays", settings.crackRays,
                   "rays per mesh and feature for the crack count")
        ->check(CLI::Range(size_t(1), size_t(10000000)));
}

std::function<std::optional<int>()> addEngineCommands(CLI::App& app) {
    auto commands = std::make_shared<EngineCommands>(app);
    return [commands] { return commands->run(); };
}

}  // namespace boxes
