// Step 03: bounds, union, overlap and the slab tests with hand-worked numbers, every hard
// case by name, the exact reference on hard rays, the pre-test, and the program.
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>

#include "03_aabb/aabb.hpp"
#include "03_aabb/slab_reference.hpp"
#include "03_aabb/why_we_care.hpp"
#include "core/render.hpp"
#include "support.hpp"

using namespace boxes;
using boxes::test::checkVec;

namespace {

const Bounds3d kUnitBox({0, 0, 0}, {1, 1, 1});
const Bounds3f kUnitBoxF({0, 0, 0}, {1, 1, 1});

template <typename T>
std::optional<RayInterval<T>> slabs(const RayT<T>& ray, const Bounds3T<T>& box) {
    return intersectSlabs(SlabRayT<T>(ray), box);
}
template <typename T>
std::optional<RayInterval<T>> conservative(const RayT<T>& ray, const Bounds3T<T>& box) {
    return intersectSlabsConservative(SlabRayT<T>(ray), box);
}

// The named hard cases, for a slab test given as a function (3.6 or 3.7).
template <typename Test>
void checkSlabHardCase(const std::string& name, Test test) {
    const double inf = std::numeric_limits<double>::infinity();
    if (name == "+0") {
        // Parallel to x inside the x slab: the slab is "all t" (1/+0 = +inf).
        auto h = test(Rayd({0.5, -1, 0.5}, {0.0, 1, 0.0}), kUnitBox);
        REQUIRE(h.has_value());
        CHECK(h->tnear == doctest::Approx(1.0));
        CHECK(h->tfar == doctest::Approx(2.0).epsilon(1e-12));
        // Outside the x slab: never inside it.
        CHECK_FALSE(test(Rayd({1.5, -1, 0.5}, {0.0, 1, 0.0}), kUnitBox));
        CHECK_FALSE(test(Rayd({-0.5, -1, 0.5}, {0.0, 1, 0.0}), kUnitBox));
    } else if (name == "-0") {
        // -0.0 == 0 compares equal, but 1/-0 = -inf: the sign bit must decide which plane is
        // near; a test that asks "D < 0" treats -0 as positive and misses this box.
        auto h = test(Rayd({0.5, -1, 0.5}, {-0.0, 1, -0.0}), kUnitBox);
        REQUIRE(h.has_value());
        CHECK(h->tnear == doctest::Approx(1.0));
        auto f = test(Ray({0.5f, -1, 0.25f}, {-0.0f, 2, -0.0f}), kUnitBoxF);
        REQUIRE(f.has_value());
        CHECK(f->tnear == 0.5f);
        CHECK_FALSE(test(Rayd({1.5, -1, 0.5}, {-0.0, 1, -0.0}), kUnitBox));
    } else if (name == "origin on plane") {
        // O_x on the plane x = 0 or x = 1 with D_x = +0 or -0: (plane - O) * (1/D) = 0 * inf
        // = NaN. The ray lies in the face's plane, which belongs to the closed box: a hit in
        // every one of the four combinations, entering at y = 0 (t = 1) and leaving at t = 2.
        test::FpTrapsOff nanOnPurpose;  // that 0 * inf is the case under test
        for (double plane : {0.0, 1.0})
            for (double zero : {0.0, -0.0}) {
                INFO("plane x = " << plane << ", D_x = " << (std::signbit(zero) ? "-0" : "+0"));
                auto h = test(Rayd({plane, -1, 0.5}, {zero, 1, 0}), kUnitBox);
                REQUIRE(h.has_value());
                CHECK(h->tnear == doctest::Approx(1.0));
                CHECK(h->tfar == doctest::Approx(2.0).epsilon(1e-12));
                CHECK_FALSE(std::isnan(h->tnear));
                CHECK_FALSE(std::isnan(h->tfar));
                // Float too, and along a face plane of a flat box.
                Ray f(Vec3(float(plane), -1, 0.5f), Vec3(float(zero), 1, 0));
                CHECK(test(f, kUnitBoxF).has_value());
                // The NaN on the last axis (z), where no later axis can overwrite it.
                auto z = test(Rayd({0.5, -1, plane}, {0, 1, zero}), kUnitBox);
                REQUIRE(z.has_value());
                CHECK(z->tnear == doctest::Approx(1.0));
                CHECK(z->tfar == doctest::Approx(2.0).epsilon(1e-12));
            }
    } else if (name == "flat") {
        Bounds3d flat({0, 0, 0}, {1, 0, 1});  // the square y = 0
        auto h = test(Rayd({0.5, 2, 0.5}, {0, -1, 0}), flat);
        REQUIRE(h.has_value());
        CHECK(h->tnear == doctest::Approx(2.0));
        CHECK(h->tfar == doctest::Approx(2.0).epsilon(1e-12));
        CHECK(test(Rayd({0.5, 2, 0.5}, {0.25, -1, 0}), flat).has_value());
        CHECK_FALSE(test(Rayd({1.5, 2, 0.5}, {0, -1, 0}), flat));
        // Flat on every axis: a point, hit exactly.
        CHECK(test(Rayd({-1, -1, -1}, {1, 1, 1}), Bounds3d({0, 0, 0}, {0, 0, 0})).has_value());
    } else if (name == "inside") {
        auto h = test(Rayd({0.5, 0.5, 0.5}, {1, 0, 0}), kUnitBox);
        REQUIRE(h.has_value());
        CHECK(h->tnear == 0.0);  // clipped to tmin
        CHECK(h->tfar == doctest::Approx(0.5).epsilon(1e-12));
    } else if (name == "behind") {
        CHECK_FALSE(test(Rayd({2, 0.5, 0.5}, {1, 0, 0}), kUnitBox));
        CHECK_FALSE(test(Rayd({0.5, 0.5, -3}, {0, 0, -1}), kUnitBox));
        // With tmin = -inf the box behind counts.
        CHECK(test(Rayd({2, 0.5, 0.5}, {1, 0, 0}, -inf, inf), kUnitBox).has_value());
    } else if (name == "tmax") {
        CHECK_FALSE(test(Rayd({-2, 0.5, 0.5}, {1, 0, 0}, 0.0, 1.5), kUnitBox));
        auto h = test(Rayd({-2, 0.5, 0.5}, {1, 0, 0}, 0.0, 2.0), kUnitBox);  // touches at tmax
        REQUIRE(h.has_value());
        CHECK(h->tnear == 2.0);
        CHECK(h->tfar == 2.0);
    } else if (name == "touch") {
        // Through the edge x = 1, y = 1 and the corner (1, 1, 1): closed boxes, a hit.
        CHECK(test(Rayd({2, 2, 0.5}, {-1, -1, 0}), kUnitBox).has_value());
        CHECK(test(Rayd({2, 2, 2}, {-1, -1, -1}), kUnitBox).has_value());
        CHECK(test(Ray({2, 2, 2}, {-1, -1, -1}), kUnitBoxF).has_value());
        CHECK_FALSE(test(Rayd({2, 3.5, 0.5}, {-1, -1, 0}), kUnitBox));
        // Touching only: the edge x = y = 1 at t = 1 and nothing else (tnear = tfar), and
        // the corner (1, 1, 1) the same way.
        auto edge = test(Rayd({0, 2, 0.5}, {1, -1, 0}), kUnitBox);
        REQUIRE(edge.has_value());
        CHECK(edge->tnear == 1.0);
        CHECK(test(Rayd({0, 2, 2}, {1, -1, -1}), kUnitBox).has_value());
    }
}

}  // namespace

TEST_SUITE("exercise 3.1") {
    TEST_CASE("sphere bounds: centre minus and plus the radius") {
        Bounds3d b = sphereBounds(SphereT<double>{{1, 2, 3}, 0.5});
        checkVec(b.min, Vec3d(0.5, 1.5, 2.5), 0.0);
        checkVec(b.max, Vec3d(1.5, 2.5, 3.5), 0.0);
        Bounds3f f = sphereBounds(Sphere{{-1, 0, 4}, 2});
        checkVec(f.min, Vec3(-3, -2, 2), 0.0);
        checkVec(f.max, Vec3(1, 2, 6), 0.0);
        // A point sphere is a point box.
        Bounds3d p = sphereBounds(SphereT<double>{{1, 1, 1}, 0.0});
        CHECK(p.min == p.max);
    }
    TEST_CASE("sphere bounds: the box is twice the radius wide on every axis") {
        Bounds3d b = sphereBounds(SphereT<double>{{0, 0, 0}, 3.0});
        checkVec(b.diagonal(), Vec3d(6, 6, 6), 0.0);
    }
}

TEST_SUITE("exercise 3.2") {
    TEST_CASE("triangle bounds: per axis the smallest and largest vertex coordinate") {
        Triangled t{{1, 5, -2}, {3, -1, 0}, {-2, 2, 4}};
        Bounds3d b = triangleBounds(t);
        checkVec(b.min, Vec3d(-2, -1, -2), 0.0);
        checkVec(b.max, Vec3d(3, 5, 4), 0.0);
        // A triangle in the plane z = 7 has a flat box.
        Bounds3f f = triangleBounds(Triangle{{0, 0, 7}, {1, 0, 7}, {0, 1, 7}});
        CHECK(f.min.z == 7.0f);
        CHECK(f.max.z == 7.0f);
        CHECK_FALSE(f.isEmpty());
    }
    TEST_CASE("triangle bounds: the third vertex can hold the minimum") {
        Bounds3d b = triangleBounds(Triangled{{1, 1, 1}, {2, 2, 2}, {-1, -2, -3}});
        checkVec(b.min, Vec3d(-1, -2, -3), 0.0);
        checkVec(b.max, Vec3d(2, 2, 2), 0.0);
    }
}

TEST_SUITE("exercise 3.3") {
    TEST_CASE("mesh bounds: the vertices the triangles use") {
        Mesh m = parseObj("v 0 0 0\nv 2 0 0\nv 0 3 -1\nv 100 100 100\nf 1 2 3\n");
        Bounds3f b = meshBounds(m);
        checkVec(b.min, Vec3(0, 0, -1), 0.0);
        checkVec(b.max, Vec3(2, 3, 0), 0.0);  // the unused vertex (100,100,100) is not in it
        CHECK(meshBounds(Mesh{}).isEmpty());
        Mesh sh1 = loadObj(test::dataDir() + "/meshes/sh1.obj");
        Bounds3f s = meshBounds(sh1);
        for (const Vec3& p : sh1.positions) CHECK(s.contains(p));
    }
    TEST_CASE("mesh bounds: every vertex of every triangle counts") {
        // The extremes are the triangles' third vertices.
        Mesh m = parseObj("v 0 0 0\nv 1 0 0\nv 0 1 5\nv 0 0 -4\nf 1 2 3\nf 1 2 4\n");
        Bounds3f b = meshBounds(m);
        checkVec(b.min, Vec3(0, 0, -4), 0.0);
        checkVec(b.max, Vec3(1, 1, 5), 0.0);
    }
}

TEST_SUITE("exercise 3.4") {
    TEST_CASE("union of two boxes: worked example") {
        Bounds3d a({0, 0, 0}, {1, 2, 3}), b({-1, 1, 2}, {0.5, 4, 5});
        Bounds3d u = unionBounds(a, b);
        checkVec(u.min, Vec3d(-1, 0, 0), 0.0);
        checkVec(u.max, Vec3d(1, 4, 5), 0.0);
        CHECK(unionBounds(b, a) == u);
        // The empty box (the default) is the identity.
        CHECK(unionBounds(Bounds3d(), a) == a);
        CHECK(unionBounds(a, Bounds3d()) == a);
    }
    TEST_CASE("hard case: the slide's bmin.y line reads B.bmin.x and loses the bottom of B") {
        // The slide: box.bmin.y = min(A.bmin.y, B.bmin.x). B lies below A in y, and B's x
        // minimum (5) is above A's y minimum (0): the typo starts y at 0 and B's y extent
        // [-3, -2] is outside the "union".
        Bounds3d A({0, 0, 0}, {1, 1, 1}), B({5, -3, 0}, {6, -2, 1});
        Bounds3d wrong = unionBoundsSlideTypo(A, B);
        Bounds3d right = unionBounds(A, B);
        CHECK(wrong.min.y == 0.0);
        CHECK(right.min.y == -3.0);
        CHECK_FALSE(wrong.contains(Vec3d(5.5, -2.5, 0.5)));  // B's centre is outside it
        CHECK(right.contains(Vec3d(5.5, -2.5, 0.5)));
        // One operand only: every other line of the slide is right.
        CHECK(wrong.min.x == right.min.x);
        CHECK(wrong.max.x == right.max.x);
        CHECK(wrong.max.y == right.max.y);
        CHECK(wrong.min.z == right.min.z);
        CHECK(wrong.max.z == right.max.z);
        // The other way round the typo makes the box too big (B.bmin.x = -4 below both y
        // minima): conservative, only slower.
        Bounds3d C({-4, 10, 0}, {-3, 11, 1});
        CHECK(unionBoundsSlideTypo(A, C).min.y == -4.0);
        CHECK(unionBounds(A, C).min.y == 0.0);
        // Where B.bmin.x equals B.bmin.y (cubes on the diagonal) the typo does not matter:
        // why it survives on a slide.
        Bounds3d c({0, 0, 0}, {1, 1, 1}), d({0.5, 0.5, 0.5}, {2, 2, 2});
        CHECK(unionBoundsSlideTypo(c, d) == unionBounds(c, d));
        CHECK(unionBoundsSlideTypo(d, c) == unionBounds(d, c));
    }
}

TEST_SUITE("exercise 3.5") {
    TEST_CASE("overlap: worked examples on every axis") {
        Bounds3d a({0, 0, 0}, {2, 2, 2});
        CHECK(overlaps(a, Bounds3d({1, 1, 1}, {3, 3, 3})));
        CHECK(overlaps(a, Bounds3d({0.5, 0.5, 0.5}, {1, 1, 1})));  // inside
        CHECK(overlaps(a, Bounds3d({2, 0, 0}, {3, 1, 1})));        // touching a face counts
        CHECK(overlaps(a, Bounds3d({2, 2, 2}, {3, 3, 3})));        // touching a corner counts
        for (int k = 0; k < 3; ++k) {
            Vec3d lo(0.5), hi(1.5);
            lo[k] = 3, hi[k] = 4;  // separated along axis k only
            CHECK_FALSE(overlaps(a, Bounds3d(lo, hi)));
            CHECK_FALSE(overlaps(Bounds3d(lo, hi), a));
            lo[k] = -4, hi[k] = -3;
            CHECK_FALSE(overlaps(a, Bounds3d(lo, hi)));
            CHECK_FALSE(overlaps(Bounds3d(lo, hi), a));
        }
    }
    TEST_CASE("overlap: boxes that only touch overlap (closed boxes)") {
        Bounds3d a({0, 0, 0}, {1, 1, 1});
        CHECK(overlaps(a, Bounds3d({1, 0, 0}, {2, 1, 1})));     // a shared face
        CHECK(overlaps(Bounds3d({-1, -1, -1}, {0, 0, 0}), a));  // a shared corner
    }
    TEST_CASE("hard case: the slide's half test reports a false overlap") {
        // The slide: (A.bmin.x < B.bmax.x) && (A.bmin.y < B.bmax.y) && (A.bmin.z < B.bmax.z).
        // B lies entirely beyond A's max side on x: A.bmin < B.bmax holds on every axis, so
        // the half test says "overlap"; the missing half (B.bmin <= A.bmax) fails on x.
        Bounds3d A({0, 0, 0}, {1, 1, 1}), B({5, 0, 0}, {6, 1, 1});
        CHECK(overlapsHalfTest(A, B));
        CHECK_FALSE(overlaps(A, B));
        CHECK_FALSE(overlaps(B, A));
        CHECK_FALSE(overlapsHalfTest(B, A));  // the other order happens to catch it
        Bounds3f af({0, 0, 0}, {1, 1, 1}), bf({0, 0, 5}, {1, 1, 6});
        CHECK(overlapsHalfTest(af, bf));
        CHECK_FALSE(overlaps(af, bf));
        // Boxes that really overlap: the slide's test agrees.
        Bounds3d C({0.5, 0.5, 0.5}, {2, 2, 2});
        CHECK(overlapsHalfTest(A, C));
        CHECK(overlaps(A, C));
    }
    TEST_CASE(
        "hard case: the slide's strict comparison says touching closed boxes do not overlap") {
        // A starts where B ends on x (A.bmin.x = B.bmax.x = 1): closed boxes share the face
        // x = 1, but 1 < 1 is false.
        Bounds3d A({1, 0, 0}, {2, 1, 1}), B({0, 0, 0}, {1, 1, 1});
        CHECK_FALSE(overlapsHalfTest(A, B));
        CHECK(overlaps(A, B));
        CHECK(overlaps(B, A));
    }
}

TEST_SUITE("exercise 3.6") {
    TEST_CASE("slab test: worked interval") {
        // From (-1, 0.25, 0.5) along (2, 1, 0): x in [0, 1] for t in [0.5, 1], y in [0, 1]
        // for t in [-0.25, 0.75]: [tnear, tfar] = [0.5, 0.75].
        auto h = slabs(Rayd({-1, 0.25, 0.5}, {2, 1, 0}), kUnitBox);
        REQUIRE(h.has_value());
        CHECK(h->tnear == doctest::Approx(0.5));
        CHECK(h->tfar == doctest::Approx(0.75));
        // The same ray moving in -x from the other side: (2, 0.25, 0.5) along (-2, 1, 0).
        auto g = slabs(Rayd({2, 0.25, 0.5}, {-2, 1, 0}), kUnitBox);
        REQUIRE(g.has_value());
        CHECK(g->tnear == doctest::Approx(0.5));
        CHECK(g->tfar == doctest::Approx(0.75));
        auto f = slabs(Ray({-1, 0.25f, 0.5f}, {2, 1, 0}), kUnitBoxF);
        REQUIRE(f.has_value());
        CHECK(f->tnear == 0.5f);
        CHECK(f->tfar == 0.75f);
        CHECK_FALSE(slabs(Rayd({-1, 0.75, 0.5}, {2, 1, 0}), kUnitBox));  // y leaves before x enters
    }
    TEST_CASE("slab test: a negative direction enters through the max plane") {
        // From x = 5 along -x: the plane x = 1 at t = 4 first, x = 0 at t = 5.
        auto h = slabs(Rayd({5, 0.5, 0.5}, {-1, 0, 0}), kUnitBox);
        REQUIRE(h.has_value());
        CHECK(h->tnear == 4.0);
        CHECK(h->tfar == 5.0);
    }
    TEST_CASE("hard case: direction component +0.0") {
        checkSlabHardCase("+0", [](const auto& r, const auto& b) { return slabs(r, b); });
    }
    TEST_CASE("hard case: direction component -0.0") {
        checkSlabHardCase("-0", [](const auto& r, const auto& b) { return slabs(r, b); });
    }
    TEST_CASE("hard case: origin on a slab plane with a zero direction component") {
        checkSlabHardCase("origin on plane",
                          [](const auto& r, const auto& b) { return slabs(r, b); });
        test::FpTrapsOff nanOnPurpose;  // 0 * inf = NaN in the naive test, on purpose
        // The slide's naive test depends on the order of the arguments of min and max there:
        // two orders, two different answers for the same ray (NaN is not ordered).
        Rayd onMax({1, -1, 0.5}, {0.0, 1, 0});
        Rayd onMin({0, -1, 0.5}, {0.0, 1, 0});
        CHECK_FALSE(intersectSlabsNaive(onMax, kUnitBox).has_value());
        CHECK(intersectSlabsNaive(onMin, kUnitBox).has_value());
        CHECK_FALSE(intersectSlabsNaive(onMin, kUnitBox, true).has_value());
    }
    TEST_CASE("hard case: flat box of zero thickness") {
        checkSlabHardCase("flat", [](const auto& r, const auto& b) { return slabs(r, b); });
    }
    TEST_CASE("hard case: ray starting inside the box") {
        checkSlabHardCase("inside", [](const auto& r, const auto& b) { return slabs(r, b); });
    }
    TEST_CASE("hard case: box behind the ray") {
        checkSlabHardCase("behind", [](const auto& r, const auto& b) { return slabs(r, b); });
    }
    TEST_CASE("hard case: hit beyond tmax") {
        checkSlabHardCase("tmax", [](const auto& r, const auto& b) { return slabs(r, b); });
    }
    TEST_CASE("hard case: touching an edge or a corner counts (closed box)") {
        checkSlabHardCase("touch", [](const auto& r, const auto& b) { return slabs(r, b); });
    }
    TEST_CASE("hard case: an empty box (min > max) is never hit") {
        CHECK_FALSE(slabs(Rayd({0.5, -1, 0.5}, {0, 1, 0}), Bounds3d({0, 0, 0}, {1, -1, 1})));
        CHECK_FALSE(slabs(Rayd({0.5, -1, 0.5}, {0.0, 1, -0.0}), Bounds3d()));  // the default, +-inf
        CHECK_FALSE(slabs(Ray({0, 0, 0}, {1, 1, 1}), Bounds3f()));
        // Inverted on an axis the ray is parallel to, with tmax = infinity.
        CHECK_FALSE(slabs(Rayd({-5, 0.5, 0.5}, {0.0, 1, 0}), Bounds3d({1, 0, 0}, {0, 1, 1})));
    }
    TEST_CASE("hard case: a NaN box coordinate constrains nothing (conservative)") {
        test::FpTrapsOff nanOnPurpose;  // the NaN box coordinate is the input under test
        const double nan = std::numeric_limits<double>::quiet_NaN();
        auto h = slabs(Rayd({-1, 0.5, 0.5}, {1, 0, 0}), Bounds3d({0, nan, 0}, {1, 1, 1}));
        CHECK(h.has_value());
        CHECK_FALSE(slabs(Rayd({-1, 0.5, 5}, {1, 0, 0}), Bounds3d({0, nan, 0}, {1, 1, 1})));
    }
    TEST_CASE(
        "hard case: the slide's pseudo-code tests only x and y and hits a ray beside the box") {
        // From (-1, 0.5, 5) along (1, 0.25, 0): inside the x slab for t in [1, 2] and the y
        // slab for t in [-2, 2], but at z = 5, far outside the box's z in [0, 1]. The slide
        // never looks at z: a hit.
        Rayd beside({-1, 0.5, 5}, {1, 0.25, 0});
        CHECK(intersectionSlidePseudoCode(kUnitBox, beside));
        CHECK_FALSE(slabs(beside, kUnitBox).has_value());
        // A ray that does pass through the box: both say hit.
        Rayd through({-1, 0.25, 0.5}, {2, 1, 0});
        CHECK(intersectionSlidePseudoCode(kUnitBox, through));
        CHECK(slabs(through, kUnitBox).has_value());
    }
    TEST_CASE(
        "hard case: the slide's pseudo-code misses a ray lying in a face plane where 0 / 0 is "
        "NaN") {
        // Along +y in the plane x = 1 (or x = 0), a face plane of the closed box: D.x = 0 and
        // O.x on the plane give (1 - 1) / 0 = NaN, and the slide's min and max let it poison
        // the interval: a miss. The robust test (3.6) hits, entering at y = 0 (t = 1).
        test::FpTrapsOff nanOnPurpose;  // 0 / 0 is the slide's arithmetic under test
        for (double plane : {0.0, 1.0}) {
            INFO("plane x = " << plane);
            Rayd along({plane, -1, 0.5}, {0, 1, 0});
            CHECK_FALSE(intersectionSlidePseudoCode(kUnitBox, along));
            CHECK(slabs(along, kUnitBox).has_value());
        }
    }
    TEST_CASE("hard case: the slide's pseudo-code hits a box behind the ray") {
        // From (3, 0.5, 0.5) along (1, 0.125, 0): the line met the box at t in [-3, -2]
        // (y allows [-4, 4]), behind the origin. The slide's test has no t >= 0: a hit.
        Rayd away({3, 0.5, 0.5}, {1, 0.125, 0});
        CHECK(intersectionSlidePseudoCode(kUnitBox, away));
        CHECK_FALSE(slabs(away, kUnitBox).has_value());
    }
    TEST_CASE(
        "hard case: the slide's start values t_min = +inf and t_max = -inf never report a hit") {
        // Straight through the middle of the box: max(+inf, ...) stays +inf and min(-inf, ...)
        // stays -inf, so t_min < t_max is never true.
        Rayd centre({-1, 0.5, 0.5}, {1, 0.25, 0.125});
        CHECK_FALSE(intersectionSlideFormulas(centre, kUnitBox));
        const double inf = std::numeric_limits<double>::infinity();
        CHECK(intersectionSlideFormulas(centre, kUnitBox, -inf, inf));  // swapped back: a hit
        CHECK(slabs(centre, kUnitBox).has_value());
        // With the start values right, the slide's strict t_min < t_max still misses a flat
        // box (t_min = t_max = 2) that its own code (tmax >= tmin) and 3.6 hit.
        Bounds3d flat({0, 0, 0}, {1, 0, 1});
        Rayd down({0.5, 2, 0.5}, {0.125, -1, 0.25});
        CHECK_FALSE(intersectionSlideFormulas(down, flat, -inf, inf));
        CHECK(slabs(down, flat).has_value());
    }
    TEST_CASE("robust slab test against the exact answer on hard rays") {
        // The hard rays include origins on slab planes with zero direction components:
        // 0 * inf = NaN there by design (the robust test ignores that bound).
        test::FpTrapsOff nanOnPurpose;
        std::vector<HardSlabRay> rays = makeHardSlabRays(400, 9);
        long long wrong = 0, grazingWrong = 0, grazing = 0;
        for (const HardSlabRay& r : rays) {
            bool got = slabs(r.ray, r.box).has_value();
            if (r.category <= 2) {
                grazing += 1;
                grazingWrong += got != r.exact;
            } else {
                INFO(hardSlabCategories()[size_t(r.category)] << ": origin " << r.ray.origin.x
                                                              << " " << r.ray.origin.y << " "
                                                              << r.ray.origin.z);
                CHECK(got == r.exact);
                wrong += got != r.exact;
            }
        }
        CHECK(wrong == 0);
        // Rounding may flip a few rays within a grid step of an edge, no more.
        CHECK(grazingWrong * 20 < grazing);
    }
}

TEST_SUITE("exercise 3.7") {
    TEST_CASE("conservative slab test: the interval is the exact one widened by a few ulps") {
        auto h = conservative(Rayd({-1, 0.25, 0.5}, {2, 1, 0}), kUnitBox);
        REQUIRE(h.has_value());
        CHECK(h->tnear == doctest::Approx(0.5));
        CHECK(h->tfar >= 0.75);
        CHECK(h->tfar <= 0.75 * (1 + 1e-15));
        auto f = conservative(Ray({-1, 0.25f, 0.5f}, {2, 1, 0}), kUnitBoxF);
        REQUIRE(f.has_value());
        CHECK(f->tfar > 0.75f);
        CHECK(f->tfar < 0.75f * 1.000001f);
    }
    TEST_CASE("conservative slab test: the far end grows and the near end stays") {
        // Against the robust test on the same rays: tnear equal, tfar larger.
        for (const Rayd& ray : {Rayd({-1, 0.25, 0.5}, {2, 1, 0}), Rayd({5, 0.5, 0.5}, {-1, 0, 0}),
                                Rayd({-3, -2, -1}, {1, 0.75, 0.5})}) {
            auto robust = slabs(ray, kUnitBox), wide = conservative(ray, kUnitBox);
            INFO("origin " << ray.origin << " direction " << ray.direction);
            REQUIRE(robust.has_value());
            REQUIRE(wide.has_value());
            CHECK(wide->tnear == robust->tnear);
            CHECK(wide->tfar > robust->tfar);
        }
    }
    TEST_CASE("conservative slab test: the same named hard cases") {
        auto test = [](const auto& r, const auto& b) { return conservative(r, b); };
        for (const char* name :
             {"+0", "-0", "origin on plane", "flat", "inside", "behind", "touch"}) {
            INFO(std::string(name));
            checkSlabHardCase(name, test);
        }
        CHECK_FALSE(conservative(Rayd({-2, 0.5, 0.5}, {1, 0, 0}, 0.0, 1.5), kUnitBox));
        CHECK_FALSE(conservative(Rayd({0.5, -1, 0.5}, {0, 1, 0}), Bounds3d({0, 0, 0}, {1, -1, 1})));
    }
    TEST_CASE(
        "hard case: the conservative test never misses a hard ray that the exact answer hits") {
        test::FpTrapsOff nanOnPurpose;  // 0 * inf on slab planes, as in exercise 3.6's test
        std::vector<HardSlabRay> rays = makeHardSlabRays(1000, 17);
        long long falseMisses = 0, falseHits = 0, misses = 0;
        for (const HardSlabRay& r : rays) {
            bool got = conservative(r.ray, r.box).has_value();
            falseMisses += r.exact && !got;
            falseHits += !r.exact && got;
            misses += !r.exact;
        }
        CHECK(falseMisses == 0);
        // Widened by a few ulps only: rays a grid step or more away are still missed.
        CHECK(falseHits * 2 < misses);
    }
}

TEST_SUITE("hard cases 03") {
    TEST_CASE("the exact reference: worked answers") {
        CHECK(exactRayMeetsBox(Ray({-1, 0.5f, 0.5f}, {1, 0, 0}), kUnitBoxF));
        CHECK(exactRayMeetsBox(Ray({2, 2, 0.5f}, {-1, -1, 0}), kUnitBoxF));  // an edge
        CHECK_FALSE(exactRayMeetsBox(Ray({2, 3.5f, 0.5f}, {-1, -1, 0}), kUnitBoxF));
        CHECK(exactRayMeetsBox(Ray({1, -1, 0.5f}, {-0.0f, 1, 0}), kUnitBoxF));  // in a face plane
        CHECK_FALSE(exactRayMeetsBox(Ray({-2, 0.5f, 0.5f}, {1, 0, 0}, 0, 1.5f), kUnitBoxF));
        CHECK(exactRayMeetsBox(Ray({-2, 0.5f, 0.5f}, {1, 0, 0}, 0, 2.0f), kUnitBoxF));
        CHECK_THROWS_AS(exactRayMeetsBox(Ray({0.1f, 0, 0}, {1, 0, 0}), kUnitBoxF),
                        std::invalid_argument);
    }
    TEST_CASE("every kind of hard ray is made") {
        std::vector<HardSlabRay> rays = makeHardSlabRays(50, 1);
        std::vector<int> seen(hardSlabCategories().size(), 0);
        for (const HardSlabRay& r : rays) ++seen[size_t(r.category)];
        for (size_t c = 0; c < seen.size(); ++c) {
            INFO(hardSlabCategories()[c]);
            CHECK(seen[c] >= 45);
        }
    }
}

TEST_SUITE("why we care 03") {
    TEST_CASE("the box pre-test renders the identical image with far fewer primitive tests") {
        ManyObjects objects = makeManyObjects(test::dataDir(), 4.0f / 3.0f, 300, 400, false, 5);
        Mesh sh1 = loadObj(test::dataDir() + "/meshes/sh1.obj");
        objects.meshes.push_back(std::make_shared<TriangleGroups>(sh1, 5, objects.counts));
        objects.scene.geometries.push_back(objects.meshes.back());
        RenderSettings s;
        s.width = 40;
        s.height = 30;
        RayCounts raysWith, raysWithout;
        objects.setPretest(false);
        objects.counts->reset();
        Image without = renderImage(objects.scene, objects.scene.camera, s, &raysWithout);
        uint64_t testsWithout = objects.counts->primitiveTests.load();
        objects.setPretest(true);
        objects.counts->reset();
        Image with = renderImage(objects.scene, objects.scene.camera, s, &raysWith);
        uint64_t testsWith = objects.counts->primitiveTests.load();
        CHECK(with.pixels() == without.pixels());
        CHECK(raysWith.total() == raysWithout.total());
        CHECK(testsWith * 10 < testsWithout);
        CHECK(objects.counts->boxTests.load() > 0);
    }
    TEST_CASE("bad input: a sphere with a NaN or negative radius is refused") {
        auto counts = std::make_shared<TestCounts>();
        CHECK_THROWS_AS(SphereCloud({{{Vec3(0), std::nanf("")}, 0}}, counts),
                        std::invalid_argument);
        CHECK_THROWS_AS(SphereCloud({{{Vec3(0), -1.0f}, 0}}, counts), std::invalid_argument);
    }
}

TEST_SUITE("program 03") {
    const std::string program = test::stepProgram();
    const std::string small = " --spheres 200 --triangles 200";

    TEST_CASE("headless render writes a PNG of the requested size") {
        test::TempDir dir;
        test::runHeadless(program, dir, 64, 40, small);
    }
    TEST_CASE("measurements: the JSON report has the slab and pre-test tables") {
        test::TempDir dir;
        auto run = test::runHeadless(program, dir, 32, 24,
                                     "--measure --hard-rays 50 --measure-width 12 "
                                     "--measure-height 8 --scene spheres --report r.json");
        test::checkReportTables(dir.file("r.json"), {"slab_accuracy", "slab_hard_rays", "pretest"});
        test::checkVariantTables(dir.file("r.json"), {"slab_accuracy", "pretest"});
        test::checkParetoPlot(dir.file("r.json"), "slab_accuracy");
        CHECK(test::readText(dir.file("r.json")).find("\"pretest_pixels_differing\": 0") !=
              std::string::npos);
        CHECK(run.out.find("conservative (3.7)") != std::string::npos);
        // The heat maps show the pretest table's frames: each map's mean per ray (summed over
        // its pixels) is the table's count per ray (summed over the scene's objects).
        auto report = nlohmann::json::parse(test::readText(dir.file("r.json")));
        nlohmann::json pretest;
        for (const auto& t : report["tables"])
            if (t["id"] == "pretest") pretest = t;
        REQUIRE(pretest["rows"].size() == 2);
        const auto& without = pretest["rows"][0];
        const auto& with = pretest["rows"][1];
        const auto& facts = report["facts"];
        CHECK(facts["heat_primitive_tests_per_ray_without"].get<double>() ==
              doctest::Approx(without[5].get<double>()).epsilon(1e-12));
        CHECK(facts["heat_primitive_tests_per_ray_with"].get<double>() ==
              doctest::Approx(with[5].get<double>()).epsilon(1e-12));
        CHECK(facts["heat_box_tests_per_ray_with"].get<double>() ==
              doctest::Approx(with[6].get<double>()).epsilon(1e-12));
        CHECK(with[5].get<double>() < without[5].get<double>());  // the pre-test pays
        for (const char* map : {"a-heat-without.png", "a-heat-with.png", "a-heat-boxes.png"})
            CHECK(test::pngSize(dir.file(map)).first > 12 * 8);  // drawn large, with its bar
    }
    TEST_CASE("window: scripted frames with key presses under the offscreen video driver") {
        test::TempDir dir;
        test::runWindowScript(program, dir, "--scene spheres --width 64 --height 48", 4,
                              "b,Left,b");
    }
    TEST_CASE("bad input: one clear line and a non-zero exit") {
        test::TempDir dir;
        test::checkBadInput(program, dir,
                            {{"--scene nosuchscene", "unknown scene", 2},
                             {"--pretest maybe", "pretest", 2},
                             {"--spheres -3", "spheres", 2},
                             {"--frobnicate", "frobnicate", 2},
                             {"--scene missing.obj", "no such file", 1}});
    }
}

TEST_SUITE("hard cases 03") {
    TEST_CASE("hard case: a slab test hit exactly at t == tmin counts (closed interval)") {
        // The cube [-1, 1]^3 from z = 5 down: the ray is inside for t in [4, 6].
        const Bounds3f cube(Vec3(-1.0f), Vec3(1.0f));
        for (int conservative = 0; conservative < 2; ++conservative) {
            INFO((conservative ? "conservative" : "robust"));
            auto slab = [&](float tmin) {
                SlabRay ray(Ray(Vec3(0.2f, -0.3f, 5.0f), Vec3(0.0f, 0.0f, -1.0f), tmin));
                return conservative ? intersectSlabsConservative(ray, cube)
                                    : intersectSlabs(ray, cube);
            };
            auto atEntry = slab(4.0f);
            REQUIRE(atEntry.has_value());
            CHECK(atEntry->tnear == 4.0f);
            auto atExit = slab(6.0f);  // the interval [6, 6]: one point, still a hit
            REQUIRE(atExit.has_value());
            CHECK(atExit->tnear == 6.0f);
            if (!conservative) CHECK_FALSE(slab(nextFloatUp(6.0f)));
        }
    }
}
