// Step 04: cases for mistakes no hand-written case caught (found by plausible wrong
// solutions and by generated mutants, ./workbook mutants --generate). Each name says what
// it guards.
#include <doctest/doctest.h>

#include "differential/step04.hpp"
#include "step04_support.hpp"

using namespace boxes;
using namespace boxes::test04;

TEST_SUITE("exercise 4.1") {
    TEST_CASE(
        "midpoint: a node longest along y or z is split along that axis and not always along x") {
        for (int axis : {1, 2}) {
            INFO("longest axis "
                 << "xyz"[axis]);
            // Centroids spread 0..8 along `axis` and 0..3 along x in the other order: along
            // `axis` (middle 4) the first two go left; along x (middle 1.5) the last two.
            std::vector<Bounds3f> boxes;
            for (int i = 0; i < 4; ++i) {
                Vec3 c(float(3 - i), 0.0f, 0.0f);
                c[axis] = float(i == 0 ? 0 : i == 1 ? 1 : i == 2 ? 7 : 8);
                boxes.push_back({c - Vec3(0.5f), c + Vec3(0.5f)});
            }
            auto prims = primitivesOf(boxes);
            size_t left = partitionMidpoint(prims, centroidBounds(prims));
            REQUIRE(left == 2);
            for (size_t i = 0; i < 2; ++i) CHECK(prims[i].centroid[axis] < 4.0f);
        }
    }
}

TEST_SUITE("exercise 4.2") {
    TEST_CASE(
        "median: primitives are ordered by their centroids and not by their boxes' lower corners") {
        // Lower corners along x: 0, 3, 4, 8; centroids: 5, 3.5, 4.5, 8.5. By centroid the
        // two lowest are the second and the third box; by the lower corner the first and
        // the second.
        auto prims = primitivesOf({{Vec3(0, 0, 0), Vec3(10, 1, 1)},
                                   {Vec3(3, 0, 0), Vec3(4, 1, 1)},
                                   {Vec3(4, 0, 0), Vec3(5, 1, 1)},
                                   {Vec3(8, 0, 0), Vec3(9, 1, 1)}});
        size_t left = partitionMedian(prims, centroidBounds(prims));
        REQUIRE(left == 2);
        std::vector<uint32_t> l = {prims[0].index, prims[1].index};
        std::sort(l.begin(), l.end());
        CHECK(l == std::vector<uint32_t>{1, 2});
    }
}

TEST_SUITE("exercise 4.4") {
    TEST_CASE("nearest hit: a hit beyond the closest t handed in is not reported") {
        // One triangle across the z axis at t = 5 from the origin. Handed tClosest = 2 (the
        // caller knows a nearer hit), the traversal must find nothing and keep 2; handed 8,
        // it finds the triangle at 5.
        differential::TraversalInput in;
        in.triangles = {{Vec3(-1, -1, 5), Vec3(2, -1, 5), Vec3(-1, 2, 5)},
                        {Vec3(-1, -1, 7), Vec3(2, -1, 7), Vec3(-1, 2, 7)}};
        in.ray.direction = Vec3(0, 0, 1);
        in.leafSize = 1;
        for (float handed : {2.0f, 8.0f, kInfinity<float>}) {
            in.tClosest = handed;
            INFO("tClosest handed in " << handed);
            auto r = differential::NearestHitSpec::run(in);
            if (handed < 5.0f) {
                CHECK(r[0] == -1.0);
                CHECK(r[1] == double(handed));
            } else {
                CHECK(r[0] == 0.0);
                CHECK(r[1] == 5.0);
            }
        }
    }
}
