// Step 06: the rasterizer's exercises with worked numbers, and the program. The
// rasterizer against the ray tracer (generated scenes and real meshes), its hard cases,
// shadows and culling are in step06_agreement.cpp.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <random>

#include "06_raster/compare.hpp"
#include "06_raster/measure.hpp"
#include "06_raster/pipeline.hpp"
#include "06_raster/raster.hpp"
#include "core/render.hpp"
#include "support.hpp"

using namespace boxes;
using boxes::test::checkVec;

namespace {

// Test-local fill-rule rasterizer: our own exact edge function, the student's top-left rule.
int64_t localEdge(FixedPoint2 a, FixedPoint2 b, FixedPoint2 p) {
    return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}
void coverWithRule(FixedPoint2 v0, FixedPoint2 v1, FixedPoint2 v2, int width, int height,
                   std::vector<int>& counts) {
    int64_t area = localEdge(v0, v1, v2);
    if (area == 0) return;
    if (area < 0) std::swap(v1, v2);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            FixedPoint2 p = pixelCentre(x, y);
            int64_t e0 = localEdge(v1, v2, p), e1 = localEdge(v2, v0, p), e2 = localEdge(v0, v1, p);
            bool in0 = e0 > 0 || (e0 == 0 && isTopLeftEdge(v1, v2));
            bool in1 = e1 > 0 || (e1 == 0 && isTopLeftEdge(v2, v0));
            bool in2 = e2 > 0 || (e2 == 0 && isTopLeftEdge(v0, v1));
            if (in0 && in1 && in2) ++counts[size_t(y * width + x)];
        }
}

// A pixel position in fixed point from whole and half pixels.
FixedPoint2 at(double x, double y) {
    return snapToSubpixel(x, y);
}

}  // namespace

TEST_SUITE("exercise 6.1") {
    TEST_CASE("a point through view and clip space") {
        // Eye (0,0,5) looking down -z, fov 90 (f = 1), aspect 2, near 1, far 11.
        Camera c = Camera::lookingAt(Vec3(0, 0, 5), Vec3(0, 0, 0), Vec3(0, 1, 0), 90.0f, 2.0f);
        Vec4d view = viewMatrix(c) * Vec4d(1.0, 0.5, 0.0, 1.0);
        checkVec(view, Vec4d(1.0, 0.5, -5.0, 1.0), 1e-12);
        CHECK(view.w == doctest::Approx(1.0));
        Vec4d clip = projectionMatrix(c, 1.0, 11.0) * view;
        // x: f/aspect * 1 = 0.5; y: f * 0.5; z: (12/10) 5 - 22/10 = 3.8; w = 5.
        checkVec(clip, Vec4d(0.5, 0.5, 3.8, 5.0), 1e-6);
        CHECK(clip.w == doctest::Approx(5.0).epsilon(1e-12));
        // GLM's default clip depth: the near plane at z/w = -1, the far plane at +1.
        Vec4d near = projectionMatrix(c, 1.0, 11.0) * Vec4d(0, 0, -1, 1);
        Vec4d far = projectionMatrix(c, 1.0, 11.0) * Vec4d(0, 0, -11, 1);
        CHECK(near.z / near.w == doctest::Approx(-1.0));
        CHECK(far.z / far.w == doctest::Approx(1.0));
    }
    TEST_CASE("pixel centres land where the ray tracer's primary rays go") {
        Camera c = Camera::lookingAt(Vec3(0.3f, 1.2f, 4.0f), Vec3(-0.2f, 0.1f, 0.0f), Vec3(0, 1, 0),
                                     50.0f, 1.5f);
        const int w = 90, h = 60;
        Mat4d m = projectionMatrix(c, 0.01, 100.0) * viewMatrix(c);
        for (auto [x, y] : {std::pair{0, 0}, {89, 59}, {45, 30}, {3, 57}}) {
            Vec3 d = c.directionThrough(float(x) + 0.5f, float(y) + 0.5f, w, h);
            Vec4d clip = m * Vec4d(glm::dvec3(c.eye + 3.0f * d), 1.0);
            // The viewport, test-local: row 0 at the top.
            double sx = (clip.x / clip.w + 1.0) * 0.5 * w, sy = (1.0 - clip.y / clip.w) * 0.5 * h;
            CHECK(sx == doctest::Approx(x + 0.5).epsilon(1e-5));
            CHECK(sy == doctest::Approx(y + 0.5).epsilon(1e-5));
            CHECK(clip.w == doctest::Approx(3.0 * glm::dot(d, c.basis().forward)).epsilon(1e-5));
        }
    }
    TEST_CASE("hard case: view parallel to up gives a finite view matrix") {
        Camera c = Camera::lookingAt(Vec3(0, 5, 0), Vec3(0, 0, 0), Vec3(0, 1, 0), 60.0f, 1.0f);
        Mat4d v = viewMatrix(c);
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) CHECK(std::isfinite(v[i][j]));
        Vec4d p = v * Vec4d(0, 0, 0, 1);
        checkVec(p, Vec4d(0, 0, -5, 1), 1e-6);
    }
}

TEST_SUITE("exercise 6.2") {
    TEST_CASE("clip to screen: divide by w and the viewport with row 0 at the top") {
        glm::dvec3 s = clipToScreen(Vec4d(0.5, 0.5, 3.8, 5.0), 8, 4);
        checkVec(s, glm::dvec3(4.4, 1.8, 0.76), 1e-12);
        checkVec(clipToScreen(Vec4d(-2, 2, 0, 2), 8, 4), glm::dvec3(0, 0, 0),
                 1e-12);  // top-left corner
        checkVec(clipToScreen(Vec4d(3, -3, 3, 3), 8, 4), glm::dvec3(8, 4, 1),
                 1e-12);  // bottom-right
    }
    TEST_CASE("clip to screen: a point with w other than 1 is divided by w") {
        // (2, 0, 1, 4) is the normalized point (0.5, 0, 0.25): x = 1.5 * 0.5 * 8 = 6.
        checkVec(clipToScreen(Vec4d(2, 0, 1, 4), 8, 4), glm::dvec3(6, 2, 0.25), 1e-12);
    }
}

TEST_SUITE("exercise 6.3") {
    ClipPolygon triangle(Vec4d a, Vec4d b, Vec4d c) {
        ClipPolygon p;
        p.add({a, {1, 0, 0}});
        p.add({b, {0, 1, 0}});
        p.add({c, {0, 0, 1}});
        return p;
    }
    TEST_CASE("a triangle crossing the near plane becomes a quad with the new vertices") {
        // a is outside (z + w = -1), b and c inside (z + w = 1).
        ClipPolygon out =
            clipAgainstPlane(triangle({0, 0, -2, 1}, {0, 0, 0, 1}, {1, 0, 0, 1}), kClipNearPlane);
        REQUIRE(out.count == 4);
        checkVec(out.vertices[0].position, Vec4d(0, 0, -1, 1), 1e-15);
        checkVec(out.vertices[0].weights, glm::dvec3(0.5, 0.5, 0), 1e-15);
        checkVec(out.vertices[1].position, Vec4d(0, 0, 0, 1), 0.0);
        checkVec(out.vertices[2].position, Vec4d(1, 0, 0, 1), 0.0);
        checkVec(out.vertices[3].position, Vec4d(0.5, 0, -1, 1), 1e-15);
        checkVec(out.vertices[3].weights, glm::dvec3(0.5, 0, 0.5), 1e-15);
        CHECK(out.vertices[3].position.w == 1.0);
        // Unequal distances, a 2 outside and b and c 1 inside: each crossing a third of the
        // way from its inside end, t = dIn / (dIn - dOut) = 1 / 3.
        ClipPolygon far =
            clipAgainstPlane(triangle({0, 0, -3, 1}, {0, 0, 0, 1}, {1, 0, 0, 1}), kClipNearPlane);
        REQUIRE(far.count == 4);
        checkVec(far.vertices[0].position, Vec4d(0, 0, -1, 1), 1e-15);
        checkVec(far.vertices[0].weights, glm::dvec3(1.0 / 3.0, 2.0 / 3.0, 0), 1e-15);
        checkVec(far.vertices[3].position, Vec4d(2.0 / 3.0, 0, -1, 1), 1e-15);
        checkVec(far.vertices[3].weights, glm::dvec3(1.0 / 3.0, 0, 2.0 / 3.0), 1e-15);
    }
    TEST_CASE("clipping: the new vertices carry interpolated weights") {
        // a inside (z + w = 1), b outside (z + w = -3): the crossing a quarter of the way.
        ClipPolygon out =
            clipAgainstPlane(triangle({0, 0, 0, 1}, {0, 0, -4, 1}, {1, 0, 0, 1}), kClipNearPlane);
        REQUIRE(out.count == 4);
        checkVec(out.vertices[1].weights, glm::dvec3(0.75, 0.25, 0), 1e-15);
        checkVec(out.vertices[2].weights, glm::dvec3(0, 0.25, 0.75), 1e-15);
    }
    TEST_CASE("clipping: the edge from the last vertex back to the first is clipped too") {
        // a and b inside, c outside (z + w = -2): b -> c and the closing edge c -> a cross,
        // each a third of the way from its inside end.
        ClipPolygon out =
            clipAgainstPlane(triangle({0, 0, 0, 1}, {1, 0, 0, 1}, {0, 1, -3, 1}), kClipNearPlane);
        REQUIRE(out.count == 4);
        checkVec(out.vertices[3].position, Vec4d(0, 1.0 / 3.0, -1, 1), 1e-15);
    }
    TEST_CASE(
        "one vertex inside gives a smaller triangle while all inside stays and all outside "
        "goes") {
        ClipPolygon one =
            clipAgainstPlane(triangle({0, 0, 0, 1}, {0, 0, -3, 1}, {1, 0, -3, 1}), kClipNearPlane);
        REQUIRE(one.count == 3);
        for (int i = 0; i < 3; ++i)
            CHECK(glm::dot(kClipNearPlane, one.vertices[size_t(i)].position) >= -1e-15);
        ClipPolygon all =
            clipAgainstPlane(triangle({0, 0, 0, 1}, {1, 0, 0, 1}, {0, 1, 0, 1}), kClipNearPlane);
        CHECK(all.count == 3);
        ClipPolygon none =
            clipAgainstPlane(triangle({0, 0, -2, 1}, {1, 0, -2, 1}, {0, 1, -2, 1}), kClipNearPlane);
        CHECK(none.count == 0);
    }
    TEST_CASE("hard case: a triangle through w = 0 keeps only its part in front of the eye") {
        // One vertex behind the eye (w < 0); after clipping every w is positive, so the
        // divide by w cannot wrap the triangle around or flip it.
        Mat4d p = glm::perspective(glm::radians(90.0), 1.0, 0.1, 100.0);
        ClipPolygon out = clipAgainstPlane(
            triangle(p * Vec4d(-1, -1, -2, 1), p * Vec4d(1, -1, -2, 1), p * Vec4d(0, -1, 3, 1)),
            kClipNearPlane);
        REQUIRE(out.count == 4);
        for (int i = 0; i < out.count; ++i)
            CHECK(out.vertices[size_t(i)].position.w >= 0.1 - 1e-12);
    }
    TEST_CASE("hard case: two triangles sharing a clipped edge get the same new vertex") {
        Vec4d a(0.3, 0.1, -3.0, 1.7), b(-0.4, 0.2, 2.0, 2.5), c(1, 1, 1, 2), d(-1, 2, 1, 2);
        ClipPolygon first = clipAgainstPlane(triangle(a, b, c), kClipNearPlane);
        ClipPolygon second = clipAgainstPlane(triangle(b, a, d), kClipNearPlane);
        // The new vertex on the shared edge: weights only on its two ends.
        auto onEdge = [&](const ClipPolygon& p) {
            for (int i = 0; i < p.count; ++i) {
                glm::dvec3 w = p.vertices[size_t(i)].weights;
                if (w.z == 0.0 && w.x > 0.0 && w.y > 0.0) return p.vertices[size_t(i)].position;
            }
            return Vec4d(NAN);
        };
        Vec4d p1 = onEdge(first), p2 = onEdge(second);
        CHECK(p1 == p2);  // bit for bit
    }
}

TEST_SUITE("exercise 6.4") {
    TEST_CASE("edge function: side and twice the signed area") {
        FixedPoint2 a{0, 0}, b{4, 0}, c{0, 4}, p{1, 3};
        CHECK(edgeFunction(a, b, p) == 12);
        CHECK(edgeFunction(b, a, p) == -12);
        CHECK(edgeFunction(a, b, c) == 16);
        CHECK(edgeFunction(a, b, FixedPoint2{7, 0}) == 0);
        CHECK(edgeFunction(a, b, FixedPoint2{1, -2}) == -8);
    }
    TEST_CASE("edge function: an edge away from the origin") {
        // (b - a) x (p - a) with a = (2, 1), b = (6, 1), p = (3, 4): 4 * 3 - 0 * 1 = 12.
        CHECK(edgeFunction(FixedPoint2{2, 1}, FixedPoint2{6, 1}, FixedPoint2{3, 4}) == 12);
    }
    TEST_CASE("hard case: exactly opposite on a shared edge far from the origin") {
        FixedPoint2 a{123456789, -98765432}, b{-23456789, 87654321};
        std::mt19937_64 rng(3);
        std::uniform_int_distribution<int64_t> u(-200000000, 200000000);
        for (int i = 0; i < 1000; ++i) {
            FixedPoint2 p{u(rng), u(rng)};
            CHECK(edgeFunction(a, b, p) == -edgeFunction(b, a, p));
        }
    }
}

TEST_SUITE("exercise 6.5") {
    TEST_CASE("top and left edges of a clockwise triangle on a y-down screen") {
        FixedPoint2 a{0, 0}, b{4, 0}, c{0, 4};
        CHECK(isTopLeftEdge(a, b));        // horizontal, to +x: top
        CHECK_FALSE(isTopLeftEdge(b, c));  // runs down: right
        CHECK(isTopLeftEdge(c, a));        // runs up: left
        CHECK_FALSE(isTopLeftEdge(b, a));  // horizontal, to -x: bottom
    }
    TEST_CASE("two triangles sharing an edge through pixel centres: every pixel exactly once") {
        // A square split along its diagonal, corners on pixel centres: the diagonal and the
        // square's sides pass through pixel centres.
        const int w = 12, h = 12;
        std::vector<int> counts(size_t(w * h), 0);
        FixedPoint2 a = at(1.5, 1.5), b = at(9.5, 1.5), c = at(9.5, 9.5), d = at(1.5, 9.5);
        coverWithRule(a, b, c, w, h, counts);
        coverWithRule(a, c, d, w, h, counts);
        int covered = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                int n = counts[size_t(y * w + x)];
                CHECK(n <= 1);
                covered += n;
                bool interior = x >= 2 && x <= 8 && y >= 2 && y <= 8;
                if (interior) CHECK(n == 1);
            }
        // The top and left sides belong to the square, the bottom and right do not: 8 x 8.
        CHECK(covered == 64);
        for (int k = 1; k <= 8; ++k) {
            INFO("row or column " << k);
            CHECK(counts[size_t(k * w + 1)] == 1);  // on the left side
            CHECK(counts[size_t(1 * w + k)] == 1);  // on the top side
            CHECK(counts[size_t(k * w + 9)] == 0);  // on the right side
            CHECK(counts[size_t(9 * w + k)] == 0);  // on the bottom side
        }
    }
    TEST_CASE("a fan of triangles around one vertex: every covered pixel exactly once") {
        const int w = 24, h = 24;
        std::vector<int> counts(size_t(w * h), 0);
        FixedPoint2 centre = at(12.5, 12.5);
        // 12 fan triangles with rim vertices on pixel centres, both windings mixed.
        std::vector<FixedPoint2> rim = {at(20.5, 12.5), at(19.5, 17.5), at(16.5, 20.5),
                                        at(12.5, 21.5), at(7.5, 19.5),  at(4.5, 16.5),
                                        at(3.5, 12.5),  at(4.5, 7.5),   at(8.5, 4.5),
                                        at(12.5, 3.5),  at(17.5, 4.5),  at(20.5, 8.5)};
        for (size_t i = 0; i < rim.size(); ++i) {
            FixedPoint2 p = rim[i], q = rim[(i + 1) % rim.size()];
            if (i % 2)
                coverWithRule(centre, p, q, w, h, counts);
            else
                coverWithRule(q, centre, p, w, h, counts);
        }
        // Strictly inside the rim polygon: exactly once; anywhere: at most once.
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                FixedPoint2 p = pixelCentre(x, y);
                bool strictlyInside = true;
                for (size_t i = 0; i < rim.size(); ++i)
                    strictlyInside =
                        strictlyInside && localEdge(rim[i], rim[(i + 1) % rim.size()], p) < 0;
                int n = counts[size_t(y * w + x)];
                INFO("pixel " << x << "," << y);
                CHECK(n <= 1);
                if (strictlyInside) CHECK(n == 1);
            }
        CHECK(counts[size_t(12 * w + 12)] == 1);  // the shared vertex's pixel
    }
}

TEST_SUITE("exercise 6.6") {
    TEST_CASE("z-buffer: nearer wins and a tie keeps the first") {
        float stored = kInfinity<float>;
        CHECK(depthTest(stored, 2.0f));
        CHECK(stored == 2.0f);
        CHECK_FALSE(depthTest(stored, 2.0f));  // the tie: the first triangle keeps the pixel
        CHECK_FALSE(depthTest(stored, 3.0f));
        CHECK(depthTest(stored, 1.0f));
        CHECK(stored == 1.0f);
        {
            // A NaN depth is this check's input, not a result of the pipeline: the ordered
            // comparison `incoming < stored` raises FE_INVALID for it (IEEE 754).
            test::FpTrapsOff nanOnPurpose;
            CHECK_FALSE(depthTest(stored, NAN));
        }
        CHECK(stored == 1.0f);
    }
    TEST_CASE("z-buffer: the nearer depth is stored for the next triangle") {
        float stored = kInfinity<float>;
        REQUIRE(depthTest(stored, 4.0f));
        CHECK(stored == 4.0f);
        CHECK_FALSE(depthTest(stored, 5.0f));  // behind the first triangle
    }
    TEST_CASE("z-buffer: a farther fragment is rejected") {
        float stored = 2.0f;
        CHECK_FALSE(depthTest(stored, 7.0f));
        CHECK(stored == 2.0f);
    }
}

TEST_SUITE("exercise 6.7") {
    TEST_CASE("perspective-correct weights: worked numbers") {
        // Screen weights 1/3 each, w = 1, 2, 4: (1/3, 1/6, 1/12) / (7/12) = (4/7, 2/7, 1/7).
        glm::dvec3 l = perspectiveCorrectWeights(glm::dvec3(1.0 / 3.0), glm::dvec3(1, 2, 4));
        checkVec(l, glm::dvec3(4.0 / 7.0, 2.0 / 7.0, 1.0 / 7.0), 1e-15);
        // Equal w: the screen weights themselves.
        checkVec(perspectiveCorrectWeights(glm::dvec3(0.2, 0.3, 0.5), glm::dvec3(3.0)),
                 glm::dvec3(0.2, 0.3, 0.5), 1e-15);
    }
    TEST_CASE("a known attribute: the 3D barycentrics of a projected point are recovered") {
        // Camera-space vertices (looking down -z), w = -z; the point P = 0.2 A + 0.3 B + 0.5 C.
        glm::dvec3 A(-1, -1, -2), B(1, -1, -4), C(0, 1, -8);
        glm::dvec3 P = 0.2 * A + 0.3 * B + 0.5 * C;
        auto project = [](glm::dvec3 p) { return glm::dvec2(p.x / -p.z, p.y / -p.z); };
        glm::dvec2 a = project(A), b = project(B), c = project(C), p = project(P);
        auto cross = [](glm::dvec2 u, glm::dvec2 v) { return u.x * v.y - u.y * v.x; };
        double area = cross(b - a, c - a);
        glm::dvec3 screen(cross(c - b, p - b) / area, cross(a - c, p - c) / area,
                          cross(b - a, p - a) / area);
        glm::dvec3 l = perspectiveCorrectWeights(screen, glm::dvec3(2, 4, 8));
        checkVec(l, glm::dvec3(0.2, 0.3, 0.5), 1e-12);
        // The affine (screen) weights are not the 3D ones: that is the warp.
        CHECK(std::abs(screen.x - 0.2) > 0.05);
    }
    TEST_CASE("perspective-correct weights: they sum to 1") {
        glm::dvec3 l = perspectiveCorrectWeights(glm::dvec3(0.5, 0.25, 0.25), glm::dvec3(2, 3, 5));
        CHECK(l.x + l.y + l.z == doctest::Approx(1.0).epsilon(1e-15));
    }
}

TEST_SUITE("exercise 6.8") {
    TEST_CASE("shadow map lookup: in front lit and behind shadowed and the bias") {
        ShadowMap map;
        map.size = 2;
        map.viewProjection =
            glm::perspective(glm::radians(90.0), 1.0, 1.0, 100.0);  // light at 0 looking down -z
        map.depth = {kInfinity<float>, 5.0f, kInfinity<float>, kInfinity<float>};
        // (0.5, 0.5, -4): w = 4, screen (1.125, 0.875): texel (1, 0), stored depth 5.
        CHECK(litByShadowMap(map, Vec3(0.5f, 0.5f, -4.0f), 0.0));
        CHECK_FALSE(litByShadowMap(map, Vec3(1.25f, 1.25f, -10.0f), 0.0));  // w = 10 behind 5
        CHECK(litByShadowMap(map, Vec3(1.25f, 1.25f, -10.0f), 6.0));        // 10 - 6 <= 5
        CHECK_FALSE(litByShadowMap(map, Vec3(1.25f, 1.25f, -10.0f), 4.0));
        CHECK(litByShadowMap(map, Vec3(-1.0f, 1.0f, -10.0f), 0.0));  // an empty texel
        CHECK(litByShadowMap(map, Vec3(0.5f, 0.5f, 4.0f), 0.0));     // behind the light
        CHECK(litByShadowMap(map, Vec3(50.0f, 0.5f, -4.0f), 0.0));   // outside the map
    }
    // A 2 x 2 map from the light at the origin looking down -z; only texel (1, 0), the
    // top right, holds an occluder, at depth 5.
    ShadowMap topRightMap() {
        ShadowMap map;
        map.size = 2;
        map.viewProjection = glm::perspective(glm::radians(90.0), 1.0, 1.0, 100.0);
        map.depth = {kInfinity<float>, 5.0f, kInfinity<float>, kInfinity<float>};
        return map;
    }
    TEST_CASE("shadow map lookup: the bias lets a point just behind the stored depth be lit") {
        // w = 5.5, 0.5 behind the stored 5: a bias of 1 accepts it as the same surface.
        CHECK(litByShadowMap(topRightMap(), Vec3(0.5f, 0.5f, -5.5f), 1.0));
    }
    TEST_CASE("shadow map lookup: a point less than one unit from the light is shadowed too") {
        // The light's near plane at 0.1: (0.25, 0.25, -0.8) has w = 0.8, screen (1.3125,
        // 0.6875), texel (1, 0), where an occluder at depth 0.5 lies between it and the light.
        ShadowMap map;
        map.size = 2;
        map.viewProjection = glm::perspective(glm::radians(90.0), 1.0, 0.1, 100.0);
        map.depth = {kInfinity<float>, 0.5f, kInfinity<float>, kInfinity<float>};
        CHECK_FALSE(litByShadowMap(map, Vec3(0.25f, 0.25f, -0.8f), 0.0));
        CHECK(litByShadowMap(map, Vec3(0.25f, 0.25f, -0.8f), 0.5));  // 0.8 - 0.5 <= 0.5
    }
    TEST_CASE("shadow map lookup: the texel row counts from the top") {
        // Up and right (y > 0) is row 0: the occluder's texel; down and right is row 1, empty.
        CHECK_FALSE(litByShadowMap(topRightMap(), Vec3(2.0f, 2.0f, -10.0f), 0.0));
        CHECK(litByShadowMap(topRightMap(), Vec3(2.0f, -2.0f, -10.0f), 0.0));
    }
}

TEST_SUITE("exercise 6.9") {
    TEST_CASE("hybrid shadow ray: the point's own surface does not shadow it") {
        // A point on a floor plane lit from above: the ray starts on the plane (t = 0).
        Scene s;
        s.lights.push_back({Vec3(0, 10, 0), Vec3(100.0f), kInfinity<float>});
        s.planes.push_back({{Vec3(0, 1, 0), 0.0f}, 0});
        CHECK(litByShadowRay(s, Vec3(3, 0, 0), Vec3(0, 1, 0), s.lights[0]));
    }
    TEST_CASE("hybrid shadow ray: an occluder between the point and the light") {
        Scene s;
        s.lights.push_back({Vec3(0, 10, 0), Vec3(100.0f), kInfinity<float>});
        const PointLight& light = s.lights[0];
        CHECK(litByShadowRay(s, Vec3(0, 0, 0), Vec3(0, 1, 0), light));
        s.spheres.push_back({{Vec3(0, 5, 0), 1.0f}, 0});
        CHECK_FALSE(litByShadowRay(s, Vec3(0, 0, 0), Vec3(0, 1, 0), light));
        CHECK(litByShadowRay(s, Vec3(3, 0, 0), Vec3(0, 1, 0), light));
        // A point on a floor plane does not shadow itself (the origin is offset).
        s.planes.push_back({{Vec3(0, 1, 0), 0.0f}, 0});
        CHECK(litByShadowRay(s, Vec3(3, 0, 0), Vec3(0, 1, 0), light));
        // Between the sphere and the light: the sphere behind the point does not shadow it.
        CHECK(litByShadowRay(s, Vec3(0, 7, 0), Vec3(0, 1, 0), light));
    }
    TEST_CASE("hybrid shadow ray: an occluder beyond the light does not shadow the point") {
        // The light at y = 10, spheres above it (the nearest surface at y = 10.5): a shadow
        // ray that does not stop at the light hits them.
        Scene s;
        s.lights.push_back({Vec3(0, 10, 0), Vec3(100.0f), kInfinity<float>});
        s.spheres.push_back({{Vec3(0, 11.5f, 0), 1.0f}, 0});
        s.spheres.push_back({{Vec3(3, 40, 0), 5.0f}, 0});
        const PointLight& light = s.lights[0];
        CHECK(litByShadowRay(s, Vec3(0, 0, 0), Vec3(0, 1, 0), light));
        CHECK(litByShadowRay(s, Vec3(-0.3f, 1, 0), Vec3(0, 1, 0), light));
        // The same sphere between the point and the light does shadow it.
        s.spheres.push_back({{Vec3(0, 5, 0), 1.0f}, 0});
        CHECK_FALSE(litByShadowRay(s, Vec3(0, 0, 0), Vec3(0, 1, 0), light));
    }
}

TEST_SUITE("program 06") {
    const std::string program = test::stepProgram();

    TEST_CASE("headless render writes a PNG and the ids and depth buffers") {
        test::TempDir dir;
        auto run = test::runHeadless(program, dir, 64, 40,
                                     "--scene sh1 --ids a.ids --depth a.depth --json");
        std::string ids = test::readText(dir.file("a.ids")),
                    depth = test::readText(dir.file("a.depth"));
        REQUIRE(ids.size() == 64 * 40 * 4);
        REQUIRE(depth.size() == 64 * 40 * 4);
        size_t covered = 0;
        for (size_t i = 0; i < 64 * 40; ++i) {
            uint32_t id;
            float d;
            std::memcpy(&id, ids.data() + 4 * i, 4);
            std::memcpy(&d, depth.data() + 4 * i, 4);
            CHECK((id == kNoPrimitive) == std::isinf(d));
            if (id != kNoPrimitive) {
                ++covered;
                CHECK(id < 3290u);
                CHECK(d > 0.0f);
            }
        }
        CHECK(covered > 200);
        CHECK(run.out.find("\"triangles_drawn\"") != std::string::npos);
        CHECK(run.out.find("\"boxes_culled\"") != std::string::npos);
        CHECK(run.out.find("\"pixels_covered\": " + std::to_string(covered)) != std::string::npos);
    }
    TEST_CASE("compare mode prints the agreement and writes the difference image") {
        test::TempDir dir;
        auto run = test::runHeadless(program, dir, 64, 48, "--scene sh1 --compare");
        CHECK(run.out.find("same triangle:") != std::string::npos);
        CHECK(test::pngSize(dir.file("a-diff.png")) == std::pair{64, 48});
    }
    TEST_CASE("measurements: the JSON report has the step's tables") {
        test::TempDir dir;
        test::runHeadless(program, dir, 48, 36, "--measure --report r.json");
        test::checkReportTables(dir.file("r.json"),
                                {"visibility", "frame_time", "shadow_bias", "shadows",
                                 "interpolation", "culling", "vertex_precalc", "texture"});
        test::checkVariantTables(dir.file("r.json"), {"shadow_bias", "shadows", "interpolation",
                                                      "culling", "vertex_precalc", "texture"});
        test::checkParetoPlot(dir.file("r.json"), "shadows");
        CHECK(test::pngSize(dir.file("a-affine.png")) == std::pair{48, 36});
        for (const char* png : {"a-texture.png", "a-texture-affine.png", "a-texture-traced.png"})
            CHECK(test::pngSize(dir.file(png)) == std::pair{48, 36});
    }
    TEST_CASE("the textured floor: perspective-correct shows the ray tracer's texels") {
        test::TempDir dir;
        auto run = test::runHeadless(program, dir, 64, 48, "--floor-texture --compare");
        CHECK(test::pngSize(dir.file("a-traced.png")) == std::pair{64, 48});
        CHECK(run.out.find("textured floor (perspective-correct): 0 of ") != std::string::npos);
        auto affine = test::runHeadless(program, dir, 64, 48, "--floor-texture --affine --compare");
        CHECK(affine.out.find("textured floor (affine): ") != std::string::npos);
        CHECK(affine.out.find("textured floor (affine): 0 of ") == std::string::npos);
    }
    TEST_CASE("window: scripted frames with key presses under the offscreen video driver") {
        test::TempDir dir;
        test::runWindowScript(program, dir, "--scene sh1 --width 64 --height 48", 8,
                              "r,d,h,b,p,f,Left");
    }
    TEST_CASE("window: the textured floor rasterized and ray traced under the offscreen driver") {
        test::TempDir dir;
        test::runWindowScript(program, dir, "--floor-texture --width 64 --height 48", 6, "p,r");
    }
    TEST_CASE("bad input: one clear line and a non-zero exit") {
        test::TempDir dir;
        std::ofstream(dir.file("nan.obj")) << "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n";
        test::checkBadInput(program, dir,
                            {{"--scene sh1 --eye 1,2,3 --look 1,2,3", "view direction is zero", 2},
                             {"--scene sh1 --near 0", "--near", 2},
                             {"--scene sh1 --near -2", "--near", 2},
                             {"--scene sh1 --near 2 --far 1", "--far", 2},
                             {"--scene sh1 --width 0", "width", 2},
                             {"--scene sh1 --height 0", "height", 2},
                             {"--scene nan.obj", "non-finite", 1},
                             {"--scene sh1 --shadows sometimes", "shadows", 2}});
    }
    TEST_CASE("a view parallel to up renders") {
        test::TempDir dir;
        test::runHeadless(program, dir, 32, 24,
                          "--scene sh1 --eye 176,100,-112 --look 176,0,-112 --up 0,1,0");
    }
}
