// Step 04: traversing the hierarchy. A ray prepared for box tests, the test of one node's
// box, and the two traversals: exercise 4.4 (nearest hit) and 4.5 (any hit). Both are
// templates over the primitive test, so the same loop serves the watertight triangle test
// (trace.cpp), a test's reference triangle test, and anything else with bounds. The
// engine's fast copy of these loops is advanced/traverse.hpp.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>

#include "04_bvh/bvh.hpp"
#include "core/math.hpp"

namespace boxes {

// 1 + 2 gamma(3), gamma(n) = n eps / (1 - n eps) with eps = 2^-24 (pbrt-v4, Ize 2013):
// widening the slab test's far distance by it makes the float slab test itself
// conservative (its own roundings never drop a box the exact ray touches). The ray folds it
// into the far planes' 1/d once: (b - o) * (1/d * scale) has four roundings, like
// (b - o) * 1/d * scale, and the same bound, with one product less per slab.
constexpr float kBoxFarScale = 1.0f + 2.0f * (3.0f * 0x1p-24f) / (1.0f - 3.0f * 0x1p-24f);

// A ray prepared for box tests: reciprocal direction (+infinity for a zero component),
// and the origin moved by a margin, so the box test is conservative with respect to the
// watertight triangle test. That test translates the vertices to the ray origin and shears
// them, rounding each time: it can report a hit up to a few float steps of |vertex - O|
// outside the exact triangle (Woop, Benthin, Wald 2013, section 4: the box test must
// allow for the same error). We widen each box by
//   margin = 64 * 2^-24 * (|O - centre| + radius)   (the root's bounding sphere; taxicab
//   lengths, see marginFor),
// an upper bound of that error for every vertex in the tree, folded into two origins:
// minimum planes use O + margin and maximum planes O - margin (same cost as one origin).
struct TraversalRay {
    Vec3 originForMin, originForMax, direction, inverseDirection;
    Vec3 farInverseDirection;  // inverseDirection * kBoxFarScale
    float tmin, tmax;
    // Per axis, which bound the ray meets first (offsets into a node seen as 8 floats:
    // min at 0..2, max at 4..6) and the origin that goes with it: no swap in the slab test.
    int nearOffset[3], farOffset[3];
    float nearOrigin[3], farOrigin[3];

    explicit TraversalRay(const Ray& ray, float margin = 0.0f)
        : originForMin(ray.origin + Vec3(margin)),
          originForMax(ray.origin - Vec3(margin)),
          direction(ray.direction),
          inverseDirection(inverse(ray.direction.x), inverse(ray.direction.y),
                           inverse(ray.direction.z)),
          tmin(ray.tmin),
          tmax(ray.tmax) {
        for (int axis = 0; axis < 3; ++axis) {
            bool positive = (&inverseDirection.x)[axis] >= 0.0f;
            nearOffset[axis] = positive ? axis : 4 + axis;
            farOffset[axis] = positive ? 4 + axis : axis;
            nearOrigin[axis] = positive ? (&originForMin.x)[axis] : (&originForMax.x)[axis];
            farOrigin[axis] = positive ? (&originForMax.x)[axis] : (&originForMin.x)[axis];
            (&farInverseDirection.x)[axis] = (&inverseDirection.x)[axis] * kBoxFarScale;
        }
    }
    // The margin for the triangles of `bvh` (see above).
    TraversalRay(const Ray& ray, const Bvh& bvh) : TraversalRay(ray, marginFor(ray, bvh)) {}

    // 1/d, but +infinity for both +0 and -0: then a zero component gives (NaN or -inf,
    // NaN or +inf) for an origin inside the slab (no constraint: the NaN is ignored below)
    // and (+inf, +inf) or (-inf, -inf) outside it (a miss), as it must be.
    static float inverse(float d) { return d == 0.0f ? kInfinity<float> : 1.0f / d; }

    static float marginFor(const Ray& ray, const Bvh& bvh) {
        return bvh.empty() ? 0.0f : marginFor(ray, bvh.bounds());
    }
    // In double: in float the sums overflow for coordinates beyond about 1e38, and an
    // infinite margin turns every slab distance into NaN (every box entered). The lengths
    // are taxicab lengths, an upper bound of the Euclidean ones (at most sqrt(3) times
    // larger): a margin a little wider, no square root per ray.
    static float marginFor(const Ray& ray, const Bounds3f& rootBounds) {
        Vec3d lo(rootBounds.min), hi(rootBounds.max);
        Vec3d halfExtent = 0.5 * (hi - lo), offset = Vec3d(ray.origin) - (lo + halfExtent);
        double radius = halfExtent.x + halfExtent.y + halfExtent.z;
        // std::fabs, not glm::abs: GCC compiles the latter to compares and branches, which
        // incoherent rays mispredict.
        double distance = std::fabs(offset.x) + std::fabs(offset.y) + std::fabs(offset.z);
        return float(64.0 * 0x1p-24 * (distance + radius));
    }
};

// The conservative slab test against a node's box in [ray.tmin, tmax]; tEntry is where the
// ray enters (>= ray.tmin). Not step 03's exercise: the hierarchy needs its own copy.
// 0 * infinity (origin on a slab plane, zero direction component) gives NaN, and the
// comparisons below ignore a NaN bound: the ray lies in that plane, and the closed box
// contains it along that axis. Components through pointers: glm's operator[] is a switch.
[[gnu::always_inline]] inline bool intersectNodeBounds(const BvhNode& node, const TraversalRay& ray,
                                                       float tmax, float& tEntry) {
    static_assert(offsetof(BvhNode, boundsMax) == 4 * sizeof(float), "node as 8 floats");
    const float* bounds = &node.boundsMin.x;
    const float* inv = &ray.inverseDirection.x;
    const float* farInv = &ray.farInverseDirection.x;
    float t0 = ray.tmin, t1 = tmax;
    for (int axis = 0; axis < 3; ++axis) {
        float tNear = (bounds[ray.nearOffset[axis]] - ray.nearOrigin[axis]) * inv[axis];
        float tFar = (bounds[ray.farOffset[axis]] - ray.farOrigin[axis]) * farInv[axis];
        t0 = tNear > t0 ? tNear : t0;  // a NaN bound is ignored (see above)
        t1 = tFar < t1 ? tFar : t1;
    }
    tEntry = t0;
    return t0 <= t1;
}

// Depth of the traversal stack: the builders cap the depth below it.
constexpr int kTraversalStackSize = 2 * kMaxBvhDepth;

// EXERCISE 4.4: nearest-hit traversal: nearer child first, early out (4 points)
// intersect(slot, tClosest) tests the primitive in leaf slot `slot` for a hit in
// [ray.tmin, tClosest], and on a hit lowers tClosest and returns true. Returns the slot of
// the nearest hit (tClosest its distance), or kTraversalMiss. Skip every node the ray
// enters beyond tClosest; visit the child the ray enters first before the other.
constexpr uint32_t kTraversalMiss = 0xFFFFFFFFu;
template <typename PrimitiveIntersector>
uint32_t traverseNearest(const Bvh& bvh, const TraversalRay& ray, float& tClosest,
                         PrimitiveIntersector&& intersect) {
    // BEGIN SOLUTION
    if (bvh.nodes.empty()) return kTraversalMiss;
    uint32_t nearestSlot = kTraversalMiss;
    // The stack keeps where the ray enters each postponed node: a pop skips it without a
    // second box test once a hit nearer than that is known.
    struct Entry {
        uint32_t node;
        float tEntry;
    } stack[kTraversalStackSize];
    int stackSize = 0;
    float tRoot;
    if (!intersectNodeBounds(bvh.nodes[0], ray, tClosest, tRoot)) return kTraversalMiss;
    uint32_t current = 0;
    for (;;) {
        const BvhNode& node = bvh.nodes[current];
        if (node.isLeaf()) {
            for (uint32_t slot = node.leftFirst; slot < node.leftFirst + node.count; ++slot)
                if (intersect(slot, tClosest)) nearestSlot = slot;
        } else {
            // Both children at once: descend into the nearer, keep the farther for later.
            uint32_t near = node.leftFirst, far = node.leftFirst + 1;
            float tNear, tFar;
            bool hitNear = intersectNodeBounds(bvh.nodes[near], ray, tClosest, tNear);
            bool hitFar = intersectNodeBounds(bvh.nodes[far], ray, tClosest, tFar);
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
            if (e.tEntry <= tClosest) {
                current = e.node;
                found = true;
                break;
            }
        }
        if (!found) break;
    }
    return nearestSlot;
    // END SOLUTION
}

// EXERCISE 4.5: any-hit traversal for shadow rays: stop at the first hit (2 points)
// intersect(slot, tmax) returns true when the primitive in `slot` is hit in
// [ray.tmin, tmax]. Returns true as soon as any primitive is hit in [ray.tmin, ray.tmax].
template <typename PrimitiveIntersector>
bool traverseAny(const Bvh& bvh, const TraversalRay& ray, PrimitiveIntersector&& intersect) {
    // BEGIN SOLUTION
    if (bvh.nodes.empty()) return false;
    const BvhNode* nodes = bvh.nodes.data();
    uint32_t stack[kTraversalStackSize];
    int stackSize = 0;
    stack[stackSize++] = 0;
    while (stackSize > 0) {
        const BvhNode& node = nodes[stack[--stackSize]];
        float tEntry;
        if (!intersectNodeBounds(node, ray, ray.tmax, tEntry)) continue;
        if (node.isLeaf()) {
            for (uint32_t slot = node.leftFirst; slot < node.leftFirst + node.count; ++slot)
                if (intersect(slot, ray.tmax)) return true;
        } else {
            // No order is needed: any hit ends the search.
            stack[stackSize++] = node.leftFirst + 1;
            stack[stackSize++] = node.leftFirst;
        }
    }
    return false;
    // END SOLUTION
}

}  // namespace boxes
