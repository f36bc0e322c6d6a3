// Step 04's traversal (exercises 4.4 and 4.5) on trees of the tests' reference builder,
// with a test-local double-precision triangle test.
#include <doctest/doctest.h>

#include <vector>

#include "step04_support.hpp"

using namespace boxes;
using namespace boxes::test04;

namespace {

// traverseNearest along the ray from (0.2, 0.1, 10) down -z, the primitive in slot s hit at
// t = tOfSlot(s); the slots it tests go to `calls`.
template <typename TOfSlot>
uint32_t nearestDown(const Bvh& bvh, float& tClosest, TOfSlot tOfSlot,
                     std::vector<uint32_t>* calls = nullptr) {
    Ray ray(Vec3(0.2f, 0.1f, 10.0f), Vec3(0, 0, -1));
    tClosest = ray.tmax;
    return traverseNearest(bvh, TraversalRay(ray), tClosest, [&](uint32_t s, float& tmax) {
        if (calls) calls->push_back(s);
        float t = tOfSlot(s);
        if (t > tmax) return false;
        tmax = t;
        return true;
    });
}

}  // namespace

TEST_SUITE("exercise 4.4") {
    TEST_CASE("nearest hit equals brute force on a triangle soup") {
        Mesh m = triangleSoup(2000, 11);
        Bvh bvh = referenceTree(m);
        size_t hits = 0;
        for (const Ray& ray : randomRays(2000, 12)) {
            double tTree, tBrute;
            uint32_t a = nearestWithReference(bvh, ray, tTree);
            uint32_t b = bruteWithReference(m, ray, tBrute);
            hits += b != kNoPrimitive;
            CHECK((a == b || tTree == tBrute));
        }
        CHECK(hits > 200);
    }
    TEST_CASE("the nearer child first and early out: a hit skips the far box") {
        // Root with two leaves, the far one stored first (left): the ray along -z from
        // z = 10 meets the right child's triangle at t = 1, and must not open the left one
        // (its box starts at t = 5).
        Bvh bvh;
        bvh.nodes.resize(3);
        bvh.nodes[0] = {Vec3(-1, -1, 0), 1, Vec3(1, 1, 9), 0};
        bvh.nodes[1] = {Vec3(-1, -1, 0), 0, Vec3(1, 1, 5), 1};  // far leaf, slot 0
        bvh.nodes[2] = {Vec3(-1, -1, 9), 1, Vec3(1, 1, 9), 1};  // near leaf, slot 1
        bvh.primitiveIndices = {0, 1};
        std::vector<uint32_t> calls;
        float tClosest;  // the near leaf's primitive at z = 9
        uint32_t slot = nearestDown(
            bvh, tClosest, [](uint32_t s) { return s == 1 ? 1.0f : 7.0f; }, &calls);
        CHECK(slot == 1);
        CHECK(tClosest == 1.0f);
        CHECK(calls == std::vector<uint32_t>{1});
    }
    TEST_CASE("nearest hit: after a hit the children beyond it are not opened") {
        // The ray along -z from z = 10 (t = 10 - z). Root: leaf A (z in [8, 9.5], entered
        // at t = 0.5, its primitive hit at t = 1) and inner node B (entered at t = 0.8,
        // before that hit, so it is opened). B's children: B1 beside the ray, B2 in z [0, 4]
        // (entered at t = 6): tested against the hit at t = 1, B2 is never opened. Tested
        // against the ray's tmax it is, and its primitive is tested for nothing.
        Bvh bvh;
        bvh.nodes.resize(5);
        bvh.nodes[0] = {Vec3(-1, -1, 0), 1, Vec3(3, 1, 9.5f), 0};
        bvh.nodes[1] = {Vec3(-1, -1, 8), 0, Vec3(1, 1, 9.5f), 1};  // A, slot 0
        bvh.nodes[2] = {Vec3(-1, -1, 0), 3, Vec3(3, 1, 9.2f), 0};  // B
        bvh.nodes[3] = {Vec3(2, -1, 8), 1, Vec3(3, 1, 9.2f), 1};   // B1, slot 1
        bvh.nodes[4] = {Vec3(-1, -1, 0), 2, Vec3(1, 1, 4), 1};     // B2, slot 2
        bvh.primitiveIndices = {0, 1, 2};
        std::vector<uint32_t> calls;
        float tClosest;
        uint32_t slot = nearestDown(
            bvh, tClosest, [](uint32_t s) { return s == 0 ? 1.0f : 7.0f; }, &calls);
        CHECK(slot == 0);
        CHECK(tClosest == 1.0f);
        CHECK(calls == std::vector<uint32_t>{0});
    }
    TEST_CASE("nearest hit: a postponed node entered beyond the nearest hit is not opened") {
        // The near leaf stored first this time: its hit at t = 1 ends the search before the
        // far leaf, which the ray enters at t = 5.
        Bvh bvh;
        bvh.nodes.resize(3);
        bvh.nodes[0] = {Vec3(-1, -1, 0), 1, Vec3(1, 1, 9), 0};
        bvh.nodes[1] = {Vec3(-1, -1, 9), 0, Vec3(1, 1, 9), 1};  // near leaf, slot 0
        bvh.nodes[2] = {Vec3(-1, -1, 0), 1, Vec3(1, 1, 5), 1};  // far leaf, slot 1
        bvh.primitiveIndices = {0, 1};
        std::vector<uint32_t> calls;
        float tClosest;
        uint32_t slot = nearestDown(
            bvh, tClosest, [](uint32_t s) { return s == 0 ? 1.0f : 7.0f; }, &calls);
        CHECK(slot == 0);
        CHECK(calls == std::vector<uint32_t>{0});
    }
    TEST_CASE("nearest hit: the nearest of two overlapping hits and not the first found") {
        // One leaf with two primitives: slot 0 hit at t = 5, slot 1 at t = 2.
        Bvh bvh;
        bvh.nodes = {{Vec3(-1, -1, 0), 0, Vec3(1, 1, 9), 2}};
        bvh.primitiveIndices = {0, 1};
        float tClosest;
        uint32_t slot = nearestDown(bvh, tClosest, [](uint32_t s) { return s == 0 ? 5.0f : 2.0f; });
        CHECK(slot == 1);
        CHECK(tClosest == 2.0f);
    }
    TEST_CASE("a miss of the root box tests nothing and an empty tree misses") {
        Mesh m = triangleSoup(100, 13);
        Bvh bvh = referenceTree(m);
        int calls = 0;
        float t = kInfinity<float>;
        Ray away(Vec3(5.0f), Vec3(1.0f, 0.0f, 0.0f));
        auto count = [&](uint32_t, float&) { return ++calls < 0; };
        CHECK(traverseNearest(bvh, TraversalRay(away), t, count) == kTraversalMiss);
        CHECK(calls == 0);
        CHECK(traverseNearest(Bvh{}, TraversalRay(away), t, count) == kTraversalMiss);
    }
    TEST_CASE("hard case: axis-parallel rays with origins on slab planes") {
        // Unit boxes on a grid; rays along +x with origins exactly on box faces (y, z on
        // the planes): 0 * infinity in the slab test must not lose the hit.
        test::FpTrapsOff nanOnPurpose;  // that 0 * inf = NaN is the case under test
        Mesh m;
        for (int i = 0; i < 4; ++i) {
            float x = float(i) * 2.0f;
            uint32_t base = uint32_t(m.positions.size());
            m.positions.insert(m.positions.end(), {Vec3(x, 0, 0), Vec3(x, 1, 0), Vec3(x, 0, 1)});
            m.triangles.push_back({base, base + 1, base + 2});
        }
        Bvh bvh = referenceTree(m);
        for (float y : {0.0f, 0.25f}) {
            for (Vec3 dir : {Vec3(1.0f, 0.0f, 0.0f), Vec3(1.0f, -0.0f, -0.0f)}) {
                Ray ray(Vec3(-1.0f, y, 0.25f), dir);
                double t;
                uint32_t tri = nearestWithReference(bvh, ray, t);
                CHECK(tri == 0);
                CHECK(t == 1.0);
            }
        }
    }
}

TEST_SUITE("exercise 4.5") {
    TEST_CASE("any hit agrees with brute force") {
        Mesh m = triangleSoup(1500, 14);
        Bvh bvh = referenceTree(m);
        size_t blocked = 0;
        std::mt19937_64 rng(15);
        std::uniform_real_distribution<float> len(0.05f, 1.0f);
        for (Ray ray : randomRays(1500, 16)) {
            ray.tmax = len(rng);  // shadow rays of finite length
            bool tree = traverseAny(bvh, TraversalRay(ray), [&](uint32_t s, float) {
                double t;
                return referenceTriangle(ray, bvh.leafTriangles[s], t);
            });
            double t;
            bool brute = bruteWithReference(m, ray, t) != kNoPrimitive;
            blocked += brute;
            CHECK(tree == brute);
        }
        CHECK(blocked > 100);
    }
    TEST_CASE("any hit stops at the first hit") {
        Mesh m = triangleSoup(500, 17, 0.5f);  // large overlapping triangles: many hits
        Bvh bvh = referenceTree(m);
        Ray ray(Vec3(0.5f, 0.5f, -1.0f), Vec3(0, 0, 1));
        int calls = 0, hitsSeen = 0;
        bool any = traverseAny(bvh, TraversalRay(ray), [&](uint32_t s, float) {
            ++calls;
            double t;
            bool hit = referenceTriangle(ray, bvh.leafTriangles[s], t);
            hitsSeen += hit;
            return hit;
        });
        CHECK(any);
        CHECK(hitsSeen == 1);
    }
    TEST_CASE("any hit: boxes beyond the shadow ray's end are not opened") {
        // The shadow ray from z = 10 along -z ends at t = 2. Leaf A (z in [0, 5]) starts at
        // t = 5: never opened. Leaf B is beside the ray.
        Bvh bvh;
        bvh.nodes.resize(3);
        bvh.nodes[0] = {Vec3(-1, -1, 0), 1, Vec3(3, 1, 9.5f), 0};
        bvh.nodes[1] = {Vec3(-1, -1, 0), 0, Vec3(1, 1, 5), 1};    // A, slot 0
        bvh.nodes[2] = {Vec3(2, -1, 8), 1, Vec3(3, 1, 9.5f), 1};  // B, slot 1
        bvh.primitiveIndices = {0, 1};
        Ray ray(Vec3(0.2f, 0.1f, 10.0f), Vec3(0, 0, -1), 0.0f, 2.0f);
        int calls = 0;
        bool any =
            traverseAny(bvh, TraversalRay(ray), [&](uint32_t, float) { return ++calls < 0; });
        CHECK_FALSE(any);
        CHECK(calls == 0);
    }
    TEST_CASE("any hit: an empty tree blocks nothing") {
        // A scene without triangles: no root to read, no primitive to test.
        int calls = 0;
        Ray ray(Vec3(0.0f), Vec3(0, 0, 1), 0.0f, 10.0f);
        CHECK_FALSE(
            traverseAny(Bvh{}, TraversalRay(ray), [&](uint32_t, float) { return ++calls > 0; }));
        CHECK(calls == 0);
    }
}
