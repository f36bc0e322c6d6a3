// Step 02: cases for mistakes no hand-written case caught (found by plausible wrong
// solutions and by generated mutants, ./workbook mutants --generate). Each name says what
// it guards.
#include <doctest/doctest.h>

#include <cmath>

#include "02_box/box.hpp"
#include "support.hpp"

using namespace boxes;

namespace {

// A half extent float cannot hold (float rounds it to 1): a float intermediate in a double
// routine loses it, and t moves by 1e-12, a hundred times the bound below.
constexpr double kNotFloat = 1.0 + 0x1p-40;

OrientedBoxd notFloatCube() {
    OrientedBoxd box;
    box.halfExtents = Vec3d(kNotFloat);
    return box;
}

// The cube [-1, 1]^3 from z = 5 straight down: entered at t = 4 through +z, left at 6.
template <typename Test>
void checkClosedInterval(Test test) {
    Vec3 o(0.2f, -0.3f, 5.0f), d(0.0f, 0.0f, -1.0f);
    auto entry = test(Ray(o, d, 4.0f, kInfinity<float>));  // entered exactly at tmin
    REQUIRE(entry.has_value());
    CHECK(entry->t == 4.0f);
    CHECK(entry->entering);
    auto exit = test(Ray(o, d, 6.0f, kInfinity<float>));  // left exactly at tmin
    REQUIRE(exit.has_value());
    CHECK(exit->t == 6.0f);
    CHECK_FALSE(exit->entering);
    CHECK_FALSE(test(Ray(o, d, std::nextafter(6.0f, 7.0f), kInfinity<float>)).has_value());
    auto toTmax = test(Ray(o, d, 0.0f, 4.0f));  // entered exactly at tmax
    REQUIRE(toTmax.has_value());
    CHECK(toTmax->t == 4.0f);
    CHECK_FALSE(test(Ray(o, d, 0.0f, std::nextafter(4.0f, 0.0f))).has_value());
}

}  // namespace

TEST_SUITE("exercise 2.1") {
    TEST_CASE("face planes in double: d keeps double's precision (no float inside)") {
        auto planes = boxFacePlanes(notFloatCube());
        for (const auto& p : planes) CHECK(std::fabs(p.d + kNotFloat) <= 1e-14);
    }
}

TEST_SUITE("exercise 2.2") {
    TEST_CASE("six planes: a hit exactly at t == tmin or t == tmax counts (closed interval)") {
        checkClosedInterval(
            [](const Ray& r) { return intersectSixPlanes(r, boxFacePlanes(OrientedBox())); });
    }
    TEST_CASE("six planes in double: t keeps double's precision (no float inside)") {
        OrientedBoxd box = notFloatCube();
        std::array<PlaneT<double>, 6> planes;
        for (int f = 0; f < 6; ++f) {
            Vec3d n(0.0);
            n[f / 2] = f % 2 ? 1.0 : -1.0;
            planes[size_t(f)] = {n, -kNotFloat};
        }
        auto h = intersectSixPlanes(Rayd(Vec3d(0.2, -0.3, 5.0), Vec3d(0, 0, -1)), planes);
        REQUIRE(h.has_value());
        CHECK(std::fabs(h->t - (5.0 - kNotFloat)) <= 1e-14);
    }
}

TEST_SUITE("exercise 2.3") {
    TEST_CASE("axis plane distance in double: t keeps double's precision (no float inside)") {
        CHECK(std::fabs(axisPlaneDistance(kNotFloat, 5.0, -1.0) - (5.0 - kNotFloat)) <= 1e-14);
    }
}

TEST_SUITE("exercise 2.4") {
    TEST_CASE("slabs: a hit exactly at t == tmin or t == tmax counts (closed interval)") {
        checkClosedInterval([](const Ray& r) { return intersectBoxSlabs(r, OrientedBox()); });
    }
    TEST_CASE("slabs in double: t keeps double's precision (no float inside)") {
        auto h = intersectBoxSlabs(Rayd(Vec3d(0.2, -0.3, 5.0), Vec3d(0, 0, -1)), notFloatCube());
        REQUIRE(h.has_value());
        CHECK(std::fabs(h->t - (5.0 - kNotFloat)) <= 1e-14);
    }
}
