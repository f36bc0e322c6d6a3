// Hard cases of the core, each named: rays, the camera basis, spheres and planes.
#include <cmath>
#include <random>

#include "core/math.hpp"
#include "core/render.hpp"
#include "core/scene.hpp"
#include "support.hpp"

using namespace boxes;

TEST_SUITE("hard cases") {
    TEST_CASE("hard case: a ray with a zero or NaN direction is an error") {
        CHECK_THROWS_WITH_AS(Ray(Vec3(0), Vec3(0)), "ray direction is zero", std::invalid_argument);
        CHECK_THROWS_WITH_AS(Ray(Vec3(0), Vec3(-0.0f, 0.0f, -0.0f)), "ray direction is zero",
                             std::invalid_argument);
        CHECK_THROWS_AS(Ray(Vec3(0), Vec3(std::nanf(""), 1, 0)), std::invalid_argument);
        CHECK_THROWS_AS(Rayd(Vec3d(0), Vec3d(1, INFINITY, 0)), std::invalid_argument);
        CHECK_NOTHROW(Ray(Vec3(0), Vec3(0, -0.0f, 1e-30f)));
    }
    TEST_CASE("hard case: the camera basis when the view is parallel to up") {
        for (Vec3d view : {Vec3d(0, 1, 0), Vec3d(0, -3, 0), Vec3d(0, 1e-20, 0)}) {
            Camerad c;
            c.view = view;
            c.up = Vec3d(0, 1, 0);
            auto b = c.basis();
            INFO("view " << view.y);
            CHECK(isFinite(b.right));
            CHECK(isFinite(b.up));
            CHECK(glm::length(b.right) == doctest::Approx(1.0));
            CHECK(glm::length(b.up) == doctest::Approx(1.0));
            CHECK(glm::dot(b.right, b.up) == doctest::Approx(0.0));
            CHECK(glm::dot(b.right, b.forward) == doctest::Approx(0.0));
            // Right-handed: right x up = -forward (the camera looks down its -z).
            test::checkVec(glm::cross(b.right, b.up), -b.forward, 1e-12);
            auto corners = c.screenCorners();
            CHECK(isFinite(corners.topLeft));
        }
    }
    TEST_CASE("hard case: a camera with a zero view or up vector is refused") {
        Camera c;
        c.view = Vec3(0);
        CHECK_THROWS_AS(c.basis(), std::invalid_argument);
        c.view = Vec3(0, 0, -1);
        c.up = Vec3(0);
        CHECK_THROWS_AS(c.basis(), std::invalid_argument);
        c.up = Vec3(0, 1, 0);
        c.fovYDegrees = 180.0f;
        CHECK_THROWS_AS(c.basis(), std::invalid_argument);
    }
}

// Spheres and planes (core/math.hpp). Each case says which safeguard it guards.
TEST_SUITE("hard cases") {
    TEST_CASE("hard case: a sphere or plane hit exactly at t == tmin counts (closed interval)") {
        // Unit sphere, ray from z = 5 down: the roots are exactly 4 (entry) and 6 (exit).
        const Sphere unit;
        Ray down(Vec3(0.0f, 0.0f, 5.0f), Vec3(0.0f, 0.0f, -1.0f));
        down.tmin = 4.0f;
        CHECK(intersectSphere(down, unit) == std::optional<float>(4.0f));  // the entry, not 6
        down.tmin = 6.0f;
        CHECK(intersectSphere(down, unit) == std::optional<float>(6.0f));  // the exit
        down.tmin = nextFloatUp(6.0f);
        CHECK_FALSE(intersectSphere(down, unit));
        // The plane y = 0 from y = 2: t = 2 exactly.
        const Plane ground{{0.0f, 1.0f, 0.0f}, 0.0f};
        Ray fall(Vec3(0.3f, 2.0f, -1.0f), Vec3(0.0f, -1.0f, 0.0f), 2.0f);
        CHECK(intersectPlane(fall, ground) == std::optional<float>(2.0f));
        fall.tmin = nextFloatUp(2.0f);
        CHECK_FALSE(intersectPlane(fall, ground));
    }
    TEST_CASE("hard case: spheres 1e4 and 1e5 from the origin are hit and missed as in double") {
        // The textbook discriminant b^2 - ac subtracts two numbers near distance^2 = 1e10,
        // whose float spacing (1024) swamps r^2 = 1: hits and misses become noise. The
        // discriminant r^2 - |f - (f.d)d|^2 (Haines et al. 2019) keeps them.
        std::mt19937_64 rng(3);
        std::uniform_real_distribution<double> u01(0.0, 1.0);
        for (double distance : {1e4, 1e5}) {
            const SphereT<double> exact{Vec3d(0.3 * distance, -0.2 * distance, -distance), 1.0};
            const Sphere sphere{Vec3(exact.centre), 1.0f};
            const Vec3d centre(sphere.centre);  // the float sphere, widened
            int hits = 0, wrong = 0;
            for (int i = 0; i < 2000; ++i) {
                // Aim at the sphere's disc seen from the origin, out to 1.2 radii, but not
                // within 1% of the silhouette (where float rounding may decide either way).
                double angle = 2.0 * kPi * u01(rng), r = 1.2 * std::sqrt(u01(rng));
                if (std::abs(r - 1.0) < 0.01) continue;
                Vec3d side = glm::normalize(glm::cross(centre, Vec3d(0, 1, 0)));
                Vec3d up = glm::normalize(glm::cross(side, centre));
                Vec3d target = centre + r * (std::cos(angle) * side + std::sin(angle) * up);
                Ray ray(Vec3(0.0f), Vec3(glm::normalize(target)));
                auto t = intersectSphere(ray, sphere);
                auto tRef = intersectSphere(ray.as<double>(), SphereT<double>{centre, 1.0});
                if (t.has_value() != tRef.has_value()) ++wrong;
                if (t && tRef) {
                    ++hits;
                    CHECK(std::abs(double(*t) - *tRef) < 1e-6 * distance);
                }
            }
            INFO("distance " << distance << ": " << hits << " hits");
            CHECK(hits > 1000);
            CHECK(wrong == 0);
        }
    }
    TEST_CASE("hard case: a ray touching a sphere tangentially hits it once at the tangent point") {
        // From (-5, 1, 0) along +x the unit sphere's discriminant is exactly 0: one root,
        // t = 5. A strict test (disc <= 0 a miss) drops it.
        const Sphere unit;
        float t0 = -1.0f, t1 = -1.0f;
        REQUIRE(sphereRoots(Ray(Vec3(-5.0f, 1.0f, 0.0f), Vec3(1.0f, 0.0f, 0.0f)), unit, t0, t1));
        CHECK(t0 == 5.0f);
        CHECK(t1 == 5.0f);
        CHECK(intersectSphere(Ray(Vec3(-5.0f, 1.0f, 0.0f), Vec3(1.0f, 0.0f, 0.0f)), unit) ==
              std::optional<float>(5.0f));
        // Just outside: a miss.
        CHECK_FALSE(intersectSphere(Ray(Vec3(-5.0f, 1.001f, 0.0f), Vec3(1.0f, 0.0f, 0.0f)), unit));
    }
    TEST_CASE("hard case: a ray starting on a sphere finds the far side or nothing") {
        // From the surface point (0, 0, 1): c = |f|^2 - r^2 = 0, so the near root c / q is
        // exactly 0 (the start point: a hit at tmin = 0, closed interval) and the far root
        // 2. Starting at the tangent point along the tangent, q = 0 and c / q would be 0 / 0
        // = NaN: the roots are both 0 instead.
        const Sphere unit;
        const Vec3 top(0.0f, 0.0f, 1.0f);
        float t0 = -1.0f, t1 = -1.0f;
        REQUIRE(sphereRoots(Ray(top, Vec3(0.0f, 0.0f, -1.0f)), unit, t0, t1));
        CHECK(t0 == 0.0f);
        CHECK(t1 == 2.0f);
        CHECK(intersectSphere(Ray(top, Vec3(0.0f, 0.0f, -1.0f)), unit) ==
              std::optional<float>(0.0f));
        CHECK(intersectSphere(Ray(top, Vec3(0.0f, 0.0f, -1.0f), 1e-4f), unit) ==
              std::optional<float>(2.0f));
        CHECK_FALSE(intersectSphere(Ray(top, Vec3(0.0f, 0.3f, 1.0f), 1e-4f), unit));  // leaving
        REQUIRE(sphereRoots(Ray(top, Vec3(1.0f, 0.0f, 0.0f)), unit, t0, t1));  // tangent start
        CHECK(t0 == 0.0f);
        CHECK(t1 == 0.0f);
        CHECK_FALSE(intersectSphere(Ray(top, Vec3(1.0f, 0.0f, 0.0f), 1e-4f), unit));
        // A start point on a far sphere (1e5 away), inwards through the centre: the far
        // side at 2r, within float's spacing there.
        const Sphere far{{1e5f, 0.0f, 0.0f}, 10.0f};
        auto t =
            intersectSphere(Ray(Vec3(1e5f - 10.0f, 0.0f, 0.0f), Vec3(1.0f, 0.0f, 0.0f), 1.0f), far);
        REQUIRE(t.has_value());
        CHECK(*t == doctest::Approx(20.0).epsilon(1e-3));
    }
}

TEST_SUITE("hard cases") {
    TEST_CASE("hard case: no self-intersection acne on spheres at scene scales 1 to 1e5") {
        // A sphere facing the light cannot shadow itself (convex): a shadow ray from the
        // renderer's offset origin that hits it again is acne. The offset grows with the
        // coordinates (offsetOrigin); a fixed one falls below float's spacing at 1e5.
        for (float scale : {1.0f, 10.0f, 100.0f, 1e3f, 1e4f, 1e5f}) {
            const Sphere sphere{Vec3(0.2f, -0.1f, -3.0f) * scale, scale};
            const Vec3 light = Vec3(5.0f, 5.0f, 5.0f) * scale;
            int lit = 0, acne = 0;
            for (int y = 0; y < 40; ++y)
                for (int x = 0; x < 40; ++x) {
                    Vec3 d = sphere.centre +
                             scale * Vec3((x - 19.5f) / 20.0f, (y - 19.5f) / 20.0f, 0.0f);
                    Ray ray(Vec3(0.0f), d);
                    auto t = intersectSphere(ray, sphere);
                    if (!t) continue;
                    Vec3 p = ray.at(*t), n = glm::normalize(p - sphere.centre), toLight = light - p;
                    if (glm::dot(n, toLight) <= 0.0f) continue;
                    ++lit;
                    Ray shadow(offsetOrigin(p, n, toLight), toLight, 0.0f, 1.0f);
                    acne += intersectSphere(shadow, sphere).has_value();
                }
            INFO("scale " << scale << ": " << lit << " lit points");
            CHECK(lit > 300);
            CHECK(acne == 0);
        }
    }
}
