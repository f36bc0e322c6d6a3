// Exam questions with their exact numbers, answered by the core's routines and checked
// against values worked out by hand.
#include <cmath>

#include "core/math.hpp"
#include "core/scene.hpp"
#include "support.hpp"

using namespace boxes;
using test::checkVec;

TEST_SUITE("exam") {
    TEST_CASE("exam: vector fluency: dot and cross products and normalization and combinations") {
        Vec3d a(1, 2, 3), b(4, -5, 6);
        CHECK(glm::dot(a, b) == 12.0);                        // 4 - 10 + 18
        checkVec(glm::cross(a, b), Vec3d(27, 6, -13), 0.0);   // (12+15, 12-6, -5-8)
        checkVec(glm::cross(b, a), Vec3d(-27, -6, 13), 0.0);  // anti-commutative
        checkVec(glm::normalize(Vec3d(3, 4, 0)), Vec3d(0.6, 0.8, 0), 1e-15);
        checkVec(2.0 * a - 3.0 * b, Vec3d(-10, 19, -12), 0.0);
        CHECK(glm::dot(glm::cross(a, b), a) == 0.0);  // the cross product is orthogonal to both
        CHECK(glm::length(Vec3d(2, 3, 6)) == 7.0);
    }
    TEST_CASE("exam: virtual screen corners for fov 90 and aspect 2") {
        Camerad c;
        c.eye = Vec3d(0, 0, 0);
        c.view = Vec3d(0, 0, -1);
        c.up = Vec3d(0, 1, 0);
        c.fovYDegrees = 90.0;
        c.aspect = 2.0;
        // Half height tan(45) = 1 at distance 1, half width 2.
        auto s = c.screenCorners();
        checkVec(s.topLeft, Vec3d(-2, 1, -1), 1e-12);
        checkVec(s.topRight, Vec3d(2, 1, -1), 1e-12);
        checkVec(s.bottomLeft, Vec3d(-2, -1, -1), 1e-12);
        checkVec(s.bottomRight, Vec3d(2, -1, -1), 1e-12);
    }
    TEST_CASE(
        "exam: screen corners from eye (1 1 1) looking along (1 0 1) with fov 60 and aspect 4/3") {
        Camerad c;
        c.eye = Vec3d(1, 1, 1);
        c.view = Vec3d(1, 0, 1);
        c.fovYDegrees = 60.0;
        c.aspect = 4.0 / 3.0;
        // w = (1,0,1)/sqrt2, right = w x up = (-1,0,1)/sqrt2, up' = right x w = (0,1,0);
        // half height h = tan 30 = 1/sqrt3, half width 4/(3 sqrt3).
        double r2 = std::sqrt(2.0), h = 1.0 / std::sqrt(3.0), w = 4.0 / (3.0 * std::sqrt(3.0));
        Vec3d centre(1 + 1 / r2, 1, 1 + 1 / r2), right(-1 / r2, 0, 1 / r2), up(0, 1, 0);
        auto b = c.basis();
        checkVec(b.right, right, 1e-15);
        checkVec(b.up, up, 1e-15);
        auto s = c.screenCorners();
        checkVec(s.topLeft, centre - w * right + h * up, 1e-12);
        checkVec(s.bottomRight, centre + w * right - h * up, 1e-12);
        // Numerically: top-left = (1.707107 + 0.544331, 1 + 0.577350, 1.707107 - 0.544331).
        checkVec(s.topLeft, Vec3d(2.251438, 1.577350, 1.162776), 1e-6);
    }
    TEST_CASE("exam: a primary ray's normalized direction") {
        Camerad c;
        c.fovYDegrees = 90.0;
        c.aspect = 1.0;
        // 2x2 image: pixel (0,0) has its centre at (0.5, 0.5) -> screen point (-0.5, 0.5, -1).
        Rayd r = c.primaryRay(0, 0, 2, 2);
        checkVec(r.direction, Vec3d(-0.5, 0.5, -1) / std::sqrt(1.5), 1e-15);
        checkVec(r.origin, Vec3d(0), 0.0);
        // The centre pixel of an odd image looks straight along the view.
        checkVec(c.primaryRay(1, 1, 3, 3).direction, Vec3d(0, 0, -1), 1e-15);
    }
    TEST_CASE("exam: the worked example: leaving the sphere |p - C| = sqrt(20)") {
        // E = (1,1,1), V = (1,0,1), C = (-1,1,-1): E is inside (|E - C|^2 = 8 < 20), so the
        // ray leaves the sphere at P = (sqrt10 - 1, 1, sqrt10 - 1), t = sqrt10 - 2.
        Rayd ray({1, 1, 1}, {1, 0, 1});
        SphereT<double> s{{-1, 1, -1}, std::sqrt(20.0)};
        auto t = intersectSphere(ray, s);
        REQUIRE(t.has_value());
        double r10 = std::sqrt(10.0);
        CHECK(*t == doctest::Approx(r10 - 2.0).epsilon(1e-14));
        Vec3d p = ray.at(*t);
        checkVec(p, Vec3d(r10 - 1, 1, r10 - 1), 1e-14);
        // The normal there pointing to the inside: -(P - C)/r = (-1,0,-1)/sqrt2.
        Vec3d inward = -(p - s.centre) / s.radius;
        checkVec(inward, Vec3d(-1, 0, -1) / std::sqrt(2.0), 1e-14);
        // Both roots: the entry lies behind the eye.
        double t0, t1;
        REQUIRE(sphereRoots(ray, s, t0, t1));
        CHECK(t0 == doctest::Approx(-r10 - 2.0));
        CHECK(t1 == doctest::Approx(r10 - 2.0));
    }
    TEST_CASE("exam: the worked example: the planes x + z = 10 and -x - z = 10") {
        Rayd ray({1, 1, 1}, {1, 0, 1});
        auto t = intersectPlane(ray, PlaneT<double>{{1, 0, 1}, -10});
        REQUIRE(t.has_value());
        checkVec(ray.at(*t), Vec3d(5, 1, 5), 1e-14);
        // -x - z = 10: t = -6, behind the eye, so no hit for t >= 0.
        Rayd line({1, 1, 1}, {1, 0, 1}, -kInfinity<double>, kInfinity<double>);
        CHECK(*intersectPlane(line, PlaneT<double>{{-1, 0, -1}, -10}) == doctest::Approx(-6.0));
        CHECK_FALSE(intersectPlane(ray, PlaneT<double>{{-1, 0, -1}, -10}).has_value());
    }
    TEST_CASE("exam: ray/sphere from outside: entry point and outward normal") {
        // From (0,0,5) towards the unit sphere at the origin: enters at (0,0,1), t = 4.
        Rayd ray({0, 0, 5}, {0, 0, -1});
        auto t = intersectSphere(ray, SphereT<double>{{0, 0, 0}, 1.0});
        REQUIRE(t.has_value());
        CHECK(*t == 4.0);
        // Missing by a hair: the line x = 1.0000001 passes outside.
        CHECK_FALSE(
            intersectSphere(Rayd({1.0000001, 0, 5}, {0, 0, -1}), SphereT<double>{{0, 0, 0}, 1.0}));
    }
    TEST_CASE("exam: reflection direction") {
        Vec3d d = glm::normalize(Vec3d(1, -1, 0)), n(0, 1, 0);
        checkVec(reflect(d, n), glm::normalize(Vec3d(1, 1, 0)), 1e-15);
        checkVec(reflect(Vec3d(0, -1, 0), n), Vec3d(0, 1, 0), 0.0);  // head-on: straight back
    }
    TEST_CASE("exam: refraction with Snell's law from air to glass at 45 degrees") {
        double s45 = std::sqrt(0.5);
        Vec3d d(s45, -s45, 0), n(0, 1, 0), t;
        REQUIRE(refract(d, n, 1.0 / 1.5, t));
        // sin(theta_t) = sin45 / 1.5 = 0.471405; cos = sqrt(1 - 2/9) = 0.881917.
        checkVec(t, Vec3d(s45 / 1.5, -std::sqrt(1.0 - 0.5 / 2.25), 0), 1e-15);
        CHECK(glm::length(t) == doctest::Approx(1.0));
    }
    TEST_CASE("exam: total internal reflection from glass to air beyond the critical angle") {
        // Critical angle asin(1/1.5) = 41.81 degrees: 45 degrees is beyond it.
        double s45 = std::sqrt(0.5);
        Vec3d t;
        CHECK_FALSE(refract(Vec3d(s45, -s45, 0), Vec3d(0, 1, 0), 1.5, t));
        double critical = std::asin(1.0 / 1.5);
        Vec3d below(std::sin(critical - 0.01), -std::cos(critical - 0.01), 0);
        CHECK(refract(below, Vec3d(0, 1, 0), 1.5, t));
        CHECK(fresnelDielectric(std::cos(glm::radians(45.0)), 1.5, 1.0) == 1.0);
    }
    TEST_CASE("exam: Fresnel with Schlick's approximation") {
        // R0 = ((1 - 1.5)/(1 + 1.5))^2 = 0.04; grazing: 1.
        CHECK(fresnelSchlick(1.0, 1.0, 1.5) == doctest::Approx(0.04));
        CHECK(fresnelSchlick(0.0, 1.0, 1.5) == doctest::Approx(1.0));
        // At 60 degrees: 0.04 + 0.96 * 0.5^5 = 0.07.
        CHECK(fresnelSchlick(0.5, 1.0, 1.5) == doctest::Approx(0.07));
        // The exact Fresnel value at normal incidence is R0 as well.
        CHECK(fresnelDielectric(1.0, 1.0, 1.5) == doctest::Approx(0.04));
    }
}
