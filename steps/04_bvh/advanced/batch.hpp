// Step 04's engine: tracing batches of rays. The batch loop on threads, compiled twice
// (baseline x86-64 and AVX2, chosen at run time), counting the work of a batch
// (`trace --count`), and brute force over batches to check any tree.
#pragma once

#include <cstdint>
#include <functional>
#include <type_traits>
#include <vector>

#include "04_bvh/advanced/traverse.hpp"

namespace boxes {

// The work of tracing a batch of rays, summed over the rays (`trace --count`): a count of
// what the traversal does, the same on every machine, where a time is not. For the binary
// tree only its triangle tests are counted (from the leaf test its loop calls); the wide
// trees' loops count their nodes, leaves and packets too.
struct TraversalCounts {
    uint64_t rays = 0;
    uint64_t nodes = 0;      // wide nodes whose boxes were tested (wide trees only)
    uint64_t leaves = 0;     // leaves tested (wide trees only)
    uint64_t packets = 0;    // packets of four triangles tested (wide trees only)
    uint64_t triangles = 0;  // triangles tested (a packet's padding lanes not counted)
};
// The counting policies of the traversal templates: no count (the timed loops), or into
// a TraversalCounts.
struct NoTraversalCount {
    void node() {}
    void leaf(uint32_t) {}
    void triangles(uint32_t) {}
};
struct TraversalCounter {
    TraversalCounts* counts;
    void node() { ++counts->nodes; }
    void leaf(uint32_t packets) {
        ++counts->leaves;
        counts->packets += packets;
    }
    void triangles(uint32_t n) { counts->triangles += n; }
};

// Traces every ray on `threads` threads: the calling thread and workers kept between
// batches, chunks of 1,024 rays handed out dynamically.
void traceBatch(const Bvh& bvh, const std::vector<Ray>& rays, std::vector<TraceHit>& hits,
                int threads);
// The same through the chapter's traversal (`trace --chapter`).
void traceBatchChapter(const Bvh& bvh, const std::vector<Ray>& rays, std::vector<TraceHit>& hits,
                       int threads);
void traceBatchBruteForce(const Mesh& mesh, const std::vector<Ray>& rays,
                          std::vector<TraceHit>& hits, int threads);
// The batch loop itself: f(begin, end) on chunks of 1,024 of [0, count), handed out
// dynamically to `threads` threads (0: all cores): the calling thread and the workers core
// keeps between calls (core/render.hpp, runOnThreads). The first exception ends the batch early and
// reaches the caller. Every batch tracer of the step runs on it (traceBatchOf below,
// brute force).
void forEachRayChunk(size_t count, int threads, const std::function<void(size_t, size_t)>& f);

// The batch tracers' inner loop is compiled twice: for baseline x86-64 and, with every
// call inlined into it (gnu::flatten), for AVX2, chosen at run time as Embree chooses its
// instruction set. The arithmetic is the same (AVX2 brings no FMA, and -ffp-contract=off
// forbids contraction anyway), so are the bits of every hit; the AVX encoding's
// three-operand instructions save the register copies of the SSE one.
#if defined(__x86_64__) && defined(__GNUC__)
#define BOXES_TARGET_AVX2 [[gnu::target("avx2"), gnu::flatten]]
#endif
// True when the batch tracers run their AVX2 loop: the CPU has AVX2 and the environment
// does not set BOXES_NO_AVX2 (to measure or test the baseline loop). Read per batch.
bool traceUsesAvx2();

// A tree's nearest hit in the batch loop; kAvx selects the wide trees' AVX box test (their
// overload is in bvh4.hpp). The binary tree has none: its loop is the engine's copy of
// exercise 4.4's (traverse.hpp here).
template <bool kAvx>
inline TraceHit batchNearestHit(const Bvh& bvh, const Ray& ray) {
    return traceNearestFast(bvh, ray);
}
// `trace --chapter`: the binary tree through the chapter's own loop (your exercise 4.4).
struct ChapterTraversal {
    const Bvh& bvh;
};
template <bool kAvx>
inline TraceHit batchNearestHit(const ChapterTraversal& tree, const Ray& ray) {
    return traceNearest(tree.bvh, ray);
}

namespace detail {
template <bool kAvx, typename Tree>
void traceRange(const Tree& tree, const Ray* rays, TraceHit* hits, size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) hits[i] = batchNearestHit<kAvx>(tree, rays[i]);
}
#if defined(BOXES_TARGET_AVX2)
template <typename Tree>
BOXES_TARGET_AVX2 void traceRangeAvx2(const Tree& tree, const Ray* rays, TraceHit* hits,
                                      size_t begin, size_t end) {
    traceRange<true>(tree, rays, hits, begin, end);
}
#endif
}  // namespace detail

// The batch loop of every tree (Bvh, Bvh4, Bvh8): its nearest hit on each ray, on
// `threads` threads, in the AVX2 copy where traceUsesAvx2(). Each tree's traceBatch
// instantiates it.
template <typename Tree>
void traceBatchOf(const Tree& tree, const std::vector<Ray>& rays, std::vector<TraceHit>& hits,
                  int threads) {
    hits.resize(rays.size());
    auto range = &detail::traceRange<false, Tree>;
#if defined(BOXES_TARGET_AVX2)
    if (traceUsesAvx2()) range = &detail::traceRangeAvx2<Tree>;
#endif
    forEachRayChunk(rays.size(), threads, [&](size_t begin, size_t end) {
        range(tree, rays.data(), hits.data(), begin, end);
    });
}

// Counts the work of tracing `rays` (one thread, in order: the same counts every run).
template <typename Tree>
TraversalCounts countWorkOf(const Tree& tree, const std::vector<Ray>& rays) {
    TraversalCounts counts;
    counts.rays = rays.size();
    for (const Ray& ray : rays) {
        if constexpr (std::is_same_v<Tree, Bvh>)
            traceNearestFast(tree, ray, TraversalCounter{&counts});
        else
            traceNearest(tree, ray, TraversalCounter{&counts});
    }
    return counts;
}
TraversalCounts countWork(const Bvh& bvh, const std::vector<Ray>& rays);

}  // namespace boxes
