// embree_trace: the bench's Embree side. Traces a rays file against an OBJ mesh with Embree 3,
// writes the hits file and prints one JSON line, in the forms of `04_bvh trace`, so the bench
// compares the two ray by ray and in speed.
//
//   embree_trace --mesh MESH.obj --rays RAYS.bin --hits HITS.bin [--threads N] [--repeat K]
//                [--quality low|medium|high] [--config STR]
#include <CLI/CLI.hpp>
#include <ctime>
#include <iostream>
#include <nlohmann/json.hpp>

#include "04_bvh/advanced/rays.hpp"
#include "core/timing.hpp"
#include "embree_tracer.hpp"

namespace {

double processCpuSeconds() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

}  // namespace

int main(int argc, char** argv) {
    using namespace boxes;
    CLI::App app{"Embree 3 on a rays file: the bench's second tracer"};
    std::string meshPath, raysPath, hitsPath, quality = "high", config;
    int threads = 1, repeat = 1;
    app.add_option("--mesh", meshPath, "the mesh (OBJ)")->required();
    app.add_option("--rays", raysPath, "float32 ox oy oz tmin dx dy dz tmax per ray")->required();
    app.add_option("--hits", hitsPath, "written: float32 t, uint32 triangle per ray")->required();
    app.add_option("--threads", threads, "threads")
        ->check(CLI::Range(1, 256))
        ->capture_default_str();
    app.add_option("--repeat", repeat, "trace passes; the median is reported")
        ->check(CLI::Range(1, 1000))
        ->capture_default_str();
    app.add_option("--quality", quality, "Embree's build quality")
        ->check(CLI::IsMember({"low", "medium", "high"}))
        ->capture_default_str();
    app.add_option("--config", config,
                   "more of Embree's device configuration (verbose=3: its "
                   "tree statistics on stdout)");
    CLI11_PARSE(app, argc, argv);
    try {
        Mesh mesh = loadObj(meshPath);
        std::vector<Ray> rays = readRays(raysPath);
        RTCBuildQuality q = quality == "low"      ? RTC_BUILD_QUALITY_LOW
                            : quality == "medium" ? RTC_BUILD_QUALITY_MEDIUM
                                                  : RTC_BUILD_QUALITY_HIGH;
        std::string device = "threads=" + std::to_string(threads);
        if (!config.empty()) device += "," + config;
        double buildCpuStart = processCpuSeconds();
        EmbreeTracer embree(mesh, device, q);
        double buildCpuSeconds = processCpuSeconds() - buildCpuStart;
        std::vector<TraceHit> hits;
        std::vector<double> seconds, cpuSeconds;
        for (int i = 0; i < repeat; ++i) {
            Stopwatch watch;
            double cpuStart = processCpuSeconds();
            embree.trace(rays, hits, threads);
            seconds.push_back(watch.seconds());
            cpuSeconds.push_back(processCpuSeconds() - cpuStart);
        }
        double traceSeconds = summarize(seconds).median;
        size_t hitCount = 0;
        for (const TraceHit& h : hits) hitCount += h.triangle != kNoPrimitive;
        writeHits(hitsPath, hits);
        nlohmann::json j = {
            {"tris", mesh.triangleCount()},
            {"rays", rays.size()},
            {"build_ms", embree.buildMs()},
            {"build_cpu_ms", buildCpuSeconds * 1e3},
            {"build_quality", quality},
            {"trace_ms", traceSeconds * 1e3},
            {"trace_cpu_ms", summarize(cpuSeconds).median * 1e3},
            {"mrays_per_s", double(rays.size()) / traceSeconds / 1e6},
            {"hits", hitCount},
            {"threads", threads},
            {"repeat", repeat},
            {"embree", std::to_string(RTC_VERSION_MAJOR) + "." + std::to_string(RTC_VERSION_MINOR) +
                           "." + std::to_string(RTC_VERSION_PATCH)}};
        std::cout << j.dump() << "\n";
    } catch (const std::exception& e) {
        std::cerr << "embree_trace: " << e.what() << "\n";
        return 2;
    }
    return 0;
}
