// Step 01: the exercises with hand-worked numbers, the hard cases by name, and the program.
#include <cmath>
#include <random>

#include "01_triangle/measure.hpp"
#include "01_triangle/triangle.hpp"
#include "01_triangle/triangle_grid.hpp"
#include "core/render.hpp"
#include "core/scene.hpp"
#include "support.hpp"

using namespace boxes;
using boxes::test::checkVec;

namespace {

// The unit right triangle in the z = 0 plane and its neighbour across the hypotenuse.
const Triangled kUnit{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
const Triangled kUnitNeighbour{{1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
// The triangle that cuts the three axes at 1.
const Triangled kDiagonal{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};

template <typename T>
TriangleT<T> cast(const Triangled& t) {
    return {Vec3T<T>(t.a), Vec3T<T>(t.b), Vec3T<T>(t.c)};
}

}  // namespace

TEST_SUITE("exercise 1.1") {
    TEST_CASE("triangle plane: normal from the cross product and d") {
        auto p = trianglePlane(kUnit);
        REQUIRE(p.has_value());
        checkVec(p->normal, Vec3d(0, 0, 1), 1e-15);
        CHECK(p->d == 0.0);
        // x + y + z = 1: N = (1,1,1)/sqrt(3), d = -1/sqrt(3).
        auto q = trianglePlane(kDiagonal);
        REQUIRE(q.has_value());
        double s = 1.0 / std::sqrt(3.0);
        checkVec(q->normal, Vec3d(s, s, s), 1e-15);
        CHECK(q->d == doctest::Approx(-s));
        // The winding decides the side: reversed winding, reversed normal.
        auto r = trianglePlane(Triangled{kUnit.a, kUnit.c, kUnit.b});
        REQUIRE(r.has_value());
        checkVec(r->normal, Vec3d(0, 0, -1), 1e-15);
    }
    TEST_CASE("triangle plane: in float the same numbers") {
        auto q = trianglePlane(cast<float>(kDiagonal));
        REQUIRE(q.has_value());
        float s = 1.0f / std::sqrt(3.0f);
        checkVec(q->normal, Vec3(s), 1e-6);
        CHECK(q->d == doctest::Approx(-s).epsilon(1e-6));
    }
    TEST_CASE("triangle plane: d puts the triangle's own vertices on the plane") {
        // N.P + d = 0 at every vertex, for a plane away from the origin.
        const Triangled t{{1, 0, 2}, {3, 1, 2}, {0, 4, 5}};
        auto p = trianglePlane(t);
        REQUIRE(p.has_value());
        for (const Vec3d& v : {t.a, t.b, t.c}) {
            INFO("vertex " << v);
            CHECK(std::abs(glm::dot(p->normal, v) + p->d) < 1e-12);
        }
    }
    TEST_CASE("triangle plane: the normal has unit length") {
        // The cross product of these edges is (0, 0, 6): divided by its length.
        auto p = trianglePlane(Triangled{{0, 0, 2}, {2, 0, 2}, {0, 3, 2}});
        REQUIRE(p.has_value());
        checkVec(p->normal, Vec3d(0, 0, 1), 1e-15);
        CHECK(p->d == doctest::Approx(-2.0));
    }
    TEST_CASE("hard case: a degenerate triangle has no plane") {
        CHECK_FALSE(trianglePlane(Triangled{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}}).has_value());
        CHECK_FALSE(trianglePlane(Triangled{{1, 2, 3}, {1, 2, 3}, {4, 5, 6}}).has_value());
        CHECK_FALSE(trianglePlane(Triangle{{1, 2, 3}, {1, 2, 3}, {1, 2, 3}}).has_value());
    }
}

TEST_SUITE("exercise 1.2") {
    TEST_CASE("ray/plane distance: worked examples") {
        // z = 0 seen from (0,0,5) looking down: t = 5.
        auto t = rayPlaneDistance(Rayd({0, 0, 5}, {0, 0, -1}), PlaneT<double>{{0, 0, 1}, 0});
        REQUIRE(t.has_value());
        CHECK(*t == 5.0);
        // The exam's plane x + z = 10 from E = (1,1,1) along V = (1,0,1): t = 4, P = (5,1,5).
        Rayd ray({1, 1, 1}, {1, 0, 1});
        auto t2 = rayPlaneDistance(ray, PlaneT<double>{{1, 0, 1}, -10});
        REQUIRE(t2.has_value());
        CHECK(*t2 == doctest::Approx(4.0));
        checkVec(ray.at(*t2), Vec3d(5, 1, 5), 1e-12);
    }
    TEST_CASE("hard case: ray/plane parallel or in the plane and the sign of t") {
        PlaneT<double> z0{{0, 0, 1}, 0};
        CHECK_FALSE(rayPlaneDistance(Rayd({0, 0, 1}, {1, 0, 0}), z0).has_value());  // parallel
        CHECK_FALSE(rayPlaneDistance(Rayd({0, 0, 0}, {1, 1, 0}), z0).has_value());  // in plane
        // -x - z = 10 lies behind the eye: t = -6, negative, and still reported.
        auto behind =
            rayPlaneDistance(Rayd({1, 1, 1}, {1, 0, 1}), PlaneT<double>{{-1, 0, -1}, -10});
        REQUIRE(behind.has_value());
        CHECK(*behind == doctest::Approx(-6.0));
        // Float, -0.0 in the direction: still parallel.
        CHECK_FALSE(rayPlaneDistance(Ray({0, 0, 1}, {1, 0, -0.0f}), PlaneT<float>{{0, 0, 1}, 0})
                        .has_value());
    }
}

TEST_SUITE("exercise 1.2") {
    TEST_CASE("ray/plane distance: a plane behind the origin has a negative t") {
        // The distance along the line, not a hit: z = 0 from (0, 0, 3) looking up is t = -3.
        auto t = rayPlaneDistance(Rayd({0, 0, 3}, {0, 0, 1}), PlaneT<double>{{0, 0, 1}, 0});
        REQUIRE(t.has_value());
        CHECK(*t == -3.0);
    }
}

TEST_SUITE("exercise 1.3") {
    TEST_CASE(
        "inside test: a ray exactly through a shared edge is inside one of the two triangles") {
        // Straight down onto points of the shared hypotenuse: that edge's volume is exactly
        // zero, which is on the edge, inside.
        const Triangle a = cast<float>(kUnit), b = cast<float>(kUnitNeighbour);
        for (float s : {0.25f, 0.5f, 0.75f}) {
            Ray ray(Vec3(1.0f - s, s, 1.0f), Vec3(0, 0, -1));
            INFO("through " << ray.at(1.0f));
            CHECK((insideEdgePlanes(ray, a) || insideEdgePlanes(ray, b)));
        }
    }
    TEST_CASE("inside test: seen from either side of the triangle") {
        // From above the three volumes are negative, from below positive: both inside.
        for (double z : {1.0, -1.0}) {
            INFO("origin at z = " << z);
            auto uv = insideEdgePlanes(Rayd({0.5, 0.25, z}, {0, 0, -z}), kUnit);
            REQUIRE(uv.has_value());
            CHECK(uv->x == doctest::Approx(0.5));
            CHECK(uv->y == doctest::Approx(0.25));
        }
    }
    TEST_CASE("inside test: barycentrics of a worked point") {
        // (0.25, 0.25, 1) straight down: the three edge volumes are -0.5, -0.25, -0.25.
        auto uv = insideEdgePlanes(Rayd({0.25, 0.25, 1}, {0, 0, -1}), kUnit);
        REQUIRE(uv.has_value());
        CHECK(uv->x == doctest::Approx(0.25));
        CHECK(uv->y == doctest::Approx(0.25));
        // Seen from below the signs flip together: still inside.
        auto below = insideEdgePlanes(Rayd({0.25, 0.25, -1}, {0, 0, 1}), kUnit);
        REQUIRE(below.has_value());
        CHECK(below->x == doctest::Approx(0.25));
        CHECK_FALSE(insideEdgePlanes(Rayd({1, 1, 1}, {0, 0, -1}), kUnit).has_value());
        CHECK_FALSE(insideEdgePlanes(Rayd({-0.1, 0.5, 1}, {0, 0, -1}), kUnit).has_value());
    }
    TEST_CASE(
        "hard case: the inside test accepts a ray through a shared edge in one of the two "
        "triangles") {
        // The two triangles compute the same edge volume with opposite signs, so in float
        // a ray aimed at the shared edge is inside one of them (or both), never neither.
        std::mt19937_64 rng(13);
        std::uniform_real_distribution<float> u01(0.0f, 1.0f);
        const Triangle a = cast<float>(kUnit), b = cast<float>(kUnitNeighbour);
        for (int i = 0; i < 20000; ++i) {
            float s = 0.05f + 0.9f * u01(rng);  // away from the ends (vertices are harder)
            Vec3 target(1.0f - s, s, 0.0f);
            Vec3 origin(u01(rng) * 4 - 2, u01(rng) * 4 - 2, 0.5f + u01(rng) * 3);
            Ray ray(origin, target - origin);
            INFO("ray " << i);
            REQUIRE((insideEdgePlanes(ray, a) || insideEdgePlanes(ray, b)));
        }
    }
}

// The three full tests must agree on these worked numbers.
template <typename Real>
void checkWorkedHits(TriangleTest test) {
    INFO(std::string(triangleTestName(test))
         << std::string(sizeof(Real) == 4 ? " in float" : " in double"));
    RayT<Real> down({Real(0.2), Real(0.3), Real(2)}, {0, 0, -1});
    auto h = intersectTriangle(test, down, cast<Real>(kUnit));
    REQUIRE(h.has_value());
    CHECK(double(h->t) == doctest::Approx(2.0).epsilon(1e-6));
    CHECK(double(h->u) == doctest::Approx(0.2).epsilon(1e-6));
    CHECK(double(h->v) == doctest::Approx(0.3).epsilon(1e-6));
    // From the origin along (1,1,1): the centroid (1/3,1/3,1/3), t = 1/3, u = v = 1/3.
    RayT<Real> diag({0, 0, 0}, {1, 1, 1});
    auto g = intersectTriangle(test, diag, cast<Real>(kDiagonal));
    REQUIRE(g.has_value());
    CHECK(double(g->t) == doctest::Approx(1.0 / 3.0).epsilon(1e-6));
    CHECK(double(g->u) == doctest::Approx(1.0 / 3.0).epsilon(1e-6));
    CHECK(double(g->v) == doctest::Approx(1.0 / 3.0).epsilon(1e-6));
    // Outside, behind, and beyond tmax: misses.
    const auto tri = cast<Real>(kUnit);
    CHECK_FALSE(intersectTriangle(test, RayT<Real>({1, 1, 2}, {0, 0, -1}), tri));
    CHECK_FALSE(intersectTriangle(test, RayT<Real>({Real(0.2), Real(0.2), -1}, {0, 0, -1}), tri));
    CHECK_FALSE(intersectTriangle(
        test, RayT<Real>({Real(0.2), Real(0.2), 2}, {0, 0, -1}, 0, Real(1.5)), tri));
    // Closed interval: a hit exactly at tmax counts.
    CHECK(intersectTriangle(test, RayT<Real>({Real(0.25), Real(0.25), 2}, {0, 0, -1}, 0, Real(2)),
                            tri));
}

// Hard cases every full test must pass; `exact` tests must also close every crack.
void checkHardCases(TriangleTest test) {
    INFO(std::string(triangleTestName(test)));
    SUBCASE("hard case: a degenerate triangle misses without NaN") {
        for (const Triangled& t : {Triangled{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}},
                                   Triangled{{0, 0, 0}, {0, 0, 0}, {0, 1, 0}},
                                   Triangled{{1, 1, 0}, {1, 1, 0}, {1, 1, 0}}}) {
            CHECK_FALSE(intersectTriangle(test, Rayd({0.5, 0, 1}, {0, 0, -1}), t));
            CHECK_FALSE(intersectTriangle(test, Rayd({1, 1, 1}, {0, 0, -1}), t));
            CHECK_FALSE(intersectTriangle(test, Ray({1, 1, 1}, {0, 0, -1}), cast<float>(t)));
        }
    }
    SUBCASE("hard case: a ray parallel to the plane, and one inside it, miss") {
        CHECK_FALSE(intersectTriangle(test, Rayd({0.2, 0.2, 1}, {1, 0, 0}), kUnit));
        CHECK_FALSE(intersectTriangle(test, Rayd({-1, 0.25, 0}, {1, 0, 0}), kUnit));
        CHECK_FALSE(
            intersectTriangle(test, Ray({-1, 0.25f, 0}, {1, 0, -0.0f}), cast<float>(kUnit)));
    }
    SUBCASE("hard case: the scene scaled by 2^k, k in [-20, 20], keeps its hits") {
        std::mt19937_64 rng(7);
        std::uniform_real_distribution<double> u01(0.0, 1.0);
        for (int i = 0; i < 50; ++i) {
            Vec3d o(u01(rng) - 0.5, u01(rng) - 0.5, 2.0 + u01(rng));
            Vec3d target(0.6 * u01(rng), 0.6 * u01(rng), 0.0);
            Ray base(Vec3(o), Vec3(target - o));
            auto h0 = intersectTriangle(test, base, cast<float>(kDiagonal));
            for (int k = -20; k <= 20; ++k) {
                float s = std::ldexp(1.0f, k);
                Triangle t{cast<float>(kDiagonal).a * s, cast<float>(kDiagonal).b * s,
                           cast<float>(kDiagonal).c * s};
                auto h = intersectTriangle(test, Ray(base.origin * s, base.direction), t);
                INFO("k = " << k);
                REQUIRE(h.has_value() == h0.has_value());
                if (h) CHECK(std::abs(double(h->t) / (double(h0->t) * s) - 1.0) < 1e-6);
            }
        }
    }
}

template <TriangleTest X>
using TestKind = std::integral_constant<TriangleTest, X>;

// The lecture's whole test needs 1.1, 1.2 and 1.3 together, so it is checked outside the
// exercises' suites (a grade counts each exercise on its own tests).
TEST_SUITE("plane test combined") {
    TEST_CASE("plane test put together: t and u and v") {
        auto h = intersectPlaneTest(Rayd({0.2, 0.3, 2}, {0, 0, -1}), kUnit);
        REQUIRE(h.has_value());
        CHECK(h->t == doctest::Approx(2.0));
        CHECK(h->u == doctest::Approx(0.2));
        CHECK(h->v == doctest::Approx(0.3));
    }
    TEST_CASE("plane test: the worked hits in float and double") {
        checkWorkedHits<float>(TriangleTest::PlaneTest);
        checkWorkedHits<double>(TriangleTest::PlaneTest);
    }
    TEST_CASE("plane test: hard cases") {
        checkHardCases(TriangleTest::PlaneTest);
    }
}

TEST_SUITE("exercise 1.4") {
    TEST_CASE("Moller-Trumbore: the worked hits in float and double") {
        checkWorkedHits<float>(TriangleTest::MollerTrumbore);
        checkWorkedHits<double>(TriangleTest::MollerTrumbore);
    }
    TEST_CASE("Moller-Trumbore: hard cases") {
        checkHardCases(TriangleTest::MollerTrumbore);
    }
    TEST_CASE("Moller-Trumbore: a determinant that overflows float is no hit at t = 0") {
        // An edge 3e38 long: det = -6e38, -inf in float, and 1 / det = -0 would make u, v
        // and t all zero, a hit at the origin. The ray starts 0.1 above the triangle's plane
        // (z = 0) and leaves it: a miss, as in double (t = -0.1 there).
        const Triangled huge{{0, 0, 0}, {3e38, 0, 0}, {0, 2, 0}};
        CHECK_FALSE(intersectMollerTrumbore(Ray({0, 0.1f, 0.1f}, {0, 0, 1}), cast<float>(huge)));
        CHECK_FALSE(intersectMollerTrumbore(Rayd({0, 0.1, 0.1}, {0, 0, 1}), huge));
    }
    TEST_CASE("Moller-Trumbore: a point past the first edge (u < 0) is a miss") {
        // Straight down at (-0.2, 0.5): u = -0.2, v = 0.5, u + v <= 1.
        CHECK_FALSE(intersectMollerTrumbore(Rayd({-0.2, 0.5, 1}, {0, 0, -1}), kUnit));
        CHECK_FALSE(intersectMollerTrumbore(Ray({-0.2f, 0.5f, 1}, {0, 0, -1}), cast<float>(kUnit)));
    }
    TEST_CASE("Moller-Trumbore: a point past the second edge (v < 0) is a miss") {
        // Straight down at (0.5, -0.2): u = 0.5, v = -0.2, u + v <= 1.
        CHECK_FALSE(intersectMollerTrumbore(Rayd({0.5, -0.2, 1}, {0, 0, -1}), kUnit));
        CHECK_FALSE(intersectMollerTrumbore(Ray({0.5f, -0.2f, 1}, {0, 0, -1}), cast<float>(kUnit)));
    }
    TEST_CASE("Moller-Trumbore: a point past the third edge (u + v > 1) is a miss") {
        // Straight down at (0.6, 0.6): u and v in [0, 1], u + v = 1.2.
        CHECK_FALSE(intersectMollerTrumbore(Rayd({0.6, 0.6, 1}, {0, 0, -1}), kUnit));
        CHECK_FALSE(intersectMollerTrumbore(Ray({0.6f, 0.6f, 1}, {0, 0, -1}), cast<float>(kUnit)));
    }
    TEST_CASE("Moller-Trumbore: a point on an edge (u = 0 or v = 0) is a hit") {
        // The triangle is closed: (0, 0.5) has u = 0, (0.5, 0) has v = 0, exactly.
        auto onU = intersectMollerTrumbore(Rayd({0, 0.5, 1}, {0, 0, -1}), kUnit);
        REQUIRE(onU.has_value());
        CHECK(onU->u == 0.0);
        auto onV = intersectMollerTrumbore(Rayd({0.5, 0, 1}, {0, 0, -1}), kUnit);
        REQUIRE(onV.has_value());
        CHECK(onV->v == 0.0);
    }
    TEST_CASE("Moller-Trumbore: the back of the triangle is hit too (no culling)") {
        // From below, against the winding: det < 0, and still t = 2, u = 0.2, v = 0.3.
        auto h = intersectMollerTrumbore(Rayd({0.2, 0.3, -2}, {0, 0, 1}), kUnit);
        REQUIRE(h.has_value());
        CHECK(h->t == doctest::Approx(2.0));
        CHECK(h->u == doctest::Approx(0.2));
        CHECK(h->v == doctest::Approx(0.3));
    }
    TEST_CASE("Moller-Trumbore: a triangle behind the origin (t < tmin) is a miss") {
        // The line meets the triangle at t = -1.
        CHECK_FALSE(intersectMollerTrumbore(Rayd({0.2, 0.2, -1}, {0, 0, -1}), kUnit));
        // A segment starting past the triangle: t = 2 < tmin = 3.
        CHECK_FALSE(intersectMollerTrumbore(Rayd({0.2, 0.2, 2}, {0, 0, -1}, 3.0), kUnit));
    }
}

TEST_SUITE("exercise 1.5") {
    TEST_CASE("watertight: the worked hits in float and double") {
        checkWorkedHits<float>(TriangleTest::Watertight);
        checkWorkedHits<double>(TriangleTest::Watertight);
    }
    TEST_CASE("watertight: hard cases") {
        checkHardCases(TriangleTest::Watertight);
    }
    TEST_CASE("watertight: the back of the triangle is hit too (no culling)") {
        // From below the edge functions are all negative: still a hit, t = 2.
        auto h = intersectWatertight(Rayd({0.2, 0.3, -2}, {0, 0, 1}), kUnit);
        REQUIRE(h.has_value());
        CHECK(h->t == doctest::Approx(2.0));
        CHECK(h->u == doctest::Approx(0.2));
        CHECK(h->v == doctest::Approx(0.3));
        auto f = intersectWatertight(Ray({0.2f, 0.3f, -2}, {0, 0, 1}), cast<float>(kUnit));
        CHECK(f.has_value());
    }
    TEST_CASE("watertight: a ray exactly through a shared edge hits one of the two triangles") {
        // Points of the hypotenuse with exact float coordinates, straight down and slanted:
        // the shared edge's function is exactly zero, which counts as inside.
        const Triangle a = cast<float>(kUnit), b = cast<float>(kUnitNeighbour);
        for (float s : {0.25f, 0.5f, 0.75f}) {
            for (Vec3 d : {Vec3(0, 0, -1), Vec3(0.5f, 0.5f, -1), Vec3(-0.25f, -0.25f, -1)}) {
                Vec3 target(1.0f - s, s, 0.0f);
                Ray ray(target - d, d);
                INFO("target " << target << " direction " << d);
                CHECK((intersectWatertight(ray, a) || intersectWatertight(ray, b)));
            }
        }
    }
    TEST_CASE("watertight: t for a direction that is not a unit vector") {
        // D = (0, 0, -4) from z = 2 reaches the plane at t = 0.5; D = (1, 1, 2) from
        // (-0.8, -0.7, -2) reaches (0.2, 0.3, 0) at t = 1.
        auto h = intersectWatertight(Rayd({0.2, 0.3, 2}, {0, 0, -4}), kUnit);
        REQUIRE(h.has_value());
        CHECK(h->t == doctest::Approx(0.5));
        auto g = intersectWatertight(Rayd({-0.8, -0.7, -2}, {1, 1, 2}), kUnit);
        REQUIRE(g.has_value());
        CHECK(g->t == doctest::Approx(1.0));
        CHECK(g->u == doctest::Approx(0.2));
        CHECK(g->v == doctest::Approx(0.3));
    }

    TEST_CASE("hard case: a ray through a shared edge hits at least one of the two triangles") {
        // Rays at float points along the shared hypotenuse, from many directions.
        std::mt19937_64 rng(11);
        std::uniform_real_distribution<float> u01(0.0f, 1.0f);
        const Triangle a = cast<float>(kUnit), b = cast<float>(kUnitNeighbour);
        for (int i = 0; i < 20000; ++i) {
            float s = u01(rng);
            Vec3 target(1.0f - s, s, 0.0f);
            Vec3 origin(u01(rng) * 4 - 2, u01(rng) * 4 - 2, 0.5f + u01(rng) * 3);
            Ray ray(origin, target - origin);
            INFO("ray " << i);
            REQUIRE((intersectWatertight(ray, a) || intersectWatertight(ray, b)));
        }
    }
    TEST_CASE("hard case: a ray through a shared vertex hits at least one triangle of the fan") {
        // Six triangles around the vertex (0.1, 0.7, 0.3) of a hexagonal fan.
        const Vec3 centre(0.1f, 0.7f, 0.3f);
        std::vector<Triangle> fan;
        auto rim = [&](int k) {
            float a = kPi / 3 * float(k % 6);
            return centre + Vec3(std::cos(a), std::sin(a), k % 2 ? 0.1f : -0.1f);
        };
        for (int k = 0; k < 6; ++k) fan.push_back({centre, rim(k), rim(k + 1)});
        std::mt19937_64 rng(5);
        std::uniform_real_distribution<float> u01(0.0f, 1.0f);
        for (int i = 0; i < 20000; ++i) {
            Vec3 origin = centre + Vec3(u01(rng) * 2 - 1, u01(rng) * 2 - 1, 1.0f + u01(rng));
            Ray ray(origin, centre - origin);
            bool hit = false;
            for (const Triangle& t : fan) hit = hit || intersectWatertight(ray, t).has_value();
            INFO("ray " << i);
            REQUIRE(hit);
        }
    }
    TEST_CASE("hard case: far geometry has no cracks (closed mesh moved to 1000 -700 300)") {
        Mesh sh1 = loadObj(test::dataDir() + "/meshes/sh1.obj");
        const Vec3 far(1000.0f, -700.0f, 300.0f);
        CrackRaySet set = makeCrackRays(sh1, 20000, 20000, 3, far);
        CHECK(set.edgeRays.size() > 10000);
        CHECK(set.vertexRays.size() > 10000);
        CHECK(countCracks<float>(sh1, set.edgeRays, TriangleTest::Watertight, far) == 0);
        CHECK(countCracks<float>(sh1, set.vertexRays, TriangleTest::Watertight, far) == 0);
        CHECK(countCracks<double>(sh1, set.edgeRays, TriangleTest::Watertight, far) == 0);
        CrackRaySet near = makeCrackRays(sh1, 20000, 20000, 4);
        CHECK(countCracks<float>(sh1, near.edgeRays, TriangleTest::Watertight) == 0);
        CHECK(countCracks<float>(sh1, near.vertexRays, TriangleTest::Watertight) == 0);
    }
}

// Exercise 1.5's hard cases that take float out of its range (found by fuzzing step 04's
// copy of the test): the fallback to double decides them.
TEST_SUITE("exercise 1.5") {
    TEST_CASE("hard case: a triangle 1e21 across straight ahead is hit") {
        // Its float edge functions overflow (products near 1e42, inf - inf = NaN): without
        // the fallback to double the ray passes through it.
        test::FpTrapsOff overflowOnPurpose;
        const Triangle big{
            {-1e21f, -1e21f, -5e20f}, {1e21f, -1e21f, -5e20f}, {0.0f, 1e21f, -5e20f}};
        auto h = intersectWatertight(Ray(Vec3(0.0f), Vec3(0.0f, 0.0f, -1.0f)), big);
        REQUIRE(h.has_value());
        // Worked by hand: (0, 0) = (1 - u - v) a + u b + v c gives v = 1/2, u = 1/4.
        CHECK(double(h->t) == doctest::Approx(5e20).epsilon(1e-6));
        CHECK(double(h->u) == doctest::Approx(0.25).epsilon(1e-6));
        CHECK(double(h->v) == doctest::Approx(0.5).epsilon(1e-6));
        // Beside it and behind the ray: misses, also in double.
        CHECK_FALSE(
            intersectWatertight(Ray(Vec3(3e21f, 0.0f, 0.0f), Vec3(0.0f, 0.0f, -1.0f)), big));
        CHECK_FALSE(intersectWatertight(Ray(Vec3(0.0f), Vec3(0.0f, 0.0f, 1.0f)), big));
        auto d = intersectWatertight(Rayd(Vec3d(0.0), Vec3d(0.0, 0.0, -1.0)),
                                     Triangled{Vec3d(big.a), Vec3d(big.b), Vec3d(big.c)});
        REQUIRE(d.has_value());
        CHECK(d->t == doctest::Approx(double(5e20f)).epsilon(1e-12));  // the float plane, widened
    }
    TEST_CASE("hard case: a tiny triangle behind a ray with a 1e28 direction is missed (t = -0)") {
        // With |D| = 1e28 the scaled depths are about 1e-27 and the edge functions of a
        // triangle 1e-15 across about 1e-30: their float products underflow to zero, t
        // comes out -0, and -0 >= tmin = 0 accepts a triangle that lies behind the ray.
        const Triangle tiny{
            {-1e-15f, -1e-15f, 3.0f}, {1e-15f, -1e-15f, 3.0f}, {0.0f, 1e-15f, 3.0f}};
        CHECK_FALSE(
            intersectWatertight(Ray(Vec3(0.0f, 0.0f, -5.0f), Vec3(0.0f, 0.0f, -1e28f)), tiny));
        // The fuzzer's own input: a triangle without area whose line crosses the ray.
        const Triangle flat{{0.0f, 0.0f, 3.0f}, {1.0f, 1.0f, 3.0f}, {2.0f, 2.0f, 3.0f}};
        CHECK_FALSE(intersectWatertight(
            Ray(Vec3(1.0f, 1.0f, -5.0f), Vec3(0.0f, 8.149072e-10f, -1.0603488e28f)), flat));
        // Towards it the same triangle is hit, at 8 / 1e28.
        auto ahead =
            intersectWatertight(Ray(Vec3(0.0f, 0.0f, -5.0f), Vec3(0.0f, 0.0f, 1e28f)), tiny);
        REQUIRE(ahead.has_value());
        CHECK(double(ahead->t) == doctest::Approx(8e-28).epsilon(1e-5));
    }
    TEST_CASE("hard case: a triangle 3e38 away is hit at a finite t or missed (t = +inf)") {
        // The scaled depth 3e38 times an edge function of about 4 overflows: t came out
        // +inf, and t <= tmax = inf took it for a hit, even with tmin beyond the true t.
        test::FpTrapsOff overflowOnPurpose;
        const Triangle tri{{-1.0f, -1.0f, -1.0f}, {1.0f, -1.0f, -1.0f}, {0.0f, 1.0f, -1.0f}};
        const float far = 3e38f;
        auto h = intersectWatertight(Ray(Vec3(0.0f, 0.0f, far), Vec3(0.0f, 0.0f, -1.0f)), tri);
        REQUIRE(h.has_value());
        CHECK(h->t == far);  // far + 1 rounds to far
        CHECK(std::isfinite(h->u));
        // tmin just beyond the hit; and a ray of speed 1/2, whose t = 6e38 has no float.
        CHECK_FALSE(intersectWatertight(
            Ray(Vec3(0.0f, 0.0f, far), Vec3(0.0f, 0.0f, -1.0f), nextFloatUp(far)), tri));
        CHECK_FALSE(intersectWatertight(Ray(Vec3(0.0f, 0.0f, far), Vec3(0.0f, 0.0f, -0.5f)), tri));
    }
    TEST_CASE(
        "hard case: an edge function that rounds to zero on a shared edge is recomputed in "
        "double so exactly one neighbour hits") {
        // Along +z from the origin the sheared vertices are the vertices' (x, y). The shared
        // edge runs from b = (1, 1 + e) to c = -(1 + e, 1 + 2e), e = 2^-23, past the origin:
        // its edge function cx by - cy bx is -(1 + e)^2 + (1 + 2e) = -e^2 exactly, but both
        // products round to the float 1 + 2e, so in float it is 0 in both triangles, and
        // both would report the ray. The products are exact in double: -e^2 for one
        // triangle, +e^2 for the other, so the ray is in exactly one of them.
        const float e = std::ldexp(1.0f, -23);
        const Vec3 b(1.0f, 1.0f + e, 1.0f), c(-(1.0f + e), -(1.0f + 2.0f * e), 1.0f);
        REQUIRE(c.x * b.y - c.y * b.x == 0.0f);  // the float edge function is exactly 0
        const Triangle upperLeft{{-1.0f, 1.0f, 1.0f}, b, c};   // exact: u < 0 < v, w
        const Triangle lowerRight{{1.0f, -1.0f, 1.0f}, c, b};  // exact: u, v, w > 0
        const Ray ray(Vec3(0.0f), Vec3(0.0f, 0.0f, 1.0f));
        auto hitUpper = intersectWatertight(ray, upperLeft);
        auto hitLower = intersectWatertight(ray, lowerRight);
        CHECK_FALSE(hitUpper.has_value());
        REQUIRE(hitLower.has_value());
        CHECK(hitLower->t == 1.0f);
        // The origin lies on the edge c-b (u = 0 of the lower triangle's a), halfway along
        // within rounding: weights of c and b about 1/2 each.
        CHECK(double(hitLower->u) == doctest::Approx(0.5).epsilon(1e-6));
        CHECK(double(hitLower->v) == doctest::Approx(0.5).epsilon(1e-6));
    }
    TEST_CASE("hard case: an edge function that rounds to zero is recomputed as v and as w too") {
        // The two triangles above with their vertices rotated (the same triangles, the same
        // winding): the shared edge's function, u there, is v for (c, a, b) and w for
        // (b, c, a). Each must be recomputed in double, or both triangles report the ray.
        const float e = std::ldexp(1.0f, -23);
        const Vec3 b(1.0f, 1.0f + e, 1.0f), c(-(1.0f + e), -(1.0f + 2.0f * e), 1.0f);
        const Vec3 upperA(-1.0f, 1.0f, 1.0f), lowerA(1.0f, -1.0f, 1.0f);
        const Ray ray(Vec3(0.0f), Vec3(0.0f, 0.0f, 1.0f));
        struct Rotation {
            const char* edge;
            Triangle upper, lower;
        };
        for (const Rotation& r : {Rotation{"v", {c, upperA, b}, {b, lowerA, c}},
                                  Rotation{"w", {b, c, upperA}, {c, b, lowerA}}}) {
            INFO("the shared edge's function is " << r.edge);
            CHECK_FALSE(intersectWatertight(ray, r.upper).has_value());
            auto hit = intersectWatertight(ray, r.lower);
            REQUIRE(hit.has_value());
            CHECK(hit->t == 1.0f);
        }
    }
}

// The three full tests on the closed interval's lower end and on grazing rays.
TEST_SUITE("hard cases 01") {
    TEST_CASE("hard case: a triangle hit exactly at t == tmin counts (closed interval)") {
        for (TriangleTest test : kAllTriangleTests) {
            INFO(triangleTestName(test));
            // Straight down from z = 2 onto z = 0: t = 2 exactly in every test.
            Ray ray(Vec3(0.25f, 0.25f, 2.0f), Vec3(0.0f, 0.0f, -1.0f), 2.0f);
            auto h = intersectTriangle(test, ray, cast<float>(kUnit));
            REQUIRE(h.has_value());
            CHECK(h->t == 2.0f);
            ray.tmin = nextFloatUp(2.0f);
            CHECK_FALSE(intersectTriangle(test, ray, cast<float>(kUnit)));
        }
    }
    TEST_CASE("hard case: no self-intersection acne on meshes at scene scales 1 to 1e5") {
        // A convex mesh (a latitude-longitude sphere of 12 x 24 planar quads, each two
        // triangles) cannot shadow a point of a face that looks at the light: such a point
        // and the light are both outside that face's plane, the mesh inside it. A shadow
        // ray from the renderer's offset origin (offsetOrigin) that hits the mesh again is
        // acne; a fixed offset falls below float's spacing at 1e5.
        constexpr int rings = 12, segments = 24;
        for (float scale : {1.0f, 10.0f, 100.0f, 1e3f, 1e4f, 1e5f}) {
            const Vec3 centre = Vec3(0.2f, -0.1f, -3.0f) * scale, light = Vec3(5.0f) * scale;
            auto vertex = [&](int ring, int segment) {
                float theta = kPi * float(ring) / rings,
                      phi = 2.0f * kPi * float(segment) / segments;
                return centre + scale * Vec3(std::sin(theta) * std::cos(phi), std::cos(theta),
                                             std::sin(theta) * std::sin(phi));
            };
            std::vector<Triangle> mesh;
            for (int r = 0; r < rings; ++r)
                for (int k = 0; k < segments; ++k) {
                    Vec3 a = vertex(r, k), b = vertex(r, k + 1), c = vertex(r + 1, k),
                         d = vertex(r + 1, k + 1);
                    if (r > 0) mesh.push_back({a, b, d});  // the poles' quads are triangles
                    if (r < rings - 1) mesh.push_back({a, d, c});
                }
            auto nearest = [&](const Ray& ray, int& which) {
                std::optional<float> best;
                for (size_t i = 0; i < mesh.size(); ++i)
                    if (auto h = intersectWatertight(ray, mesh[i]); h && (!best || h->t < *best))
                        best = h->t, which = int(i);
                return best;
            };
            int lit = 0, acne = 0;
            for (int y = 0; y < 40; ++y)
                for (int x = 0; x < 40; ++x) {
                    Vec3 target =
                        centre + scale * Vec3((x - 19.5f) / 20.0f, (y - 19.5f) / 20.0f, 0.0f);
                    Ray ray(Vec3(0.0f), target);
                    int face = -1;
                    auto t = nearest(ray, face);
                    if (!t) continue;
                    const Triangle& f = mesh[size_t(face)];
                    Vec3 p = ray.at(*t), n = glm::normalize(glm::cross(f.b - f.a, f.c - f.a));
                    if (glm::dot(n, (f.a + f.b + f.c) / 3.0f - centre) < 0.0f) n = -n;  // outward
                    Vec3 toLight = light - p;
                    if (glm::dot(n, toLight) <= 0.0f) continue;
                    ++lit;
                    Ray shadow(offsetOrigin(p, n, toLight), toLight, 0.0f, 1.0f);
                    int ignored = -1;
                    acne += nearest(shadow, ignored).has_value();
                }
            INFO("scale " << scale << ": " << lit << " lit points");
            CHECK(lit > 300);
            CHECK(acne == 0);
        }
    }
    TEST_CASE("hard case: grazing rays nearly parallel to a triangle hit it where double does") {
        // Slopes from 1e-3 down to 1e-30 against the plane z = 0: D.N is tiny but not 0,
        // so the ray meets the plane at x = 0.25. An epsilon on the determinant (|det| <
        // 1e-8 taken for parallel) loses these hits; just beside the triangle, a miss.
        for (TriangleTest test : kAllTriangleTests) {
            for (float slope : {1e-3f, 1e-6f, 1e-12f, 1e-30f}) {
                INFO(triangleTestName(test) << ", slope " << slope);
                Ray in(Vec3(-1.0f, 0.25f, 1.25f * slope), Vec3(1.0f, 0.0f, -slope));
                auto h = intersectTriangle(test, in, cast<float>(kUnit));
                REQUIRE(h.has_value());
                CHECK(double(h->t) == doctest::Approx(1.25).epsilon(1e-5));
                CHECK(double(h->u) == doctest::Approx(0.25).epsilon(1e-4));
                CHECK(double(h->v) == doctest::Approx(0.25).epsilon(1e-4));
                Ray beside(Vec3(-1.0f, -0.25f, 1.25f * slope), Vec3(1.0f, 0.0f, -slope));
                CHECK_FALSE(intersectTriangle(test, beside, cast<float>(kUnit)));
                Rayd inDouble(Vec3d(-1.0, 0.25, 1.25 * double(slope)),
                              Vec3d(1.0, 0.0, -double(slope)));
                auto d = intersectTriangle(test, inDouble, kUnit);
                REQUIRE(d.has_value());
                CHECK(d->t == doctest::Approx(1.25).epsilon(1e-9));
            }
        }
    }
}

TEST_SUITE("exercise 1.6") {
    TEST_CASE("normal interpolation: worked values") {
        Vec3 x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
        float s3 = 1.0f / std::sqrt(3.0f), s2 = 1.0f / std::sqrt(2.0f);
        checkVec(interpolateNormal(x, y, z, 1.0f / 3, 1.0f / 3), Vec3(s3), 1e-6);
        checkVec(interpolateNormal(x, y, z, 0.5f, 0.0f), Vec3(s2, s2, 0), 1e-6);
        checkVec(interpolateNormal(x, y, z, 0.0f, 1.0f), z, 1e-7);
        checkVec(interpolateNormal(x, y, z, 0.0f, 0.0f), x, 1e-7);
        CHECK(glm::length(interpolateNormal(x, y, z, 0.2f, 0.7f)) == doctest::Approx(1.0f));
    }
    TEST_CASE("normal interpolation: the result has unit length") {
        // Halfway between two unit normals 90 degrees apart the blend is 0.707 long.
        Vec3 x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
        for (auto [u, v] : {std::pair{0.5f, 0.0f}, {0.5f, 0.5f}, {0.1f, 0.3f}, {0.3f, 0.3f}}) {
            INFO("u = " << u << ", v = " << v);
            CHECK(std::abs(glm::length(interpolateNormal(x, y, z, u, v)) - 1.0f) < 1e-6f);
        }
    }
}

TEST_SUITE("renderer") {
    TEST_CASE("effects on demand: a mesh scene renders the same image with fewer rays") {
        Scene scene = makeScene("sh1", SceneOptions{test::dataDir(), 4.0f / 3.0f});
        scene.geometries.push_back(std::make_shared<TriangleGrid>(scene.mesh, scene.meshMaterial));
        auto c = test::renderBothWays(scene, 48, 36);
        CHECK(c.identical);
        CHECK(c.lean.total() < c.forced.total());
        CHECK(c.lean.reflection == 0);
        CHECK(c.forced.reflection > 0);
        CHECK(c.lean.shadow > 0);  // a mesh can shadow itself
    }
}

TEST_SUITE("program 01") {
    const std::string program = test::stepProgram();

    TEST_CASE("headless render writes a PNG of the requested size") {
        test::TempDir dir;
        test::runHeadless(program, dir, 64, 40, "--scene sh1");
    }
    TEST_CASE("measurements: the JSON report has the speed and crack tables") {
        test::TempDir dir;
        auto run = test::runHeadless(program, dir, 32, 24,
                                     "--scene sh1 --measure --crack-rays 2000 --report r.json");
        test::checkReportTables(dir.file("r.json"), {"triangle_speed", "cracks"});
        test::checkVariantTables(dir.file("r.json"), {"triangle_speed", "accuracy_vs_time"});
        test::checkParetoPlot(dir.file("r.json"), "accuracy_vs_time");
        CHECK(test::pngSize(dir.file("a-disagree.png")) == std::pair{32, 24});
        CHECK(run.out.find("watertight float") != std::string::npos);
    }
    TEST_CASE("window: scripted frames with key presses under the offscreen video driver") {
        test::TempDir dir;
        test::runWindowScript(program, dir, "--scene sh1 --width 64 --height 48", 4, "t,m,t,Left");
    }
    TEST_CASE("bad input: one clear line and a non-zero exit") {
        test::TempDir dir;
        std::ofstream(dir.file("letters.obj")) << "v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n";
        std::ofstream(dir.file("range.obj")) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n";
        std::ofstream(dir.file("empty.obj")) << "";
        test::checkBadInput(program, dir,
                            {{"--scene missing.obj", "no such file", 1},
                             {"--scene letters.obj", "not a number", 1},
                             {"--scene range.obj", "out of range", 1},
                             {"--scene empty.obj", "empty", 1},
                             {"--scene nosuchscene", "unknown scene", 2},
                             {"--frobnicate", "frobnicate", 2},
                             {"--width 0", "width", 2},
                             {"--eye 1,2,3 --look 1,2,3", "view direction is zero", 2},
                             {"--up 0,0,0", "up vector is zero", 2},
                             {"--eye 1,2", "expected X,Y,Z", 2}});
    }
}
