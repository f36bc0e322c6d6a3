#include "04_bvh/advanced/commands.hpp"

#include <CLI/CLI.hpp>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <nlohmann/json.hpp>

#include "04_bvh/advanced/build.hpp"
#include "04_bvh/advanced/bvh4.hpp"
#include "04_bvh/advanced/measure.hpp"
#include "04_bvh/advanced/rays.hpp"
#include "core/timing.hpp"

namespace boxes {

namespace {

// CPU time of the process (all threads): on a loaded machine the wall time includes the
// time other processes held the core; the CPU time of one thread does not.
double processCpuSeconds() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

// `trace`: build, trace every ray (median of --repeat), write HITS.bin, one JSON line.
int runTrace(const TraceCommandOptions& o) {
    if (o.chapter && o.width != 2)
        throw InputError("--chapter traces the binary tree: it goes with --width 2");
    Mesh mesh = loadObj(o.mesh);
    std::vector<Ray> rays = readRays(o.rays);
    BvhBuildOptions build;
    build.builder = parseBvhBuilder(o.builder);
    build.bins = o.bins;
    BvhBuildStats stats;
    double buildCpuStart = processCpuSeconds();
    Bvh bvh = buildEngineBvh(mesh, build, &stats);
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
        else if (o.chapter)
            traceBatchChapter(bvh, rays, hits, o.threads);
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
                        {"traversal", o.chapter ? "chapter" : "engine"},
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

RayKind parseRayKind(const std::string& kind) {
    return kind == "primary"   ? RayKind::Primary
           : kind == "diffuse" ? RayKind::Diffuse
                               : RayKind::Random;
}

Vec3 parseTriple(const std::string& text, const std::string& flag) {
    Vec3 v;
    char tail = 0;
    if (std::sscanf(text.c_str(), "%f,%f,%f%c", &v.x, &v.y, &v.z, &tail) != 3 || !isFinite(v))
        throw UsageError(flag + " '" + printable(text) + "': expected three numbers X,Y,Z");
    return v;
}

// `rays`: write a generated ray set; one JSON line says what was written.
int runRays(const RaysCommandOptions& o) {
    Mesh mesh = loadObj(o.mesh);
    std::vector<Ray> rays;
    nlohmann::json j = {{"mesh", o.mesh}, {"kind", o.kind}, {"seed", o.seed}};
    if (!o.eye.empty()) {
        if (o.kind != "primary") throw UsageError("--eye places a camera: only for --kind primary");
        Vec3 eye = parseTriple(o.eye, "--eye");
        Bounds3f bounds;
        for (const Vec3& p : mesh.positions) bounds.extend(p);
        Vec3 look = o.look.empty() ? bounds.centroid() : parseTriple(o.look, "--look");
        Camera camera = Camera::lookingAt(eye, look, parseTriple(o.up, "--up"), o.fov, 1.0f);
        try {
            camera.validate();
        } catch (const std::invalid_argument& e) {
            throw InputError(std::string("rays: ") + e.what());
        }
        rays = makeCameraRays(camera, o.count);
        j["eye"] = o.eye;
    } else {
        rays = makeRays(mesh, parseRayKind(o.kind), o.count, o.seed);
    }
    writeRays(o.out, rays);
    j["rays"] = rays.size();
    std::cout << j.dump() << "\n";
    return 0;
}

// `check`: every builder's nearest hits against brute force over all triangles, and
// optionally rays aimed at shared edges and vertices. Exit 1 on any difference.
int runCheck(const CheckCommandOptions& o) {
    Mesh mesh = loadObj(o.mesh);
    std::vector<Ray> rays;
    if (!o.rays.empty()) {
        rays = readRays(o.rays);
    } else {
        rays = makeRays(mesh, parseRayKind(o.kind), o.count, o.seed);
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
        Bvh bvh = buildEngineBvh(mesh, build);
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

}  // namespace

EngineCommands::EngineCommands(CLI::App& app) {
    traceCommand_ = app.add_subcommand(
        "trace", "trace RAYS.bin against MESH.obj, write HITS.bin, print one JSON line");
    traceCommand_->add_option("--mesh", trace_.mesh, "the mesh (OBJ)")->required();
    traceCommand_->add_option("--rays", trace_.rays, "float32 ox oy oz tmin dx dy dz tmax per ray")
        ->required();
    traceCommand_->add_option("--hits", trace_.hits, "written: float32 t, uint32 triangle per ray")
        ->required();
    traceCommand_
        ->add_option("--builder", trace_.builder,
                     "midpoint, median, sah, sweep-sah or sbvh (SAH with spatial splits)")
        ->check(CLI::IsMember({"midpoint", "median", "sah", "sweep-sah", "sbvh"}))
        ->capture_default_str();
    traceCommand_->add_option("--threads", trace_.threads, "threads")
        ->check(CLI::Range(1, 256))
        ->capture_default_str();
    traceCommand_->add_option("--repeat", trace_.repeat, "trace runs; the median is reported")
        ->check(CLI::Range(1, 1000))
        ->capture_default_str();
    traceCommand_
        ->add_option("--width", trace_.width,
                     "2: the binary tree; 4 or 8: its collapse to 4- or 8-wide nodes, SIMD "
                     "traversal")
        ->check(CLI::IsMember({2, 4, 8}))
        ->capture_default_str();
    traceCommand_->add_option("--bins", trace_.bins, "binned SAH: bins per axis")
        ->check(CLI::Range(2, 256))
        ->capture_default_str();
    traceCommand_->add_flag("--chapter", trace_.chapter,
                            "--width 2 through the chapter's traversal (exercise 4.4) instead "
                            "of the engine's copy (advanced/traverse.hpp)");
    traceCommand_->add_flag("--count", trace_.count,
                            "also count the work per ray (one more, untimed pass): "
                            "triangles tested; with --width 4 or 8 also nodes, leaves "
                            "and packets");

    checkCommand_ = app.add_subcommand(
        "check", "compare every builder's nearest hits with brute force; exit 1 on a difference");
    checkCommand_->add_option("--mesh", check_.mesh, "the mesh (OBJ)")->required();
    checkCommand_->add_option("--rays", check_.rays, "a rays file (else --kind and --count)");
    checkCommand_->add_option("--kind", check_.kind, "generated rays: primary, diffuse, random")
        ->check(CLI::IsMember({"primary", "diffuse", "random"}));
    checkCommand_->add_option("--count", check_.count, "generated rays")
        ->check(CLI::Range(size_t(1), size_t(100000000)));
    checkCommand_->add_option("--cracks", check_.cracks,
                              "also this many rays per feature at shared edges and vertices");
    checkCommand_->add_option("--threads", check_.threads, "threads (0: all)");
    checkCommand_->add_option("--seed", check_.seed, "seed of generated rays");
    raysCommand_ = app.add_subcommand(
        "rays", "write a ray set for MESH.obj as RAYS.bin (float32 ox oy oz tmin dx dy dz tmax)");
    raysCommand_->add_option("--mesh", rays_.mesh, "the mesh (OBJ)")->required();
    raysCommand_->add_option("--out", rays_.out, "the rays file written")->required();
    raysCommand_
        ->add_option("--kind", rays_.kind,
                     "primary (a camera framing the mesh), diffuse (from its surface), random")
        ->check(CLI::IsMember({"primary", "diffuse", "random"}))
        ->capture_default_str();
    raysCommand_->add_option("--count", rays_.count, "rays")
        ->check(CLI::Range(size_t(1), kMaxRays))
        ->capture_default_str();
    raysCommand_->add_option("--seed", rays_.seed, "seed (diffuse and random rays)")
        ->capture_default_str();
    raysCommand_->add_option("--eye", rays_.eye, "primary rays from this eye X,Y,Z instead");
    raysCommand_->add_option("--look", rays_.look,
                             "with --eye: the point looked at (default: "
                             "the mesh's centre)");
    raysCommand_->add_option("--up", rays_.up, "with --eye: the up vector")->capture_default_str();
    raysCommand_->add_option("--fov", rays_.fov, "with --eye: the field of view in degrees")
        ->check(CLI::Range(1.0f, 179.0f))
        ->capture_default_str();
    app.require_subcommand(0, 1);
}

std::optional<int> EngineCommands::run() const {
    if (*traceCommand_) return runTrace(trace_);
    if (*checkCommand_) return runCheck(check_);
    if (*raysCommand_) return runRays(rays_);
    return std::nullopt;
}

}  // namespace boxes
