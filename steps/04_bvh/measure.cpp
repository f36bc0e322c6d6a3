#include "04_bvh/measure.hpp"

#include <iostream>

#include "04_bvh/advanced/batch.hpp"
#include "04_bvh/advanced/build.hpp"
#include "04_bvh/advanced/rays.hpp"
#include "core/app.hpp"
#include "core/timing.hpp"

namespace boxes {

namespace {

BvhBuildOptions optionsFor(BvhBuilder builder, int bins) {
    BvhBuildOptions o;
    o.builder = builder;
    o.bins = bins;
    return o;
}

double traceMrays(const Bvh& bvh, const std::vector<Ray>& rays, int repeats, int threads) {
    std::vector<TraceHit> hits;
    Timing t = measure(repeats, [&] { traceBatch(bvh, rays, hits, threads); });
    return double(rays.size()) / t.median / 1e6;
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

}  // namespace

Table measureBuilds(const NamedMesh& mesh, int bins, int repeats) {
    Table t;
    t.id = "bvh_build";
    t.title = "Builders on '" + mesh.name + "' (" + std::to_string(mesh.mesh->triangleCount()) +
              " triangles): build time and tree quality";
    t.columns = {"builder",   "build ms", "ms/Mtri", "nodes",    "leaves",    "leaf min",
                 "leaf mean", "leaf max", "depth",   "SAH cost", "vs sweep %"};
    t.note = "median of " + std::to_string(repeats) +
             " builds, one thread; SAH cost with "
             "C_trav = C_isect = 1 relative to the root's area; 'vs sweep' is the excess over "
             "the full-sweep SAH tree (every centroid a candidate plane); binned SAH with " +
             std::to_string(bins) + " bins";
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
        double median = summarize(ms).median;
        t.row({std::string(bvhBuilderName(builder)), median,
               median / (double(mesh.mesh->triangleCount()) / 1e6), (long long)s.nodes,
               (long long)s.leaves, (long long)s.minLeafSize, s.meanLeafSize,
               (long long)s.maxLeafSize, (long long)s.depth, s.sahCost,
               100.0 * (s.sahCost / sweep.sahCost - 1.0)});
    }
    return t;
}

Table measureTraceSpeed(const NamedMesh& mesh, size_t rays, size_t bruteForceRays, int repeats,
                        uint64_t seed, int bins) {
    Table t;
    t.id = "bvh_trace";
    t.title = "Trace speed on '" + mesh.name + "', one thread, against brute force";
    t.columns = {"builder",  "rays",  "Mrays/s", "build ms",
                 "SAH cost", "hit %", "checked", "differ"};
    t.note = std::to_string(rays) + " rays per kind, median of " + std::to_string(repeats) +
             " runs; 'differ': rays among the first " + std::to_string(bruteForceRays) +
             " whose nearest hit is neither the brute-force triangle nor at its t";
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
            double mrays = traceMrays(bvh, sets[k], repeats, 1);
            std::vector<TraceHit> hits;
            traceBatch(bvh, sets[k], hits, 1);
            size_t hit = 0, differ = 0;
            for (const TraceHit& h : hits) hit += h.triangle != kNoPrimitive;
            for (size_t i = 0; i < reference[k].size(); ++i)
                differ += !hitsAgree(hits[i], reference[k][i]);
            t.row({std::string(bvhBuilderName(builder)) + " " + rayKindName(RayKind(k)),
                   (long long)sets[k].size(), mrays, stats.buildMs, stats.sahCost,
                   100.0 * double(hit) / double(hits.size()), (long long)reference[k].size(),
                   (long long)differ});
        }
    }
    return t;
}

Table measureThreads(const NamedMesh& mesh, size_t rays, int repeats, uint64_t seed) {
    Table t;
    t.id = "bvh_threads";
    t.title = "Threads: binned SAH on '" + mesh.name + "', 1 thread against 2";
    t.columns = {"rays", "1 thread Mrays/s", "2 threads Mrays/s", "speed-up"};
    t.note = "rays handed out in chunks of 1024 through an atomic counter; median of " +
             std::to_string(repeats) +
             " runs; 'control': a loop that touches no memory, split the same way (millions of "
             "iterations per second): the speed-up two threads can have on this machine now";
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

Table measureTradeoff(const Table& traceSpeed) {
    Table t;
    t.id = "bvh_tradeoff";
    t.title = "Build time against trace speed (primary rays, one thread)";
    t.columns = {"builder", "build ms", "Mrays/s"};
    for (const auto& row : traceSpeed.rows) {
        std::string name = std::get<std::string>(row[0]);
        if (!name.ends_with(" primary")) continue;
        t.row(
            {name.substr(0, name.size() - 8), std::get<double>(row[3]), std::get<double>(row[2])});
    }
    return t;
}

void addMeasurements(Report& report, const NamedMesh& mesh, const Bvh& bvh,
                     const MeasureSettings& settings) {
    std::cerr << "04_bvh: measuring builds...\n";
    report.add(measureBuilds(mesh, settings.bins, 5));
    std::cerr << "04_bvh: measuring traversal...\n";
    Table speed =
        measureTraceSpeed(mesh, settings.traceRays, 1000, 5, settings.seed, settings.bins);
    report.add(speed);
    report.add(measureThreads(mesh, settings.traceRays, 5, settings.seed));
    std::cerr << "04_bvh: counting cracks...\n";
    Mesh sh1 = loadObj(settings.dataDir + "/meshes/sh1.obj");
    Mesh bunny =
        mesh.name == "bunny" ? *mesh.mesh : loadObj(settings.dataDir + "/meshes/bunny.obj");
    report.add(
        measureBvhCracks({{"bunny", &bunny}, {"sh1", &sh1}}, settings.crackRays, settings.seed));
    std::cerr << "04_bvh: culling...\n";
    report.add(measureCulling(mesh, bvh, 8));
    report.add(measureTradeoff(speed));
    report.plots.push_back({{"table", "bvh_tradeoff"},
                            {"x", "build ms"},
                            {"y", "Mrays/s"},
                            {"series", "builder"},
                            {"title", "Builders: build time against trace speed"}});
}

CullingView cullingView(const Bounds3f& bounds, int index, int count, float aspect) {
    Vec3 centre = bounds.centroid();
    float radius = 0.5f * glm::length(bounds.diagonal());
    float angle = 2.0f * kPi * float(index) / float(std::max(1, count));
    Vec3 offset(std::sin(angle), 0.35f, std::cos(angle));
    CullingView v;
    v.camera.eye = centre + 1.3f * radius * glm::normalize(offset);
    v.camera.view = centre - v.camera.eye;
    v.camera.fovYDegrees = 40.0f;
    v.camera.aspect = aspect;
    v.nearDistance = 0.01f * radius;
    v.farDistance = glm::length(v.camera.view);  // the far plane cuts the mesh in two
    return v;
}

Table measureCulling(const NamedMesh& mesh, const Bvh& bvh, int cameras) {
    Table t;
    t.id = "bvh_culling";
    t.title = "Frustum culling of the hierarchy on '" + mesh.name + "' (binned SAH tree)";
    t.columns = {"view", "test",         "visited",        "culled",
                 "kept", "wrongly kept", "kept triangles", "ms"};
    t.note =
        "views around the mesh, fov 40, far plane through the mesh's centre; 'wrongly "
        "kept': kept boxes that lie entirely outside the frustum (exact separating-axis "
        "test); 'ms': culling traversal without the exact classification";
    for (int i = 0; i < cameras; ++i) {
        CullingView v = cullingView(bvh.bounds(), i, cameras, 4.0f / 3.0f);
        Frustum f = makeFrustum(v.camera, v.nearDistance, v.farDistance);
        for (CullTest test : {CullTest::Planes, CullTest::PlanesAndCorners}) {
            CullCounts c;
            cullHierarchy(bvh, f, test, &c);
            Timing time = measure(5, [&] { cullHierarchy(bvh, f, test); });
            t.row({(long long)i,
                   std::string(test == CullTest::Planes ? "planes" : "planes+corners"),
                   (long long)c.visited, (long long)c.culled, (long long)c.kept,
                   (long long)c.wronglyKept, (long long)c.keptTriangles, time.median * 1e3});
        }
    }
    return t;
}

namespace {

void plot(Image& image, int x0, int width, int x, int y, Vec3 colour) {
    if (x < 0 || x >= width || y < 0 || y >= image.height()) return;
    image.at(x0 + x, y) = colour;
}

void line(Image& image, int x0, int width, Vec2 a, Vec2 b, Vec3 colour) {
    float length = std::max(std::abs(b.x - a.x), std::abs(b.y - a.y));
    int steps = int(std::min(4096.0f, std::ceil(length))) + 1;
    for (int i = 0; i <= steps; ++i) {
        Vec2 p = a + (b - a) * (float(i) / float(steps));
        plot(image, x0, width, int(std::floor(p.x)), int(std::floor(p.y)), colour);
    }
}

}  // namespace

void drawCullingMap(Image& image, int x0, int width, const Bvh& bvh, const Frustum& frustum,
                    CullTest test, int level, Vec3 up) {
    for (int y = 0; y < image.height(); ++y)
        for (int x = 0; x < width; ++x) image.at(x0 + x, y) = Vec3(0.08f);
    if (bvh.empty()) return;
    // Map axes: two directions perpendicular to up.
    up = glm::normalize(up);
    Vec3 across = std::abs(up.x) < 0.9f ? Vec3(1, 0, 0) : Vec3(0, 0, 1);
    Vec3 mapX = glm::normalize(across - glm::dot(across, up) * up);
    Vec3 mapY = glm::cross(up, mapX);
    Bounds3f region = bvh.bounds();
    region.extend(frustum.corners[0]);  // the eye's neighbourhood
    Vec3 centre = region.centroid();
    float extent = 0.6f * glm::length(region.diagonal());
    float scale = 0.5f * float(std::min(width, image.height())) / extent;
    auto toMap = [&](Vec3 p) {
        Vec3 d = p - centre;
        return Vec2(0.5f * float(width) + glm::dot(d, mapX) * scale,
                    0.5f * float(image.height()) - glm::dot(d, mapY) * scale);
    };
    std::vector<NodeVisibility> verdict = classifyNodes(bvh, frustum, test);
    const Vec3 colours[] = {Vec3(0.25f), Vec3(0.35f), Vec3(0.2f, 0.85f, 0.3f),
                            Vec3(1.0f, 0.2f, 0.2f)};
    // Boxes at the level, drawn culled first so kept and wrongly kept stay on top.
    std::vector<std::pair<uint32_t, int>> stack = {{0, 0}}, drawn;
    while (!stack.empty()) {
        auto [index, depth] = stack.back();
        stack.pop_back();
        const BvhNode& node = bvh.nodes[index];
        if (node.isLeaf() || depth == level) {
            drawn.push_back({index, int(verdict[index])});
            continue;
        }
        stack.push_back({node.leftFirst, depth + 1});
        stack.push_back({node.leftFirst + 1, depth + 1});
    }
    std::stable_sort(drawn.begin(), drawn.end(),
                     [](const auto& a, const auto& b) { return a.second < b.second; });
    for (auto [index, kind] : drawn) {
        const BvhNode& node = bvh.nodes[index];
        Vec2 lo(kInfinity<float>), hi(-kInfinity<float>);
        for (int i = 0; i < 8; ++i) {
            Vec3 p(i & 1 ? node.boundsMax.x : node.boundsMin.x,
                   i & 2 ? node.boundsMax.y : node.boundsMin.y,
                   i & 4 ? node.boundsMax.z : node.boundsMin.z);
            Vec2 m = toMap(p);
            lo = glm::min(lo, m);
            hi = glm::max(hi, m);
        }
        Vec3 c = colours[kind];
        line(image, x0, width, lo, Vec2(hi.x, lo.y), c);
        line(image, x0, width, Vec2(hi.x, lo.y), hi, c);
        line(image, x0, width, hi, Vec2(lo.x, hi.y), c);
        line(image, x0, width, Vec2(lo.x, hi.y), lo, c);
    }
    // The frustum's twelve edges, in light blue.
    const auto& k = frustum.corners;
    const int edges[12][2] = {{0, 1}, {1, 3}, {3, 2}, {2, 0}, {4, 5}, {5, 7},
                              {7, 6}, {6, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
    for (const auto& e : edges)
        line(image, x0, width, toMap(k[size_t(e[0])]), toMap(k[size_t(e[1])]),
             Vec3(0.4f, 0.7f, 1.0f));
}

void addCullingMap(Report& report, const Bvh& bvh, const std::string& png, int width, int height,
                   Vec3 up) {
    CullingView v = cullingView(bvh.bounds(), 1, 8, float(width) / float(height));
    Frustum f = makeFrustum(v.camera, v.nearDistance, v.farDistance);
    Image map(width, height);
    drawCullingMap(map, 0, width, bvh, f, CullTest::Planes, 6, up);
    std::string path = pngWithSuffix(png, "-cull");
    map.writePng(path);
    report.images.push_back({path,
                             "the hierarchy from above (depth 6): grey culled, green kept, red "
                             "wrongly kept by the plane test; the frustum in blue"});
}

}  // namespace boxes
