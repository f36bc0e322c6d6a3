// Step 04's engine: the binary tree's fast traversal, the loop the trace command and the
// batch tracers run on a binary tree. The same visits as the chapter's exercise 4.4 and
// 4.5 (traverse.hpp, trace.cpp), so the same hits bit for bit (tests/step04_advanced_wide.cpp
// compares them), with what the teaching loop leaves out: the leaf test's axis order fixed
// at compile time (one copy of the loop per order, chosen once per ray), the ray and the
// nearest t copied into locals the compiler keeps in registers, and a prefetch of what a
// child holds while the current pair is tested.
#pragma once

#include <cstdint>
#include <utility>

#include "04_bvh/leaf_test.hpp"
#include "04_bvh/trace.hpp"
#include "04_bvh/traverse.hpp"

namespace boxes {

// The six axis orders (kz the dominant axis, kx and ky swapped for a negative d[kz]),
// as compile-time constants: the leaf test then reads components from registers instead
// of through a run-time index (a store and an indexed load per component), and the
// traversal is instantiated once per order, chosen once per ray (withWatertightAxes).
template <int Kz, bool Swap>
struct WatertightAxes {
    static constexpr int kz = Kz;
    static constexpr int kx = Swap ? (Kz + 2) % 3 : (Kz + 1) % 3;
    static constexpr int ky = Swap ? (Kz + 1) % 3 : (Kz + 2) % 3;
};

// Calls f(WatertightAxes<...>{}) with the ray's axis order.
template <typename F>
decltype(auto) withWatertightAxes(const WatertightRay& r, F&& f) {
    bool swap = r.kx != (r.kz + 1) % 3;
    switch (r.kz * 2 + int(swap)) {
        case 0:
            return f(WatertightAxes<0, false>{});
        case 1:
            return f(WatertightAxes<0, true>{});
        case 2:
            return f(WatertightAxes<1, false>{});
        case 3:
            return f(WatertightAxes<1, true>{});
        case 4:
            return f(WatertightAxes<2, false>{});
        default:
            return f(WatertightAxes<2, true>{});
    }
}

// A hint for the traversal: ask for what it will read after `node` (its children's pair
// of boxes, or its leaf's triangles) while it still tests the current pair. Incoherent
// rays spend most of their time waiting for memory, and the fetch then overlaps the work.
// Only a hint: a traversal is correct without it (try yours with and without, in time).
// Always inlined: GCC finds that a call to it has no effect and drops the call, hints and
// all, once it is too large to be inlined early (a version with two more hints lost them).
[[gnu::always_inline]] inline void prefetchNodeContents(const Bvh& bvh, const BvhNode& node) {
    if (!node.isLeaf())
        __builtin_prefetch(&bvh.nodes[node.leftFirst]);
    else if (!bvh.leafTriangles.empty()) {
        // A leaf's triangles (36 bytes each) span two cache lines from its second one on.
        const char* first = reinterpret_cast<const char*>(&bvh.leafTriangles[node.leftFirst]);
        __builtin_prefetch(first);
        if (node.count > 1) __builtin_prefetch(first + 64);
    }
}

// Does the ray enter the tree's root box (any tree with empty() and rootNode())? Decided
// before the triangle test's per-ray set-up: most rays of a camera framing a mesh miss
// it. The root is read where it lies: a copy on the stack makes the loads through the
// ray's run-time plane offsets wait for the copy's stores.
template <typename Tree>
[[gnu::always_inline]] inline bool entersRoot(const Tree& tree, const TraversalRay& traversal) {
    if (tree.empty()) return false;
    float tEntry;
    return intersectNodeBounds(tree.rootNode(), traversal, traversal.tmax, tEntry);
}

// What the nearest-hit set-up tells a counter: nothing by default (the engine's
// `trace --count` counts the triangle tests).
struct NoTriangleCount {
    void triangles(uint32_t) {}
};

// Exercise 4.4's loop (traverse.hpp) with the ray and the nearest t in locals and the
// prefetches above; the same nodes in the same order, so the same hits. A copy, not a
// call: the chapter's loop is the exercise (a starter kit's is a stub) in the plain form
// its README teaches, and this one is what the trace command and the bench run.
template <typename PrimitiveIntersector>
uint32_t traverseNearestFast(const Bvh& bvh, const TraversalRay& ray, float& tClosest,
                             PrimitiveIntersector&& intersect) {
    if (bvh.nodes.empty()) return kTraversalMiss;
    uint32_t nearestSlot = kTraversalMiss;
    const BvhNode* nodes = bvh.nodes.data();
    // Local copies: the compiler may then keep them in registers across intersect(),
    // which it must otherwise assume writes to them.
    const TraversalRay r = ray;
    float tBest = tClosest;
    // The stack keeps where the ray enters each postponed node: a pop skips it without a
    // second box test once a hit nearer than that is known.
    struct Entry {
        uint32_t node;
        float tEntry;
    } stack[kTraversalStackSize];
    int stackSize = 0;
    float tRoot;
    if (!intersectNodeBounds(nodes[0], r, tBest, tRoot)) return kTraversalMiss;
    uint32_t current = 0;
    for (;;) {
        const BvhNode& node = nodes[current];
        if (node.isLeaf()) {
            for (uint32_t slot = node.leftFirst; slot < node.leftFirst + node.count; ++slot)
                if (intersect(slot, tBest)) nearestSlot = slot;
        } else {
            // Both children at once: descend into the nearer, keep the farther for later.
            uint32_t near = node.leftFirst, far = node.leftFirst + 1;
            prefetchNodeContents(bvh, nodes[near]);
            prefetchNodeContents(bvh, nodes[far]);
            float tNear, tFar;
            bool hitNear = intersectNodeBounds(nodes[near], r, tBest, tNear);
            bool hitFar = intersectNodeBounds(nodes[far], r, tBest, tFar);
            if (hitNear && hitFar) {
                if (tFar < tNear) {
                    std::swap(near, far);
                    std::swap(tNear, tFar);
                }
                stack[stackSize++] = {far, tFar};
                current = near;
                continue;
            }
            if (hitNear || hitFar) {
                current = hitNear ? near : far;
                continue;
            }
        }
        // Pop until a node the ray enters before the nearest hit so far (early out).
        bool found = false;
        while (stackSize > 0) {
            const Entry& e = stack[--stackSize];
            if (e.tEntry <= tBest) {
                current = e.node;
                found = true;
                break;
            }
        }
        if (!found) break;
    }
    tClosest = tBest;
    return nearestSlot;
}

// The nearest triangle of `ray` through `bvh`: the ray is prepared for the boxes (with the
// tree's margin) and for the triangles, the root box decided first, then the loop above
// runs with the watertight leaf test, its axis order fixed at compile time. Returns the
// leaf slot (kTraversalMiss on a miss) with t in tClosest and, when asked, the
// barycentrics of b and c.
template <typename Counter = NoTriangleCount>
inline uint32_t nearestSlotFast(const Bvh& bvh, const Ray& ray, float& tClosest, float* u = nullptr,
                                float* v = nullptr, Counter counter = {}) {
    tClosest = ray.tmax;
    TraversalRay traversal(ray, bvh);
    if (!entersRoot(bvh, traversal)) return kTraversalMiss;
    WatertightRay watertight(ray);
    const LeafTriangle* tris = bvh.leafTriangles.data();
    return withWatertightAxes(watertight, [&](auto axes) {
        return traverseNearestFast(bvh, traversal, tClosest, [&](uint32_t s, float& tmax) {
            counter.triangles(1);
            return intersectLeafTriangle(axes, watertight, tris[s], tmax, u, v);
        });
    });
}

template <typename Counter = NoTriangleCount>
inline TraceHit traceNearestFast(const Bvh& bvh, const Ray& ray, Counter counter = {}) {
    float tClosest;
    uint32_t slot = nearestSlotFast(bvh, ray, tClosest, nullptr, nullptr, counter);
    if (slot == kTraversalMiss) return {};
    return {tClosest, bvh.primitiveIndices[slot]};
}

// Any triangle in [ray.tmin, ray.tmax]: the chapter's exercise 4.5 with the set-up above.
inline bool traceOccludedFast(const Bvh& bvh, const Ray& ray) {
    TraversalRay traversal(ray, bvh);
    if (!entersRoot(bvh, traversal)) return false;
    WatertightRay watertight(ray);
    const LeafTriangle* tris = bvh.leafTriangles.data();
    return withWatertightAxes(watertight, [&](auto axes) {
        return traverseAny(bvh, traversal, [&](uint32_t s, float tmax) {
            return intersectLeafTriangle(axes, watertight, tris[s], tmax);
        });
    });
}

}  // namespace boxes
