// Step 05: the lab's exercises with checked numbers (the incremental renderer against an
// injected clock) and the program. The renderer's effects on demand are in
// step05_renderer.cpp, the lab's measured tables in step05_lab.cpp.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <random>

#include "05_efficiency/lab.hpp"
#include "05_efficiency/measure.hpp"
#include "05_efficiency/progressive.hpp"
#include "core/render.hpp"
#include "core/scene.hpp"
#include "support.hpp"

using namespace boxes;

namespace {

// A correct table filled here, so the tests of 5.2 and 5.3 do not need exercise 5.1.
std::vector<float> referenceTable(int n) {
    std::vector<float> t(size_t(n) + 1);
    for (int i = 0; i <= n; ++i) t[size_t(i)] = float(std::sin(2.0 * M_PI * double(i % n) / n));
    return t;
}

bool bitIdentical(const Image& a, const Image& b) {
    return a.width() == b.width() && a.height() == b.height() &&
           std::memcmp(a.pixels().data(), b.pixels().data(), a.pixels().size() * sizeof(Vec3)) == 0;
}

double maxErrorOverCircle(const std::function<float(float)>& f, int samples = 200000) {
    double worst = 0.0;
    for (int i = 0; i < samples; ++i) {
        double x = 2.0 * M_PI * i / samples;
        worst = std::max(worst, std::abs(double(f(float(x))) - std::sin(x)));
    }
    return worst;
}

}  // namespace

TEST_SUITE("hard cases 05") {
    TEST_CASE("hard case: the lecture's sine table returns wrong values") {
        LectureSinTable lecture;
        // sin(90 degrees) should be 1; the table holds sin(90 radians) = 0.894.
        REQUIRE(lecture.sin(90.0f).has_value());
        CHECK(*lecture.sin(90.0f) == doctest::Approx(std::sin(90.0)).epsilon(1e-6));
        CHECK(*lecture.sin(90.0f) == doctest::Approx(0.893997).epsilon(1e-5));
        // 30 degrees: sin(30 radians) = -0.988 instead of 0.5.
        CHECK(*lecture.sin(30.0f) == doctest::Approx(-0.988032).epsilon(1e-5));
        // i / 10 is an integer division: entries 0..9 all hold sin(0) = 0.
        CHECK(*lecture.sin(0.5f) == 0.0f);
        CHECK(*lecture.sin(0.95f) == 0.0f);
        // No wrap: a negative angle or 360 degrees reads outside the table.
        CHECK_FALSE(lecture.sin(-10.0f).has_value());
        CHECK_FALSE(lecture.sin(360.0f).has_value());
        CHECK_FALSE(lecture.sin(725.0f).has_value());
    }
}

TEST_SUITE("exercise 5.1") {
    TEST_CASE("sine table: radians over one full circle plus the wrap entry") {
        std::vector<float> t = fillSinTable(3600);
        REQUIRE(t.size() == 3601);
        CHECK(t[0] == 0.0f);
        CHECK(t[900] == doctest::Approx(1.0f).epsilon(1e-7));    // 90 degrees
        CHECK(t[300] == doctest::Approx(0.5f).epsilon(1e-6));    // 30 degrees
        CHECK(t[2700] == doctest::Approx(-1.0f).epsilon(1e-7));  // 270 degrees
        CHECK(t[3600] == t[0]);
        for (int i = 0; i < 3600; i += 37)
            CHECK(t[size_t(i)] == float(std::sin(2.0 * M_PI * i / 3600.0)));
    }
    TEST_CASE("sine table: n + 1 entries with the last repeating the first") {
        std::vector<float> t = fillSinTable(8);
        REQUIRE(t.size() == 9);
        CHECK(t[8] == t[0]);
    }
    TEST_CASE("sine table: every entry is the float nearest the true sine") {
        // Computed in double and rounded once; in float the angle itself is rounded first.
        std::vector<float> t = fillSinTable(3600);
        REQUIRE(t.size() == 3601);
        int off = 0;
        for (int i = 0; i < 3600; ++i)
            off += t[size_t(i)] != float(std::sin(2.0 * M_PI * i / 3600.0));
        CHECK(off == 0);
    }
    TEST_CASE("hard case: a table of fewer than 2 entries is refused") {
        CHECK_THROWS_AS(fillSinTable(1), std::invalid_argument);
        CHECK_THROWS_AS(fillSinTable(0), std::invalid_argument);
    }
}

TEST_SUITE("exercise 5.2") {
    TEST_CASE("nearest entry: worked angles and wrapped indices") {
        SinTable t(referenceTable(3600));
        CHECK(t.sinNearest(0.0f) == 0.0f);
        CHECK(t.sinNearest(float(M_PI / 2)) == doctest::Approx(1.0f));
        CHECK(t.sinNearest(float(M_PI / 6)) == doctest::Approx(0.5f).epsilon(1e-3));
        // Wrapped: -90 degrees, 450 degrees, -3 full turns.
        CHECK(t.sinNearest(float(-M_PI / 2)) == doctest::Approx(-1.0f));
        CHECK(t.sinNearest(float(5 * M_PI / 2)) == doctest::Approx(1.0f));
        CHECK(t.sinNearest(float(-6 * M_PI + 1.0)) == doctest::Approx(std::sin(1.0)).epsilon(1e-3));
        CHECK(t.cosNearest(0.0f) == doctest::Approx(1.0f));
    }
    TEST_CASE("nearest entry: a negative angle wraps to the end of the table") {
        // -30 degrees is entry 330 of 360: sin = -0.5, not the +0.5 of entry 30.
        SinTable t(referenceTable(360));
        CHECK(t.sinNearest(float(-M_PI / 6)) == doctest::Approx(-0.5f).epsilon(1e-3));
        CHECK(t.sinNearest(float(-7 * M_PI / 6)) == doctest::Approx(0.5f).epsilon(1e-3));
    }
    TEST_CASE("nearest entry: within the stated bound (half a step) over the full circle") {
        for (int n : {360, 3600}) {
            SinTable t(referenceTable(n));
            double worst = maxErrorOverCircle([&](float a) { return t.sinNearest(a); });
            INFO("n = " << n << ", worst " << worst);
            CHECK(worst <= t.nearestErrorBound());
            CHECK(worst > 0.4 * t.nearestErrorBound());  // and the bound is not loose
        }
        CHECK(SinTable(referenceTable(3600)).nearestErrorBound() ==
              doctest::Approx(M_PI / 3600).epsilon(1e-3));
    }
}

TEST_SUITE("exercise 5.3") {
    TEST_CASE("interpolated: exact on entries and between them within step^2 / 8") {
        SinTable t(referenceTable(360));
        CHECK(t.sinInterpolated(float(M_PI / 2)) == doctest::Approx(1.0f));
        CHECK(t.sinInterpolated(float(-M_PI / 2)) == doctest::Approx(-1.0f));
        // Halfway between 0 and 1 degree: the mean of sin 0 and sin 1 degree.
        float half = float(0.5 * M_PI / 180.0);
        CHECK(t.sinInterpolated(half) ==
              doctest::Approx(0.5 * std::sin(M_PI / 180.0)).epsilon(1e-4));
        double worst = maxErrorOverCircle([&](float a) { return t.sinInterpolated(a); });
        INFO("worst " << worst);
        CHECK(worst <= t.interpolatedErrorBound());
        // 360 entries: (2 pi / 360)^2 / 8 = 3.8e-5, far below the nearest entry's 8.7e-3.
        CHECK(t.interpolatedErrorBound() == doctest::Approx(3.8e-5 + 4e-6).epsilon(0.02));
    }
    TEST_CASE("hard case: interpolation wraps at the end of the table and for negative angles") {
        SinTable t(referenceTable(3600));
        for (float a :
             {-1e-4f, float(2 * M_PI) - 1e-4f, float(-2 * M_PI), float(4 * M_PI + 0.3), -100.0f})
            CHECK(t.sinInterpolated(a) ==
                  doctest::Approx(std::sin(double(a))).epsilon(1e-3).scale(1.0));
    }
}

TEST_SUITE("exercise 5.4") {
    TEST_CASE("any hit stops at the first occluder and counts the tests") {
        std::vector<bool> blocks = {false, false, true, true, false};
        uint64_t tests = 0;
        CHECK(anyHit(
            blocks.size(), [&](size_t i) { return bool(blocks[i]); }, tests));
        CHECK(tests == 3);
        tests = 0;
        CHECK_FALSE(anyHit(
            3, [](size_t) { return false; }, tests));
        CHECK(tests == 3);
        tests = 0;
        CHECK_FALSE(anyHit(
            0, [](size_t) { return true; }, tests));
        CHECK(tests == 0);
    }
    TEST_CASE("any hit over spheres: fewer tests than a nearest-hit loop") {
        std::vector<Sphere> spheres;
        for (int i = 0; i < 10; ++i) spheres.push_back({Vec3(0, 0, -3.0f * float(i + 1)), 1.0f});
        Ray ray(Vec3(0), Vec3(0, 0, -1));
        uint64_t tests = 0;
        CHECK(anyHit(
            spheres.size(), [&](size_t i) { return intersectSphere(ray, spheres[i]).has_value(); },
            tests));
        CHECK(tests == 1);
    }
}

TEST_SUITE("exercise 5.5") {
    TEST_CASE("finite light radius: intensity / r^2 equals the threshold") {
        // The default threshold is half an 8-bit step of the sRGB image in linear light,
        // 0.5 / 255 / 12.92: 40 / r^2 = 0.5 / (255 * 12.92)  =>  r = sqrt(263568) = 513.39...
        CHECK(finiteLightRadius(Vec3(40.0f)) == doctest::Approx(std::sqrt(263568.0)).epsilon(1e-6));
        // The largest channel decides.
        CHECK(finiteLightRadius(Vec3(1.0f, 4.0f, 2.0f), 1.0f) == doctest::Approx(2.0f));
        float r = finiteLightRadius(Vec3(12.0f, 11.0f, 9.0f));
        CHECK(12.0 / (double(r) * r) == doctest::Approx(0.5 / 255.0 / 12.92).epsilon(1e-6));
        // The old linear half step gives sqrt(40 * 510) = sqrt(20400).
        CHECK(finiteLightRadius(Vec3(40.0f), 0.5f / 255.0f) ==
              doctest::Approx(std::sqrt(20400.0)).epsilon(1e-6));
        CHECK(finiteLightRadius(Vec3(0.0f)) == 0.0f);
    }
    TEST_CASE("finite light radius: the brightest component decides") {
        // Green 9, red and blue 0: the radius where 9 / r^2 = 1 is 3 (the mean would give 1.7).
        CHECK(finiteLightRadius(Vec3(0.0f, 9.0f, 0.0f), 1.0f) == doctest::Approx(3.0f));
    }
    TEST_CASE("hard case: a zero or negative threshold is refused") {
        CHECK_THROWS_AS(finiteLightRadius(Vec3(1.0f), 0.0f), std::invalid_argument);
        CHECK_THROWS_AS(finiteLightRadius(Vec3(1.0f), -1.0f), std::invalid_argument);
    }
}

TEST_SUITE("exercise 5.6") {
    TEST_CASE("reciprocal slab test: worked boxes") {
        Bounds3f box(Vec3(-1), Vec3(1));
        auto t = slabReciprocal(precomputeRay(Ray(Vec3(0, 0, 5), Vec3(0, 0, -1))), box);
        REQUIRE(t.has_value());
        CHECK(*t == 4.0f);
        CHECK_FALSE(
            slabReciprocal(precomputeRay(Ray(Vec3(0, 3, 5), Vec3(0, 0, -1))), box).has_value());
        // Origin inside: the entry distance is tmin.
        auto inside = slabReciprocal(precomputeRay(Ray(Vec3(0), Vec3(1, 2, 3))), box);
        REQUIRE(inside.has_value());
        CHECK(*inside == 0.0f);
        // Touching an edge counts (boxes are closed). The origin lies on the slab planes
        // x = 1 and y = 1 with zero direction components there: 0 * inf = NaN by design.
        test::FpTrapsOff nanOnPurpose;
        CHECK(slabReciprocal(precomputeRay(Ray(Vec3(1, 1, 5), Vec3(0, 0, -1))), box).has_value());
    }
    TEST_CASE("reciprocal slab test: the entry distance is returned") {
        // From z = 5 along -z into [-1, 1]^3: entry at t = 4, exit at t = 6.
        auto t = slabReciprocal(precomputeRay(Ray(Vec3(0.5f, 0, 5), Vec3(0, 0, -1))),
                                Bounds3f(Vec3(-1), Vec3(1)));
        REQUIRE(t.has_value());
        CHECK(*t == 4.0f);
    }
    TEST_CASE("reciprocal slab results equal the division form on random rays") {
        std::mt19937_64 rng(5);
        std::uniform_real_distribution<float> u(-3.0f, 3.0f);
        int hits = 0;
        for (int i = 0; i < 20000; ++i) {
            Bounds3f box(Vec3(-1, -0.5f, -2), Vec3(1.5f, 0.5f, 0.25f));
            Vec3 d(u(rng), u(rng), u(rng));
            if (i % 4 == 0) d[i % 3] = 0.0f;  // axis-parallel rays
            if (i % 8 == 1) d[i % 3] = -0.0f;
            if (isZero(d)) continue;
            Vec3 o(u(rng), u(rng), u(rng));
            if (i % 16 == 2) o.x = box.min.x;  // origin on a slab plane
            Ray ray(o, d, 0.0f, 4.0f);
            auto a = slabDivision(ray, box);
            auto b = slabReciprocal(precomputeRay(ray), box);
            INFO("ray " << i);
            REQUIRE(a.has_value() == b.has_value());
            if (a) {
                ++hits;
                // x * (1/d) and x / d differ by at most one rounding: a few ulps of t.
                CHECK(std::abs(*a - *b) <= 4e-7f * std::max(1.0f, std::abs(*a)));
            }
        }
        CHECK(hits > 1500);
    }
    TEST_CASE("reciprocal slab test: a NaN slab leaves the entry distance of the others alone") {
        // An origin on a slab plane with a zero direction component: (0 - 0) * inf = NaN.
        // std::max(tNear, t0) would take the NaN and lose the other slabs' entry.
        test::FpTrapsOff nanOnPurpose;
        // The NaN slab (z) last: x enters at t = 1, the NaN must not be returned.
        Bounds3f cube(Vec3(0), Vec3(1));
        Ray last(Vec3(-1, 0.5f, 0), Vec3(1, 0, 0));
        auto a = slabReciprocal(precomputeRay(last), cube);
        REQUIRE(a.has_value());
        CHECK(*a == 1.0f);
        // The NaN slab (y) between x, which enters at t = 2, and z, which enters at 0.5:
        // the entry is 2, the later of the two.
        Bounds3f tall(Vec3(0), Vec3(1, 1, 4));
        for (float zero : {0.0f, -0.0f}) {
            Ray middle(Vec3(-2, 0, -0.5f), Vec3(1, zero, 1));
            auto b = slabReciprocal(precomputeRay(middle), tall);
            INFO("y direction " << zero);
            REQUIRE(b.has_value());
            CHECK(*b == 2.0f);
            CHECK(slabDivision(middle, tall) == b);
        }
    }
    TEST_CASE("hard case: zero direction components with -0.0 and an origin on a slab") {
        Bounds3f box(Vec3(0), Vec3(1));
        test::FpTrapsOff nanOnPurpose;  // the origin on a slab plane: 0 * inf = NaN by design
        for (float zero : {0.0f, -0.0f}) {
            Ray ray(Vec3(0.5f, 0.0f, -1.0f), Vec3(zero, zero, 1.0f));  // y origin on the min slab
            auto a = slabDivision(ray, box), b = slabReciprocal(precomputeRay(ray), box);
            REQUIRE(b.has_value());
            CHECK(a.has_value());
            CHECK(*b == 1.0f);
        }
        Ray miss(Vec3(2.0f, 0.5f, -1.0f), Vec3(0.0f, 0.0f, 1.0f));
        CHECK_FALSE(slabReciprocal(precomputeRay(miss), box).has_value());
    }
}

TEST_SUITE("exercise 5.7") {
    TEST_CASE("precomputed triangle: a worked hit") {
        PrecomputedTriangle tri = precomputeTriangle({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)});
        auto h = intersectPrecomputed(Ray(Vec3(0.25f, 0.5f, 2.0f), Vec3(0, 0, -1)), tri);
        REQUIRE(h.has_value());
        CHECK(h->t == 2.0f);
        CHECK(h->u == 0.25f);
        CHECK(h->v == 0.5f);
        CHECK_FALSE(
            intersectPrecomputed(Ray(Vec3(0.75f, 0.5f, 2.0f), Vec3(0, 0, -1)), tri).has_value());
        CHECK_FALSE(
            intersectPrecomputed(Ray(Vec3(0.25f, 0.5f, 2.0f), Vec3(0, 0, -1), 0.0f, 1.0f), tri)
                .has_value());
    }
    TEST_CASE("precomputed triangle: bit for bit the result computed from the vertices") {
        std::mt19937_64 rng(7);
        std::uniform_real_distribution<float> u(-2.0f, 2.0f);
        int hits = 0;
        for (int i = 0; i < 20000; ++i) {
            TriangleVertices v{Vec3(u(rng), u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng)),
                               Vec3(u(rng), u(rng), u(rng))};
            Vec3 o(u(rng), u(rng), 5.0f);
            Ray ray(o, Vec3(u(rng), u(rng), -4.0f) - o * 0.25f);
            auto a = intersectFromVertices(ray, v);
            auto b = intersectPrecomputed(ray, precomputeTriangle(v));
            REQUIRE(a.has_value() == b.has_value());
            if (a) {
                ++hits;
                CHECK(a->t == b->t);
                CHECK(a->u == b->u);
                CHECK(a->v == b->v);
            }
        }
        CHECK(hits > 1000);
        // An edge that a + (c - a) does not give back: c.x - a.x = 1 + 2^-24 is a tie and
        // rounds to 1, and 2^-24 + 1 rounds to 1 again, so (a + e2) - a = 1 - 2^-24. Edges
        // recomputed from the vertices in another order are not the stored ones.
        const float a = std::ldexp(1.0f, -24), c = 1.0f + std::ldexp(1.0f, -23);
        REQUIRE((a + (c - a)) - a != c - a);
        TriangleVertices tie{Vec3(a, 0, 0), Vec3(0, 1, 0), Vec3(c, 0, 0)};
        for (Vec3 o : {Vec3(0.25f, 0.25f, 1), Vec3(0.5f, 0.125f, 2), Vec3(0.1f, 0.7f, 3)}) {
            Ray ray(o, Vec3(0.01f, -0.02f, -1));
            auto x = intersectFromVertices(ray, tie);
            auto y = intersectPrecomputed(ray, precomputeTriangle(tie));
            INFO("origin " << o);
            REQUIRE(x.has_value());
            REQUIRE(y.has_value());
            CHECK(x->t == y->t);
            CHECK(x->u == y->u);
            CHECK(x->v == y->v);
        }
    }
}

TEST_SUITE("exercise 5.8") {
    TEST_CASE("approximate reciprocal square root: within 0.18 percent") {
        CHECK(approxInverseSqrt(4.0f) == doctest::Approx(0.5f).epsilon(0.0018));
        CHECK(approxInverseSqrt(0.01f) == doctest::Approx(10.0f).epsilon(0.0018));
        double worst = 0.0;
        for (int i = 0; i <= 100000; ++i) {
            float x = float(std::pow(10.0, -6.0 + 12.0 * i / 100000.0));
            double exact = 1.0 / std::sqrt(double(x));
            worst = std::max(worst, std::abs(approxInverseSqrt(x) - exact) / exact);
        }
        INFO("worst relative error " << worst);
        CHECK(worst < 0.00176);  // Lomont 2003: 0.175% after one Newton step
        CHECK(worst > 0.0015);   // one step, not an exact answer
    }
    TEST_CASE("approximate reciprocal square root: the initial guess halves the exponent") {
        // x = 4^k: x^(-1/2) = 2^-k over 40 octaves, within a percent.
        for (int k = -10; k <= 10; ++k) {
            float x = std::ldexp(1.0f, 2 * k);
            INFO("x = 2^" << 2 * k);
            CHECK(approxInverseSqrt(x) == doctest::Approx(std::ldexp(1.0, -k)).epsilon(0.01));
        }
    }
}

TEST_SUITE("exercise 5.9") {
    // A fake clock that advances only when a line is rendered, by a fixed cost. Costs and
    // budgets are multiples of 1/1024 s, so the sums are exact in double.
    constexpr double kMs = 1.0 / 1024.0;
    struct FakeLines {
        double now = 0.0;
        double cost = 0.002;
        int rendered = 0;
        Clock clock() {
            return [this] { return now; };
        }
    };

    TEST_CASE("incremental renderer: exact lines per frame for a cost and a budget") {
        struct Case {
            double cost, budget;
            int perFrame;
        };
        for (Case c : {Case{2 * kMs, 15 * kMs, 7}, Case{5 * kMs, 15 * kMs, 3},
                       Case{1 * kMs, 15 * kMs, 15}, Case{20 * kMs, 15 * kMs, 1}}) {
            FakeLines f;
            f.cost = c.cost;
            IncrementalRenderer r(
                8, 40,
                [&](Image& img, int row) {
                    img.at(0, row) = Vec3(float(row));
                    f.now += f.cost;
                    ++f.rendered;
                },
                f.clock());
            INFO("cost " << c.cost << " budget " << c.budget);
            int frames = 0;
            // Bounded: an advance() that renders nothing must not loop until the time limit.
            while (!r.complete() && frames <= 40) {
                double start = f.now;
                int lines = r.advance(c.budget);
                int expected = std::min(c.perFrame, 40 - (r.linesDone() - lines));
                REQUIRE(lines == expected);  // the first wrong frame says it, once
                if (lines > 1) CHECK(f.now - start <= c.budget + 1e-12);
                ++frames;
                REQUIRE(frames <= 40);  // a frame without a line would loop here forever
            }
            CHECK(f.rendered == 40);  // every line once: each frame resumed where it stopped
            CHECK(frames == (40 + c.perFrame - 1) / c.perFrame);
            for (int y = 0; y < 40; ++y) CHECK(r.image().at(0, y).x == float(y));
            CHECK(r.advance(c.budget) == 0);  // complete: nothing more to do
        }
    }
    TEST_CASE(
        "incremental renderer: a clock far from its start (days of uptime) keeps the budget") {
        // A steady clock may count from boot: 2^20 s (12 days) and 3 ms. Float keeps only
        // eighths of a second there, so a start or a line's start held in float is off by
        // milliseconds and the frame holds 6 lines, or 8, instead of floor(15 / 2) = 7.
        FakeLines f;
        f.now = 1048576.0 + 3 * kMs;
        f.cost = 2 * kMs;
        IncrementalRenderer r(
            4, 21, [&](Image&, int) { f.now += f.cost; }, f.clock());
        CHECK(r.advance(15 * kMs) == 7);
        CHECK(r.advance(15 * kMs) == 7);
        CHECK(r.advance(15 * kMs) == 7);
        CHECK(r.complete());
    }
    TEST_CASE("incremental renderer: a line more expensive than the budget still advances") {
        // 20 ms a line, 15 ms a frame: one line per frame, or the image never progresses.
        FakeLines f;
        f.cost = 20 * kMs;
        IncrementalRenderer r(
            4, 3, [&](Image&, int) { f.now += f.cost; }, f.clock());
        CHECK(r.advance(15 * kMs) == 1);
        CHECK(r.linesDone() == 1);
        // Every later frame too, once the last line's cost (20 ms) predicts an overrun.
        CHECK(r.advance(15 * kMs) == 1);
        CHECK(r.advance(15 * kMs) == 1);
        CHECK(r.linesDone() == 3);
        CHECK(r.complete());
    }
    TEST_CASE("incremental renderer: the completed image equals the direct render bit for bit") {
        Scene scene = makeScene("spheres", {});
        RenderSettings s;
        s.width = 48;
        s.height = 36;
        s.threads = 2;
        Image direct = renderImage(scene, scene.camera, s);
        Renderer renderer(scene, scene.camera, s);
        FakeLines f;
        IncrementalRenderer r(
            s.width, s.height,
            [&](Image& img, int row) {
                RayCounts c;
                renderer.renderRows(img, row, row + 1, c);
                f.now += 4 * kMs;
            },
            f.clock());
        int frames = 0;
        // REQUIRE: a stub's exception or a wrong count ends the case at once; bounded, so an
        // advance() that renders nothing cannot loop until the time limit.
        while (!r.complete() && frames <= s.height) {
            int before = r.linesDone();
            REQUIRE(r.advance(15 * kMs) == std::min(3, s.height - before));  // floor(15 / 4) lines
            ++frames;
            REQUIRE(frames <= s.height);
        }
        CHECK(frames == 12);
        CHECK(bitIdentical(r.image(), direct));
    }
    TEST_CASE("incremental renderer: camera motion restarts from the first line over the preview") {
        FakeLines f;
        IncrementalRenderer r(
            4, 10,
            [&](Image& img, int row) {
                img.at(0, row) = Vec3(1.0f);
                f.now += kMs;
            },
            f.clock());
        r.advance(4.5 * kMs);
        CHECK(r.linesDone() == 4);
        Image preview(4, 10, Vec3(0.5f));
        r.restart(preview);
        CHECK(r.linesDone() == 0);
        CHECK(r.image().at(0, 0).x == 0.5f);  // the preview shows until refined
        CHECK(r.image().at(0, 9).x == 0.5f);
        r.advance(2.5 * kMs);
        CHECK(r.linesDone() == 2);
        CHECK(r.image().at(0, 1).x == 1.0f);
        CHECK(r.image().at(0, 2).x == 0.5f);
    }
}

TEST_SUITE("exercise 5.10") {
    TEST_CASE("adaptive resolution converges on a synthetic cost model") {
        // A frame costs 2 ms plus 50 ms per full-resolution frame's pixels (scale^2).
        auto cost = [](float scale) { return 0.002 + 0.05 * double(scale) * scale; };
        AdaptiveResolution a(1.0 / 30.0);
        CHECK(a.scale() == 1.0f);
        for (int i = 0; i < 30; ++i) a.update(cost(a.scale()));
        double expected = std::sqrt((1.0 / 30.0 - 0.002) / 0.05);  // 0.7916
        CHECK(a.scale() == doctest::Approx(expected).epsilon(0.01));
        CHECK(cost(a.scale()) == doctest::Approx(1.0 / 30.0).epsilon(0.01));
    }
    TEST_CASE("adaptive resolution: a pure pixel cost is met in one frame") {
        AdaptiveResolution a(0.02);
        a.update(0.08);  // at scale 1: 4x too slow, so half the width and height
        CHECK(a.scale() == doctest::Approx(0.5f));
        a.update(0.02);
        CHECK(a.scale() == doctest::Approx(0.5f));
    }
    TEST_CASE("adaptive resolution: the scale changes by the square root of the time ratio") {
        // Twice too slow: the pixels halve, so each side shrinks by 1/sqrt(2).
        AdaptiveResolution a(0.02);
        a.update(0.04);
        CHECK(a.scale() == doctest::Approx(std::sqrt(0.5)));
    }
    TEST_CASE("adaptive resolution: one slow frame changes the scale by at most a factor 2") {
        AdaptiveResolution a(0.02);
        a.update(2.0);  // 100 times too slow, once
        CHECK(a.scale() == doctest::Approx(0.5f));
    }
    TEST_CASE("hard case: adaptive resolution stays within its limits") {
        AdaptiveResolution a(0.03, 0.25f, 1.0f);
        for (int i = 0; i < 10; ++i) a.update(10.0);  // hopelessly slow
        CHECK(a.scale() == 0.25f);
        for (int i = 0; i < 10; ++i) a.update(1e-6);  // very fast
        CHECK(a.scale() == 1.0f);
        a.update(0.0);  // a zero or NaN time changes nothing
        {
            // The NaN is this check's input, not a result: comparing it (the guard's
            // `frameSeconds > 0`) raises FE_INVALID, as IEEE 754 says an ordered
            // comparison with NaN does.
            test::FpTrapsOff nanOnPurpose;
            a.update(std::nan(""));
        }
        CHECK(a.scale() == 1.0f);
    }
}

TEST_SUITE("program 05") {
    const std::string program = test::stepProgram();

    TEST_CASE("headless render writes the image and every preview") {
        test::TempDir dir;
        auto run = test::runHeadless(program, dir, 64, 40);
        for (const char* p : {"a-depth.png", "a-depth-material.png", "a-no-recursion.png",
                              "a-limited-recursion.png", "a-half-resolution.png", "a-adaptive.png"})
            CHECK(test::pngSize(dir.file(p)) == std::pair{64, 40});
        CHECK(run.err.find("bit-identical") != std::string::npos);
    }
    TEST_CASE("measurements: the JSON report has every lab table") {
        test::TempDir dir;
        auto run = test::runHeadless(program, dir, 32, 24,
                                     "--scene sh1 --measure --quick --repeats 1 --report r.json");
        test::checkReportTables(
            dir.file("r.json"),
            {"measuring", "float_double", "acne", "sincos", "early_out", "light_radius", "effects",
             "precalc", "expensive_ops", "rsqrt", "op_cost", "language", "threads", "antialiasing",
             "previews", "total", "effects_parts", "effects_identity"});
        test::checkVariantTables(
            dir.file("r.json"),
            {"float_double", "acne", "sincos", "early_out", "light_radius", "effects",
             "effects_parts", "precalc", "expensive_ops", "rsqrt", "op_cost", "language", "threads",
             "antialiasing", "previews", "total"});
        test::checkParetoPlot(dir.file("r.json"), "total");
        CHECK(run.out.find("table nearest 3600") != std::string::npos);
    }
    TEST_CASE("window: previews and refinement under the offscreen video driver") {
        test::TempDir dir;
        test::runWindowScript(program, dir, "--width 64 --height 48", 8, "1,2,Left,3,4,5,6,0");
    }
    TEST_CASE("window: the photograph is saved and its path printed") {
        test::TempDir dir;
        auto run =
            test::runWindowScript(program, dir, "--width 48 --height 36 --photo-spp 4", 40, "p");
        CHECK(run.out.find("photograph saved to 05_efficiency-photo-1.png") != std::string::npos);
        CHECK(test::pngSize(dir.file("05_efficiency-photo-1.png")) == std::pair{48, 36});
    }
    TEST_CASE("window: Escape cancels the photograph and does not quit") {
        test::TempDir dir;
        // The screenshot (checked by runWindowScript): the window ran to its last frame.
        auto run = test::runWindowScript(program, dir, "--width 320 --height 240 --photo-spp 64", 4,
                                         "p,Escape,1");
        CHECK(run.out.find("photograph cancelled") != std::string::npos);
        CHECK_FALSE(std::filesystem::exists(dir.file("05_efficiency-photo-1.png")));
    }
    TEST_CASE("bad input: one clear line and a non-zero exit") {
        test::TempDir dir;
        test::checkBadInput(program, dir,
                            {{"--scene missing.obj", "no such file", 1},
                             {"--scene nosuchscene", "unknown scene", 2},
                             {"--frobnicate", "frobnicate", 2},
                             {"--width 0", "width", 2},
                             {"--repeats 0", "repeats", 2},
                             {"--budget-ms 0", "budget", 2},
                             {"--eye 1,2,3 --look 1,2,3", "view direction is zero", 2}});
    }
}
