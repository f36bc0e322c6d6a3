// Step 05: cases for mistakes no hand-written case caught (found by plausible wrong
// solutions and by generated mutants, ./workbook mutants --generate). Each name says what
// it guards.
#include <doctest/doctest.h>

#include "05_efficiency/lab.hpp"
#include "support.hpp"

using namespace boxes;

TEST_SUITE("exercise 5.4") {
    TEST_CASE("any hit: the test counter adds to the count it is handed and never resets") {
        // The counter runs over many shadow rays: each call adds its tests to it.
        uint64_t tests = 100;
        std::vector<bool> blocks = {false, true, false};
        CHECK(anyHit(
            blocks.size(), [&](size_t i) { return bool(blocks[i]); }, tests));
        CHECK(tests == 102);
        CHECK_FALSE(anyHit(
            4, [](size_t) { return false; }, tests));
        CHECK(tests == 106);
    }
}

TEST_SUITE("exercise 5.6") {
    TEST_CASE("reciprocal slab test: a ray in a face plane is NaN-safe and hits the closed box") {
        // The origin on a min or a max plane with a zero direction component (of either
        // sign) along it: (plane - O) * (1 / +-0) = 0 * inf = NaN, which must constrain
        // nothing, near or far, on whichever axis it falls: a NaN that wins a comparison
        // forgets what the axes before it said. The other two axes are crossed at t in
        // [2, 3] and at [2, 3] (a hit at 2) or [4, 5] (a miss: one slab is left before the
        // other is entered).
        test::FpTrapsOff nanOnPurpose;
        const Bounds3f box(Vec3(0), Vec3(1));
        for (int axis = 0; axis < 3; ++axis)
            for (float plane : {0.0f, 1.0f})
                for (float zero : {0.0f, -0.0f})
                    for (bool swap : {false, true}) {
                        int b = (axis + 1) % 3, c = (axis + 2) % 3;
                        if (swap) std::swap(b, c);
                        Vec3 o(0.0f), d(0.0f);
                        o[axis] = plane;
                        d[axis] = zero;
                        o[b] = -2.0f;
                        d[b] = 1.0f;
                        d[c] = 1.0f;
                        INFO("axis " << axis << ", plane " << plane << ", direction component "
                                     << zero << ", other axes " << b << " then " << c);
                        o[c] = -2.0f;
                        auto hit = slabReciprocal(precomputeRay(Ray(o, d)), box);
                        REQUIRE(hit.has_value());
                        CHECK(*hit == 2.0f);
                        o[c] = -4.0f;
                        CHECK_FALSE(slabReciprocal(precomputeRay(Ray(o, d)), box).has_value());
                    }
    }
}
