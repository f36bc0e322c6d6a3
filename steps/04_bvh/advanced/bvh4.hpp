// Step 04's engine: a 4-wide (and an 8-wide) hierarchy traversed with SIMD.
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
// 2008, "Getting rid of packets"): each wide node's children are binary subtrees, chosen
// by the SAH over the whole tree (Ylitie, Karras, Laine 2017: dynamic programming, see
// bvh4.cpp). The binary tree's leaves stay leaves, and a subtree of at most 8 triangles
// may become one leaf (two packets for the 4-triangle test); leaves are stored as packets
// of four triangles, "structure of arrays" as well.
//
// Traversal is conservative exactly as the scalar one: the same margin-shifted origins,
// the same operations in the same order, kBoxFarScale on the far distance, and a NaN from
// 0 * infinity (origin in a slab plane, zero direction component) ignored (the min/max
// operand order below). The four entry distances and the scalar test's agree bit for bit.
//
// The 8-wide tree (Bvh8) is the same code with W = 8: eight boxes per node (256 bytes, four
// cache lines), tested as two groups of four, one level for every three binary ones where
// the 4-wide tree takes one for two. Embree traces with 8-wide nodes on CPUs with AVX.
#pragma once

#include <bit>
#include <cstdint>
#include <vector>

#include "04_bvh/advanced/batch.hpp"
#include "04_bvh/bvh.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(BOXES_TARGET_AVX2)
#include <immintrin.h>
#endif

namespace boxes {

template <int W>
struct alignas(64) BvhWideNode {
    static_assert(W == 4 || W == 8, "groups of four SSE lanes");
    float boundsMin[3][W];  // [axis][child]
    float boundsMax[3][W];
    uint32_t child[W];  // inner child: node index; leaf: first slot; empty: 0
    uint32_t count[W];  // 0: inner child (or empty slot), else the leaf's size

    bool isLeaf(int i) const { return count[i] != 0; }
    Bounds3f bounds(int i) const {
        return {Vec3(boundsMin[0][i], boundsMin[1][i], boundsMin[2][i]),
                Vec3(boundsMax[0][i], boundsMax[1][i], boundsMax[2][i])};
    }
    // An empty slot: an inverted box (+inf .. -inf) that every ray misses, NaN-free.
    bool isEmpty(int i) const { return count[i] == 0 && boundsMin[0][i] > boundsMax[0][i]; }
};
using Bvh4Node = BvhWideNode<4>;
using Bvh8Node = BvhWideNode<8>;
static_assert(sizeof(Bvh4Node) == 128, "two 64-byte cache lines");
static_assert(sizeof(Bvh8Node) == 256, "four 64-byte cache lines");

// Four triangles "structure of arrays" (vertex, axis, lane) for the 4-triangle leaf test,
// and their primitives: a hit's primitive is then on a line the test has read, where in
// primitiveIndices it was a miss at the end of most diffuse rays. 160 bytes aligned to 32:
// three cache lines, as the 144 bytes without the primitives.
struct alignas(32) TrianglePacket4 {
    float vertex[3][3][4];
    uint32_t primitive[4];  // the same as primitiveIndices[4 * packet + lane]
};
static_assert(sizeof(TrianglePacket4) == 160, "three cache lines at 32-byte alignment");

// Slots are regrouped by four: every leaf starts a packet (slot first = 4 * packet), and
// the lanes after a leaf's last triangle repeat that triangle (same primitive index), so
// a leaf's slots [first, first + count) are packet lanes and a packet never mixes leaves.
template <int W>
struct BvhWide {
    std::vector<BvhWideNode<W>> nodes;        // nodes[0] is the root (when not empty); new aligns
    std::vector<uint32_t> primitiveIndices;   // slot -> primitive
    std::vector<LeafTriangle> leafTriangles;  // meshes only: slot -> vertices
    std::vector<TrianglePacket4> packets;     // meshes only: the same by four
    BvhNode root;  // the whole tree's box, as a binary node for the tracers' first test

    bool empty() const { return nodes.empty(); }
    Bounds3f bounds() const { return root.bounds(); }
    const BvhNode& rootNode() const { return root; }
};
using Bvh4 = BvhWide<4>;
using Bvh8 = BvhWide<8>;

// Collapses a binary hierarchy: its leaves are kept, a subtree of at most
// kBvh4MergedLeafSize primitives may become one leaf, and the slots of every leaf are
// regrouped into packets. The collapse's SAH counts a wide node's test as
// kCollapseNodeCost packet tests: of 1, 2, 3 and 4, 2 traced fastest with 8-wide nodes
// and as fast as any with 4-wide ones (advanced/README.md).
constexpr uint32_t kBvh4MergedLeafSize = 8;
constexpr double kCollapseNodeCost = 2.0;
template <int W>
BvhWide<W> collapseToWide(const Bvh& binary);  // W = 4 or 8
inline Bvh4 collapseToBvh4(const Bvh& binary) {
    return collapseToWide<4>(binary);
}
inline Bvh8 collapseToBvh8(const Bvh& binary) {
    return collapseToWide<8>(binary);
}

struct BvhWideStats {
    size_t nodes = 0, leaves = 0, emptySlots = 0;
    int depth = 0;  // the deepest leaf; children of the root are depth 1
    // The SAH cost in the units of Embree's BVH statistics (`verbose=3`), so the two trees
    // compare directly: each wide node costs its area, each leaf its area times its packets
    // (Embree: its blocks of four triangles), all relative to the root's area. A node test
    // and a packet test count 1 each.
    double nodeSahCost = 0.0, leafSahCost = 0.0;
};
using Bvh4Stats = BvhWideStats;
template <int W>
BvhWideStats bvhWideStats(const BvhWide<W>& bvh);  // W = 4 or 8
inline Bvh4Stats bvh4Stats(const Bvh4& bvh) {
    return bvhWideStats(bvh);
}

// A ray prepared for the W-box test: per axis the offset (in floats into a node) of the
// plane array met first and of the one met last, and broadcast origins and 1/d.
template <int W>
struct WideRay {
    int nearOffset[3], farOffset[3];
    float nearOrigin[3], farOrigin[3], inverseDirection[3], farInverseDirection[3], tmin;
#if defined(__SSE2__)
    __m128 nearOriginV[3], farOriginV[3], inverseDirectionV[3], farInverseDirectionV[3], tminV;
#endif
    explicit WideRay(const TraversalRay& ray) : tmin(ray.tmin) {
        for (int axis = 0; axis < 3; ++axis) {
            bool positive = ray.nearOffset[axis] == axis;  // the min plane first
            nearOffset[axis] = positive ? W * axis : 3 * W + W * axis;
            farOffset[axis] = positive ? 3 * W + W * axis : W * axis;
            nearOrigin[axis] = ray.nearOrigin[axis];
            farOrigin[axis] = ray.farOrigin[axis];
            inverseDirection[axis] = (&ray.inverseDirection.x)[axis];
            farInverseDirection[axis] = (&ray.farInverseDirection.x)[axis];
#if defined(__SSE2__)
            nearOriginV[axis] = _mm_set1_ps(nearOrigin[axis]);
            farOriginV[axis] = _mm_set1_ps(farOrigin[axis]);
            inverseDirectionV[axis] = _mm_set1_ps(inverseDirection[axis]);
            farInverseDirectionV[axis] = _mm_set1_ps(farInverseDirection[axis]);
#endif
        }
#if defined(__SSE2__)
        tminV = _mm_set1_ps(tmin);
#endif
    }
};
using Bvh4Ray = WideRay<4>;

// The slab test of one ray against a node's W boxes in [ray.tmin, tmax]: bit i of the
// result is set when the ray enters box i, at tEntry[i]. Per box, the same arithmetic as
// intersectNodeBounds; groups of four boxes at a time.
template <int W>
inline int intersectChildBounds(const BvhWideNode<W>& node, const WideRay<W>& ray, float tmax,
                                float tEntry[W]) {
    const float* planes = &node.boundsMin[0][0];
#if defined(__SSE2__)
    int mask = 0;
    for (int group = 0; group < W; group += 4) {
        const float* p = planes + group;
        __m128 t0 = ray.tminV, t1 = _mm_set1_ps(tmax);
        for (int axis = 0; axis < 3; ++axis) {
            __m128 tNear =
                _mm_mul_ps(_mm_sub_ps(_mm_load_ps(p + ray.nearOffset[axis]), ray.nearOriginV[axis]),
                           ray.inverseDirectionV[axis]);
            __m128 tFar =
                _mm_mul_ps(_mm_sub_ps(_mm_load_ps(p + ray.farOffset[axis]), ray.farOriginV[axis]),
                           ray.farInverseDirectionV[axis]);
            // maxps/minps return the second operand when either is NaN: the running bound
            // goes second, so a NaN plane distance is ignored (as `tNear > t0 ? tNear : t0`).
            t0 = _mm_max_ps(tNear, t0);
            t1 = _mm_min_ps(tFar, t1);
        }
        _mm_storeu_ps(tEntry + group, t0);
        // Empty slots (min > max) are masked out: with a non-finite origin (coordinates near
        // the float range's end) every slab distance is NaN and every box looks entered.
        __m128 filled = _mm_cmple_ps(_mm_load_ps(p), _mm_load_ps(p + 3 * W));
        mask |= _mm_movemask_ps(_mm_and_ps(_mm_cmple_ps(t0, t1), filled)) << group;
    }
    return mask;
#else
    int mask = 0;
    for (int i = 0; i < W; ++i) {
        float t0 = ray.tmin, t1 = tmax;
        for (int axis = 0; axis < 3; ++axis) {
            float tNear = (planes[ray.nearOffset[axis] + i] - ray.nearOrigin[axis]) *
                          ray.inverseDirection[axis];
            float tFar = (planes[ray.farOffset[axis] + i] - ray.farOrigin[axis]) *
                         ray.farInverseDirection[axis];
            t0 = tNear > t0 ? tNear : t0;
            t1 = tFar < t1 ? tFar : t1;
        }
        tEntry[i] = t0;
        mask |= int(t0 <= t1 && planes[i] <= planes[3 * W + i]) << i;  // not an empty slot
    }
    return mask;
#endif
}

#if defined(BOXES_TARGET_AVX2)
// The same for eight boxes at once with AVX: the same operations lane by lane (vmaxps and
// vminps treat a NaN as maxps and minps do), so the same bits. Only for code compiled for
// AVX2 (the batch tracers' AVX2 loop, see traceUsesAvx2); tEntry aligned to 32 bytes.
[[gnu::target("avx2")]] inline int intersectChildBoundsAvx(const Bvh8Node& node,
                                                           const WideRay<8>& ray, float tmax,
                                                           float tEntry[8]) {
    const float* planes = &node.boundsMin[0][0];
    __m256 t0 = _mm256_set1_ps(ray.tmin), t1 = _mm256_set1_ps(tmax);
    for (int axis = 0; axis < 3; ++axis) {
        __m256 tNear = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(planes + ray.nearOffset[axis]),
                                                   _mm256_set1_ps(ray.nearOrigin[axis])),
                                     _mm256_set1_ps(ray.inverseDirection[axis]));
        __m256 tFar = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(planes + ray.farOffset[axis]),
                                                  _mm256_set1_ps(ray.farOrigin[axis])),
                                    _mm256_set1_ps(ray.farInverseDirection[axis]));
        t0 = _mm256_max_ps(tNear, t0);
        t1 = _mm256_min_ps(tFar, t1);
    }
    _mm256_store_ps(tEntry, t0);
    // _CMP_LE_OS is cmpleps: the same (signalling) compare as the SSE test.
    __m256 filled = _mm256_cmp_ps(_mm256_load_ps(planes), _mm256_load_ps(planes + 24), _CMP_LE_OS);
    return _mm256_movemask_ps(_mm256_and_ps(_mm256_cmp_ps(t0, t1, _CMP_LE_OS), filled));
}
#endif

// The box test the traversal runs: with kAvx (set only by code compiled for AVX2), the
// 8-wide node's boxes in one AVX pass.
template <bool kAvx, int W>
[[gnu::always_inline]] inline int intersectChildBoundsFor(const BvhWideNode<W>& node,
                                                          const WideRay<W>& ray, float tmax,
                                                          float tEntry[W]) {
#if defined(BOXES_TARGET_AVX2)
    if constexpr (kAvx && W == 8) return intersectChildBoundsAvx(node, ray, tmax, tEntry);
#endif
    return intersectChildBounds(node, ray, tmax, tEntry);
}

// Asks for a postponed child's first cache lines: its fetch then overlaps the work on the
// nearer children (incoherent rays spend most of their time waiting for nodes).
template <int W>
inline void prefetchChild(const BvhWide<W>& bvh, uint32_t child, uint32_t count) {
#if defined(__SSE2__)
    if (count == 0) {
        const char* p = reinterpret_cast<const char*>(&bvh.nodes[child]);
        for (int line = 0; line < W / 2; ++line) _mm_prefetch(p + 64 * line, _MM_HINT_T0);
    } else {
        const char* p = reinterpret_cast<const char*>(&bvh.packets[child / 4]);
        _mm_prefetch(p, _MM_HINT_T0);
        _mm_prefetch(p + 64, _MM_HINT_T0);
    }
#else
    (void)bvh, (void)child, (void)count;
#endif
}

// Inner children push up to W - 1 entries per level, and the builders cap the depth at
// kTraversalStackSize / 2 = 64; a wide node may span one binary level on a path and still
// push W - 1 entries. The sort writes W entries above the top before it keeps W - 1.
template <int W>
constexpr int kWideStackSize = W == 4 ? 256 : 512;
static_assert(kWideStackSize<4> > 3 * (kTraversalStackSize / 2) + 4, "the builders' depth cap");
static_assert(kWideStackSize<8> > 7 * (kTraversalStackSize / 2) + 8, "the builders' depth cap");
constexpr int kBvh4StackSize = kWideStackSize<4>;

// Nearest hit, nearest child first, early out. intersectLeaf(first, count, tClosest) tests
// a leaf's slots [first, first + count), lowers tClosest on a hit and returns the slot of
// its nearest hit (or kTraversalMiss). Returns the slot of the nearest hit or kTraversalMiss.
template <bool kAvx = false, int W, typename LeafIntersector, typename NodeCount = NoTraversalCount>
uint32_t traverseNearest4Leaves(const BvhWide<W>& bvh, const TraversalRay& traversal,
                                float& tClosest, LeafIntersector&& intersectLeaf,
                                NodeCount nodeCount = {}) {  // counts (countWork) or not
    if (bvh.empty()) return kTraversalMiss;
    const WideRay<W> ray(traversal);
    const BvhWideNode<W>* nodes = bvh.nodes.data();
    struct Entry {
        uint32_t child, count;
        float tEntry;
    } stack[kWideStackSize<W>];
    int stackSize = 0;
    uint32_t nearestSlot = kTraversalMiss;
    uint32_t child = 0, count = 0;  // the root, an inner node
    for (;;) {
        if (count == 0) {
            const BvhWideNode<W>& node = nodes[child];
#if defined(__SSE2__)
            // The children's indices lie on the node's last line, read only after the box
            // test: asked for now, their fetch overlaps the test.
            _mm_prefetch(reinterpret_cast<const char*>(node.child), _MM_HINT_T0);
#endif
            nodeCount.node();
            alignas(32) float t[W];
            int mask = intersectChildBoundsFor<kAvx>(node, ray, tClosest, t);
            if (mask != 0) {
                int first = std::countr_zero(unsigned(mask));
                mask &= mask - 1;
                if (mask == 0) {  // one child: descend, nothing to keep
                    child = node.child[first];
                    count = node.count[first];
                    continue;
                }
                int second = std::countr_zero(unsigned(mask));
                mask &= mask - 1;
                if (mask == 0) {  // two children: no sort loop, the order by a select
                    // On a tie the later child first, as the sort below would.
                    bool secondFirst = t[second] <= t[first];
                    int nearer = secondFirst ? second : first,
                        farther = secondFirst ? first : second;
                    stack[stackSize++] = {node.child[farther], node.count[farther], t[farther]};
                    prefetchChild(bvh, node.child[farther], node.count[farther]);
                    child = node.child[nearer];
                    count = node.count[nearer];
                    continue;
                }
                mask |= 1 << second;
                // Three or more: sorted farthest first onto the stack, the nearest descended.
                // Sorted where they go, on the stack: a separate array and its copy (a `rep
                // movsq`) were slower.
                Entry* hit = stack + stackSize;
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
                for (int j = 0; j < hits - 1; ++j) prefetchChild(bvh, hit[j].child, hit[j].count);
                stackSize += hits - 1;
                child = hit[hits - 1].child;
                count = hit[hits - 1].count;
                continue;
            }
        } else {
            uint32_t slot = intersectLeaf(child, count, tClosest);
            if (slot != kTraversalMiss) nearestSlot = slot;
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

// The same with the interface of traverseNearest: intersect(slot, tClosest) per slot.
template <int W, typename PrimitiveIntersector>
uint32_t traverseNearest4(const BvhWide<W>& bvh, const TraversalRay& traversal, float& tClosest,
                          PrimitiveIntersector&& intersect) {
    return traverseNearest4Leaves(bvh, traversal, tClosest,
                                  [&](uint32_t first, uint32_t count, float& tmax) {
                                      uint32_t nearest = kTraversalMiss;
                                      for (uint32_t slot = first; slot < first + count; ++slot)
                                          if (intersect(slot, tmax)) nearest = slot;
                                      return nearest;
                                  });
}

// Any hit in [ray.tmin, ray.tmax] (shadow rays): no order, stop at the first hit.
// intersectLeaf(first, count, tmax) is true when a slot of the leaf is hit.
template <int W, typename LeafIntersector>
bool traverseAny4Leaves(const BvhWide<W>& bvh, const TraversalRay& traversal,
                        LeafIntersector&& intersectLeaf) {
    if (bvh.empty()) return false;
    const WideRay<W> ray(traversal);
    const BvhWideNode<W>* nodes = bvh.nodes.data();
    struct Entry {
        uint32_t child, count;
    } stack[kWideStackSize<W>];
    int stackSize = 0;
    stack[stackSize++] = {0, 0};
    while (stackSize > 0) {
        Entry e = stack[--stackSize];
        if (e.count != 0) {
            if (intersectLeaf(e.child, e.count, traversal.tmax)) return true;
            continue;
        }
        const BvhWideNode<W>& node = nodes[e.child];
        alignas(16) float t[W];
        int mask = intersectChildBounds(node, ray, traversal.tmax, t);
        while (mask != 0) {
            int i = std::countr_zero(unsigned(mask));
            mask &= mask - 1;
            stack[stackSize++] = {node.child[i], node.count[i]};
        }
    }
    return false;
}

template <int W, typename PrimitiveIntersector>
bool traverseAny4(const BvhWide<W>& bvh, const TraversalRay& traversal,
                  PrimitiveIntersector&& intersect) {
    return traverseAny4Leaves(bvh, traversal, [&](uint32_t first, uint32_t count, float tmax) {
        for (uint32_t slot = first; slot < first + count; ++slot)
            if (intersect(slot, tmax)) return true;
        return false;
    });
}

// The margin of the scalar traversal, from the same root bounds.
template <int W>
inline float traversalMargin(const Ray& ray, const BvhWide<W>& bvh) {
    return bvh.empty() ? 0.0f : TraversalRay::marginFor(ray, bvh.bounds());
}

// The watertight test (intersectLeafTriangle) on the four triangles of a packet at once:
// the same operations in the same order per lane, so every lane's u, v, w, det and t are
// bit for bit the scalar test's. Lanes the scalar test would decide in double (an edge
// function exactly 0, a non-finite det, a scaled t outside the normal range) are handed to
// it, one by one. Tests a leaf's slots [first, first + count) (first a multiple of 4) in
// [ray.tmin, tClosest]; lowers tClosest to the nearest hit and returns its slot, or
// kTraversalMiss. The sign test reads sign bits: for lanes whose u, v, w are all non-zero,
// "some negative and some positive" is "the sign bits differ".
struct WatertightRay4 {
#if defined(__SSE2__)
    __m128 origin[3], sx, sy, sz, tmin;
    explicit WatertightRay4(const WatertightRay& r)
        : origin{_mm_set1_ps(r.origin.x), _mm_set1_ps(r.origin.y), _mm_set1_ps(r.origin.z)},
          sx(_mm_set1_ps(r.sx)),
          sy(_mm_set1_ps(r.sy)),
          sz(_mm_set1_ps(r.sz)),
          tmin(_mm_set1_ps(r.tmin)) {}
#else
    explicit WatertightRay4(const WatertightRay&) {}
#endif
};

#if defined(BOXES_TARGET_AVX2)
// The double test from AVX code. It is compiled for baseline x86-64, and its SSE
// instructions, run while the upper halves of the registers are in use, stalled (most of
// its samples on its first instruction): vzeroupper right before the call clears them (a
// vzeroupper further up is undone, e.g. by a 256-bit copy of the triangle).
template <typename Axes>
[[gnu::target("avx2")]] inline bool intersectLeafTriangleDoubleFromAvx(Axes axes,
                                                                       const WatertightRay& r,
                                                                       const LeafTriangle& tri,
                                                                       float& tmax) {
    _mm256_zeroupper();
    return intersectLeafTriangleDouble(axes, r, tri, tmax, nullptr, nullptr);
}
#endif

// kAvx: only from code compiled for AVX2 (the batch tracers' AVX2 loop).
template <bool kAvx = false, typename Axes, int W>
inline uint32_t intersectLeafPackets(Axes axes, const WatertightRay& r, const WatertightRay4& r4,
                                     const BvhWide<W>& bvh, uint32_t first, uint32_t count,
                                     float& tClosest) {
    uint32_t nearest = kTraversalMiss;
#if defined(__SSE2__)
    constexpr int kx = Axes::kx, ky = Axes::ky, kz = Axes::kz;
    const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f);
    const __m128i absMask = _mm_set1_epi32(0x7FFFFFFF);
    for (uint32_t base = first; base < first + count; base += 4) {
        const TrianglePacket4& p = bvh.packets[base / 4];
        auto rel = [&](int v, int axis) {
            return _mm_sub_ps(_mm_load_ps(p.vertex[v][axis]), r4.origin[axis]);
        };
        const __m128 aKz = rel(0, kz), bKz = rel(1, kz), cKz = rel(2, kz);
        const __m128 ax = _mm_sub_ps(rel(0, kx), _mm_mul_ps(r4.sx, aKz));
        const __m128 ay = _mm_sub_ps(rel(0, ky), _mm_mul_ps(r4.sy, aKz));
        const __m128 bx = _mm_sub_ps(rel(1, kx), _mm_mul_ps(r4.sx, bKz));
        const __m128 by = _mm_sub_ps(rel(1, ky), _mm_mul_ps(r4.sy, bKz));
        const __m128 cx = _mm_sub_ps(rel(2, kx), _mm_mul_ps(r4.sx, cKz));
        const __m128 cy = _mm_sub_ps(rel(2, ky), _mm_mul_ps(r4.sy, cKz));
        __m128 u = _mm_sub_ps(_mm_mul_ps(cx, by), _mm_mul_ps(cy, bx));
        __m128 v = _mm_sub_ps(_mm_mul_ps(ax, cy), _mm_mul_ps(ay, cx));
        __m128 w = _mm_sub_ps(_mm_mul_ps(bx, ay), _mm_mul_ps(by, ax));
        const __m128 det = _mm_add_ps(_mm_add_ps(u, v), w);
        // Lanes for the scalar test: an edge function exactly 0 (cmpeq is a quiet compare),
        // or det not finite (exponent bits all ones; integer compares raise nothing).
        const __m128 anyZero = _mm_or_ps(_mm_or_ps(_mm_cmpeq_ps(u, zero), _mm_cmpeq_ps(v, zero)),
                                         _mm_cmpeq_ps(w, zero));
        const __m128 notFinite = _mm_castsi128_ps(_mm_cmpgt_epi32(
            _mm_and_si128(_mm_castps_si128(det), absMask), _mm_set1_epi32(0x7F7FFFFF)));
        __m128 scalar = _mm_or_ps(anyZero, notFinite);
        const __m128 mixedSigns = _mm_castsi128_ps(
            _mm_srai_epi32(_mm_castps_si128(_mm_or_ps(_mm_xor_ps(u, v), _mm_xor_ps(u, w))), 31));
        // Lanes that go on to t: all signs equal, decided here (det != 0 follows).
        const __m128 onward =
            _mm_andnot_ps(_mm_or_ps(scalar, mixedSigns), _mm_cmpneq_ps(det, zero));
        const uint32_t lanes = std::min(4u, first + count - base);
        const int live = (1 << lanes) - 1;  // the lanes after a leaf's end repeat its last
        // Most packets a ray meets are missed on every lane: no t to compute, no division.
        if ((_mm_movemask_ps(_mm_or_ps(onward, scalar)) & live) == 0) continue;
        // Zero the others' edge functions and give them det 1: their t is then 0 / 1, no
        // spurious overflow or 0 / 0 where the scalar test would not have computed t.
        u = _mm_and_ps(u, onward);
        v = _mm_and_ps(v, onward);
        w = _mm_and_ps(w, onward);
        const __m128 divisor = _mm_or_ps(_mm_and_ps(det, onward), _mm_andnot_ps(onward, one));
        const __m128 tScaled = _mm_add_ps(_mm_add_ps(_mm_mul_ps(u, _mm_mul_ps(r4.sz, aKz)),
                                                     _mm_mul_ps(v, _mm_mul_ps(r4.sz, bKz))),
                                          _mm_mul_ps(w, _mm_mul_ps(r4.sz, cKz)));
        // Below the normal range or not finite (integer compares on the magnitude's bits).
        const __m128i tScaledBits = _mm_and_si128(_mm_castps_si128(tScaled), absMask);
        const __m128 outOfRange = _mm_castsi128_ps(
            _mm_or_si128(_mm_cmplt_epi32(tScaledBits, _mm_set1_epi32(0x00800000)),
                         _mm_cmpgt_epi32(tScaledBits, _mm_set1_epi32(0x7F7FFFFF))));
        scalar = _mm_or_ps(scalar, _mm_and_ps(outOfRange, onward));
        const __m128 t = _mm_div_ps(tScaled, divisor);
        const __m128 tmax = _mm_set1_ps(tClosest);
        const __m128 tFinite = _mm_castsi128_ps(_mm_cmplt_epi32(
            _mm_and_si128(_mm_castps_si128(t), absMask), _mm_set1_epi32(0x7F800000)));
        __m128 hit = _mm_and_ps(_mm_andnot_ps(outOfRange, onward), tFinite);
        hit = _mm_and_ps(hit, _mm_and_ps(_mm_cmpge_ps(t, r4.tmin), _mm_cmple_ps(t, tmax)));
        int hitMask = _mm_movemask_ps(hit) & live;
        if (hitMask != 0) {
            __m128 tHit =
                _mm_or_ps(_mm_and_ps(hit, t), _mm_andnot_ps(hit, _mm_set1_ps(kInfinity<float>)));
            __m128 m = _mm_min_ps(tHit, _mm_shuffle_ps(tHit, tHit, _MM_SHUFFLE(2, 3, 0, 1)));
            m = _mm_min_ps(m, _mm_shuffle_ps(m, m, _MM_SHUFFLE(1, 0, 3, 2)));
            int lane = std::countr_zero(unsigned(_mm_movemask_ps(_mm_cmpeq_ps(tHit, m)) & hitMask));
            tClosest = _mm_cvtss_f32(m);
            nearest = base + uint32_t(lane);
        }
        // Diffuse rays start on a triangle: its t is about 0, out of the normal range, so
        // most of them meet one such lane. The lane's triangle is read from the packet (in
        // the cache, the same floats as leafTriangles[slot], which is not), and a lane
        // without a zero edge function goes straight to the double test, as the scalar
        // test would with these u, v, w and det.
        int scalarMask = _mm_movemask_ps(scalar) & live;
        const int zeroMask = _mm_movemask_ps(anyZero);
        while (scalarMask != 0) [[unlikely]] {
                const int lane = std::countr_zero(unsigned(scalarMask));
                scalarMask &= scalarMask - 1;
                const LeafTriangle tri{
                    Vec3(p.vertex[0][0][lane], p.vertex[0][1][lane], p.vertex[0][2][lane]),
                    Vec3(p.vertex[1][0][lane], p.vertex[1][1][lane], p.vertex[1][2][lane]),
                    Vec3(p.vertex[2][0][lane], p.vertex[2][1][lane], p.vertex[2][2][lane])};
                bool hitLane;
                if (zeroMask >> lane & 1) {
                    hitLane = intersectLeafTriangle(axes, r, tri, tClosest);
                } else {
#if defined(BOXES_TARGET_AVX2)
                    if constexpr (kAvx)
                        hitLane = intersectLeafTriangleDoubleFromAvx(axes, r, tri, tClosest);
                    else
#endif
                        hitLane =
                            intersectLeafTriangleDouble(axes, r, tri, tClosest, nullptr, nullptr);
                }
                if (hitLane) nearest = base + uint32_t(lane);
            }
    }
#else
    (void)r4;
    for (uint32_t slot = first; slot < first + count; ++slot)
        if (intersectLeafTriangle(axes, r, bvh.leafTriangles[slot], tClosest)) nearest = slot;
#endif
    return nearest;
}

// kAvx: only from code compiled for AVX2 (the batch tracers' AVX2 loop). With a
// TraversalCounter, the work is counted (countWork); the hit is the same.
template <bool kAvx = false, int W, typename Counter = NoTraversalCount>
inline TraceHit traceNearest(const BvhWide<W>& bvh, const Ray& ray, Counter counter = {}) {
    TraversalRay traversal(ray, traversalMargin(ray, bvh));
    if (!entersRoot(bvh, traversal)) return {};
    WatertightRay watertight(ray);
    WatertightRay4 watertight4(watertight);
    float tClosest = ray.tmax;
    uint32_t slot = withWatertightAxes(watertight, [&](auto axes) {
        return traverseNearest4Leaves<kAvx>(
            bvh, traversal, tClosest,
            [&](uint32_t first, uint32_t count, float& tmax) {
                counter.leaf((count + 3) / 4);
                counter.triangles(count);
                return intersectLeafPackets<kAvx>(axes, watertight, watertight4, bvh, first, count,
                                                  tmax);
            },
            counter);
    });
    if (slot == kTraversalMiss) return {};
    return {tClosest, bvh.packets[slot / 4].primitive[slot % 4]};
}

// The batch loop's nearest hit (batch.hpp).
template <bool kAvx, int W>
inline TraceHit batchNearestHit(const BvhWide<W>& bvh, const Ray& ray) {
    return traceNearest<kAvx>(bvh, ray);
}

template <int W>
inline bool traceOccluded(const BvhWide<W>& bvh, const Ray& ray) {
    TraversalRay traversal(ray, traversalMargin(ray, bvh));
    if (!entersRoot(bvh, traversal)) return false;
    WatertightRay watertight(ray);
    WatertightRay4 watertight4(watertight);
    return withWatertightAxes(watertight, [&](auto axes) {
        return traverseAny4Leaves(bvh, traversal, [&](uint32_t first, uint32_t count, float tmax) {
            return intersectLeafPackets(axes, watertight, watertight4, bvh, first, count, tmax) !=
                   kTraversalMiss;
        });
    });
}

void traceBatch(const Bvh4& bvh, const std::vector<Ray>& rays, std::vector<TraceHit>& hits,
                int threads);
void traceBatch(const Bvh8& bvh, const std::vector<Ray>& rays, std::vector<TraceHit>& hits,
                int threads);
TraversalCounts countWork(const Bvh4& bvh, const std::vector<Ray>& rays);
TraversalCounts countWork(const Bvh8& bvh, const std::vector<Ray>& rays);

}  // namespace boxes
