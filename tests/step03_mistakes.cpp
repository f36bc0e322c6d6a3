// Step 03: cases for mistakes no hand-written case caught (found by plausible wrong
// solutions and by generated mutants, ./workbook mutants --generate). Each name says what
// it guards.
#include <doctest/doctest.h>

#include <cmath>

#include "03_aabb/aabb.hpp"
#include "support.hpp"

using namespace boxes;

namespace {

// A coordinate float cannot hold (float rounds it to 1): a float intermediate in a double
// routine loses it.
constexpr double kNotFloat = 1.0 + 0x1p-40;

// The box [0, 1]^3 along x from x = -2: entered at t = 2, left at 3.
template <bool Conservative>
void checkClosedInterval() {
    const Bounds3f box(Vec3(0), Vec3(1));
    auto test = [&](float tmin, float tmax) {
        SlabRay r(Ray(Vec3(-2.0f, 0.5f, 0.5f), Vec3(1, 0, 0), tmin, tmax));
        return Conservative ? intersectSlabsConservative(r, box) : intersectSlabs(r, box);
    };
    auto atEntry = test(0.0f, 2.0f);  // entered exactly at tmax: the interval [2, 2]
    REQUIRE(atEntry.has_value());
    CHECK(atEntry->tnear == 2.0f);
    CHECK(atEntry->tfar == 2.0f);
    auto atExit = test(3.0f, kInfinity<float>);  // left exactly at tmin: [3, 3]
    REQUIRE(atExit.has_value());
    CHECK(atExit->tnear == 3.0f);
    CHECK_FALSE(test(0.0f, std::nextafter(2.0f, 0.0f)).has_value());
    if (!Conservative) CHECK_FALSE(test(std::nextafter(3.0f, 4.0f), kInfinity<float>).has_value());
}

}  // namespace

TEST_SUITE("exercise 3.1") {
    TEST_CASE("sphere bounds in double: keep double's precision (no float inside)") {
        auto b = sphereBounds(SphereT<double>{Vec3d(kNotFloat), 0x1p-41});
        CHECK(b.min == Vec3d(kNotFloat - 0x1p-41));
        CHECK(b.max == Vec3d(kNotFloat + 0x1p-41));
    }
}

TEST_SUITE("exercise 3.5") {
    TEST_CASE("overlap in double: boxes 2^-40 apart do not overlap (no float inside)") {
        Bounds3d a(Vec3d(0), Vec3d(1)), b(Vec3d(0, 0, kNotFloat), Vec3d(2));
        CHECK_FALSE(overlaps(a, b));
        CHECK_FALSE(overlaps(b, a));
        CHECK(overlaps(a, Bounds3d(Vec3d(0, 0, 1), Vec3d(2))));
    }
}

TEST_SUITE("exercise 3.6") {
    TEST_CASE(
        "slab test: a box entered at t == tmax or left at t == tmin is hit (closed interval)") {
        checkClosedInterval<false>();
    }
    TEST_CASE("slab test in double: tnear and tfar keep double's precision (no float inside)") {
        auto r = intersectSlabs(SlabRayT<double>(Rayd(Vec3d(-2, 0.5, 0.5), Vec3d(1, 0, 0))),
                                Bounds3d(Vec3d(0), Vec3d(kNotFloat)));
        REQUIRE(r.has_value());
        CHECK(r->tnear == 2.0);
        CHECK(std::fabs(r->tfar - (2.0 + kNotFloat)) <= 1e-14);
    }
}

TEST_SUITE("exercise 3.7") {
    TEST_CASE(
        "conservative slab test: a box entered at t == tmax or left at t == tmin is hit (closed "
        "interval)") {
        checkClosedInterval<true>();
    }
    TEST_CASE(
        "conservative slab test in double: tfar widened by double's own bound (no float inside)") {
        auto r =
            intersectSlabsConservative(SlabRayT<double>(Rayd(Vec3d(-2, 0.5, 0.5), Vec3d(1, 0, 0))),
                                       Bounds3d(Vec3d(0), Vec3d(kNotFloat)));
        REQUIRE(r.has_value());
        CHECK(r->tnear == 2.0);
        // 1 + 2 gamma(3) in double widens by about 7e-16: far less than float's 4e-7.
        CHECK(r->tfar >= 2.0 + kNotFloat);
        CHECK(r->tfar - (2.0 + kNotFloat) <= 1e-14);
    }
}
