// Step 04's builders, by the structure they build (exercises 4.1 to 4.3), and the hard
// cases of building and tracing exercise trees.
#include <doctest/doctest.h>

#include <vector>

#include "step04_support.hpp"

using namespace boxes;
using namespace boxes::test04;

TEST_SUITE("exercise 4.1") {
    TEST_CASE("midpoint: hand-worked split of four boxes") {
        // Centroids at x = 0.5, 1.5, 2.5, 10.5: centroid bounds [0.5, 10.5], middle 5.5.
        auto prims = primitivesOf({unitBoxAt({10, 0, 0}), unitBoxAt({0, 0, 0}),
                                   unitBoxAt({2, 0, 0}), unitBoxAt({1, 0, 0})});
        size_t left = partitionMidpoint(prims, centroidBounds(prims));
        CHECK(left == 3);
        for (size_t i = 0; i < prims.size(); ++i) CHECK((prims[i].centroid.x < 5.5f) == (i < 3));
    }
    TEST_CASE("midpoint: the middle of centroid bounds away from the origin") {
        // Centroids at x = 100.5, 101.5, 102.5, 110.5: the middle is 105.5.
        auto prims = primitivesOf({unitBoxAt({110, 0, 0}), unitBoxAt({100, 0, 0}),
                                   unitBoxAt({102, 0, 0}), unitBoxAt({101, 0, 0})});
        CHECK(partitionMidpoint(prims, centroidBounds(prims)) == 3);
    }
    TEST_CASE("midpoint: the longest axis of the centroid bounds is split") {
        auto prims = primitivesOf({unitBoxAt({0, 0, 0}), unitBoxAt({0, 8, 0}), unitBoxAt({1, 1, 0}),
                                   unitBoxAt({0, 5, 1})});
        size_t left = partitionMidpoint(prims, centroidBounds(prims));  // y, middle 4.5
        CHECK(left == 2);
        for (size_t i = 0; i < 2; ++i) CHECK(prims[i].centroid.y < 4.5f);
    }
    TEST_CASE("midpoint: every triangle in one leaf and bounds that fit") {
        Mesh m = triangleSoup(3000, 7);
        Bvh bvh = buildBvh(m, optionsFor(BvhBuilder::Midpoint));
        checkStructure(bvh, triangleBounds(m));
        BvhBuildStats s = bvhStats(bvh, optionsFor(BvhBuilder::Midpoint));
        CHECK(s.maxLeafSize <= 4);
        CHECK(s.leaves * 2 - 1 == s.nodes);
    }
}

TEST_SUITE("exercise 4.2") {
    TEST_CASE("median: half on each side and ordered along the axis") {
        auto prims =
            primitivesOf({unitBoxAt({9, 0, 0}), unitBoxAt({0, 0, 0}), unitBoxAt({100, 0, 0}),
                          unitBoxAt({3, 0, 0}), unitBoxAt({1, 0, 0})});
        size_t left = partitionMedian(prims, centroidBounds(prims));
        CHECK(left == 2);
        float maxLeft = std::max(prims[0].centroid.x, prims[1].centroid.x);
        for (size_t i = 2; i < prims.size(); ++i) CHECK(prims[i].centroid.x >= maxLeft);
        CHECK(maxLeft == 1.5f);
    }
    TEST_CASE("median: the split runs along the longest axis of the centroid bounds") {
        // Centroids spread 0..30 along y, 0..3 along x in the other order: the two lowest
        // in y go left (the two lowest in x are the highest in y).
        auto prims = primitivesOf({unitBoxAt({3, 0, 0}), unitBoxAt({0, 30, 0}),
                                   unitBoxAt({2, 10, 0}), unitBoxAt({1, 20, 0})});
        size_t left = partitionMedian(prims, centroidBounds(prims));
        REQUIRE(left == 2);
        for (size_t i = 0; i < prims.size(); ++i) {
            INFO("primitive " << i << " centroid " << prims[i].centroid);
            CHECK((prims[i].centroid.y < 15.0f) == (i < 2));
        }
    }
    TEST_CASE("median: a balanced tree") {
        Mesh m = triangleSoup(4096, 8);
        Bvh bvh = buildBvh(m, optionsFor(BvhBuilder::Median));
        checkStructure(bvh, triangleBounds(m));
        BvhBuildStats s = bvhStats(bvh, optionsFor(BvhBuilder::Median));
        // 4096 / 2^10 = 4 per leaf: exactly 10 levels below the root, 1024 leaves.
        CHECK(s.depth == 10);
        CHECK(s.leaves == 1024);
        CHECK(s.minLeafSize == 4);
        CHECK(s.maxLeafSize == 4);
    }
}

TEST_SUITE("exercise 4.3") {
    TEST_CASE("binned SAH: two clusters are split between them with the hand-worked cost") {
        // Node [0,10]x[0,1]x[0,1]: area 2(10 + 1 + 10) = 42; each unit box has area 6.
        auto prims = primitivesOf({unitBoxAt({9, 0, 0}), unitBoxAt({0, 0, 0})});
        BvhBuildOptions o = optionsFor(BvhBuilder::BinnedSah);
        float cost = 0.0f;
        size_t left = partitionBinnedSah(prims, boundsOf(prims), centroidBounds(prims), o, cost);
        CHECK(left == 1);
        CHECK(prims[0].centroid.x == 0.5f);
        CHECK(cost == doctest::Approx(1.0 + 12.0 / 42.0).epsilon(1e-6));
    }
    TEST_CASE("binned SAH: the cheaper of two planes wins") {
        // x: 0 | 4 5 | 10 ... boxes at 0, 4, 5 and 10: the split 0,4,5 | 10 separates the
        // far box; cost 1 + (A([0,6]) * 3 + A(unit) * 1) / A([0,11]) = 1 + (26*3 + 6)/46.
        auto prims = primitivesOf({unitBoxAt({0, 0, 0}), unitBoxAt({4, 0, 0}), unitBoxAt({5, 0, 0}),
                                   unitBoxAt({10, 0, 0})});
        BvhBuildOptions o = optionsFor(BvhBuilder::BinnedSah);
        o.bins = 20;
        float cost = 0.0f;
        size_t left = partitionBinnedSah(prims, boundsOf(prims), centroidBounds(prims), o, cost);
        // Candidates: {0}|{4,5,10}: 1 + (6 + 3*A([4,11]=30))/46 = 1 + 96/46;
        //             {0,4}|{5,10}: 1 + (2*A([0,5]=22) + 2*A([5,11]=26))/46 = 1 + 96/46;
        //             {0,4,5}|{10}: 1 + (3*A([0,6]=26) + 6)/46 = 1 + 84/46 (best).
        CHECK(left == 3);
        CHECK(cost == doctest::Approx(1.0 + 84.0 / 46.0).epsilon(1e-6));
    }
    TEST_CASE("binned SAH: the cost of a split includes the traversal cost") {
        // The two clusters again with a traversal cost of 3: 3 + 12 / 42 (intersection 1).
        auto prims =
            primitivesOf({unitBoxAt({9, 0, 0}), unitBoxAt({0, 0, 0}), unitBoxAt({0, 0, 0})});
        BvhBuildOptions o = optionsFor(BvhBuilder::BinnedSah);
        o.traversalCost = 3.0f;
        o.intersectionCost = 1.0f;
        float cost = 0.0f;
        size_t left = partitionBinnedSah(prims, boundsOf(prims), centroidBounds(prims), o, cost);
        CHECK(left == 2);
        CHECK(cost == doctest::Approx(3.0 + (6.0 * 2 + 6.0) / 42.0).epsilon(1e-6));
    }
    TEST_CASE("binned SAH: the primitives are partitioned at the plane that was priced") {
        // Centroids 0.5, 1.5 and 9.5: the cheapest plane leaves the box at 9 alone on the right.
        auto prims =
            primitivesOf({unitBoxAt({9, 0, 0}), unitBoxAt({1, 0, 0}), unitBoxAt({0, 0, 0})});
        float cost = 0.0f;
        size_t left = partitionBinnedSah(prims, boundsOf(prims), centroidBounds(prims),
                                         optionsFor(BvhBuilder::BinnedSah), cost);
        REQUIRE(left == 2);
        CHECK(prims[2].centroid.x == 9.5f);
    }
    TEST_CASE("binned SAH: a split along z is found") {
        // Three boxes: two at z = 0, one at z = 20; x and y are all the same.
        auto prims =
            primitivesOf({unitBoxAt({0, 0, 20}), unitBoxAt({0, 0, 0}), unitBoxAt({0, 0, 0.5f})});
        float cost = 0.0f;
        size_t left = partitionBinnedSah(prims, boundsOf(prims), centroidBounds(prims),
                                         optionsFor(BvhBuilder::BinnedSah), cost);
        REQUIRE(left == 2);
        CHECK(prims[2].centroid.z == 20.5f);
    }
    TEST_CASE("binned SAH: costs are relative to the node's surface area") {
        // Three unit boxes in a node given as [0, 10] x [0, 2] x [0, 1], area 2 (20 + 2 + 10)
        // = 64: the best split {0, 1} | {9} costs 1 + (A([0,2]x[0,1]^2) 2 + 6) / 64, with
        // intersection cost 1.
        auto prims =
            primitivesOf({unitBoxAt({9, 0, 0}), unitBoxAt({0, 0, 0}), unitBoxAt({1, 0, 0})});
        BvhBuildOptions o = optionsFor(BvhBuilder::BinnedSah);
        o.traversalCost = 1.0f;
        o.intersectionCost = 1.0f;
        float cost = 0.0f;
        Bounds3f node(Vec3(0, 0, 0), Vec3(10, 2, 1));
        size_t left = partitionBinnedSah(prims, node, centroidBounds(prims), o, cost);
        CHECK(left == 2);
        CHECK(cost == doctest::Approx(1.0 + (10.0 * 2 + 6.0) / 64.0).epsilon(1e-6));
    }
    TEST_CASE("binned SAH: identical centroids give no split and no division by zero") {
        auto prims =
            primitivesOf({unitBoxAt({1, 2, 3}), unitBoxAt({1, 2, 3}), unitBoxAt({1, 2, 3})});
        float cost = 0.0f;
        size_t left = partitionBinnedSah(prims, boundsOf(prims), centroidBounds(prims),
                                         optionsFor(BvhBuilder::BinnedSah), cost);
        CHECK(left == 0);
        CHECK(cost == kInfinity<float>);
    }
    TEST_CASE(
        "binned SAH: centroids on a line along one axis are split (the others without extent)") {
        // Unit boxes at 0, 1 and 4 along the axis: centroid extent 4, and with 4 bins a bin
        // scale of exactly 1. Node area 2 (5 + 1 + 5) = 22; the best split {0, 1} | {4}
        // costs 1 + (10 * 2 + 6 * 1) / 22.
        for (int axis = 0; axis < 3; ++axis) {
            INFO("the line along axis " << axis);
            std::vector<Bounds3f> boxes;
            for (float at : {4.0f, 0.0f, 1.0f}) {
                Vec3 lo(0.0f);
                lo[axis] = at;
                boxes.push_back(unitBoxAt(lo));
            }
            auto prims = primitivesOf(boxes);
            BvhBuildOptions o = optionsFor(BvhBuilder::BinnedSah);
            o.bins = 4;
            float cost = 0.0f;
            size_t left =
                partitionBinnedSah(prims, boundsOf(prims), centroidBounds(prims), o, cost);
            REQUIRE(left == 2);
            CHECK(prims[2].centroid[axis] == 4.5f);
            CHECK(cost == doctest::Approx(1.0 + 26.0 / 22.0).epsilon(1e-6));
        }
    }
    TEST_CASE("binned SAH: two primitives apart only along z are split") {
        // Node [0,1] x [0,1] x [0,4], area 18: cost 1 + (6 + 6) / 18.
        auto prims = primitivesOf({unitBoxAt({0, 0, 3}), unitBoxAt({0, 0, 0})});
        float cost = 0.0f;
        size_t left = partitionBinnedSah(prims, boundsOf(prims), centroidBounds(prims),
                                         optionsFor(BvhBuilder::BinnedSah), cost);
        REQUIRE(left == 1);
        CHECK(prims[0].centroid.z == 0.5f);
        CHECK(cost == doctest::Approx(1.0 + 12.0 / 18.0).epsilon(1e-6));
    }
    TEST_CASE("binned SAH: points on a line (a node without area) give no split and no NaN cost") {
        // Every cost would be 0 / 0: no split, for two primitives and for more.
        for (size_t n : {2u, 3u}) {
            INFO(n << " points");
            std::vector<Bounds3f> boxes;
            for (size_t i = 0; i < n; ++i)
                boxes.push_back({Vec3(float(i), 0, 0), Vec3(float(i), 0, 0)});
            auto prims = primitivesOf(boxes);
            float cost = 0.0f;
            size_t left = partitionBinnedSah(prims, boundsOf(prims), centroidBounds(prims),
                                             optionsFor(BvhBuilder::BinnedSah), cost);
            CHECK(left == 0);
            CHECK(cost == kInfinity<float>);
        }
    }
    TEST_CASE("binned SAH: boxes whose areas overflow float give no NaN-priced split") {
        // Half-size 10^20: each area is about 2.4e41, beyond float's 3.4e38, so every plane
        // prices inf / inf = NaN and none is cheaper than no split.
        test::FpTrapsOff nanOnPurpose;  // the NaN prices are the case under test
        std::vector<Bounds3f> boxes;
        for (float x : {0.0f, 3e20f, 6e20f, 9e20f})
            boxes.push_back({Vec3(x - 1e20f, -1e20f, -1e20f), Vec3(x + 1e20f, 1e20f, 1e20f)});
        auto prims = primitivesOf(boxes);
        float cost = 0.0f;
        size_t left = partitionBinnedSah(prims, boundsOf(prims), centroidBounds(prims),
                                         optionsFor(BvhBuilder::BinnedSah), cost);
        CHECK(left == 0);
        CHECK(cost == kInfinity<float>);
    }
    TEST_CASE("binned SAH: structure and a cost close to the full sweep") {
        Mesh m = triangleSoup(4000, 9);
        // 256: the most the build allows (every bin array used to its last element).
        for (int bins : {4, 16, 64, 256}) {
            INFO("bins " << bins);
            BvhBuildOptions o = optionsFor(BvhBuilder::BinnedSah);
            o.bins = bins;
            BvhBuildStats s, sweep;
            Bvh bvh = buildBvh(m, o, &s);
            checkStructure(bvh, triangleBounds(m));
            referenceTree(m, &sweep);
            CHECK(s.sahCost <= sweep.sahCost * (bins >= 16 ? 1.05 : 1.15));
            CHECK(s.maxLeafSize <= size_t(o.maxLeafSize));
        }
    }
}

TEST_SUITE("hard cases 04") {
    TEST_CASE("hard case: identical centroids build a finite tree for every builder") {
        std::vector<Bounds3f> boxes(1000, Bounds3f(Vec3(-1.0f), Vec3(1.0f)));
        for (BvhBuilder b : kExerciseBuilders) {
            INFO(std::string(bvhBuilderName(b)));
            BvhBuildStats s;
            Bvh bvh = buildBvh(boxes, optionsFor(b), &s);
            checkStructure(bvh, boxes);
            CHECK(s.depth <= 10);  // halves in array order: log2(1000 / 4) levels and a bit
        }
    }
    TEST_CASE("hard case: flat boxes and a depth cap") {
        // Triangles in the plane z = 0 (flat boxes), and points on a line (no area at all).
        std::vector<Bounds3f> flat, line;
        for (int i = 0; i < 500; ++i) {
            flat.push_back({Vec3(float(i % 25), float(i / 25), 0.0f),
                            Vec3(float(i % 25) + 1.0f, float(i / 25) + 1.0f, 0.0f)});
            line.push_back({Vec3(float(i), 0.0f, 0.0f), Vec3(float(i), 0.0f, 0.0f)});
        }
        for (BvhBuilder b : kExerciseBuilders) {
            INFO(std::string(bvhBuilderName(b)));
            checkStructure(buildBvh(flat, optionsFor(b)), flat);
            checkStructure(buildBvh(line, optionsFor(b)), line);
            BvhBuildOptions capped = optionsFor(b);
            capped.maxDepth = 3;
            BvhBuildStats s;
            checkStructure(buildBvh(flat, capped, &s), flat, 3);
            CHECK(s.depth <= 2);
        }
    }
    TEST_CASE("hard case: an empty list and a single primitive") {
        for (BvhBuilder b : kExerciseBuilders) {
            CHECK(buildBvh(std::vector<Bounds3f>{}, optionsFor(b)).empty());
            std::vector<Bounds3f> one = {unitBoxAt({0, 0, 0})};
            Bvh bvh = buildBvh(one, optionsFor(b));
            REQUIRE(bvh.nodes.size() == 1);
            CHECK(bvh.nodes[0].count == 1);
        }
    }
    TEST_CASE("hard case: huge coordinates and a large scene") {
        // The float leaf test overflows this far out (inf - inf = NaN) and falls back to
        // double: a NaN on purpose.
        test::FpTrapsOff overflowOnPurpose;
        Mesh m = triangleSoup(50000, 10, 0.01f);
        for (Vec3& p : m.positions) p = p * 1e20f + Vec3(3e20f, -1e20f, 0.0f);
        for (BvhBuilder b : kExerciseBuilders) {
            INFO(std::string(bvhBuilderName(b)));
            Bvh bvh = buildBvh(m, optionsFor(b));
            checkStructure(bvh, triangleBounds(m));
            // A ray at the centroid of triangle 123 finds a triangle at least that near.
            Vec3 target = (m.vertex(123, 0) + m.vertex(123, 1) + m.vertex(123, 2)) / 3.0f;
            Vec3 origin = target + Vec3(0.0f, 0.0f, 5e20f);
            Ray ray(origin, target - origin);
            TraceHit h = traceNearest(bvh, ray);
            CHECK(h.triangle != kNoPrimitive);
            CHECK(h.t <= 1.0001f);
        }
    }
    TEST_CASE("hard case: a triangle 1e21 across straight ahead is hit") {
        // Its float edge functions overflow (products near 1e42, inf - inf = NaN); the leaf
        // test then redoes the triangle in double. The overflow is on purpose here.
        test::FpTrapsOff overflowOnPurpose;
        Mesh m;
        m.positions = {{-1e21f, -1e21f, -5e20f}, {1e21f, -1e21f, -5e20f}, {0.0f, 1e21f, -5e20f}};
        m.triangles = {{0, 1, 2}};
        for (BvhBuilder b : kExerciseBuilders) {
            INFO(std::string(bvhBuilderName(b)));
            Bvh bvh = buildBvh(m, optionsFor(b));
            TraceHit h = traceNearest(bvh, Ray(Vec3(0.0f), Vec3(0.0f, 0.0f, -1.0f)));
            CHECK(h.triangle == 0u);
            CHECK(h.t == doctest::Approx(5e20).epsilon(1e-6));
            // Seen from the side and behind the ray: still a miss.
            CHECK(
                traceNearest(bvh, Ray(Vec3(3e21f, 0.0f, 0.0f), Vec3(0.0f, 0.0f, -1.0f))).triangle ==
                kNoPrimitive);
            CHECK(traceNearest(bvh, Ray(Vec3(0.0f), Vec3(0.0f, 0.0f, 1.0f))).triangle ==
                  kNoPrimitive);
        }
    }
    TEST_CASE("hard case: a tiny triangle behind a ray with a huge direction is missed") {
        // Found by fuzz_rays. With |d| = 1e28 the scaled depths are about 1e-27 and the edge
        // functions of a triangle 1e-15 across about 1e-30: their products underflow to a
        // signed zero, and t = -0 passed t >= tmin = 0 although the triangle lies behind.
        Mesh m;
        m.positions = {{-1e-15f, -1e-15f, 3.0f}, {1e-15f, -1e-15f, 3.0f}, {0.0f, 1e-15f, 3.0f}};
        m.triangles = {{0, 1, 2}};
        // The fuzzer's own input: a zero-area triangle whose line passes through the ray.
        Mesh flat;
        flat.positions = {{0.0f, 0.0f, 3.0f}, {1.0f, 1.0f, 3.0f}, {2.0f, 2.0f, 3.0f}};
        flat.triangles = {{0, 1, 2}};
        Ray away(Vec3(0.0f, 0.0f, -5.0f), Vec3(0.0f, 0.0f, -1e28f));
        Ray awayFuzz(Vec3(1.0f, 1.0f, -5.0f), Vec3(0.0f, 8.149072e-10f, -1.0603488e28f));
        CHECK(traceBruteForce(m, away).triangle == kNoPrimitive);
        CHECK(traceBruteForce(flat, awayFuzz).triangle == kNoPrimitive);
        // Towards it the same triangle is hit, at 8 / 1e28.
        TraceHit ahead = traceBruteForce(m, Ray(Vec3(0.0f, 0.0f, -5.0f), Vec3(0.0f, 0.0f, 1e28f)));
        CHECK(ahead.triangle == 0u);
        CHECK(ahead.t == doctest::Approx(8e-28).epsilon(1e-5));
        for (BvhBuilder b : kExerciseBuilders) {
            INFO(std::string(bvhBuilderName(b)));
            CHECK(traceNearest(buildBvh(m, optionsFor(b)), away).triangle == kNoPrimitive);
            CHECK(traceNearest(buildBvh(flat, optionsFor(b)), awayFuzz).triangle == kNoPrimitive);
        }
    }
}
