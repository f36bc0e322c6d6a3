// Step 04, the advanced variant (not an exercise): a 4-wide hierarchy traversed with SIMD.
//
// Layout (as Embree's BVH4 and tinybvh's BVH4): one node holds its four children's boxes
// "structure of arrays", minimum x of the four children in one float[4], then minimum y, ...,
// so one SSE load brings one plane of all four boxes, and one ray is tested against the
// four boxes at once. 128 bytes, aligned to two 64-byte cache lines. A child is an inner
// node (count 0, child = its node index), a leaf (count > 0, child = its first slot) or
// an empty slot (an inverted box no ray enters).
//
// Built by collapsing a binary tree (Dammertz, Hanika, Keller 2008, "Shallow bounding
// volume hierarchies for fast SIMD ray tracing of incoherent rays"; Wald, Benthin, Boulos
// 2008, "Getting rid of packets"): a node starts with its two children, and while it has
// fewer than four, the inner child with the largest surface area (the one a ray most likely
// enters) is replaced by its own two children. Leaves, slots and the leaf triangles are the
// binary tree's, unchanged.
//
// Traversal is conservative exactly as the scalar one: the same margin-shifted origins,
// the same operations in the same order, kBoxFarScale on the far distance, and a NaN from
// 0 * infinity (origin in a slab plane, zero direction component) ignored (the min/max
// operand order below). The four entry distances and the scalar test's agree bit for bit.
#pragma once

#include <bit>
#include <cstdint>
#include <vector>

#include "04_bvh/bvh.hpp"
#include "04_bvh/trace.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace boxes {

struct alignas(64) Bvh4Node {
    float boundsMin[3][4];  // [axis][child]
    float boundsMax[3][4];
    uint32_t child[4];  // inner child: node index; leaf: first slot; empty: 0
    uint32_t count[4];  // 0: inner child (or empty slot), else the leaf's size

    bool isLeaf(int i) const { return count[i] != 0; }
    Bounds3f bounds(int i) const {
        return {Vec3(boundsMin[0][i], boundsMin[1][i], boundsMin[2][i]),
                Vec3(boundsMax[0][i], boundsMax[1][i], boundsMax[2][i])};
    }
    // An empty slot: an inverted box (+inf .. -inf) that every ray misses, NaN-free.
    bool isEmpty(int i) const { return count[i] == 0 && boundsMin[0][i] > boundsMax[0][i]; }
};
static_assert(sizeof(Bvh4Node) == 128, "two 64-byte cache lines");

struct Bvh4 {
    std::vector<Bvh4Node> nodes;  // nodes[0] is the root (when not empty); alignas: new aligns
    std::vector<uint32_t> primitiveIndices;   // the binary tree's slots
    std::vector<LeafTriangle> leafTriangles;  // meshes only
    Bounds3f rootBounds;

    bool empty() const { return nodes.empty(); }
    Bounds3f bounds() const { return rootBounds; }
};

// Collapses a binary hierarchy (the arrays of slots and triangles move over).
Bvh4 collapseToBvh4(Bvh binary);

struct Bvh4Stats {
    size_t nodes = 0, leaves = 0, emptySlots = 0;
    int depth = 0;  // the deepest leaf; children of the root are depth 1
};
Bvh4Stats bvh4Stats(const Bvh4& bvh);

// A ray prepared for the four-box test: per axis the offset (in floats into a node) of the
// plane array met first and of the one met last, and broadcast origins and 1/d.
struct Bvh4Ray {
    int nearOffset[3], farOffset[3];
    float nearOrigin[3], farOrigin[3], inverseDirection[3], tmin;
#if defined(__SSE2__)
    __m128 nearOriginV[3], farOriginV[3], inverseDirectionV[3], tminV;
#endif
    explicit Bvh4Ray(const TraversalRay& ray) : tmin(ray.tmin) {
        for (int axis = 0; axis < 3; ++axis) {
            bool positive = ray.nearOffset[axis] == axis;  // the min plane first
            nearOffset[axis] = positive ? 4 * axis : 12 + 4 * axis;
            farOffset[axis] = positive ? 12 + 4 * axis : 4 * axis;
            nearOrigin[axis] = ray.nearOrigin[axis];
            farOrigin[axis] = ray.farOrigin[axis];
            inverseDirection[axis] = (&ray.inverseDirection.x)[axis];
#if defined(__SSE2__)
            nearOriginV[axis] = _mm_set1_ps(nearOrigin[axis]);
            farOriginV[axis] = _mm_set1_ps(farOrigin[axis]);
            inverseDirectionV[axis] = _mm_set1_ps(inverseDirection[axis]);
#endif
        }
#if defined(__SSE2__)
        tminV = _mm_set1_ps(tmin);
#endif
    }
};

// The slab test of one ray against a node's four boxes in [ray.tmin, tmax]: bit i of the
// result is set when the ray enters box i, at tEntry[i]. Per box, the same arithmetic as
// intersectNodeBounds.
inline int intersectChildBounds(const Bvh4Node& node, const Bvh4Ray& ray, float tmax,
                                float tEntry[4]) {
    const float* planes = &node.boundsMin[0][0];
#if defined(__SSE2__)
    __m128 t0 = ray.tminV, t1 = _mm_set1_ps(tmax);
    const __m128 farScale = _mm_set1_ps(kBoxFarScale);
    for (int axis = 0; axis < 3; ++axis) {
        __m128 tNear = _mm_mul_ps(
            _mm_sub_ps(_mm_load_ps(planes + ray.nearOffset[axis]), ray.nearOriginV[axis]),
            ray.inverseDirectionV[axis]);
        __m128 tFar = _mm_mul_ps(
            _mm_mul_ps(_mm_sub_ps(_mm_load_ps(planes + ray.farOffset[axis]), ray.farOriginV[axis]),
                       ray.inverseDirectionV[axis]),
            farScale);
        // maxps/minps return the second operand when either is NaN: the running bound
        // goes second, so a NaN plane distance is ignored (as `tNear > t0 ? tNear : t0`).
        t0 = _mm_max_ps(tNear, t0);
        t1 = _mm_min_ps(tFar, t1);
    }
    _mm_storeu_ps(tEntry, t0);
    // Empty slots (min > max) are masked out: with a non-finite origin (coordinates near
    // the float range's end) every slab distance is NaN and every box looks entered.
    __m128 filled = _mm_cmple_ps(_mm_load_ps(planes), _mm_load_ps(planes + 12));
    return _mm_movemask_ps(_mm_and_ps(_mm_cmple_ps(t0, t1), filled));
#else
    int mask = 0;
    for (int i = 0; i < 4; ++i) {
        float t0 = ray.tmin, t1 = tmax;
        for (int axis = 0; axis < 3; ++axis) {
            float tNear = (planes[ray.nearOffset[axis] + i] - ray.nearOrigin[axis]) *
                          ray.inverseDirection[axis];
            float tFar = (planes[ray.farOffset[axis] + i] - ray.farOrigin[axis]) *
                         ray.inverseDirection[axis] * kBoxFarScale;
            t0 = tNear > t0 ? tNear : t0;
            t1 = tFar < t1 ? tFar : t1;
        }
        tEntry[i] = t0;
        mask |= int(t0 <= t1 && planes[i] <= planes[12 + i]) << i;  // not an empty slot
    }
    return mask;
#endif
}

// Inner children push up to three entries per level, and the builders cap the depth at 64.
constexpr int kBvh4StackSize = 256;

// Nearest hit, nearest child first, early out; the interface of traverseNearest
// (intersect(slot, tClosest) lowers tClosest on a hit). Returns the slot or kTraversalMiss.
template <typename PrimitiveIntersector>
uint32_t traverseNearest4(const Bvh4& bvh, const TraversalRay& traversal, float& tClosest,
                          PrimitiveIntersector&& intersect) {
    if (bvh.empty()) return kTraversalMiss;
    const Bvh4Ray ray(traversal);
    const Bvh4Node* nodes = bvh.nodes.data();
    struct Entry {
        uint32_t child, count;
        float tEntry;
    } stack[kBvh4StackSize];
    int stackSize = 0;
    uint32_t nearestSlot = kTraversalMiss;
    uint32_t child = 0, count = 0;  // the root, an inner node
    for (;;) {
        if (count == 0) {
            const Bvh4Node& node = nodes[child];
            alignas(16) float t[4];
            int mask = intersectChildBounds(node, ray, tClosest, t);
            if (mask != 0) {
                int first = std::countr_zero(unsigned(mask));
                mask &= mask - 1;
                if (mask == 0) {  // one child: descend, nothing to keep
                    child = node.child[first];
                    count = node.count[first];
                    continue;
                }
                // Two to four: sorted farthest first onto the stack, the nearest descended.
                Entry hit[4];
                hit[0] = {node.child[first], node.count[first], t[first]};
                int hits = 1;
                while (mask != 0) {
                    int i = std::countr_zero(unsigned(mask));
                    mask &= mask - 1;
                    Entry e{node.child[i], node.count[i], t[i]};
                    int j = hits++;
                    for (; j > 0 && hit[j - 1].tEntry < e.tEntry; --j) hit[j] = hit[j - 1];
                    hit[j] = e;
                }
                for (int j = 0; j < hits - 1; ++j) stack[stackSize++] = hit[j];
                child = hit[hits - 1].child;
                count = hit[hits - 1].count;
                continue;
            }
        } else {
            for (uint32_t slot = child; slot < child + count; ++slot)
                if (intersect(slot, tClosest)) nearestSlot = slot;
        }
        // Pop until an entry the ray enters before the nearest hit so far.
        for (;;) {
            if (stackSize == 0) return nearestSlot;
            const Entry& e = stack[--stackSize];
            if (e.tEntry <= tClosest) {
                child = e.child;
                count = e.count;
                break;
            }
        }
    }
}

// Any hit in [ray.tmin, ray.tmax] (shadow rays): no order, stop at the first hit.
template <typename PrimitiveIntersector>
bool traverseAny4(const Bvh4& bvh, const TraversalRay& traversal,
                  PrimitiveIntersector&& intersect) {
    if (bvh.empty()) return false;
    const Bvh4Ray ray(traversal);
    const Bvh4Node* nodes = bvh.nodes.data();
    struct Entry {
        uint32_t child, count;
    } stack[kBvh4StackSize];
    int stackSize = 0;
    stack[stackSize++] = {0, 0};
    while (stackSize > 0) {
        Entry e = stack[--stackSize];
        if (e.count != 0) {
            for (uint32_t slot = e.child; slot < e.child + e.count; ++slot)
                if (intersect(slot, traversal.tmax)) return true;
            continue;
        }
        const Bvh4Node& node = nodes[e.child];
        alignas(16) float t[4];
        int mask = intersectChildBounds(node, ray, traversal.tmax, t);
        while (mask != 0) {
            int i = std::countr_zero(unsigned(mask));
            mask &= mask - 1;
            stack[stackSize++] = {node.child[i], node.count[i]};
        }
    }
    return false;
}

// The margin of the scalar traversal, from the same root bounds.
inline float traversalMargin(const Ray& ray, const Bvh4& bvh) {
    return bvh.empty() ? 0.0f : TraversalRay::marginFor(ray, bvh.bounds());
}

inline TraceHit traceNearest(const Bvh4& bvh, const Ray& ray) {
    TraversalRay traversal(ray, traversalMargin(ray, bvh));
    WatertightRay watertight(ray);
    float tClosest = ray.tmax;
    const LeafTriangle* tris = bvh.leafTriangles.data();
    uint32_t slot = withWatertightAxes(watertight, [&](auto axes) {
        return traverseNearest4(bvh, traversal, tClosest, [&](uint32_t s, float& tmax) {
            return intersectLeafTriangle(axes, watertight, tris[s], tmax);
        });
    });
    if (slot == kTraversalMiss) return {};
    return {tClosest, bvh.primitiveIndices[slot]};
}

inline bool traceOccluded(const Bvh4& bvh, const Ray& ray) {
    TraversalRay traversal(ray, traversalMargin(ray, bvh));
    WatertightRay watertight(ray);
    const LeafTriangle* tris = bvh.leafTriangles.data();
    return withWatertightAxes(watertight, [&](auto axes) {
        return traverseAny4(bvh, traversal, [&](uint32_t s, float tmax) {
            return intersectLeafTriangle(axes, watertight, tris[s], tmax);
        });
    });
}

void traceBatch(const Bvh4& bvh, const std::vector<Ray>& rays, std::vector<TraceHit>& hits,
                int threads);

}  // namespace boxes
