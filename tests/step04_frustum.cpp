// Step 04's frustum culling (exercises 4.6 to 4.8) with hand-worked numbers, and the
// culling of a hierarchy.
#include <doctest/doctest.h>

#include <set>
#include <stdexcept>
#include <vector>

#include "04_bvh/frustum.hpp"
#include "step04_support.hpp"

using namespace boxes;
using namespace boxes::test04;

TEST_SUITE("exercise 4.6") {
    TEST_CASE("frustum of a 90 degree camera at the origin: corners and planes") {
        Frustum f = makeFrustum(frustumCamera(), 1.0f, 100.0f);
        Frustum expected = handFrustum();
        for (size_t i = 0; i < 8; ++i) test::checkVec(f.corners[i], expected.corners[i], 1e-3);
        for (size_t i = 0; i < 6; ++i) {
            INFO("plane " << i);
            test::checkVec(f.planes[i].normal, expected.planes[i].normal, 1e-5);
            CHECK(f.planes[i].d == doctest::Approx(expected.planes[i].d).epsilon(1e-5));
        }
    }
    TEST_CASE("points inside and outside a general frustum") {
        Camera c;
        c.eye = Vec3(1, 2, 3);
        c.view = Vec3(1, 0, 1);
        c.fovYDegrees = 50.0f;
        c.aspect = 2.0f;
        Frustum f = makeFrustum(c, 0.5f, 20.0f);
        auto inside = [&](Vec3 p) {
            for (const auto& pl : f.planes)
                if (glm::dot(pl.normal, p) + pl.d < -1e-4f) return false;
            return true;
        };
        Vec3 forward = glm::normalize(c.view);
        CHECK(inside(c.eye + 10.0f * forward));
        CHECK_FALSE(inside(c.eye + 0.25f * forward));  // before near
        CHECK_FALSE(inside(c.eye + 21.0f * forward));  // beyond far
        CHECK_FALSE(inside(c.eye - 5.0f * forward));   // behind
        for (const Vec3& corner : f.corners) CHECK(inside(corner));
        for (const auto& pl : f.planes) CHECK(glm::length(pl.normal) == doctest::Approx(1.0));
        CHECK_THROWS_AS(makeFrustum(c, 0.0f, 1.0f), std::invalid_argument);
        CHECK_THROWS_AS(makeFrustum(c, 2.0f, 1.0f), std::invalid_argument);
    }
}

TEST_SUITE("exercise 4.6") {
    TEST_CASE("frustum: the side planes follow the aspect ratio") {
        // The 90 degree camera with aspect 2: the far corners at x = +-200, y = +-100.
        Camera c = frustumCamera();
        c.aspect = 2.0f;
        Frustum f = makeFrustum(c, 1.0f, 100.0f);
        test::checkVec(f.corners[5], Vec3(200, 100, -100), 1e-3);
        // 15 to the right at distance 10 is inside (x / -z = 1.5 < 2).
        for (const auto& plane : f.planes)
            CHECK(glm::dot(plane.normal, Vec3(15, 0, -10)) + plane.d >= 0.0f);
    }
    TEST_CASE(
        "frustum: the side planes face inwards for an eye far from the origin and far = 10^5") {
        // A point to orient the side planes by must lie clearly inside: one a few millionths
        // in front of an eye at z = 1000 (float's spacing there is 6e-5) rounds to the eye,
        // which lies on every side plane and orients none of them.
        Camera c = frustumCamera();
        c.eye = Vec3(0, 0, 1000);
        Frustum f = makeFrustum(c, 1.0f, 1e5f);
        for (size_t i = 0; i < 6; ++i) {
            INFO("plane " << i);
            CHECK(glm::dot(f.planes[i].normal, Vec3(0, 0, 950)) + f.planes[i].d > 0.0f);
        }
    }
    TEST_CASE("frustum: near and far must satisfy 0 < near < far") {
        Camera c;
        CHECK_THROWS_AS(makeFrustum(c, 0.0f, 1.0f), std::invalid_argument);
        CHECK_THROWS_AS(makeFrustum(c, -1.0f, 5.0f), std::invalid_argument);
        CHECK_THROWS_AS(makeFrustum(c, 2.0f, 2.0f), std::invalid_argument);
        CHECK_THROWS_AS(makeFrustum(c, 1.0f, kInfinity<float>), std::invalid_argument);
    }
}

TEST_SUITE("exercise 4.7") {
    TEST_CASE("p-vertex: a box touching a plane is kept") {
        // Between the eye and the near plane z = -1, its face on that plane: touching counts.
        CHECK_FALSE(cullByPlanes(handFrustum(), {Vec3(-0.5f, -0.5f, -1), Vec3(0.5f, 0.5f, -0.5f)}));
    }
    TEST_CASE("p-vertex: every plane can cull") {
        // A small box outside each plane in turn (and inside the other five where it can be).
        Frustum f = handFrustum();
        const Bounds3f outside[] = {
            {Vec3(-60, -1, -50), Vec3(-55, 1, -45)},               // left
            {Vec3(55, -1, -50), Vec3(60, 1, -45)},                 // right
            {Vec3(-1, -60, -50), Vec3(1, -55, -45)},               // bottom
            {Vec3(-1, 55, -50), Vec3(1, 60, -45)},                 // top
            {Vec3(-0.1f, -0.1f, -0.9f), Vec3(0.1f, 0.1f, -0.5f)},  // before near
            {Vec3(-1, -1, -130), Vec3(1, 1, -110)}};               // beyond far
        for (const Bounds3f& box : outside) {
            INFO("box " << box.min << " to " << box.max);
            CHECK(cullByPlanes(f, box));
        }
    }
    TEST_CASE("p-vertex: outside one plane culled while straddling and inside kept") {
        Frustum f = handFrustum();
        CHECK(cullByPlanes(f, {Vec3(-1, -1, 1), Vec3(1, 1, 3)}));        // behind the eye
        CHECK(cullByPlanes(f, {Vec3(-1, -1, -300), Vec3(1, 1, -200)}));  // beyond far
        CHECK(cullByPlanes(f, {Vec3(60, -1, -50), Vec3(70, 1, -40)}));   // right of it
        CHECK_FALSE(cullByPlanes(f, {Vec3(-1, -1, -20), Vec3(1, 1, -10)}));
        CHECK_FALSE(cullByPlanes(f, {Vec3(40, -1, -50), Vec3(60, 1, -40)}));  // straddles
        CHECK_FALSE(cullByPlanes(f, {Vec3(-1000), Vec3(1000)}));              // contains it
    }
    TEST_CASE("hard case: the box near a frustum corner is kept by the plane test") {
        // x in [101, 105] beyond the far corners' x = 100, z in [-110, -95]: for the right
        // plane the p-vertex (101, 1, -110) has -x - z = 9 >= 0; for the far plane z = -95
        // is in front of -100. No plane rejects it: conservatively kept.
        Frustum f = handFrustum();
        Bounds3f box(Vec3(101, -1, -110), Vec3(105, 1, -95));
        CHECK_FALSE(cullByPlanes(f, box));
        CHECK_FALSE(boxIntersectsFrustumExact(f, box));  // yet entirely outside
    }
}

TEST_SUITE("exercise 4.8") {
    TEST_CASE("hard case: the refinement culls the box near the frustum corner") {
        Frustum f = handFrustum();
        // Every frustum corner has x <= 100 < 101 = the box's min x.
        CHECK(cullByBoxPlanes(f, {Vec3(101, -1, -110), Vec3(105, 1, -95)}));
    }
    TEST_CASE("corners against box planes: a frustum entirely above the box culls it") {
        // Every corner has y >= -100 > -150, the box's max y.
        CHECK(cullByBoxPlanes(handFrustum(), {Vec3(-5, -200, -50), Vec3(5, -150, -40)}));
    }
    TEST_CASE("corners against box planes: a frustum touching a face keeps the box") {
        // The far corners have x = 100: the box from x = 100 touches the frustum.
        CHECK_FALSE(cullByBoxPlanes(handFrustum(), {Vec3(100, -5, -100), Vec3(110, 5, -90)}));
        CHECK_FALSE(cullByBoxPlanes(handFrustum(), {Vec3(-5, -5, -120), Vec3(5, 5, -100)}));
    }
    TEST_CASE("corners against box planes: boxes the frustum reaches are kept") {
        Frustum f = handFrustum();
        CHECK_FALSE(cullByBoxPlanes(f, {Vec3(-1, -1, -20), Vec3(1, 1, -10)}));
        CHECK_FALSE(cullByBoxPlanes(f, {Vec3(-1000), Vec3(1000)}));
        CHECK_FALSE(cullByBoxPlanes(f, {Vec3(99, 99, -101), Vec3(101, 101, -99)}));  // a corner
        CHECK(cullByBoxPlanes(f, {Vec3(-5, 120, -50), Vec3(5, 130, -40)}));  // above every corner
        CHECK(cullByBoxPlanes(f, {Vec3(-5, -5, -150), Vec3(5, 5, -120)}));   // beyond far
    }
}

TEST_SUITE("culling 04") {
    TEST_CASE("hierarchy culling keeps every triangle inside the frustum") {
        // Uses the hand-made frustum and both culling exercises through boxCulled.
        Mesh m = triangleSoup(3000, 18, 0.02f);
        for (Vec3& p : m.positions) p = p * 200.0f - Vec3(100.0f, 100.0f, 150.0f);
        Bvh bvh = referenceTree(m);
        Frustum f = handFrustum();
        for (CullTest test : {CullTest::Planes, CullTest::PlanesAndCorners}) {
            CullCounts counts;
            std::vector<uint32_t> visible = cullHierarchy(bvh, f, test, &counts);
            std::set<uint32_t> kept(visible.begin(), visible.end());
            CHECK(checkKeptInsideFrustum(m, f, kept) > 100);
            CHECK(counts.culled > 0);
            CHECK(counts.visited == counts.culled + counts.kept);
            CHECK(kept.size() < m.triangleCount());
        }
    }
}
