#include "04_bvh/advanced/batch.hpp"

#include <algorithm>
#include <atomic>
#include <cstdlib>

#include "core/render.hpp"

namespace boxes {

bool traceUsesAvx2() {
#if defined(BOXES_TARGET_AVX2)
    static const bool cpu = __builtin_cpu_supports("avx2");  // checks the OS saves YMM too
    return cpu && std::getenv("BOXES_NO_AVX2") == nullptr;
#else
    return false;
#endif
}

void traceBatch(const Bvh& bvh, const std::vector<Ray>& rays, std::vector<TraceHit>& hits,
                int threads) {
    traceBatchOf(bvh, rays, hits, threads);
}

void traceBatchChapter(const Bvh& bvh, const std::vector<Ray>& rays, std::vector<TraceHit>& hits,
                       int threads) {
    traceBatchOf(ChapterTraversal{bvh}, rays, hits, threads);
}

TraversalCounts countWork(const Bvh& bvh, const std::vector<Ray>& rays) {
    return countWorkOf(bvh, rays);
}

void forEachRayChunk(size_t count, int threads, const std::function<void(size_t, size_t)>& f) {
    constexpr size_t kChunk = 1024;
    std::atomic<size_t> next{0};
    auto drain = [&](int) {
        try {
            for (size_t begin; (begin = next.fetch_add(kChunk, std::memory_order_relaxed)) < count;)
                f(begin, std::min(count, begin + kChunk));
        } catch (...) {
            next.store(count, std::memory_order_relaxed);  // stop the others
            throw;
        }
    };
    if (count <= kChunk) return drain(0);
    runOnThreads(threads, drain);
}

void traceBatchBruteForce(const Mesh& mesh, const std::vector<Ray>& rays,
                          std::vector<TraceHit>& hits, int threads) {
    hits.assign(rays.size(), TraceHit{});
    // The same answer as traceBruteForce per ray (triangles in file order, strictly nearer
    // wins), blocked for the cache: a block of triangles (small enough for L2) is tested
    // against every ray of a chunk before the next block, instead of streaming the whole
    // mesh once per ray (the motorbike's vertices are 9.5 MB).
    constexpr size_t kTriangleBlock = 2048;
    size_t triangleCount = mesh.triangles.size();
    std::vector<LeafTriangle> triangles(triangleCount);
    for (size_t i = 0; i < triangleCount; ++i) triangles[i] = leafTriangleOf(mesh, i);
    forEachRayChunk(rays.size(), threads, [&](size_t begin, size_t end) {
        std::vector<WatertightRay> prepared;
        std::vector<float> tClosest;
        for (size_t r = begin; r < end; ++r) {
            prepared.emplace_back(rays[r]);
            tClosest.push_back(rays[r].tmax);
        }
        for (size_t block = 0; block < triangleCount; block += kTriangleBlock) {
            size_t blockEnd = std::min(triangleCount, block + kTriangleBlock);
            for (size_t r = begin; r < end; ++r) {
                const WatertightRay& watertight = prepared[r - begin];
                float& closest = tClosest[r - begin];
                TraceHit& best = hits[r];
                withWatertightAxes(watertight, [&](auto axes) {
                    for (size_t i = block; i < blockEnd; ++i) {
                        float t = closest;
                        if (intersectLeafTriangle(axes, watertight, triangles[i], t) &&
                            (best.triangle == kNoPrimitive || t < closest)) {
                            closest = t;
                            best = {t, uint32_t(i)};
                        }
                    }
                });
            }
        }
    });
}

}  // namespace boxes
