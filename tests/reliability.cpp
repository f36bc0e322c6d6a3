// Reliability hard cases: a renderer that survives NaN or infinite scenes, zero-area and
// identical triangles and a camera inside an object, each with a clear error or a correct
// image; step 04's hierarchy on the same cases, and its leaf test against exercise 1.5's
// bits. The files read and the command lines are in reliability_obj.cpp and
// reliability_flags.cpp.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>

#include "01_triangle/triangle.hpp"
#include "01_triangle/triangle_grid.hpp"
#include "04_bvh/advanced/rays.hpp"
#include "core/mesh.hpp"
#include "core/render.hpp"
#include "core/scene.hpp"
#include "reliability_support.hpp"
#include "step04_support.hpp"
#include "support.hpp"

using namespace boxes;
using test::cube;
using test::refusal;

namespace {

// One triangle facing the camera, lit from the front; the mesh as given.
struct TriangleScene {
    Scene scene;
    explicit TriangleScene(Mesh mesh) {
        scene.name = "triangle";
        scene.mesh = std::move(mesh);
        scene.lights.push_back({Vec3(0.5f, 0.5f, 4.0f), Vec3(20.0f), kInfinity<float>});
        scene.camera.eye = Vec3(0.3f, 0.3f, 3.0f);
        scene.camera.view = Vec3(0, 0, -1);
        scene.geometries.push_back(std::make_shared<TriangleGrid>(scene.mesh, 0));
    }
    Image render(int width, int height) const {
        RenderSettings settings;
        settings.width = width;
        settings.height = height;
        settings.threads = 2;
        Camera camera = scene.camera;
        camera.aspect = float(width) / float(height);
        return renderImage(scene, camera, settings);
    }
};

Mesh oneTriangle() {
    Mesh m;
    m.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0.2f), Vec3(0, 1, -0.1f)};
    m.triangles = {{0, 1, 2}};
    m.computeVertexNormals();
    return m;
}

double maxDifference(const Image& a, const Image& b) {
    double worst = 0.0;
    for (int y = 0; y < a.height(); ++y)
        for (int x = 0; x < a.width(); ++x)
            for (int c = 0; c < 3; ++c)
                worst = std::max(worst, double(std::abs(a.at(x, y)[c] - b.at(x, y)[c])));
    return worst;
}

}  // namespace
TEST_SUITE("hard cases reliability") {
    TEST_CASE("hard case: vertex normals of tiny and huge triangles have unit length") {
        // A triangle of size 1e-10 has a cross product of 1e-20, whose squared length is
        // subnormal: the normal came out of length 0.6 (found by fuzzing,
        // fuzz/corpus/obj/crash-0376038b...). One of size 1e38 overflowed to NaN.
        for (float size : {1e-10f, 1e-19f, 1e-30f, 1e19f, 1e38f}) {
            INFO(size);
            Mesh m;
            m.positions = {Vec3(0), Vec3(size, 0, 0), Vec3(0, 0, size)};
            m.triangles = {{0, 1, 2}};
            m.computeVertexNormals();
            for (const Vec3& n : m.normals) {
                CHECK(glm::length(n) == doctest::Approx(1.0f).epsilon(1e-6));
                CHECK(n.y == doctest::Approx(-1.0f).epsilon(1e-6));
            }
        }
    }
    TEST_CASE("hard case: a scene with a NaN or infinite sphere or light is refused") {
        auto refused = [](const Scene& scene) {
            try {
                Renderer renderer(scene, scene.camera, RenderSettings{});
            } catch (const InputError& e) {
                return std::string(e.what());
            }
            return std::string("(accepted)");
        };
        Scene base = makeScene("single-sphere", SceneOptions{});
        CHECK(refused(base) == "(accepted)");
        Scene s = base;
        s.spheres[0].shape.centre.y = std::nanf("");
        CHECK(refused(s) == "scene 'single-sphere': sphere 0 has a non-finite or invalid value");
        s = base;
        s.spheres[0].shape.radius = kInfinity<float>;
        CHECK(refused(s).find("sphere 0") != std::string::npos);
        s = base;
        s.lights[0].position.x = std::nanf("");
        CHECK(refused(s) == "scene 'single-sphere': light 0 has a non-finite or invalid value");
        s = base;
        s.lights[0].intensity = Vec3(kInfinity<float>);
        CHECK(refused(s).find("light 0") != std::string::npos);
        s = base;
        s.planes.push_back({{Vec3(0, 1, 0), -kInfinity<float>}, 0});
        CHECK(refused(s).find("plane 0") != std::string::npos);
    }
    TEST_CASE("hard case: a mesh vertex made NaN after loading is refused by the renderer") {
        Mesh mesh = oneTriangle();
        TriangleScene good(mesh);
        mesh.positions[1].x = std::nanf("");
        Scene s;
        s.name = "nan-mesh";
        s.mesh = mesh;
        s.geometries = good.scene.geometries;  // any geometry: the mesh check comes first
        CHECK_THROWS_WITH_AS(Renderer(s, good.scene.camera, RenderSettings{}),
                             "scene 'nan-mesh' mesh: vertex 2 has a non-finite coordinate",
                             InputError);
    }
    TEST_CASE("hard case: zero-area triangles render as if absent") {
        Mesh clean = oneTriangle();
        Mesh withDegenerate = clean;
        // A point, a segment, and a segment crossing the triangle's interior.
        withDegenerate.positions.insert(withDegenerate.positions.end(),
                                        {Vec3(0.2f, 0.2f, 0.05f), Vec3(0, 0, 0), Vec3(1, 1, 0),
                                         Vec3(0.5f, 0.5f, 0.0f), Vec3(0.1f, 0.1f, 0.0f)});
        withDegenerate.triangles.push_back({3, 3, 3});
        withDegenerate.triangles.push_back({4, 5, 6});
        withDegenerate.triangles.push_back({6, 7, 6});
        withDegenerate.computeVertexNormals();
        Image expected = TriangleScene(clean).render(48, 36);
        Image actual = TriangleScene(withDegenerate).render(48, 36);
        CHECK(maxDifference(expected, actual) == 0.0);
        for (int y = 0; y < actual.height(); ++y)
            for (int x = 0; x < actual.width(); ++x) REQUIRE(isFinite(actual.at(x, y)));
    }
    TEST_CASE("hard case: 100000 identical triangles through the uniform grid") {
        // Every copy overlaps every cell: the grid used to ask for ~10^10 cell entries
        // (overflowing its 32-bit counts); it now coarsens to a bounded number.
        Mesh one = oneTriangle();
        Mesh many = one;
        many.triangles.assign(100000, one.triangles[0]);
        Image expected = TriangleScene(one).render(12, 9);
        Image actual = TriangleScene(many).render(12, 9);
        CHECK(maxDifference(expected, actual) == 0.0);
    }
    TEST_CASE("hard case: a million identical triangles build a grid of bounded size") {
        Mesh one = oneTriangle();
        Mesh many = one;
        many.triangles.assign(1000000, one.triangles[0]);
        TriangleGrid grid(many, 0);
        float t = 0.0f;
        uint32_t hit = grid.nearestTriangle(Ray(Vec3(0.2f, 0.2f, 3.0f), Vec3(0, 0, -1)),
                                            TriangleTest::Watertight, &t);
        CHECK(hit < 1000000u);
        // The plane through the triangle: z = 0.2 x - 0.1 y.
        CHECK(t == doctest::Approx(3.0 - (0.2 * 0.2 - 0.1 * 0.2)).epsilon(1e-5));
    }
    TEST_CASE("hard case: the camera inside a sphere sees its inside unlit") {
        // The light is outside a closed sphere: inside, only the ambient term remains. The
        // renderer skipped shadow rays for convex objects even for hits from inside, so
        // the far side of the inner wall was lit.
        Scene scene = makeScene("single-sphere", SceneOptions{});
        scene.camera.eye = Vec3(0.0f, 0.0f, 0.2f);
        for (Vec3 view : {Vec3(0, 0, -1), Vec3(0.6f, -0.8f, 0.1f)}) {
            scene.camera.view = view;
            RenderSettings settings;
            settings.width = 32;
            settings.height = 24;
            settings.threads = 2;
            scene.camera.aspect = 32.0f / 24.0f;
            Image image = renderImage(scene, scene.camera, settings);
            Vec3 ambientOnly = scene.ambient * scene.materials[0].albedo;
            for (int y = 0; y < image.height(); ++y)
                for (int x = 0; x < image.width(); ++x) {
                    INFO("pixel " << x << " " << y);
                    REQUIRE(maxComponent(glm::abs(image.at(x, y) - ambientOnly)) < 1e-6f);
                }
        }
    }
}

// Step 04's hierarchy (build and the trace command's path) on the same hard cases.
TEST_SUITE("hard cases reliability") {
    TEST_CASE("hard case: BVH over a million identical triangles builds bounded and traces") {
        // Identical centroids: no split plane separates them; every builder must still
        // stop (depth cap, leaves of bounded size) and the nearest hit is the triangle.
        Mesh one = oneTriangle();
        Mesh many = one;
        many.triangles.assign(1000000, one.triangles[0]);
        for (BvhBuilder b : {BvhBuilder::BinnedSah, BvhBuilder::Midpoint}) {
            INFO(std::string(bvhBuilderName(b)));
            BvhBuildOptions options;
            options.builder = b;
            BvhBuildStats stats;
            Bvh bvh = buildBvh(many, options, &stats);
            CHECK(stats.depth <= options.maxDepth);
            CHECK(bvh.nodes.size() < 2 * many.triangleCount());
            Ray ray(Vec3(0.2f, 0.2f, 3.0f), Vec3(0, 0, -1));
            TraceHit hit = traceNearest(bvh, ray);
            CHECK(hit.triangle < 1000000u);
            // The plane through the triangle: z = 0.2 x - 0.1 y.
            CHECK(hit.t == doctest::Approx(3.0 - (0.2 * 0.2 - 0.1 * 0.2)).epsilon(1e-5));
            CHECK(traceOccluded(bvh, ray));
            CHECK(traceNearest(bvh, Ray(Vec3(2.0f, 2.0f, 3.0f), Vec3(0, 0, -1))).triangle ==
                  kNoPrimitive);
        }
    }
    TEST_CASE("hard case: BVH zero-area triangles are never hit") {
        Mesh clean = cube();
        Mesh withDegenerate = clean;
        size_t base = withDegenerate.positions.size();
        // A point, a segment across a face, and a segment through the cube's inside.
        withDegenerate.positions.insert(withDegenerate.positions.end(),
                                        {Vec3(0.3f, 0.2f, -1.0f), Vec3(-1, -1, -1), Vec3(1, 1, -1),
                                         Vec3(-1, -1, 1), Vec3(0, 0, 0)});
        withDegenerate.triangles.push_back({uint32_t(base), uint32_t(base), uint32_t(base)});
        withDegenerate.triangles.push_back(
            {uint32_t(base + 1), uint32_t(base + 2), uint32_t(base + 1)});
        withDegenerate.triangles.push_back(
            {uint32_t(base + 3), uint32_t(base + 4), uint32_t(base + 4)});
        Bvh bvh = buildBvh(withDegenerate, BvhBuildOptions{});
        std::vector<Ray> rays = makeRays(clean, RayKind::Random, 2000, 7);
        rays.emplace_back(Vec3(0.3f, 0.2f, -5.0f), Vec3(0, 0, 1));  // at the point
        rays.emplace_back(Vec3(0.1f, 0.1f, -5.0f), Vec3(0, 0, 1));  // along the segment
        for (const Ray& ray : rays) {
            TraceHit got = traceNearest(bvh, ray), want = traceBruteForce(clean, ray);
            // A miss, or one of the cube's own triangles (the degenerate ones come after).
            REQUIRE((got.triangle == kNoPrimitive || got.triangle < clean.triangleCount()));
            REQUIRE(hitsAgree(got, want));
        }
    }
    TEST_CASE("hard case: BVH rays from inside a closed mesh hit its inner walls") {
        // A camera inside an object: every ray leaves through a wall, at the distance
        // to the wall along the ray.
        Mesh m = cube();
        Bvh bvh = buildBvh(m, BvhBuildOptions{});
        Vec3 eye(0.2f, -0.3f, 0.1f);
        std::vector<Ray> rays = makeRays(m, RayKind::Random, 500, 3);
        for (const Ray& r : rays) {
            Ray ray(eye, r.direction);
            TraceHit hit = traceNearest(bvh, ray);
            REQUIRE(hit.triangle != kNoPrimitive);
            double exit = kInfinity<double>;
            for (int axis = 0; axis < 3; ++axis) {
                double d = ray.direction[axis], o = ray.origin[axis];
                if (d != 0.0) exit = std::min(exit, ((d > 0.0 ? 1.0 : -1.0) - o) / d);
            }
            REQUIRE(hit.t == doctest::Approx(exit).epsilon(1e-5));
        }
    }
    TEST_CASE("hard case: BVH trace input with NaN or infinity is refused with a message") {
        // The trace command reads the mesh through parseObj and the rays through readRays:
        // both refuse a NaN or an infinity with the line or ray that has it, before any
        // hierarchy is built.
        CHECK(refusal("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n") ==
              "x.obj:2: coordinate 'nan' is non-finite");
        CHECK(refusal("v 0 0 0\nv 1 0 inf\nv 0 1 0\nf 1 2 3\n") ==
              "x.obj:2: coordinate 'inf' is non-finite");
        auto rayRefusal = [](std::vector<float> record) {
            try {
                parseRays(record.data(), record.size() * sizeof(float), "rays file 'r.bin'");
            } catch (const InputError& e) {
                return std::string(e.what());
            }
            return std::string("(accepted)");
        };
        const float nan = std::nanf(""), inf = kInfinity<float>;
        CHECK(rayRefusal({0, 0, 0, 0, 0, 0, 1, inf}) == "(accepted)");
        CHECK(rayRefusal({0, 0, 0, 0, 0, 0, 1, inf, 0, nan, 0, 0, 0, 0, 1, inf}) ==
              "rays file 'r.bin': ray 1: NaN value");
        CHECK(rayRefusal({0, 0, 0, 0, inf, 0, 1, inf}) ==
              "rays file 'r.bin': ray 0: infinite origin or direction");
        CHECK(rayRefusal({0, 0, 0, 0, 0, -0.0f, 0, 1}) ==
              "rays file 'r.bin': ray 0: zero direction");
        // A subnormal direction made a hit at t = -infinity (found by fuzzing).
        CHECK(rayRefusal({0.3f, 0.2f, 5, -inf, 0, 5.9e-39f, 2.3e-38f, 0}) ==
              "rays file 'r.bin': ray 0: direction too short (largest component below 2^-32)");
        CHECK(rayRefusal({0, 0, 0, 0, 0, 0, 0x1p-32f, 1}) == "(accepted)");
        CHECK(rayRefusal({0, 0, 0, 0, 0, 0}) ==
              "rays file 'r.bin': size 24 bytes is not a multiple of 32 (8 float32 per ray)");
        // tmin > tmax is an empty interval: read, and a miss.
        Mesh m = cube();
        Bvh bvh = buildBvh(m, BvhBuildOptions{});
        std::vector<float> empty = {0, 0, -5, 5, 0, 0, 1, 3};
        std::vector<Ray> rays = parseRays(empty.data(), 32, "r.bin");
        CHECK(traceNearest(bvh, rays[0]).triangle == kNoPrimitive);
        CHECK(traceBruteForce(m, rays[0]).triangle == kNoPrimitive);
    }
    TEST_CASE("hard case: a rays file larger than the limit is refused before reading") {
        // A sparse file: its size says more than kMaxRays rays, no disk or memory is used.
        test::TempDir dir;
        std::string path = dir.file("huge.bin");
        std::ofstream(path, std::ios::binary).put('\0');
        std::filesystem::resize_file(path, (kMaxRays + 1) * sizeof(RayRecord));
        CHECK_THROWS_WITH_AS(
            readRays(path),
            ("rays file '" + path + "': " + std::to_string((kMaxRays + 1) * sizeof(RayRecord)) +
             " bytes is more than the limit of 33554432 rays")
                .c_str(),
            InputError);
    }
}

namespace {

// Does step 04's leaf test give exercise 1.5's answer, bit for bit (t, u and v)?
bool sameBits(float a, float b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}
int leafTestsDiffer(const Ray& ray, const Triangle& tri) {
    auto exercise = intersectWatertight(ray, tri);
    WatertightRay prepared(ray);
    float t = ray.tmax, u = 0.0f, v = 0.0f;
    bool leaf = intersectLeafTriangle(prepared, LeafTriangle{tri.a, tri.b, tri.c}, t, &u, &v);
    if (leaf != exercise.has_value()) return 1;
    return leaf &&
           !(sameBits(t, exercise->t) && sameBits(u, exercise->u) && sameBits(v, exercise->v));
}

}  // namespace

// Step 04 keeps its own copy of exercise 1.5 (prepared once per ray: bench_leaf_test
// measures the difference); the copy must give the exercise's bits, also where both fall
// back to double.
TEST_SUITE("hard cases reliability") {
    TEST_CASE("hard case: step 04's leaf test gives exercise 1.5's bits on the hard-case rays") {
        test::FpTrapsOff overflowOnPurpose;  // the float paths overflow before the fallback
        const float e = std::ldexp(1.0f, -23), far = 3e38f;
        const Vec3 b(1.0f, 1.0f + e, 1.0f), c(-(1.0f + e), -(1.0f + 2.0f * e), 1.0f);
        const Triangle big{
            {-1e21f, -1e21f, -5e20f}, {1e21f, -1e21f, -5e20f}, {0.0f, 1e21f, -5e20f}},
            tiny{{-1e-15f, -1e-15f, 3.0f}, {1e-15f, -1e-15f, 3.0f}, {0.0f, 1e-15f, 3.0f}},
            flat{{0.0f, 0.0f, 3.0f}, {1.0f, 1.0f, 3.0f}, {2.0f, 2.0f, 3.0f}},
            unit{{-1.0f, -1.0f, -1.0f}, {1.0f, -1.0f, -1.0f}, {0.0f, 1.0f, -1.0f}},
            upperLeft{{-1.0f, 1.0f, 1.0f}, b, c}, lowerRight{{1.0f, -1.0f, 1.0f}, c, b};
        const Vec3 down(0.0f, 0.0f, -1.0f);
        const std::pair<Ray, Triangle> named[] = {
            {Ray(Vec3(0.0f), down), big},
            {Ray(Vec3(3e21f, 0.0f, 0.0f), down), big},
            {Ray(Vec3(0.0f, 0.0f, -5.0f), Vec3(0.0f, 0.0f, -1e28f)), tiny},
            {Ray(Vec3(0.0f, 0.0f, -5.0f), Vec3(0.0f, 0.0f, 1e28f)), tiny},
            {Ray(Vec3(1.0f, 1.0f, -5.0f), Vec3(0.0f, 8.149072e-10f, -1.0603488e28f)), flat},
            {Ray(Vec3(0.0f, 0.0f, far), down), unit},
            {Ray(Vec3(0.0f, 0.0f, far), down, nextFloatUp(far)), unit},
            {Ray(Vec3(0.0f, 0.0f, far), Vec3(0.0f, 0.0f, -0.5f)), unit},
            {Ray(Vec3(0.0f), Vec3(0.0f, 0.0f, 1.0f)), upperLeft},
            {Ray(Vec3(0.0f), Vec3(0.0f, 0.0f, 1.0f)), lowerRight}};
        for (const auto& [ray, tri] : named) CHECK(leafTestsDiffer(ray, tri) == 0);
        // Random rays at random points of random triangles (a third of them on an edge):
        // a soup near the origin and the same soup 1e20 away (where most tests fall back
        // to double), each with ordinary, huge and tiny (1e-20) directions.
        Mesh near = test04::triangleSoup(500, 17, 0.05f), farSoup = near;
        for (Vec3& p : farSoup.positions) p = p * 1e20f + Vec3(3e20f, -1e20f, 0.0f);
        std::mt19937_64 rng(23);
        std::uniform_real_distribution<float> u01(0.0f, 1.0f);
        int differ = 0, hits = 0, tests = 0;
        for (const Mesh* m : {&near, &farSoup}) {
            const float distance = m == &near ? 2.0f : 5e20f;
            for (int r = 0; r < 2000; ++r) {
                size_t i = size_t(rng() % m->triangleCount());
                Triangle tri{m->vertex(i, 0), m->vertex(i, 1), m->vertex(i, 2)};
                float u = u01(rng), v = u01(rng) * (1.0f - u);
                if (r % 3 == 0) v = 1.0f - u;  // on the edge b-c
                Vec3 target = (1.0f - u - v) * tri.a + u * tri.b + v * tri.c;
                Vec3 offset(u01(rng) - 0.5f, u01(rng) - 0.5f, u01(rng) - 0.5f);
                if (glm::length(offset) < 0.1f) offset = Vec3(0.0f, 0.0f, 1.0f);
                Vec3 origin = target + glm::normalize(offset) * distance;
                // Huge: 1e28 near, 1e15 far (5e20 * 1e28 has no float).
                for (float scale : {1.0f, m == &near ? 1e28f : 1e15f, 1e-20f}) {
                    Ray ray(origin, (target - origin) * scale);
                    size_t j = (i + 1) % m->triangleCount();
                    for (const Triangle& t :
                         {tri, Triangle{m->vertex(j, 0), m->vertex(j, 1), m->vertex(j, 2)}}) {
                        hits += intersectWatertight(ray, t).has_value();
                        differ += leafTestsDiffer(ray, t);
                        ++tests;
                    }
                }
            }
        }
        INFO(tests << " pairs, " << hits << " hits");
        CHECK(hits > 6000);  // most rays hit the triangle they are aimed at
        CHECK(differ == 0);
    }
}
