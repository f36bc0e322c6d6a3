// Step 01: cases for mistakes no hand-written case caught (found by plausible wrong
// solutions and by generated mutants, ./workbook mutants --generate). Each name says what
// it guards.
#include <doctest/doctest.h>

#include <cmath>

#include "01_triangle/triangle.hpp"
#include "support.hpp"

using namespace boxes;

namespace {

// A scale that float cannot hold (float rounds it to 1): a float intermediate in a double
// routine loses it, and the answer moves by 2e-13 or more, twenty times the bound below.
constexpr double kNotFloat = 1.0 + 0x1p-40;

// The unit right triangle in z = 0 scaled by kNotFloat, and a ray straight down from
// z = 3 + 2^-35 (t is not a float either) through (0.25, 0.5).
const Triangled kScaled{{0, 0, 0}, {kNotFloat, 0, 0}, {0, kNotFloat, 0}};
const Rayd kDown(Vec3d(0.25, 0.5, 3.0 + 0x1p-35), Vec3d(0, 0, -1));

void checkDoubleHit(const std::optional<TriangleHit<double>>& h) {
    REQUIRE(h.has_value());
    CHECK(std::fabs(h->t - (3.0 + 0x1p-35)) <= 1e-14);
    CHECK(std::fabs(h->u - 0.25 / kNotFloat) <= 1e-14);
    CHECK(std::fabs(h->v - 0.5 / kNotFloat) <= 1e-14);
}

// Straight down from z = 2 onto the unit triangle: t = 2 exactly, in float.
const Triangle kUnit{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
template <typename Test>
void checkClosedInterval(Test test) {
    Vec3 o(0.25f, 0.25f, 2.0f), d(0.0f, 0.0f, -1.0f);
    CHECK(test(Ray(o, d, 2.0f, kInfinity<float>)).has_value());                  // t == tmin
    CHECK(test(Ray(o, d, 0.0f, 2.0f)).has_value());                              // t == tmax
    CHECK(test(Ray(o, d, 2.0f, 2.0f)).has_value());                              // both
    CHECK_FALSE(test(Ray(o, d, std::nextafter(2.0f, 3.0f), kInfinity<float>)));  // just past
    CHECK_FALSE(test(Ray(o, d, 0.0f, std::nextafter(2.0f, 1.0f))));              // just short
}

}  // namespace

TEST_SUITE("exercise 1.1") {
    TEST_CASE(
        "triangle plane in double: the normal and d keep double's precision (no float inside)") {
        // The plane z = 2^-35 (not a float) through a triangle at that height.
        const double z = 0x1p-35 + 1.0;
        auto p = trianglePlane(Triangled{{0, 0, z}, {kNotFloat, 0, z}, {0, kNotFloat, z}});
        REQUIRE(p.has_value());
        CHECK(p->normal == Vec3d(0, 0, 1));
        CHECK(std::fabs(p->d + z) <= 1e-14);
    }
}

TEST_SUITE("exercise 1.2") {
    TEST_CASE("ray/plane distance in double: t keeps double's precision (no float inside)") {
        auto t = rayPlaneDistance(kDown, PlaneT<double>{Vec3d(0, 0, kNotFloat), 0.0});
        REQUIRE(t.has_value());
        CHECK(std::fabs(*t - (3.0 + 0x1p-35)) <= 1e-14);
    }
}

TEST_SUITE("exercise 1.3") {
    TEST_CASE("inside test in double: the barycentrics keep double's precision (no float inside)") {
        auto uv = insideEdgePlanes(kDown, kScaled);
        REQUIRE(uv.has_value());
        CHECK(std::fabs(uv->x - 0.25 / kNotFloat) <= 1e-14);
        CHECK(std::fabs(uv->y - 0.5 / kNotFloat) <= 1e-14);
    }
}

TEST_SUITE("exercise 1.4") {
    TEST_CASE("Moller-Trumbore: a hit exactly at t == tmin or t == tmax counts (closed interval)") {
        checkClosedInterval([](const Ray& r) { return intersectMollerTrumbore(r, kUnit); });
    }
    TEST_CASE("Moller-Trumbore in double: t u and v keep double's precision (no float inside)") {
        checkDoubleHit(intersectMollerTrumbore(kDown, kScaled));
    }
}

TEST_SUITE("exercise 1.5") {
    TEST_CASE("watertight: a hit exactly at t == tmin or t == tmax counts (closed interval)") {
        checkClosedInterval([](const Ray& r) { return intersectWatertight(r, kUnit); });
    }
    TEST_CASE("watertight in double: t u and v keep double's precision (no float inside)") {
        checkDoubleHit(intersectWatertight(kDown, kScaled));
    }
}
