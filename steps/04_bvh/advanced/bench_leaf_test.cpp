// Paired benchmark (Google Benchmark): step 04's leaf test (intersectLeafTriangle, the
// per-ray set-up of exercise 1.5 done once) against step 01's exercise 1.5 called from the
// same traversal, on the same tree and rays, repetitions interleaved at random. It prints
// each variant's median, the ratio of the medians, and the median ratio of a pair run back
// to back in each iteration; it fails if any ray's hit differs.
//
//   bench_leaf_test [--rays N] [google benchmark flags]   (mesh: BOXES_MESH, else the bunny)
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <map>
#include <string>
#include <vector>

#include "01_triangle/triangle.hpp"
#include "04_bvh/advanced/build.hpp"
#include "04_bvh/advanced/rays.hpp"
#include "04_bvh/advanced/traverse.hpp"

using namespace boxes;

namespace {

// Exercise 1.5 as the leaf test: a copy of the ray with the current tmax, per triangle.
uint32_t nearestStep01(const Bvh& bvh, const Ray& ray, float& tClosest) {
    tClosest = ray.tmax;
    TraversalRay traversal(ray, bvh);
    if (!entersRoot(bvh, traversal)) return kTraversalMiss;
    const LeafTriangle* tris = bvh.leafTriangles.data();
    return traverseNearestFast(bvh, traversal, tClosest, [&](uint32_t s, float& tmax) {
        Ray shorter = ray;
        shorter.tmax = tmax;
        auto h = intersectWatertight(shorter, Triangle{tris[s].a, tris[s].b, tris[s].c});
        if (!h) return false;
        tmax = h->t;
        return true;
    });
}

uint32_t nearestStep04(const Bvh& bvh, const Ray& ray, float& tClosest) {
    return nearestSlotFast(bvh, ray, tClosest);
}

struct Fixture {
    Mesh mesh;
    Bvh bvh;
    std::vector<Ray> rays;
};
Fixture* fixture = nullptr;

template <uint32_t (*Nearest)(const Bvh&, const Ray&, float&)>
void traceAll(benchmark::State& state) {
    for (auto _ : state) {
        float sum = 0.0f;
        for (const Ray& ray : fixture->rays) {
            float t;
            if (Nearest(fixture->bvh, ray, t) != kTraversalMiss) sum += t;
        }
        benchmark::DoNotOptimize(sum);
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(fixture->rays.size()));
}

double threadCpuSeconds() {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

// The pair in one iteration: both variants on the same rays back to back, the order
// alternating, and the ratio of their CPU times as the counter: on a loaded machine a
// burst of load then spoils one iteration's ratio, not one variant's median.
void pairedRatio(benchmark::State& state) {
    double ratioSum = 0.0;
    int64_t n = 0;
    for (auto _ : state) {
        double seconds[2] = {0.0, 0.0};
        for (int k = 0; k < 2; ++k) {
            int variant = (k + int(n)) % 2;
            float sum = 0.0f, t;
            double start = threadCpuSeconds();
            for (const Ray& ray : fixture->rays)
                if ((variant ? nearestStep01 : nearestStep04)(fixture->bvh, ray, t) !=
                    kTraversalMiss)
                    sum += t;
            seconds[variant] = threadCpuSeconds() - start;
            benchmark::DoNotOptimize(sum);
        }
        ratioSum += seconds[1] / seconds[0];
        ++n;
    }
    state.counters["step01_over_step04"] = ratioSum / double(n);
}

// Keeps the medians to print their ratio after the console's table.
struct MedianReporter : benchmark::ConsoleReporter {
    std::map<std::string, double> median, medianCpu;
    double pairedMedian = 0.0;
    void ReportRuns(const std::vector<Run>& runs) override {
        for (const Run& r : runs)
            if (r.run_type == Run::RT_Aggregate && r.aggregate_name == "median") {
                median[r.run_name.function_name] = r.GetAdjustedRealTime();
                medianCpu[r.run_name.function_name] = r.GetAdjustedCPUTime();
                auto ratio = r.counters.find("step01_over_step04");
                if (ratio != r.counters.end()) pairedMedian = ratio->second.value;
            }
        ConsoleReporter::ReportRuns(runs);
    }
};

}  // namespace

int main(int argc, char** argv) {
    size_t count = 100000;
    std::vector<char*> args{argv[0]};
    std::string reps = "--benchmark_repetitions=15",
                interleave = "--benchmark_enable_random_interleaving=true",
                aggregates = "--benchmark_report_aggregates_only=true";
    args.push_back(reps.data());
    args.push_back(interleave.data());
    args.push_back(aggregates.data());
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--rays") == 0 && i + 1 < argc) {
            char* end;
            long n = std::strtol(argv[++i], &end, 10);
            if (*end || n <= 0) {
                std::fprintf(stderr, "bench_leaf_test: --rays needs a positive count\n");
                return 2;
            }
            count = size_t(n);
        } else {
            args.push_back(argv[i]);  // later flags override the defaults above
        }
    }
    const char* meshPath = std::getenv("BOXES_MESH");
    Fixture f;
    try {
        f.mesh = loadObj(meshPath ? meshPath : BOXES_DATA_DIR "/meshes/bunny.obj");
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_leaf_test: %s\n", e.what());
        return 1;
    }
    f.bvh = buildEngineBvh(f.mesh, BvhBuildOptions{});
    // Half primary rays, half diffuse rays from surface points.
    f.rays = makeRays(f.mesh, RayKind::Primary, count / 2, 1);
    std::vector<Ray> diffuse = makeRays(f.mesh, RayKind::Diffuse, count - count / 2, 2);
    f.rays.insert(f.rays.end(), diffuse.begin(), diffuse.end());
    fixture = &f;
    // The two must agree on every ray before their speed means anything.
    size_t differ = 0;
    for (const Ray& ray : f.rays) {
        float t1, t4;
        uint32_t s1 = nearestStep01(f.bvh, ray, t1), s4 = nearestStep04(f.bvh, ray, t4);
        if (s1 != s4 || (s1 != kTraversalMiss && std::memcmp(&t1, &t4, sizeof t1) != 0)) ++differ;
    }
    if (differ) {
        std::fprintf(stderr, "bench_leaf_test: %zu of %zu rays differ\n", differ, f.rays.size());
        return 1;
    }
    benchmark::RegisterBenchmark("step04_leaf_test", traceAll<nearestStep04>)
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark("step01_exercise_1_5", traceAll<nearestStep01>)
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark("paired_cpu_ratio", pairedRatio)->Unit(benchmark::kMillisecond);
    int n = int(args.size());
    benchmark::Initialize(&n, args.data());
    if (benchmark::ReportUnrecognizedArguments(n, args.data())) return 2;
    MedianReporter reporter;
    benchmark::RunSpecifiedBenchmarks(&reporter);
    benchmark::Shutdown();
    // On a shared machine the CPU time is the steadier of the two (docs/measuring.md).
    const char *slow = "step01_exercise_1_5", *fast = "step04_leaf_test";
    if (reporter.median.count(slow) && reporter.median.count(fast))
        std::printf(
            "%zu rays (mesh: %zu triangles), 0 differ; median step01 / step04: wall time "
            "%.3f, CPU time %.3f\n",
            f.rays.size(), f.mesh.triangles.size(), reporter.median[slow] / reporter.median[fast],
            reporter.medianCpu[slow] / reporter.medianCpu[fast]);
    if (reporter.pairedMedian > 0.0)
        std::printf("paired in each iteration, median of the CPU-time ratios: %.3f\n",
                    reporter.pairedMedian);
    return 0;
}
