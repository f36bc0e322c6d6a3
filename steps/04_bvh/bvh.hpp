// Step 04: a bounding volume hierarchy over triangles (or any primitives with bounds).
//
// Layout (after Bikker's tinybvh and pbrt's LinearBVHNode): one array of 32-byte nodes,
// two per cache line; the children of an interior node are adjacent (left, left + 1), so
// a node needs one index; a leaf names a range of "slots" in primitiveIndices, which the
// builder reorders so every leaf's primitives are contiguous. For meshes the triangles'
// vertices are also copied in slot order (leafTriangles): the leaf test reads them
// sequentially instead of chasing two indices per triangle.
//
// Builders share one recursive framework (buildBvh); what differs is how a node's
// primitives are split, and that is the exercises: 4.1 midpoint, 4.2 object median,
// 4.3 binned SAH. A full-sweep SAH builder (not an exercise) is the quality reference.
// Traversal (4.4 nearest hit, 4.5 any hit) is a template over the primitive test, so the
// same loop serves triangles, tests with a reference triangle test, and anything else.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <new>
#include <span>
#include <string>
#include <vector>

#include "core/bounds.hpp"
#include "core/exercise.hpp"
#include "core/mesh.hpp"
#include "core/ray.hpp"

namespace boxes {

// 32 bytes: bounds, then leftFirst (interior: index of the left child, the right child is
// leftFirst + 1; leaf: first slot) and count (0 for an interior node, else the leaf's size).
struct alignas(32) BvhNode {
    Vec3 boundsMin{kInfinity<float>};
    uint32_t leftFirst = 0;
    Vec3 boundsMax{-kInfinity<float>};
    uint32_t count = 0;

    bool isLeaf() const { return count != 0; }
    Bounds3f bounds() const { return {boundsMin, boundsMax}; }
};
static_assert(sizeof(BvhNode) == 32, "two nodes per 64-byte cache line");

// A triangle's vertices, stored in leaf-slot order for the leaf test.
struct LeafTriangle {
    Vec3 a, b, c;
};

// The leaf-test copy of a mesh's triangle. A triangle without area (the cross product of
// its edge vectors exactly zero in double: a repeated vertex, or three on one line) is
// stored as its first vertex three times, which the watertight test misses for every ray
// (its edge functions and det are exactly 0), at no cost in the hot loop. pbrt-v4's
// IntersectTriangle rejects such triangles too: their edge functions are rounding noise,
// and so is a t computed from them (rays aimed within 1e-7 of a segment on the y axis hit
// it 3.7% of the time, up to 0.62 off the axis: outside the triangle's box, where a
// hierarchy and brute force then differ).
LeafTriangle leafTriangleOf(const Mesh& mesh, size_t triangle);

// Memory for large arrays (bvh_build.cpp): at least 64-byte aligned; from half a megabyte
// on, 2 MiB aligned and on transparent huge pages where Linux offers them (far fewer page
// faults while the build fills it, fewer TLB misses while tracing).
constexpr size_t kHugePage = size_t(2) << 20;
void* allocateLarge(size_t bytes);
void freeLarge(void* p, size_t bytes);
// Asks for transparent huge pages over the whole 2 MiB blocks inside [data, data + bytes).
// Advice only: any failure changes nothing.
void adviseHugePages(const void* data, size_t bytes);

// An array a build fills once (leaf triangles, slot order, a 4-wide tree's arrays): when it
// is large, its reserved, not yet touched capacity goes on huge pages (without 2 MiB
// alignment the blocks at its ends keep 4 KiB pages).
template <typename Vector>
void reserveOnHugePages(Vector& v, size_t capacity) {
    v.reserve(capacity);
    adviseHugePages(v.data(), v.capacity() * sizeof(*v.data()));
}

// The node array's allocator: it places node 0 (the root, which has no sibling) in the
// second half of a 64-byte cache line, so every pair of children (1, 2), (3, 4), ...
// starts a cache line: one fetch brings both children's boxes. (With an ordinary
// allocation the pairs straddle two lines, and every node fetch costs two misses.)
template <typename T>
struct ChildPairAllocator {
    using value_type = T;
    static constexpr size_t kLine = 64, kOffset = 64 - sizeof(T) % 64;
    ChildPairAllocator() = default;
    template <typename U>
    ChildPairAllocator(const ChildPairAllocator<U>&) {}
    T* allocate(size_t n) {
        void* p = allocateLarge(n * sizeof(T) + kOffset);
        return reinterpret_cast<T*>(static_cast<std::byte*>(p) + kOffset);
    }
    void deallocate(T* p, size_t n) {
        freeLarge(reinterpret_cast<std::byte*>(p) - kOffset, n * sizeof(T) + kOffset);
    }
    template <typename U>
    bool operator==(const ChildPairAllocator<U>&) const {
        return true;
    }
};

struct Bvh {
    // nodes[0] is the root (when not empty); children pairs start cache lines.
    std::vector<BvhNode, ChildPairAllocator<BvhNode>> nodes;
    std::vector<uint32_t> primitiveIndices;   // slot -> primitive (triangle index in file order)
    std::vector<LeafTriangle> leafTriangles;  // meshes only: vertices per slot

    bool empty() const { return nodes.empty(); }
    Bounds3f bounds() const { return empty() ? Bounds3f() : nodes[0].bounds(); }
    const BvhNode& rootNode() const { return nodes[0]; }  // not when empty
};

enum class BvhBuilder { Midpoint, Median, BinnedSah, SweepSah, SpatialSah };
constexpr BvhBuilder kExerciseBuilders[] = {BvhBuilder::Midpoint, BvhBuilder::Median,
                                            BvhBuilder::BinnedSah};
// "midpoint", "median", "sah", "sweep-sah", "sbvh"
const char* bvhBuilderName(BvhBuilder builder);
BvhBuilder parseBvhBuilder(const std::string& name);  // throws InputError

struct BvhBuildOptions {
    BvhBuilder builder = BvhBuilder::BinnedSah;
    int bins = 16;         // binned SAH: candidate planes per axis are bins - 1
    int leafSize = 4;      // midpoint / median: a node with at most this many is a leaf
    int maxLeafSize = 16;  // SAH: a node may become a leaf (when cheaper) up to this size
    int maxDepth = 64;     // below this a node becomes a leaf, whatever its size
    // SAH constants: cost of a node visit and of a primitive test (Goldsmith & Salmon 1987,
    // MacDonald & Booth 1990). Only their ratio matters for the tree. A node visit here
    // tests two boxes and may wait for memory; one watertight triangle test from a leaf's
    // contiguous slots costs about half of that (measured: step 04's README).
    float traversalCost = 1.0f;
    float intersectionCost = 0.5f;
    // Spatial splits (builder sbvh): tried where the best object split's children overlap
    // by more than alpha times the root's area, until the triangles cut in two reach this
    // fraction of the triangle count. Stich et al. 2009 use alpha 1e-5; 1e-4 and 1e-3
    // traced as fast here (paired rounds, three meshes), and 1e-3 builds 1.5-1.7x faster
    // than 1e-4, 2.4-3.6x faster than 1e-5 (measured: step 04's README).
    float spatialSplitAlpha = 1e-3f;
    float spatialSplitBudget = 1.0f;
};

// Per build: what the report prints for every hierarchy.
struct BvhBuildStats {
    double buildMs = 0.0;  // the build only (primitive bounds included, file reading not)
    size_t nodes = 0, leaves = 0;
    size_t minLeafSize = 0, maxLeafSize = 0;
    double meanLeafSize = 0.0;
    int depth = 0;         // the deepest leaf; the root is depth 0
    double sahCost = 0.0;  // see bvhSahCost
};

// A primitive during the build: its bounds, their centroid, its index.
struct BuildPrimitive {
    Bounds3f bounds;
    Vec3 centroid;
    uint32_t index;
};

// The split rules. Each reorders `prims` (one node's primitives) and returns how many go
// to the left child (the first ones). Returning 0 or prims.size() means "no useful split";
// the framework then makes a leaf when it may, else splits the range in the middle.

// Exercise 4.1: midpoint split: the middle of the centroid bounds' longest axis.
size_t partitionMidpoint(std::span<BuildPrimitive> prims, const Bounds3f& centroidBounds);

// Exercise 4.2: object median: half of the primitives (by centroid) on each side, along
// the centroid bounds' longest axis.
size_t partitionMedian(std::span<BuildPrimitive> prims, const Bounds3f& centroidBounds);

// Exercise 4.3: binned SAH (Wald 2007): centroids into `bins` equal bins per axis, the
// split between bins with the least SAH cost. Sets `cost` to that split's cost,
// traversalCost + intersectionCost * (A_L N_L + A_R N_R) / A_node, and returns 0 (cost
// infinity) when no axis can be split (all centroids equal).
size_t partitionBinnedSah(std::span<BuildPrimitive> prims, const Bounds3f& nodeBounds,
                          const Bounds3f& centroidBounds, const BvhBuildOptions& options,
                          float& cost);

// Not an exercise: the full-sweep SAH split (every primitive boundary on every axis), the
// reference the binned builder's quality is measured against. O(n log n) per node.
size_t partitionSweepSah(std::span<BuildPrimitive> prims, const Bounds3f& nodeBounds,
                         const BvhBuildOptions& options, float& cost);

// Not an exercise: the binned SAH with spatial splits (SBVH, Stich, Friedrich, Dietrich
// 2009; bvh_spatial.cpp): a triangle may be referenced by several leaves, each time with
// the box of its part there. Builds nodes and primitiveIndices from the triangles' boxes.
Bvh buildSpatialSplitBvh(const Mesh& mesh, std::vector<BuildPrimitive> refs,
                         const BvhBuildOptions& options);

// Builds the hierarchy over primitives with the given bounds (index = position).
// Handles every input: empty lists, identical centroids, flat boxes, huge counts.
Bvh buildBvh(std::span<const Bounds3f> primitiveBounds, const BvhBuildOptions& options,
             BvhBuildStats* stats = nullptr);
// The same over a mesh's triangles, also filling leafTriangles. Builder sbvh needs the
// triangles; over bare bounds it is the binned SAH.
Bvh buildBvh(const Mesh& mesh, const BvhBuildOptions& options, BvhBuildStats* stats = nullptr);

// SAH cost of a built tree: sum over interior nodes of traversalCost * A(node) / A(root)
// plus over leaves of intersectionCost * count * A(leaf) / A(root).
double bvhSahCost(const Bvh& bvh, float traversalCost = 1.0f, float intersectionCost = 1.0f);
// Nodes, leaves, leaf sizes, depth and the SAH cost (buildMs left 0).
BvhBuildStats bvhStats(const Bvh& bvh, const BvhBuildOptions& options);

// ---------------------------------------------------------------------------------------
// Traversal.

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
constexpr int kTraversalStackSize = 128;

// Asks for what the traversal will read after `node` (its children's pair of boxes, or
// its leaf's triangles) while the box tests of the current pair are still running:
// incoherent rays spend most of their time waiting for memory, and the fetch overlaps.
inline void prefetchNodeContents(const Bvh& bvh, const BvhNode& node) {
    if (!node.isLeaf())
        __builtin_prefetch(&bvh.nodes[node.leftFirst]);
    else if (!bvh.leafTriangles.empty()) {
        // A leaf's triangles (36 bytes each) span two cache lines from its second one on.
        const char* first = reinterpret_cast<const char*>(&bvh.leafTriangles[node.leftFirst]);
        __builtin_prefetch(first);
        if (node.count > 1) __builtin_prefetch(first + 64);
    }
}

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
