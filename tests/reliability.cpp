// Reliability hard cases: bounded inputs, one-line messages, and a renderer that
// survives NaN or infinite scenes, zero-area and identical triangles, and a camera inside an
// object, each with a clear error or a correct image. The OBJ and message cases were found
// by the fuzz targets in fuzz/ (their inputs are in fuzz/corpus/).
#include <sys/inotify.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>

#include "01_triangle/triangle.hpp"
#include "01_triangle/triangle_grid.hpp"
#include "04_bvh/advanced/rays.hpp"
#include "core/app.hpp"
#include "core/mesh.hpp"
#include "core/render.hpp"
#include "core/scene.hpp"
#include "step04_support.hpp"
#include "support.hpp"

using namespace boxes;

namespace {

std::string refusal(const std::string& text, ObjLimits limits = {}) {
    try {
        parseObj(text, "x.obj", limits);
    } catch (const InputError& e) {
        return e.what();
    }
    return "(accepted)";
}

std::string polygon(int n) {
    std::string s;
    for (int i = 0; i < n; ++i) {
        float a = 6.2831853f * float(i) / float(n);
        s += "v " + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " 0\n";
    }
    s += "f";
    for (int i = 1; i <= n; ++i) s += " " + std::to_string(i);
    return s + "\n";
}

// Three vertices, then `rest` (a face or more lines).
std::string triangleThen(const std::string& rest) {
    return "v 0 0 0\nv 1 0 0\nv 0 1 0\n" + rest;
}

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

// The closed cube [-1, 1]^3, two triangles a face, facing out.
Mesh cube() {
    Mesh m;
    m.positions = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                   {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
    m.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                   {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
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
    TEST_CASE("hard case: an OBJ face of more than 255 vertices is refused") {
        // tinyobjloader keeps a face's vertex count in one byte: a 300-vertex face became
        // 42 wrong triangles and shifted every later face (found by fuzzing).
        std::string message = refusal(polygon(300));
        CHECK(message == "x.obj:301: a face of more than 255 vertices");
        Mesh largest = parseObj(polygon(255));
        CHECK(largest.triangleCount() == 253);
        CHECK(largest.triangles.back() == std::array<uint32_t, 3>{0, 253, 254});
    }
    TEST_CASE("hard case: an OBJ with more vertices or triangles than the limit is refused") {
        // Counted before tinyobjloader allocates anything (limits lowered for the test).
        const std::string quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
        CHECK(parseObj(quad, "x.obj", ObjLimits{4, 2}).triangleCount() == 2);
        CHECK(refusal(quad, ObjLimits{3, 2}) == "x.obj: more than 3 vertices (the limit)");
        CHECK(refusal(quad, ObjLimits{4, 1}) == "x.obj: more than 1 triangles (the limit)");
        CHECK(kMaxObjVertices == size_t(1) << 25);
        CHECK(kMaxObjTriangles == size_t(1) << 25);
    }
    TEST_CASE(
        "hard case: OBJ vertex lines after blanks or with carriage-return line ends are checked") {
        // tinyobjloader skips leading blanks and ends lines at \r too; the check did not,
        // so these coordinates were read as 0.
        CHECK(refusal("v 0 0 0\n  v 1 x 0\nv 0 1 0\nf 1 2 3\n") ==
              "x.obj:2: coordinate 'x' is not a number");
        CHECK(refusal("v 0 0 0\rv 1 x 0\rv 0 1 0\rf 1 2 3\r") ==
              "x.obj:2: coordinate 'x' is not a number");
        CHECK(parseObj("v 0 0 0\r\nv 1 0 0\r\n\tv 0 1 0\r\nf 1 2 3\r\n").triangleCount() == 1);
    }
    TEST_CASE("hard case: OBJ vertex weights with a joint out of int range are refused") {
        // tinyobjloader converts a "vw" joint to int unchecked: 1e38 was undefined
        // behaviour (found by fuzzing, fuzz/corpus/obj/crash-f1210a...).
        const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        CHECK(refusal(tri + "vw 0 1e38 0.5\n") ==
              "x.obj:5: vertex weight field '1e38' is not an index");
        CHECK(refusal(tri + "vw 0 1 0.5 nan 1\n") ==
              "x.obj:5: vertex weight field 'nan' is not an index");
        CHECK(refusal(tri + "vw 0 1 x\n") == "x.obj:5: vertex weight field 'x' is not a number");
        CHECK(parseObj(tri + "vw 0 1 0.5 2 -0.25\n").triangleCount() == 1);
    }
    TEST_CASE("hard case: OBJ coordinates are read exactly and each rounded once to float") {
        // tinyobjloader computes mantissa * pow(10, exponent): 0e3800 came out NaN and the
        // file was refused as non-finite (found by the fuzz target's strict reader,
        // fuzz/corpus/obj/crash-b1ecff...). The reader keeps its own std::from_chars values.
        test::FpTrapsOff nanOnPurpose;  // tinyobjloader's 0 * inf, whose result is discarded
        Mesh m = parseObj("v 0e3800 0.1 16777217\nv 1 0 1e-45\nv 0 1 -0e-999\nf 1 2 3\n");
        REQUIRE(m.positions.size() == 3);
        CHECK(m.positions[0].x == 0.0f);
        CHECK(m.positions[0].y == 0.1f);         // the float nearest 0.1
        CHECK(m.positions[0].z == 16777216.0f);  // 2^24 + 1 is a tie: rounds to even
        CHECK(m.positions[1].z == 0x1p-149f);    // the smallest subnormal float
        CHECK(std::signbit(m.positions[2].z));   // -0 stays -0
    }
    TEST_CASE("hard case: an OBJ l or p line that names no vertex is refused with its line") {
        // tinyobjloader refused 'l' followed by blanks only as "zero value for vertex index"
        // and kept 'l' alone as an empty element (found by the fuzz target's strict reader,
        // fuzz/corpus/obj/crash-690497...).
        const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        CHECK(refusal(tri + "l  \n") == "x.obj:5: a 'l' line names no vertex");
        CHECK(refusal(tri + "p \n") == "x.obj:5: a 'p' line names no vertex");
        CHECK(parseObj(tri + "l 1 2\np 3\n").triangleCount() == 1);
        CHECK(parseObj(tri + "l  1 2\n").triangleCount() == 1);
    }
    TEST_CASE("hard case: an OBJ vertex weight line that ends in blanks is refused with its line") {
        // tinyobjloader reads one more joint after a trailing blank, finds none and refused
        // the file with "joint_id is negative" (found by the fuzz target's strict reader,
        // fuzz/corpus/obj/crash-79d2ff...). Blanks only, after the keyword, are no field.
        const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        CHECK(refusal(tri + "vw 0 \n") ==
              "x.obj:5: vertex weight line ends in blanks after its last field");
        CHECK(refusal(tri + "vw 0 1 0.5\t\r\n") ==
              "x.obj:5: vertex weight line ends in blanks after its last field");
        CHECK(parseObj(tri + "vw 0\n").triangleCount() == 1);
        CHECK(parseObj(tri + "vw   \n").triangleCount() == 1);
    }
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
    TEST_CASE("hard case: user text quoted in an error message stays on one line") {
        auto messageOf = [](auto&& f) {
            try {
                f();
            } catch (const std::exception& e) {
                return std::string(e.what());
            }
            return std::string("(no error)");
        };
        std::string vec = messageOf([] { parseVec3("1\n2,3", "--eye"); });
        CHECK(vec == "--eye: '1\\x0a2' is not a finite number");
        std::string scene = messageOf([] { makeScene("a\nb", SceneOptions{}); });
        CHECK(scene.find('\n') == std::string::npos);
        CHECK(scene.rfind("unknown scene 'a\\x0ab'", 0) == 0);
        CHECK(printable(std::string(100, 'a'), 10) == "aaaaaaaaaa...");
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

// Every number of an OBJ file read exactly: tinyobjloader reads indices with atoi, so an
// index that does not fit an int wrapped to another, valid one, "3.5" and "3abc" were read
// as 3, and a texture coordinate or normal beyond the file's vt and vn lines went unseen:
// each rendered a wrong mesh with exit 0.
TEST_SUITE("hard cases reliability") {
    TEST_CASE(
        "hard case: OBJ face indices that wrap or have a fraction or junk or name missing vt or vn "
        "lines are refused") {
        // 2^32 + 3 and -2^32 + 3 were both read as 3.
        CHECK(refusal(triangleThen("f 1 2 4294967299\n")) ==
              "x.obj:4: index '4294967299': vertex 4294967299 is out of range (3 v lines so far)");
        CHECK(refusal(triangleThen("f 1 2 -4294967293\n")) ==
              "x.obj:4: index '-4294967293': vertex -4294967293 is out of range (3 v lines so "
              "far)");
        CHECK(refusal(triangleThen("f 1 2 99999999999999999999\n")) ==
              "x.obj:4: index '99999999999999999999': vertex 99999999999999999999 is out of "
              "range (3 v lines so far)");
        CHECK(refusal(triangleThen("f 1 2 3.5\n")) ==
              "x.obj:4: index '3.5': vertex '3.5' is not a decimal integer");
        CHECK(refusal(triangleThen("f 1 2 3abc\n")) ==
              "x.obj:4: index '3abc': vertex '3abc' is not a decimal integer");
        CHECK(refusal(triangleThen("f 1 2 +3\n")) ==
              "x.obj:4: index '+3': vertex '+3' is not a decimal integer");
        CHECK(refusal(triangleThen("f 1 2 0\n")) ==
              "x.obj:4: index '0': vertex 0 is out of range (3 v lines so far)");
        CHECK(refusal(triangleThen("f -1 -2 -4\n")) ==
              "x.obj:4: index '-4': vertex -4 is out of range (3 v lines so far)");
        // The range is the lines read so far, as for relative indices: not a later vertex.
        CHECK(refusal("v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n") ==
              "x.obj:3: index '3': vertex 3 is out of range (2 v lines so far)");
        // Texture coordinates and normals: within the file's vt and vn lines.
        CHECK(refusal(triangleThen("f 1/1 2/1 3/1\n")) ==
              "x.obj:4: index '1/1': texture coordinate 1 is out of range (0 vt lines so far)");
        CHECK(refusal(triangleThen("vt 0 0\nf 1/1 2/2 3/1\n")) ==
              "x.obj:5: index '2/2': texture coordinate 2 is out of range (1 vt lines so far)");
        CHECK(refusal(triangleThen("vn 0 0 1\nf 1//1 2//1 3//2\n")) ==
              "x.obj:5: index '3//2': normal 2 is out of range (1 vn lines so far)");
        CHECK(refusal(triangleThen("vt 0 0\nvn 0 0 1\nf 1/1/1 2/1/4294967297 3/1/1\n")) ==
              "x.obj:6: index '2/1/4294967297': normal 4294967297 is out of range (1 vn lines "
              "so far)");
        CHECK(refusal(triangleThen("vt 0 0\nf 1/1.0 2/1 3/1\n")) ==
              "x.obj:5: index '1/1.0': texture coordinate '1.0' is not a decimal integer");
        // Malformed tokens, a face of two, and lines and points (read by tinyobjloader the
        // same way, though the workbook draws only faces).
        for (const char* token : {"1/", "1//", "/1", "1/1/1/1", "1///1", "//"})
            CHECK(refusal(triangleThen(std::string("vt 0 0\nvn 0 0 1\nf 1 2 ") + token + "\n")) ==
                  std::string("x.obj:6: index '") + token + "' is not V, V/T, V//N or V/T/N");
        CHECK(refusal(triangleThen("f 1 2\n")) == "x.obj:4: a face of 2 vertices (at least 3)");
        CHECK(refusal(triangleThen("f 1 2 3\nl 1 4294967298\n")) ==
              "x.obj:5: index '4294967298': vertex 4294967298 is out of range (3 v lines so far)");
        CHECK(refusal(triangleThen("f 1 2 3\np 2.5\n")) ==
              "x.obj:5: index '2.5': vertex '2.5' is not a decimal integer");
        // Smoothing groups and tags: tinyobjloader's atoi again.
        CHECK(refusal(triangleThen("s 4294967297\nf 1 2 3\n")) ==
              "x.obj:4: smoothing group '4294967297' is not 'off' or one integer from 0 to "
              "2147483647");
        CHECK(refusal(triangleThen("s 1.5\nf 1 2 3\n")).find("smoothing group '1.5'") !=
              std::string::npos);
        CHECK(refusal(triangleThen("t crease 2/1/0 1 2 4294967297\nf 1 2 3\n")) ==
              "x.obj:4: tag lines ('t') are not read by the workbook");
        CHECK(refusal(triangleThen("f 1 2 3\nvw 0 1.5 0.5\n")) ==
              "x.obj:5: vertex weight field '1.5' is not an index");
        // What is accepted: every form, relative indices, leading zeros, smoothing groups.
        Mesh m = parseObj(triangleThen("vt 0 0\nvt 1 0\nvn 0 0 1\ns off\ns 2\n"
                                       "f 1/1/1 2/2/1 3/1/1\nf 3//1 -2//-1 1\nf 003/-1 1/1 2/002\n"
                                       "v 1 1 0\nf -1 -3 -2 -4\n"),
                          "x.obj");
        REQUIRE(m.triangleCount() == 5);
        CHECK(m.triangles[0] == std::array<uint32_t, 3>{0, 1, 2});
        CHECK(m.triangles[1] == std::array<uint32_t, 3>{2, 1, 0});
        CHECK(m.triangles[2] == std::array<uint32_t, 3>{2, 0, 1});
        CHECK(m.triangles[3] == std::array<uint32_t, 3>{3, 1, 2});
        CHECK(m.triangles[4] == std::array<uint32_t, 3>{3, 2, 0});
    }
    TEST_CASE("hard case: OBJ mtllib and usemtl paths are never opened") {
        // The workbook's materials come from its scenes: a path an OBJ file names (beside
        // it, or anywhere by an absolute path) is not opened. inotify sees every open of the
        // two material files; opening one here proves that it would.
        test::TempDir dir, elsewhere;
        const std::string beside = dir.file("beside.mtl"), absolute = elsewhere.file("far.mtl");
        for (const std::string& path : {beside, absolute})
            std::ofstream(path) << "newmtl red\nKd 1 0 0\n";
        std::ofstream(dir.file("mesh.obj"))
            << "mtllib beside.mtl\nmtllib " << absolute << "\nusemtl red\n"
            << triangleThen("f 1 2 3\nusemtl " + absolute + "\nf 3 2 1\n");
        int fd = inotify_init1(IN_NONBLOCK);
        REQUIRE(fd >= 0);
        for (const std::string& path : {beside, absolute})
            REQUIRE(inotify_add_watch(fd, path.c_str(), IN_OPEN | IN_ACCESS) >= 0);
        auto events = [fd] {
            alignas(inotify_event) char buffer[4096];
            ssize_t n = read(fd, buffer, sizeof buffer);
            return n > 0 ? n : 0;
        };
        Mesh m = loadObj(dir.file("mesh.obj"));
        CHECK(m.triangleCount() == 2);
#ifdef BOXES_PROGRAM_01
        // The same through a step program, started in the OBJ file's folder.
        auto run = test::runProgram(
            BOXES_PROGRAM_01, "--headless --scene mesh.obj --width 8 --height 6 --out a.png", dir);
        INFO(run.err);
        CHECK(run.exitCode == 0);
#endif
        CHECK(events() == 0);
        std::ifstream(beside).get();
        CHECK(events() > 0);
        close(fd);
    }
}

#ifdef BOXES_PROGRAM_01
// Every step program reads its OBJ scene through the same reader, and so does step 04's
// trace command: each refuses the same indices with the file, the line and the token.
TEST_SUITE("hard cases reliability") {
    TEST_CASE(
        "hard case: every step program and trace refuse OBJ indices that wrap or have a fraction "
        "or junk or name missing vt or vn lines") {
        struct Case {
            std::string text, message;
        };
        const std::vector<Case> cases = {
            {triangleThen("f 1 2 4294967299\n"),
             "4: index '4294967299': vertex 4294967299 is out of range (3 v lines so far)"},
            {triangleThen("f 1 2 -4294967293\n"),
             "4: index '-4294967293': vertex -4294967293 is out of range (3 v lines so far)"},
            {triangleThen("f 1 2 3.5\n"), "4: index '3.5': vertex '3.5' is not a decimal integer"},
            {triangleThen("f 1 2 3abc\n"),
             "4: index '3abc': vertex '3abc' is not a decimal integer"},
            {triangleThen("vt 0 0\nf 1/1 2/2 3/1\n"),
             "5: index '2/2': texture coordinate 2 is out of range (1 vt lines so far)"},
            {triangleThen("vn 0 0 1\nf 1//1 2//1 3//2\n"),
             "5: index '3//2': normal 2 is out of range (1 vn lines so far)"},
        };
        const std::vector<std::pair<std::string, std::string>> programs = {
            {"01_triangle", BOXES_PROGRAM_01},   {"02_box", BOXES_PROGRAM_02},
            {"03_aabb", BOXES_PROGRAM_03},       {"04_bvh", BOXES_PROGRAM_04},
            {"05_efficiency", BOXES_PROGRAM_05}, {"06_raster", BOXES_PROGRAM_06}};
        test::TempDir dir;
        // One ray, so that trace fails on the mesh alone.
        const float ray[8] = {0.2f, 0.2f, 5.0f, 0.0f, 0.0f, 0.0f, -1.0f, 1e30f};
        std::ofstream(dir.file("r.bin"), std::ios::binary)
            .write(reinterpret_cast<const char*>(ray), sizeof ray);
        for (size_t i = 0; i < cases.size(); ++i) {
            const std::string obj = "bad" + std::to_string(i) + ".obj";
            std::ofstream(dir.file(obj)) << cases[i].text;
            for (const auto& [name, path] : programs) {
                INFO(name << " " << obj);
                auto run = test::runProgram(
                    path, "--headless --width 8 --height 6 --out bad.png --scene " + obj, dir);
                CHECK(run.exitCode == 1);
                CHECK(run.err == name + ": error: " + obj + ":" + cases[i].message + "\n");
                CHECK_FALSE(std::filesystem::exists(dir.file("bad.png")));
            }
            INFO("04_bvh trace " << obj);
            auto run = test::runProgram(
                BOXES_PROGRAM_04, "trace --mesh " + obj + " --rays r.bin --hits hits.bin", dir);
            CHECK(run.exitCode == 1);
            CHECK(run.err == "04_bvh: error: " + obj + ":" + cases[i].message + "\n");
            CHECK_FALSE(std::filesystem::exists(dir.file("hits.bin")));
        }
        // The good mesh through trace: the file is right but for the index.
        std::ofstream(dir.file("good.obj")) << triangleThen("f 1 2 3\n");
        auto run = test::runProgram(BOXES_PROGRAM_04,
                                    "trace --mesh good.obj --rays r.bin --hits hits.bin", dir);
        INFO(run.err);
        CHECK(run.exitCode == 0);
        CHECK(std::filesystem::file_size(dir.file("hits.bin")) == 8);
    }
}
#endif

// Every number on a command line read exactly. CLI11 reads numbers with strtoll, strtoull
// and strtold in base 0: --seed -1 became 2^64 - 1, an overflowing seed 2^64 - 1, "010"
// octal 8, and nan passed the range checks.
namespace {

std::string usage(std::vector<std::string> args, CommonOptions* out = nullptr) {
    CLI::App app;
    CommonOptions options;
    addCommonOptions(app, options, "bunny");
    args.insert(args.begin(), "program");
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    try {
        parseCommandLine(app, int(argv.size()), argv.data());
    } catch (const UsageError& e) {
        return e.what();
    }
    if (out) *out = options;
    return "(accepted)";
}

}  // namespace

TEST_SUITE("hard cases reliability") {
    TEST_CASE("hard case: flags that overflow or have a fraction or trailing junk are refused") {
        for (const char* flag : {"--width", "--height", "--threads", "--frames", "--seed"}) {
            INFO(flag);
            const std::string f = flag;
            CHECK(usage({f, "99999999999999999999"}) ==
                  f + ": '99999999999999999999' is out of range");
            CHECK(usage({f, "2.5"}) == f + ": '2.5' is not a decimal integer");
            CHECK(usage({f, "64px"}) == f + ": '64px' is not a decimal integer");
            CHECK(usage({f, "0x40"}) == f + ": '0x40' is not a decimal integer");
            CHECK(usage({f, "+64"}) == f + ": '+64' is not a decimal integer");
            CHECK(usage({f, " 64"}) == f + ": ' 64' is not a decimal integer");
        }
        CHECK(usage({"--seed", "-1"}) == "--seed: '-1' is negative (a count or seed is 0 or more)");
        CHECK(usage({"--seed", "18446744073709551616"}) ==
              "--seed: '18446744073709551616' is out of range");
        // Beyond int but within 64 bits: CLI11 refuses what does not fit the flag's type.
        CHECK(usage({"--threads", "4294967297"}).rfind("--threads: ", 0) == 0);
        CHECK(usage({"--width", "4294967297"}).rfind("--width: ", 0) == 0);
        CHECK(usage({"--fov", "1e999"}) == "--fov: '1e999' is out of range");
        CHECK(usage({"--fov", "nan"}) == "--fov: 'nan' is not a finite decimal number");
        CHECK(usage({"--fov", "inf"}) == "--fov: 'inf' is not a finite decimal number");
        CHECK(usage({"--fov", "45deg"}) == "--fov: '45deg' is not a finite decimal number");
        CHECK(usage({"--fov", "0x1p4"}) == "--fov: '0x1p4' is not a finite decimal number");
        // What is accepted is read as written: decimal, never octal.
        CommonOptions o;
        REQUIRE(usage({"--width", "010", "--height", "0007", "--seed", "18446744073709551615",
                       "--fov", "45.5", "--threads", "0"},
                      &o) == "(accepted)");
        CHECK(o.width == 10);
        CHECK(o.height == 7);
        CHECK(o.seed == UINT64_MAX);
        CHECK(o.fov == 45.5f);
        CHECK(o.threads == 0);
    }
    TEST_CASE("hard case: vector flags that overflow or have trailing junk are refused") {
        auto message = [](const std::string& text) {
            try {
                parseVec3(text, "--eye");
            } catch (const InputError& e) {
                return std::string(e.what());
            }
            return std::string("(accepted)");
        };
        CHECK(message("1e39,0,0") == "--eye: '1e39' is not a finite number");
        CHECK(message("0,0,-1e39") == "--eye: '-1e39' is not a finite number");
        CHECK(message("1,2,3x") == "--eye: '3x' is not a finite number");
        CHECK(message("1,2,3,4") == "--eye: '3,4' is not a finite number");
        CHECK(message("0x1p3,0,0") == "--eye: '0x1p3' is not a finite number");
        CHECK(message(" 1,2,3") == "--eye: ' 1' is not a finite number");
        CHECK(message("nan,0,0") == "--eye: 'nan' is not a finite number");
        CHECK(message("1,2") == "--eye: expected X,Y,Z, got '1,2'");
        // Fractions are what a vector holds: each component the nearest float.
        CHECK(parseVec3("0.5,-2.25,1e-3", "--eye") == Vec3(0.5f, -2.25f, 1e-3f));
    }
    TEST_CASE(
        "hard case: a rays file with trailing bytes or an infinite origin is refused by trace") {
        // Binary float32: a trailing partial record is junk, an infinity an overflow.
        auto message = [](std::vector<float> values, size_t extra) {
            std::string bytes(reinterpret_cast<const char*>(values.data()),
                              values.size() * sizeof(float));
            bytes.append(extra, '\x7f');
            try {
                parseRays(bytes.data(), bytes.size(), "rays file 'r.bin'");
            } catch (const InputError& e) {
                return std::string(e.what());
            }
            return std::string("(accepted)");
        };
        const std::vector<float> ray = {0.2f, 0.2f, 5.0f, 0.0f, 0.0f, 0.0f, -1.0f, 1e30f};
        CHECK(message(ray, 0) == "(accepted)");
        CHECK(message(ray, 1) ==
              "rays file 'r.bin': size 33 bytes is not a multiple of 32 (8 float32 per ray)");
        std::vector<float> far = ray;
        far[0] = kInfinity<float>;
        CHECK(message(far, 0) == "rays file 'r.bin': ray 0: infinite origin or direction");
    }
}

#ifdef BOXES_PROGRAM_01
TEST_SUITE("hard cases reliability") {
    TEST_CASE(
        "hard case: every numeric flag of every step program and of trace and check refuses "
        "overflow and fractions and junk") {
        // Each program's --help names every option with its type (INT, UINT, FLOAT): each of
        // them gets an overflowing, a fractional (integers) or non-finite (floats) and a
        // trailing-junk value. The common flags are also checked in-process above.
        struct Command {
            std::string name, path, prefix, help;
        };
        test::TempDir dir;
        std::ofstream(dir.file("m.obj")) << triangleThen("f 1 2 3\n");
        const float ray[8] = {0.2f, 0.2f, 5.0f, 0.0f, 0.0f, 0.0f, -1.0f, 1e30f};
        std::ofstream(dir.file("r.bin"), std::ios::binary)
            .write(reinterpret_cast<const char*>(ray), sizeof ray);
        const std::string png = "--headless --width 8 --height 6 --out bad.png ";
        const std::vector<Command> commands = {
            {"01_triangle", BOXES_PROGRAM_01, png, "--help"},
            {"02_box", BOXES_PROGRAM_02, png, "--help"},
            {"03_aabb", BOXES_PROGRAM_03, png, "--help"},
            {"04_bvh", BOXES_PROGRAM_04, png, "--help"},
            {"04_bvh", BOXES_PROGRAM_04, "trace --mesh m.obj --rays r.bin --hits bad.png ",
             "trace --help"},
            {"04_bvh", BOXES_PROGRAM_04, "check --mesh m.obj --rays r.bin ", "check --help"},
            {"05_efficiency", BOXES_PROGRAM_05, png, "--help"},
            {"06_raster", BOXES_PROGRAM_06, png, "--help"}};
        size_t checked = 0;
        for (const Command& c : commands) {
            auto help = test::runProgram(c.path, c.help, dir);
            REQUIRE(help.exitCode == 0);
            std::istringstream lines(help.out);
            for (std::string line; std::getline(lines, line);) {
                // "  --width INT:INT in [1 - 16384]" or "  -n,--count UINT ..."
                std::istringstream words(line);
                std::string names, type;
                words >> names >> type;
                size_t dashes = names.find("--");
                if (dashes == std::string::npos) continue;
                std::string flag = names.substr(dashes);
                std::string kind = type.substr(0, type.find_first_of(":="));
                std::vector<std::pair<std::string, std::string>> bad;
                if (kind == "INT" || kind == "UINT")
                    bad = {{"99999999999999999999", "is out of range"},
                           {"2.5", "is not a decimal integer"},
                           {"8abc", "is not a decimal integer"}};
                else if (kind == "FLOAT")
                    bad = {{"1e999", "is out of range"},
                           {"nan", "is not a finite decimal number"},
                           {"2.5abc", "is not a finite decimal number"}};
                for (const auto& [value, why] : bad) {
                    INFO(c.name << " " << c.prefix << flag << " " << value);
                    auto run = test::runProgram(c.path, c.prefix + flag + " " + value, dir);
                    CHECK(run.exitCode == 2);
                    CHECK(run.err == c.name + ": error: " + flag + ": '" + value + "' " + why +
                                         " (see --help)\n");
                    CHECK_FALSE(std::filesystem::exists(dir.file("bad.png")));
                    ++checked;
                }
            }
        }
        // Every program's --width --height --seed --threads --fov --frames, and more.
        CHECK(checked >= 3 * (6 * 6 + 4));
    }
}
#endif

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
