// Hard cases of the core, each named: rays, the camera basis.
#include "core/camera.hpp"
#include "core/ray.hpp"
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
