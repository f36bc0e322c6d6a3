// Step 04's engine: the 4- and 8-wide trees (advanced/bvh4.hpp). Trees from the engine's
// full-sweep SAH builder collapsed, so these pass in the starter kit too; the binned SAH
// tree of the trace command is covered by "program 04".
#include <doctest/doctest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <random>
#include <set>
#include <vector>

#include "04_bvh/advanced/build.hpp"
#include "04_bvh/advanced/bvh4.hpp"
#include "04_bvh/advanced/rays.hpp"
#include "step04_advanced_support.hpp"

using namespace boxes;
using namespace boxes::test04;

namespace {

template <int W = 4>
BvhWide<W> wideTree(const Mesh& m, BvhBuilder builder = BvhBuilder::SweepSah) {
    return collapseToWide<W>(buildEngineBvh(m, optionsFor(builder)));
}

// Every primitive in exactly one leaf child, leaves starting a packet of four slots, every
// inner child's box the union of its node's children, empty slots after the filled ones.
template <int W>
void checkStructure4(const BvhWide<W>& wide, size_t primitives) {
    REQUIRE_FALSE(wide.empty());
    REQUIRE(wide.primitiveIndices.size() % 4 == 0);
    std::vector<int> seen(primitives, 0);
    std::vector<std::pair<uint32_t, Bounds3f>> stack = {{0, wide.bounds()}};
    size_t reached = 0;
    while (!stack.empty()) {
        auto [index, expected] = stack.back();
        stack.pop_back();
        ++reached;
        REQUIRE(index < wide.nodes.size());
        const BvhWideNode<W>& node = wide.nodes[index];
        Bounds3f unionOfChildren;
        bool emptySeen = false;
        for (int i = 0; i < W; ++i) {
            if (node.isEmpty(i)) {
                emptySeen = true;
                continue;
            }
            CHECK_FALSE(emptySeen);
            unionOfChildren.extend(node.bounds(i).min);
            unionOfChildren.extend(node.bounds(i).max);
            if (node.isLeaf(i)) {
                REQUIRE(size_t(node.child[i]) + node.count[i] <= wide.primitiveIndices.size());
                CHECK(node.child[i] % 4 == 0);
                for (uint32_t s = node.child[i]; s < node.child[i] + node.count[i]; ++s) {
                    uint32_t p = wide.primitiveIndices[s];
                    REQUIRE(p < primitives);
                    ++seen[p];
                    if (!wide.packets.empty()) {  // the packet holds the slot's triangle
                        CHECK(wide.packets[s / 4].vertex[2][1][s % 4] == wide.leafTriangles[s].c.y);
                        CHECK(wide.packets[s / 4].primitive[s % 4] == p);
                    }
                }
            } else {
                REQUIRE(node.child[i] > index);
                stack.push_back({node.child[i], node.bounds(i)});
            }
        }
        CHECK(unionOfChildren == expected);
    }
    CHECK(reached == wide.nodes.size());
    for (int n : seen) REQUIRE(n == 1);
}

template <int W>
uint32_t nearest4WithReference(const BvhWide<W>& wide, const Ray& ray, double& tBest) {
    tBest = kInfinity<double>;
    float tClosest = ray.tmax;
    uint32_t slot =
        traverseNearest4(wide, TraversalRay(ray), tClosest, referenceLeafTest(wide, ray, tBest));
    return slot == kTraversalMiss ? kNoPrimitive : wide.primitiveIndices[slot];
}

// A mesh's rays of every kind against brute force, nearest and any hit; returns the hits.
template <int W>
size_t checkAgainstBruteForce(const Mesh& m, const BvhWide<W>& wide, size_t raysPerKind,
                              uint64_t seed) {
    size_t hits = 0;
    for (RayKind kind : {RayKind::Primary, RayKind::Diffuse, RayKind::Random}) {
        INFO(std::string(rayKindName(kind)));
        std::vector<Ray> rays = makeRays(m, kind, raysPerKind, seed);
        std::vector<TraceHit> brute, tree;
        traceBatchBruteForce(m, rays, brute, 1);
        traceBatch(wide, rays, tree, 1);
        size_t differ = 0, occludedDiffer = 0;
        for (size_t i = 0; i < rays.size(); ++i) {
            differ += !hitsAgree(tree[i], brute[i]);
            occludedDiffer += traceOccluded(wide, rays[i]) != (brute[i].triangle != kNoPrimitive);
            hits += brute[i].triangle != kNoPrimitive;
        }
        CHECK(differ == 0);
        CHECK(occludedDiffer == 0);
    }
    return hits;
}

}  // namespace

TEST_SUITE("bvh 4-wide") {
    TEST_CASE("4-wide: the collapse keeps every slot once in nodes that are mostly full") {
        Mesh m = triangleSoup(3000, 30);
        Bvh binary = buildEngineBvh(m, optionsFor(BvhBuilder::SweepSah));
        size_t binaryLeaves = bvhStats(binary, optionsFor(BvhBuilder::SweepSah)).leaves;
        Bvh4 wide = collapseToBvh4(binary);
        checkStructure4(wide, m.triangleCount());
        Bvh4Stats s = bvh4Stats(wide);
        CHECK(s.leaves <= binaryLeaves);  // leaves are kept or merged, never split
        // n leaves in a full 4-ary tree need (n - 1) / 3 nodes; opening only inner nodes
        // leaves a few slots empty where a leaf sits beside leaves.
        CHECK(s.nodes < binary.nodes.size() / 2);
        CHECK(double(s.emptySlots) < 0.25 * double(4 * s.nodes));
        CHECK(wide.bounds() == binary.bounds());
        CHECK(reinterpret_cast<uintptr_t>(wide.nodes.data()) % 64 == 0);
    }
    TEST_CASE(
        "8-wide: the collapse keeps every slot once in fewer and shallower nodes than 4-wide") {
        Mesh m = triangleSoup(3000, 30);
        Bvh binary = buildEngineBvh(m, optionsFor(BvhBuilder::SweepSah));
        Bvh4 wide4 = collapseToBvh4(binary);
        Bvh8 wide8 = collapseToBvh8(binary);
        checkStructure4(wide8, m.triangleCount());
        BvhWideStats s4 = bvhWideStats(wide4), s8 = bvhWideStats(wide8);
        // Leaves are kept or merged, never split; eight children per node instead of four
        // take a third fewer nodes and levels.
        CHECK(s8.leaves <= bvhStats(binary, optionsFor(BvhBuilder::SweepSah)).leaves);
        CHECK(s8.nodes < s4.nodes * 2 / 3);
        CHECK(s8.depth < s4.depth);
        CHECK(double(s8.emptySlots) < 0.25 * double(8 * s8.nodes));
        CHECK(wide8.bounds() == binary.bounds());
        CHECK(reinterpret_cast<uintptr_t>(wide8.nodes.data()) % 64 == 0);
    }
    // A box's area in double, as the collapse computes it.
    double areaInDouble(const Bounds3f& b) {
        return Bounds3d(Vec3d(b.min), Vec3d(b.max)).surfaceArea();
    }
    // The collapse's SAH (bvh4.hpp) of a wide tree, read from the tree itself: every wide
    // node's box times kCollapseNodeCost, every leaf's box times its packets. bvhWideStats
    // sums both areas (over the root's; its hand-worked case is in "trace --count").
    template <int W>
    double collapseCost(const BvhWide<W>& wide) {
        BvhWideStats s = bvhWideStats(wide);
        return (s.nodeSahCost * kCollapseNodeCost + s.leafSahCost) * areaInDouble(wide.bounds());
    }
    // The least collapse cost by enumeration: every way to pick a wide node's children
    // among the binary subtrees below it (every "cut" of at most W subtrees), each child
    // then the cheaper of a leaf (when it may be one) and a wide node, recursively.
    struct ExhaustiveCollapse {
        const Bvh& binary;
        int width;
        std::vector<uint32_t> counts;      // primitives per subtree
        mutable std::vector<double> memo;  // best1 per node, once computed (else NaN)

        uint32_t count(uint32_t n) {
            const BvhNode& node = binary.nodes[n];
            return counts[n] = node.isLeaf() ? node.count
                                             : count(node.leftFirst) + count(node.leftFirst + 1);
        }
        double area(uint32_t n) const { return areaInDouble(binary.nodes[n].bounds()); }
        // Every cut of subtree n into at most `limit` subtrees.
        std::vector<std::vector<uint32_t>> cuts(uint32_t n, int limit) const {
            std::vector<std::vector<uint32_t>> all = {{n}};
            const BvhNode& node = binary.nodes[n];
            if (node.isLeaf() || limit < 2) return all;
            for (const auto& l : cuts(node.leftFirst, limit - 1))
                for (const auto& r : cuts(node.leftFirst + 1, limit - int(l.size()))) {
                    all.push_back(l);
                    all.back().insert(all.back().end(), r.begin(), r.end());
                }
            return all;
        }
        double asNode(uint32_t n) const {
            const BvhNode& node = binary.nodes[n];
            double best = kInfinity<double>;
            for (const auto& l : cuts(node.leftFirst, width - 1))
                for (const auto& r : cuts(node.leftFirst + 1, width - int(l.size()))) {
                    double sum = 0.0;
                    for (uint32_t c : l) sum += best1(c);
                    for (uint32_t c : r) sum += best1(c);
                    best = std::min(best, sum);
                }
            return area(n) * kCollapseNodeCost + best;
        }
        double best1(uint32_t n) const {
            if (!std::isnan(memo[n])) return memo[n];
            const BvhNode& node = binary.nodes[n];
            double leaf = node.isLeaf() || counts[n] <= kBvh4MergedLeafSize
                              ? area(n) * double((counts[n] + 3) / 4)
                              : kInfinity<double>;
            return memo[n] = node.isLeaf() ? leaf : std::min(leaf, asNode(n));
        }
    };
    TEST_CASE("4- and 8-wide: the collapse takes the children of least SAH cost") {
        // Ylitie et al.'s dynamic program against every cut of small binary trees, each
        // wide tree's cost read back from the tree it built.
        for (uint64_t seed : {3, 4, 5}) {
            Mesh m = triangleSoup(48, seed, 0.2f);
            BvhBuildOptions options = optionsFor(BvhBuilder::Midpoint);
            options.leafSize = 2;
            Bvh binary = buildEngineBvh(m, options);
            for (int width : {4, 8}) {
                CAPTURE(seed);
                CAPTURE(width);
                ExhaustiveCollapse exhaustive{
                    binary, width, std::vector<uint32_t>(binary.nodes.size()),
                    std::vector<double>(binary.nodes.size(), std::nan(""))};
                exhaustive.count(0);
                double optimum = exhaustive.asNode(0);
                double built = width == 4 ? collapseCost(collapseToBvh4(binary))
                                          : collapseCost(collapseToBvh8(binary));
                CHECK(built == doctest::Approx(optimum).epsilon(1e-12));
            }
        }
    }
    TEST_CASE("4- and 8-wide: the collapse keeps every slot when its costs are NaN") {
        // A hand-made binary tree: a root over a leaf and an inner node of two leaves, one
        // leaf box with no extent in x and an infinite one in y. Its area is 0 * infinity
        // (NaN), and so is every cost that adds it in. The collapse must still keep every
        // slot, and merge no subtree of more than kBvh4MergedLeafSize primitives into a
        // leaf (it once merged the inner node's 13: no split compared below infinity).
        test::FpTrapsOff nanOnPurpose;
        auto node = [](Vec3 lo, Vec3 hi, uint32_t leftFirst, uint32_t count) {
            return BvhNode{lo, leftFirst, hi, count};
        };
        const float inf = kInfinity<float>;
        Bvh binary;
        binary.nodes.push_back(node({0, -inf, 0}, {2, inf, 1}, 1, 0));  // root
        binary.nodes.push_back(node({0, 0, 0}, {1, 1, 1}, 0, 1));       // leaf: slot 0
        binary.nodes.push_back(node({0, -inf, 0}, {2, inf, 1}, 3, 0));  // inner
        binary.nodes.push_back(node({0, -inf, 0}, {0, inf, 1}, 1, 1));  // leaf: slot 1, NaN area
        binary.nodes.push_back(node({2, 0, 0}, {2, 1, 1}, 2, 12));      // leaf: slots 2-13
        binary.primitiveIndices.resize(14);
        for (uint32_t i = 0; i < 14; ++i) binary.primitiveIndices[i] = i;
        Bvh4 wide4 = collapseToBvh4(binary);
        Bvh8 wide8 = collapseToBvh8(binary);
        checkStructure4(wide4, 14);
        checkStructure4(wide8, 14);
        // Leaves: the binary ones (1 and 12 slots) or merged subtrees of at most 8.
        auto largestLeaf = [](const auto& wide) {
            uint32_t largest = 0;
            for (const auto& n : wide.nodes)
                for (uint32_t count : n.count) largest = std::max(largest, count);
            return largest;
        };
        CHECK(largestLeaf(wide4) == 12);
        CHECK(largestLeaf(wide8) == 12);
    }
    template <int W>
    void boxTestCase() {
        // Random boxes and rays, with zero direction components and origins on box planes
        // (NaN from 0 * infinity) among them.
        test::FpTrapsOff nanOnPurpose;
        std::mt19937_64 rng(31);
        std::uniform_real_distribution<float> u(-2.0f, 2.0f);
        std::uniform_int_distribution<int> pick(0, 3);
        size_t entered = 0;
        for (int round = 0; round < 2000; ++round) {
            BvhWideNode<W> node{};
            BvhNode boxes[W];
            for (int i = 0; i < W; ++i) {
                Vec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
                Bounds3f box(glm::min(a, b), glm::max(a, b));
                if (pick(rng) == 0) box.max.y = box.min.y;  // a flat box
                boxes[i].boundsMin = box.min;
                boxes[i].boundsMax = box.max;
                for (int axis = 0; axis < 3; ++axis) {
                    node.boundsMin[axis][i] = box.min[axis];
                    node.boundsMax[axis][i] = box.max[axis];
                }
            }
            Vec3 origin(u(rng), u(rng), u(rng)), dir(u(rng), u(rng), u(rng));
            if (pick(rng) == 0) origin.x = boxes[pick(rng)].boundsMin.x;  // on a plane
            if (pick(rng) == 0) dir.x = 0.0f;
            if (pick(rng) == 0) dir.z = -0.0f;
            if (pick(rng) == 0) origin.z = boxes[pick(rng)].boundsMax.z;
            Ray ray(origin, dir, pick(rng) == 0 ? 0.5f : 0.0f);
            float margin = pick(rng) == 0 ? 1e-3f : 0.0f;
            TraversalRay traversal(ray, margin);
            float tmax = pick(rng) == 0 ? 1.5f : kInfinity<float>;
            alignas(32) float t4[W];
            int mask = intersectChildBounds(node, WideRay<W>(traversal), tmax, t4);
#if defined(BOXES_TARGET_AVX2)
            // The AVX version of the 8-box test (the AVX2 batch loop's): the same bits.
            if constexpr (W == 8) {
                if (traceUsesAvx2()) {
                    alignas(32) float tAvx[8];
                    CHECK(intersectChildBoundsAvx(node, WideRay<8>(traversal), tmax, tAvx) == mask);
                    for (int i = 0; i < 8; ++i)
                        if (mask >> i & 1) CHECK(tAvx[i] == t4[i]);
                }
            }
#endif
            for (int i = 0; i < W; ++i) {
                float t;
                bool hit = intersectNodeBounds(boxes[i], traversal, tmax, t);
                CHECK(bool(mask >> i & 1) == hit);
                if (hit) CHECK(t4[i] == t);
                entered += hit;
            }
        }
        CHECK(entered > 300);
    }
    TEST_CASE("4-wide: the four-box test equals the scalar slab test bit for bit") {
        boxTestCase<4>();
    }
    TEST_CASE("8-wide: the eight-box test equals the scalar slab test bit for bit") {
        boxTestCase<8>();
    }
    template <int W>
    void slabPlaneCase() {
        // The ray runs in the plane y = 0 of the box [0, 1]^3 (origin on the plane, d.y = 0:
        // (0 - 0) * infinity = NaN) and must enter it at x = 0; the same ray at y = -0.5 misses.
        test::FpTrapsOff nanOnPurpose;
        BvhWideNode<W> node{};
        for (int i = 0; i < W; ++i)
            for (int axis = 0; axis < 3; ++axis) {
                node.boundsMin[axis][i] = i == 0 ? 0.0f : kInfinity<float>;
                node.boundsMax[axis][i] = i == 0 ? 1.0f : -kInfinity<float>;
            }
        for (Vec3 dir : {Vec3(1.0f, 0.0f, 0.0f), Vec3(1.0f, -0.0f, 0.0f)}) {
            alignas(32) float t[W];
            int mask = intersectChildBounds(
                node, WideRay<W>(TraversalRay(Ray(Vec3(-1, 0, 0.5f), dir))), kInfinity<float>, t);
            CHECK(mask == 1);  // the box, and no empty slot
            CHECK(t[0] == 1.0f);
            CHECK(intersectChildBounds(node,
                                       WideRay<W>(TraversalRay(Ray(Vec3(-1, -0.5f, 0.5f), dir))),
                                       kInfinity<float>, t) == 0);
        }
        // Through a mesh: triangles on the planes x = 0, 2, 4, 6; rays along +x with origins
        // on box faces.
        Mesh m;
        for (int i = 0; i < 4; ++i) {
            float x = float(i) * 2.0f;
            uint32_t base = uint32_t(m.positions.size());
            m.positions.insert(m.positions.end(), {Vec3(x, 0, 0), Vec3(x, 1, 0), Vec3(x, 0, 1)});
            m.triangles.push_back({base, base + 1, base + 2});
        }
        BvhWide<W> wide = wideTree<W>(m);
        for (float y : {0.0f, 0.25f})
            for (Vec3 dir : {Vec3(1.0f, 0.0f, 0.0f), Vec3(1.0f, -0.0f, -0.0f)}) {
                Ray ray(Vec3(-1.0f, y, 0.25f), dir);
                double t;
                CHECK(nearest4WithReference(wide, ray, t) == 0u);
                CHECK(t == 1.0);
                CHECK(traceNearest(wide, ray) == TraceHit{1.0f, 0u});
            }
    }
    TEST_CASE("hard case: 4-wide ray lying in a slab plane") {
        slabPlaneCase<4>();
    }
    TEST_CASE("hard case: 8-wide ray lying in a slab plane") {
        slabPlaneCase<8>();
    }
    TEST_CASE("4-wide: the four-triangle leaf test equals the scalar test bit for bit") {
        // One leaf of 7 triangles (two packets, the last lane a repeat): large overlapping
        // triangles, a fan around the point (0.5, 0.5) the rays aim at (edge functions
        // exactly 0 go to the scalar test), and a zero-area one.
        std::mt19937_64 rng(42);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        size_t hits = 0;
        for (int round = 0; round < 300; ++round) {
            Mesh m;
            Vec3 centre(0.5f, 0.5f, u(rng));
            for (int i = 0; i < 7; ++i) {
                uint32_t base = uint32_t(m.positions.size());
                if (i < 3) {  // the fan: all share the centre
                    m.positions.insert(m.positions.end(), {centre, Vec3(u(rng), u(rng), u(rng)),
                                                           Vec3(u(rng), u(rng), u(rng))});
                } else if (i == 3) {  // zero area: three points on a line
                    Vec3 a(u(rng), u(rng), u(rng));
                    m.positions.insert(m.positions.end(), {a, a + Vec3(0.1f), a + Vec3(0.2f)});
                } else {
                    for (int k = 0; k < 3; ++k) m.positions.push_back(Vec3(u(rng), u(rng), u(rng)));
                }
                m.triangles.push_back({base, base + 1, base + 2});
            }
            BvhBuildOptions one = optionsFor(BvhBuilder::SweepSah);
            one.maxLeafSize = 16;
            one.intersectionCost = 0.01f;  // a leaf is cheaper than any split
            Bvh4 wide = collapseToBvh4(buildEngineBvh(m, one));
            REQUIRE(wide.nodes.size() == 1);
            REQUIRE(wide.nodes[0].count[0] == 7);
            Vec3 origin(u(rng) * 4.0f - 2.0f, u(rng) * 4.0f - 2.0f, 3.0f);
            Ray ray(origin, (round % 2 ? centre : Vec3(u(rng), u(rng), 0.5f)) - origin);
            WatertightRay w(ray);
            WatertightRay4 w4(w);
            withWatertightAxes(w, [&](auto axes) {
                float tPacket = ray.tmax, tScalar = ray.tmax;
                uint32_t slot = intersectLeafPackets(axes, w, w4, wide, 0, 7, tPacket);
                uint32_t scalarSlot = kTraversalMiss;
                for (uint32_t s = 0; s < 7; ++s)
                    if (intersectLeafTriangle(axes, w, wide.leafTriangles[s], tScalar))
                        scalarSlot = s;
                CHECK(tPacket == tScalar);
                CHECK((slot == kTraversalMiss) == (scalarSlot == kTraversalMiss));
                if (slot != kTraversalMiss) {
                    float tSlot = ray.tmax;
                    CHECK(intersectLeafTriangle(axes, w, wide.leafTriangles[slot], tSlot));
                    CHECK(tSlot == tPacket);  // the slot is one at that distance
                    ++hits;
                }
            });
        }
        CHECK(hits > 150);
    }
    template <int W>
    void soupCase() {
        Mesh m = triangleSoup(2000, 32);
        Bvh binary = buildEngineBvh(m, optionsFor(BvhBuilder::SweepSah));
        BvhWide<W> wide = collapseToWide<W>(binary);
        size_t hits = 0;
        for (const Ray& ray : randomRays(2000, 33)) {
            double tTree, tBrute;
            uint32_t a = nearest4WithReference(wide, ray, tTree);
            uint32_t b = bruteWithReference(m, ray, tBrute);
            hits += b != kNoPrimitive;
            CHECK((a == b || tTree == tBrute));
            // With the watertight test: brute force, and the binary tree bit for bit.
            TraceHit h = traceNearest(wide, ray);
            CHECK(hitsAgree(h, traceBruteForce(m, ray)));
            CHECK(h.t == traceNearest(binary, ray).t);
        }
        CHECK(hits > 200);
    }
    TEST_CASE("4-wide: nearest hit equals brute force on a triangle soup") {
        soupCase<4>();
    }
    TEST_CASE("8-wide: nearest hit equals brute force on a triangle soup") {
        soupCase<8>();
    }
    template <int W>
    void shadowCase() {
        Mesh m = triangleSoup(1500, 34);
        BvhWide<W> wide = wideTree<W>(m);
        size_t blocked = 0;
        std::mt19937_64 rng(35);
        std::uniform_real_distribution<float> len(0.05f, 1.0f);
        for (Ray ray : randomRays(1500, 36)) {
            ray.tmax = len(rng);
            bool brute = traceBruteForce(m, ray).triangle != kNoPrimitive;
            blocked += brute;
            CHECK(traceOccluded(wide, ray) == brute);
        }
        CHECK(blocked > 100);
    }
    TEST_CASE("4-wide: any hit agrees with brute force on shadow rays") {
        shadowCase<4>();
    }
    TEST_CASE("8-wide: any hit agrees with brute force on shadow rays") {
        shadowCase<8>();
    }
    template <int W>
    void realMeshCase() {
        Mesh sh1 = loadObj(test::dataDir() + "/meshes/sh1.obj");
        CHECK(checkAgainstBruteForce(sh1, wideTree<W>(sh1), 400, 37) > 100);
        Mesh bunny = loadObj(test::dataDir() + "/meshes/bunny.obj");
        CHECK(checkAgainstBruteForce(bunny, wideTree<W>(bunny), 100, 38) > 30);
    }
    TEST_CASE("4-wide: nearest and any hit equal brute force on real meshes") {
        realMeshCase<4>();
    }
    TEST_CASE("8-wide: nearest and any hit equal brute force on real meshes") {
        realMeshCase<8>();
    }
    TEST_CASE("trace --count: the work of one ray counted by hand") {
        // Two clusters of three stacked triangles, at x = 0 and x = 100 (z = 0, -1, -2).
        // The midpoint builder (leaves of up to 4) puts each in a leaf under the root. The
        // 4-wide collapse takes the whole tree as one leaf of 6 (two packets): its cost,
        // the root's area times 2 packets, is below a node's (the same plus the leaves').
        Mesh m;
        for (float x : {0.0f, 100.0f})
            for (float z : {0.0f, -1.0f, -2.0f}) {
                auto first = uint32_t(m.positions.size());
                m.positions.insert(m.positions.end(), {{x, 0, z}, {x + 1, 0, z}, {x, 1, z}});
                m.triangles.push_back({first, first + 1, first + 2});
            }
        BvhBuildOptions options = optionsFor(BvhBuilder::Midpoint);
        options.leafSize = 4;
        Bvh binary = buildEngineBvh(m, options);
        REQUIRE(binary.nodes.size() == 3);
        Bvh4 wide = collapseToBvh4(binary);
        REQUIRE(bvh4Stats(wide).nodes == 1);
        REQUIRE(bvh4Stats(wide).leaves == 1);
        // Its SAH cost in Embree's units: the root node (area ratio 1) and one leaf with
        // the root's box and two packets.
        CHECK(bvh4Stats(wide).nodeSahCost == 1.0);
        CHECK(bvh4Stats(wide).leafSahCost == 2.0);
        // A root without area (one triangle on a line) has no ratio: 0, not NaN.
        Mesh line;
        line.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
        line.triangles = {{0, 1, 2}};
        Bvh4Stats flat = bvh4Stats(collapseToBvh4(buildEngineBvh(line, options)));
        CHECK(flat.nodeSahCost == 0.0);
        CHECK(flat.leafSahCost == 0.0);
        // Down through the first cluster: the binary tree tests its leaf's 3 triangles (the
        // other leaf's box is missed), the 4-wide tree one node and the merged leaf's 6.
        std::vector<Ray> down = {Ray(Vec3(0.25f, 0.25f, 5.0f), Vec3(0, 0, -1))};
        TraversalCounts b = countWork(binary, down), w = countWork(wide, down);
        CHECK(b.rays == 1);
        CHECK(b.triangles == 3);
        CHECK(w.nodes == 1);
        CHECK(w.leaves == 1);
        CHECK(w.packets == 2);
        CHECK(w.triangles == 6);
        // Beside the root box (y = 50): nothing at all.
        std::vector<Ray> beside = {Ray(Vec3(50.0f, 50.0f, 5.0f), Vec3(0, 0, -1))};
        TraversalCounts bm = countWork(binary, beside), wm = countWork(wide, beside);
        CHECK(bm.triangles == 0);
        CHECK(wm.nodes + wm.leaves + wm.packets + wm.triangles == 0);
    }
    TEST_CASE("the engine's binary traversal finds the chapter's hits bit for bit") {
        Mesh m = triangleSoup(1500, 40);
        Bvh binary = buildEngineBvh(m, optionsFor(BvhBuilder::BinnedSah));
        size_t compared = 0;
        for (const Ray& ray : randomRays(2000, 43)) {
            float tChapter, tEngine, uChapter = -1, vChapter = -1, uEngine = -2, vEngine = -2;
            uint32_t chapter = nearestSlot(binary, ray, tChapter, &uChapter, &vChapter);
            uint32_t engine = nearestSlotFast(binary, ray, tEngine, &uEngine, &vEngine);
            REQUIRE(engine == chapter);
            if (chapter != kTraversalMiss) {
                // The same bits: t and the barycentrics of the same triangle.
                CHECK(std::bit_cast<uint32_t>(tEngine) == std::bit_cast<uint32_t>(tChapter));
                CHECK(std::bit_cast<uint32_t>(uEngine) == std::bit_cast<uint32_t>(uChapter));
                CHECK(std::bit_cast<uint32_t>(vEngine) == std::bit_cast<uint32_t>(vChapter));
                ++compared;
            }
            CHECK(traceOccludedFast(binary, ray) == traceOccluded(binary, ray));
        }
        // 288 of these 2000 seeded rays hit the soup (the others pass beside it): enough hits
        // to compare, and the misses check that both loops miss alike.
        CHECK(compared > 200);
    }
    TEST_CASE("trace --count: counting changes no hit and the counts fit together") {
        Mesh m = triangleSoup(1500, 40);
        Bvh binary = buildEngineBvh(m, optionsFor(BvhBuilder::BinnedSah));
        Bvh8 wide = collapseToBvh8(binary);
        std::vector<Ray> rays = randomRays(500, 41);
        for (const Ray& ray : rays) {
            TraversalCounts c;
            CHECK(traceNearest(wide, ray, TraversalCounter{&c}) == traceNearest(wide, ray));
            CHECK(traceNearestFast(binary, ray, TraversalCounter{&c}) == traceNearest(binary, ray));
        }
        TraversalCounts w = countWork(wide, rays);
        CHECK(w.rays == 500);
        CHECK(w.nodes > 500);  // most random rays cross the soup
        // A leaf is 1 to 4 packets (a binary leaf of up to maxLeafSize = 16 stays a leaf),
        // a packet 1 to 4 triangles.
        CHECK(w.leaves <= w.packets);
        CHECK(w.packets <= 4 * w.leaves);
        CHECK(w.packets <= w.triangles);
        CHECK(w.triangles <= 4 * w.packets);
    }
    template <int W>
    void cracksCase() {
        for (const char* name : {"sh1", "bunny"}) {
            INFO(std::string(name));
            Mesh m = loadObj(test::dataDir() + "/meshes/" + name + ".obj");
            BvhWide<W> wide = wideTree<W>(m);
            size_t rays = 0;
            size_t cracks = countCracks(
                m, makeCrackRays(m, 500, 500, 39),
                [&](const Ray& r) { return traceNearest(wide, r); }, rays);
            CHECK(rays > 500);
            CHECK(cracks == 0);
        }
    }
    TEST_CASE("4-wide: no cracks at shared edges and vertices") {
        cracksCase<4>();
    }
    TEST_CASE("8-wide: no cracks at shared edges and vertices") {
        cracksCase<8>();
    }
    template <int W>
    void identicalCentroidsCase() {
        // 300 copies of one triangle: every builder splits in array order; the nearest is
        // the same t for all.
        Mesh m;
        m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
        for (int i = 0; i < 300; ++i) m.triangles.push_back({0, 1, 2});
        BvhWide<W> wide = wideTree<W>(m);
        checkStructure4(wide, 300);
        TraceHit h = traceNearest(wide, Ray(Vec3(0.25f, 0.25f, 2.0f), Vec3(0, 0, -1)));
        CHECK(h.t == 2.0f);
        CHECK(h.triangle < 300u);
        CHECK(traceOccluded(wide, Ray(Vec3(0.25f, 0.25f, 2.0f), Vec3(0, 0, -1))));
        CHECK(traceNearest(wide, Ray(Vec3(0.75f, 0.75f, 2.0f), Vec3(0, 0, -1))).triangle ==
              kNoPrimitive);
    }
    TEST_CASE("hard case: 4-wide identical centroids") {
        identicalCentroidsCase<4>();
    }
    TEST_CASE("hard case: 8-wide identical centroids") {
        identicalCentroidsCase<8>();
    }
    template <int W>
    void flatBoxesCase() {
        // A 20 x 20 grid of quads in the plane z = 0: every box has zero extent in z.
        test::FpTrapsOff nanOnPurpose;  // rays in the plane: 0 * infinity in the slab test
        Mesh m;
        for (int y = 0; y <= 20; ++y)
            for (int x = 0; x <= 20; ++x) m.positions.push_back(Vec3(float(x), float(y), 0.0f));
        for (uint32_t y = 0; y < 20; ++y)
            for (uint32_t x = 0; x < 20; ++x) {
                uint32_t v = y * 21 + x;
                m.triangles.push_back({v, v + 1, v + 22});
                m.triangles.push_back({v, v + 22, v + 21});
            }
        BvhWide<W> wide = wideTree<W>(m);
        checkStructure4(wide, m.triangleCount());
        std::mt19937_64 rng(40);
        std::uniform_real_distribution<float> u(-1.0f, 21.0f);
        size_t hits = 0;
        for (int i = 0; i < 500; ++i) {
            Ray ray(Vec3(u(rng), u(rng), 3.0f), Vec3(0.1f * u(rng), 0.1f * u(rng), -1.0f));
            TraceHit brute = traceBruteForce(m, ray);
            hits += brute.triangle != kNoPrimitive;
            CHECK(hitsAgree(traceNearest(wide, ray), brute));
        }
        CHECK(hits > 300);
        // Rays lying in the plane: the triangles are edge-on, brute force and tree agree.
        for (int i = 0; i < 100; ++i) {
            Ray ray(Vec3(u(rng), u(rng), 0.0f), Vec3(u(rng) - 10.0f, u(rng) - 10.0f, 0.0f));
            CHECK(hitsAgree(traceNearest(wide, ray), traceBruteForce(m, ray)));
        }
    }
    TEST_CASE("hard case: 4-wide flat boxes of a planar mesh") {
        flatBoxesCase<4>();
    }
    TEST_CASE("hard case: 8-wide flat boxes of a planar mesh") {
        flatBoxesCase<8>();
    }
    template <int W>
    void emptyAndOneCase() {
        BvhWide<W> none = collapseToWide<W>(Bvh{});
        CHECK(none.empty());
        Ray down(Vec3(0.25f, 0.25f, 1.0f), Vec3(0, 0, -1));
        CHECK(traceNearest(none, down).triangle == kNoPrimitive);
        CHECK_FALSE(traceOccluded(none, down));
        Mesh one;
        one.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
        one.triangles = {{0, 1, 2}};
        BvhWide<W> wide = wideTree<W>(one);
        REQUIRE(wide.nodes.size() == 1);  // a root whose one child is the leaf
        checkStructure4(wide, 1);
        CHECK(traceNearest(wide, down) == TraceHit{1.0f, 0u});
        CHECK(traceOccluded(wide, down));
        CHECK(traceNearest(wide, Ray(Vec3(0.75f, 0.75f, 1.0f), Vec3(0, 0, -1))).triangle ==
              kNoPrimitive);
    }
    TEST_CASE("hard case: 4-wide empty mesh and one triangle") {
        emptyAndOneCase<4>();
    }
    TEST_CASE("hard case: 8-wide empty mesh and one triangle") {
        emptyAndOneCase<8>();
    }
    template <int W>
    void hugeCoordinatesCase() {
        // As in "hard cases 04": the float leaf test overflows this far out and falls back
        // to double (a NaN on purpose).
        test::FpTrapsOff overflowOnPurpose;
        Mesh m = triangleSoup(5000, 41, 0.01f);
        for (Vec3& p : m.positions) p = p * 1e20f + Vec3(3e20f, -1e20f, 0.0f);
        BvhWide<W> wide = wideTree<W>(m);
        checkStructure4(wide, m.triangleCount());
        for (uint32_t tri : {123u, 4000u}) {
            Vec3 target = (m.vertex(tri, 0) + m.vertex(tri, 1) + m.vertex(tri, 2)) / 3.0f;
            Vec3 origin = target + Vec3(0.0f, 0.0f, 5e20f);
            Ray ray(origin, target - origin);
            TraceHit h = traceNearest(wide, ray), brute = traceBruteForce(m, ray);
            CHECK(h.triangle != kNoPrimitive);
            CHECK(h.t <= 1.0001f);
            CHECK(hitsAgree(h, brute));
        }
        Mesh big;
        big.positions = {{-1e21f, -1e21f, -5e20f}, {1e21f, -1e21f, -5e20f}, {0.0f, 1e21f, -5e20f}};
        big.triangles = {{0, 1, 2}};
        TraceHit h = traceNearest(wideTree<W>(big), Ray(Vec3(0.0f), Vec3(0.0f, 0.0f, -1.0f)));
        CHECK(h.triangle == 0u);
        CHECK(h.t == doctest::Approx(5e20).epsilon(1e-6));
    }
    TEST_CASE("hard case: 4-wide huge coordinates") {
        hugeCoordinatesCase<4>();
    }
    TEST_CASE("hard case: 8-wide huge coordinates") {
        hugeCoordinatesCase<8>();
    }
    TEST_CASE("batch tracing: the AVX2 loop and the baseline loop give the same bits") {
        // traceBatch runs a copy of the loop compiled for AVX2 where the CPU has it; the
        // arithmetic is the same, so must be every hit, on ordinary rays and on far-away
        // geometry where the leaf test falls back to double.
        test::FpTrapsOff overflowOnPurpose;
        Mesh bunny = loadObj(test::dataDir() + "/meshes/bunny.obj");
        Mesh far = triangleSoup(3000, 42, 0.01f);
        for (Vec3& p : far.positions) p = p * 1e20f + Vec3(3e20f, -1e20f, 0.0f);
        MESSAGE("this CPU runs the AVX2 loop: " << (traceUsesAvx2() ? "yes" : "no"));
        for (const Mesh* m : {&bunny, &far}) {
            Bvh binary = buildEngineBvh(*m, BvhBuildOptions{});
            Bvh4 wide = collapseToBvh4(binary);
            Bvh8 wide8 = collapseToBvh8(binary);
            for (RayKind kind : {RayKind::Primary, RayKind::Diffuse, RayKind::Random}) {
                INFO(std::string(rayKindName(kind))
                     << std::string(m == &far ? " rays, far mesh" : " rays, bunny"));
                std::vector<Ray> rays = m == &far ? raysAtTriangles(far, 3000, 5e20f, int(kind))
                                                  : makeRays(*m, kind, 3000, 43);
                std::vector<TraceHit> fast2, fast4, fast8, base2, base4, base8;
                traceBatch(binary, rays, fast2, 1);
                traceBatch(wide, rays, fast4, 1);
                traceBatch(wide8, rays, fast8, 1);
                setenv("BOXES_NO_AVX2", "1", 1);
                CHECK_FALSE(traceUsesAvx2());
                traceBatch(binary, rays, base2, 1);
                traceBatch(wide, rays, base4, 1);
                traceBatch(wide8, rays, base8, 1);
                unsetenv("BOXES_NO_AVX2");
                size_t hits = 0;
                for (const TraceHit& h : base2) hits += h.triangle != kNoPrimitive;
                CHECK(hits > 100);
                CHECK(std::memcmp(fast2.data(), base2.data(), rays.size() * sizeof(TraceHit)) == 0);
                CHECK(std::memcmp(fast4.data(), base4.data(), rays.size() * sizeof(TraceHit)) == 0);
                CHECK(std::memcmp(fast8.data(), base8.data(), rays.size() * sizeof(TraceHit)) == 0);
                size_t disagree = 0;  // the 8-wide tree may break an exact tie another way
                for (size_t i = 0; i < rays.size(); ++i) disagree += !hitsAgree(fast8[i], fast2[i]);
                CHECK(disagree == 0);
                CHECK(std::memcmp(fast2.data(), fast4.data(), rays.size() * sizeof(TraceHit)) == 0);
            }
        }
        // Rays at shared edges and vertices: exact ties between neighbours and lanes for the
        // scalar test, where the AVX2 loop's eight-lane leaf test (two packets at once)
        // must still choose as the four-lane one does, packet by packet.
        Mesh sh1 = loadObj(test::dataDir() + "/meshes/sh1.obj");
        CrackRaySet set = makeCrackRays(sh1, 1500, 1500, 53);
        std::vector<Ray> rays;
        for (const auto* group : {&set.edgeRays, &set.vertexRays})
            for (const CrackRay& cr : *group) rays.push_back(cr.ray);
        Bvh binary = buildEngineBvh(sh1, BvhBuildOptions{});
        Bvh4 wide = collapseToBvh4(binary);
        Bvh8 wide8 = collapseToBvh8(binary);
        std::vector<TraceHit> fast4, fast8, base4, base8;
        traceBatch(wide, rays, fast4, 1);
        traceBatch(wide8, rays, fast8, 1);
        setenv("BOXES_NO_AVX2", "1", 1);
        traceBatch(wide, rays, base4, 1);
        traceBatch(wide8, rays, base8, 1);
        unsetenv("BOXES_NO_AVX2");
        CHECK(rays.size() > 2000);
        CHECK(std::memcmp(fast4.data(), base4.data(), rays.size() * sizeof(TraceHit)) == 0);
        CHECK(std::memcmp(fast8.data(), base8.data(), rays.size() * sizeof(TraceHit)) == 0);
    }
}
