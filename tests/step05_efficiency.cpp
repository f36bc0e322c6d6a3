// Step 05: the lab's exercises with checked numbers, the incremental renderer against an
// injected clock, effects on demand, and the program.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>

#include "05_efficiency/bvh_mesh.hpp"
#include "05_efficiency/lab.hpp"
#include "05_efficiency/language.hpp"
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

// The largest difference of two images in steps of their 8-bit sRGB encoding (the PNG).
int maxStep8(const Image& a, const Image& b) {
    auto x = a.toRgb8(), y = b.toRgb8();
    int worst = 0;
    for (size_t i = 0; i < x.size(); ++i) worst = std::max(worst, std::abs(int(x[i]) - int(y[i])));
    return worst;
}

// A sphere as step-supplied geometry that says it is convex: the analysis' self-shadowing
// rule for geometries, which no built-in scene exercises.
class ConvexSphereGeometry : public Geometry {
public:
    ConvexSphereGeometry(Sphere s, int material) : s_(s), material_(material) {}
    bool intersect(const Ray& ray, SurfaceHit& hit) const override {
        auto t = intersectSphere(ray, s_);
        if (!t) return false;
        hit.t = *t;
        hit.point = ray.at(*t);
        hit.geometricNormal = hit.shadingNormal = (hit.point - s_.centre) / s_.radius;
        hit.material = material_;
        hit.primitive = 0;
        hit.kind = SurfaceHit::Kind::Sphere;
        hit.u = hit.v = 0.0f;
        return true;
    }
    bool occluded(const Ray& ray) const override { return intersectSphere(ray, s_).has_value(); }
    Vec3 boundsMin() const override { return s_.centre - Vec3(s_.radius); }
    Vec3 boundsMax() const override { return s_.centre + Vec3(s_.radius); }
    bool convex() const override { return true; }
    std::vector<int> materialsUsed() const override { return {material_}; }

private:
    Sphere s_;
    int material_;
};

// A random scene for the effects-on-demand property: spheres, planes, a closed box mesh and
// an open sheet of triangles in step 04's hierarchy, a convex geometry, every material
// (mirrors of reflectance 0 too), lights inside and outside objects, finite and infinite
// radii, the camera sometimes inside a sphere. The meshes live beside the scene (the
// hierarchy refers to its mesh).
struct RandomScene {
    Scene scene;
    std::vector<std::unique_ptr<Mesh>> meshes;
};
RandomScene randomEffectsScene(std::mt19937_64& rng) {
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    auto in = [&](float a, float b) { return a + (b - a) * u(rng); };
    auto pick = [&](int n) { return int(rng() % uint64_t(n)); };
    auto point = [&](float r) { return Vec3(in(-r, r), in(-r, r), in(-r, r)); };
    RandomScene out;
    Scene& s = out.scene;
    s.name = "random";
    s.materials = {Material::diffuse(Vec3(in(0.2f, 1.0f), in(0.2f, 1.0f), in(0.2f, 1.0f))),
                   Material::mirror(Vec3(0.9f), in(0.3f, 1.0f)), Material::mirror(Vec3(0.9f), 0.0f),
                   Material::glass(in(1.1f, 2.0f)), Material::diffuse(Vec3(0.5f))};
    const int materials = int(s.materials.size());
    // Half the scenes sparse (one or two spheres, at most one plane, the lights among the
    // objects): there a light's ball often holds one or two objects, and which ones the
    // analysis keeps decides the shadow.
    const bool sparse = pick(2);
    for (int i = 0, n = 1 + pick(sparse ? 2 : 4); i < n; ++i)
        s.spheres.push_back({{point(3.0f), in(0.2f, 1.5f)}, pick(materials)});
    for (int i = 0, n = pick(sparse ? 2 : 3); i < n; ++i) {
        Vec3 normal = glm::normalize(point(1.0f) + Vec3(0.0f, 1e-3f, 0.0f));
        s.planes.push_back({{normal, in(-4.0f, 4.0f)}, pick(materials)});
    }
    if (pick(2)) {  // a closed box of 12 triangles
        Mesh& box = *out.meshes.emplace_back(std::make_unique<Mesh>());
        Vec3 c = point(2.5f), h(in(0.2f, 1.0f), in(0.2f, 1.0f), in(0.2f, 1.0f));
        for (int k = 0; k < 8; ++k)
            box.positions.push_back(c + h * Vec3(k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? 1 : -1));
        box.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                         {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
        box.computeVertexNormals();
        s.geometries.push_back(std::make_shared<LabBvhMesh>(box, pick(materials)));
    }
    if (pick(2)) {  // an open sheet of random triangles
        Mesh& sheet = *out.meshes.emplace_back(std::make_unique<Mesh>());
        // Sparse: the triangles in a cluster, where they shadow one another (the sheet is
        // not convex).
        const Vec3 cluster = point(2.0f);
        for (int k = 0, n = 1 + pick(6); k < n; ++k) {
            Vec3 c = sparse ? cluster + point(0.5f) : point(3.0f);
            for (int j = 0; j < 3; ++j) sheet.positions.push_back(c + point(1.0f));
            uint32_t b = uint32_t(3 * k);
            sheet.triangles.push_back({b, b + 1, b + 2});
        }
        sheet.computeVertexNormals();
        s.geometries.push_back(std::make_shared<LabBvhMesh>(sheet, pick(materials)));
    }
    if (pick(3) == 0)
        s.geometries.push_back(std::make_shared<ConvexSphereGeometry>(
            Sphere{point(3.0f), in(0.2f, 1.0f)}, pick(materials)));
    for (int i = 0, n = 1 + pick(3); i < n; ++i) {
        PointLight light;
        // Inside a sphere sometimes (it then lights only that sphere's inside).
        light.position = pick(4) == 0 ? s.spheres[0].shape.centre : point(sparse ? 3.0f : 5.0f);
        light.intensity = Vec3(in(0.5f, 30.0f));
        s.lights.push_back(light);
    }
    if (sparse && pick(2)) {
        // A plane between the first sphere and the first light, facing the light: it
        // shadows the sphere's lit side, and the analysis must keep it for that light.
        const Sphere& a = s.spheres[0].shape;
        Vec3 toLight = s.lights[0].position - a.centre;
        float distance = glm::length(toLight);
        if (distance > a.radius + 0.2f) {
            Vec3 normal = glm::normalize(toLight / distance + 0.3f * point(1.0f));
            Vec3 through = a.centre + toLight / distance * in(a.radius + 0.05f, distance - 0.1f);
            s.planes.push_back({{normal, -glm::dot(normal, through)}, pick(materials)});
        }
    }
    if (pick(2)) s.setLightRadii();  // finite radii (a ball of influence per light)
    // Balls that reach only part of the scene: the analysis then keeps few occluders per
    // light, and one it drops wrongly is the only one left to block some point (with any
    // other occluder kept, the shadow ray is traced against the whole scene anyway).
    for (PointLight& light : s.lights)
        if (pick(2)) light.radius = in(0.5f, 4.0f);
    Vec3 eye = pick(5) == 0 ? s.spheres[0].shape.centre : point(2.0f) + Vec3(0.0f, 0.0f, 8.0f);
    s.camera = Camera::lookingAt(eye, point(1.0f) + Vec3(0.0f, 0.0f, 1e-2f), Vec3(0, 1, 0),
                                 in(30.0f, 90.0f), 4.0f / 3.0f);
    return out;
}

// Renders with the analysis and with every part (and one random subset) off: the images
// must be bit-identical and the analysis may only save rays.
void checkEffectsIdentity(const Scene& scene, int w, int h, int maxDepth, uint64_t seed) {
    RenderSettings s;
    s.width = w;
    s.height = h;
    s.maxDepth = maxDepth;
    s.threads = 1;
    RayCounts on, off, some;
    Image a = renderImage(scene, scene.camera, s, &on);
    s.analysis = AnalysisParts::none();
    Image b = renderImage(scene, scene.camera, s, &off);
    s.analysis = {bool(seed & 1), bool(seed & 2), bool(seed & 4), bool(seed & 8)};
    Image c = renderImage(scene, scene.camera, s, &some);
    CHECK(bitIdentical(a, b));
    CHECK(bitIdentical(c, b));
    CHECK(on.total() <= some.total());
    CHECK(some.total() <= off.total());
    // The analysis skips shadow rays only: every other ray is the baseline's.
    CHECK(on.primary == off.primary);
    CHECK(on.reflection == off.reflection);
    CHECK(on.refraction == off.refraction);
}

// The analysis' decisions, checked one by one at points of the scene that random rays
// hit (from anywhere: refraction reaches points the camera does not see): wherever it skips
// the shadow ray of a light that would light the point, the traced ray must be unblocked.
// An occluder the analysis drops wrongly shows here even where the image hides it.
// Returns the number of skipped shadow rays checked.
int checkAnalysisSound(const RandomScene& random, uint64_t seed) {
    const Scene& scene = random.scene;
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> u(-6.0f, 6.0f);
    RenderSettings s;
    s.width = s.height = 1;
    const Renderer renderer(scene, scene.camera, s);
    int checked = 0, unsound = 0;
    for (int r = 0; r < 400; ++r) {
        // Towards a point near a light (half of them), where a small ball of influence
        // holds few occluders and the analysis skips most; or anywhere.
        const PointLight& near = scene.lights[size_t(r) % scene.lights.size()];
        float reach = std::min(near.radius, 3.0f);
        Vec3 target = r % 2 ? near.position + reach / 6.0f * Vec3(u(rng), u(rng), u(rng))
                            : Vec3(u(rng), u(rng), u(rng));
        Vec3 direction = target - Vec3(u(rng), u(rng), u(rng));
        if (glm::dot(direction, direction) < 1e-6f) continue;
        Ray ray(target - direction, direction);
        SurfaceHit hit;
        if (!scene.intersect(ray, hit)) continue;
        const Material& m = scene.materials[size_t(hit.material)];
        if (m.kind != Material::Kind::Diffuse) continue;
        FacingNormals normals = facingNormals(ray.direction, hit);
        for (size_t i = 0; i < scene.lights.size(); ++i) {
            DirectLight light = directLight(m, scene.lights[i], hit.point, normals);
            if (!light.contributes() || renderer.needsShadowRay(int(i), hit)) continue;
            ++checked;
            Ray shadow(offsetOrigin(hit.point, hit.geometricNormal, light.toLight), light.toLight,
                       0.0f, 1.0f - 1e-5f);
            unsound += scene.occluded(shadow);
        }
    }
    CHECK(unsound == 0);
    // The lists themselves: an object left out for a light has no point in the light's
    // ball (a sphere's nearest point, a mesh's vertices), within float rounding.
    int leftOutWrongly = 0;
    for (size_t i = 0; i < scene.lights.size(); ++i) {
        const PointLight& light = scene.lights[i];
        const std::vector<int>& list = renderer.analysis().occluders[i];
        auto outside = [&](float distance) { return distance > light.radius * (1.0f - 1e-4f); };
        auto listed = [&](int object) {
            return std::find(list.begin(), list.end(), object) != list.end();
        };
        int object = 0;
        for (const auto& sphere : scene.spheres) {
            float gap = glm::length(light.position - sphere.shape.centre) - sphere.shape.radius;
            leftOutWrongly += !listed(object++) && !outside(gap);
        }
        object += int(scene.planes.size());
        for (const auto& mesh : random.meshes) {  // the first geometries, in order
            if (!listed(object++))
                for (const Vec3& p : mesh->positions)
                    leftOutWrongly += !outside(glm::length(p - light.position));
        }
    }
    CHECK(leftOutWrongly == 0);
    return checked;
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

TEST_SUITE("renderer 05") {
    TEST_CASE("effects on demand: identical images and fewer rays on every scene kind") {
        for (const char* name :
             {"single-sphere", "diffuse", "mirrors", "glass", "spheres", "small-lights"}) {
            Scene scene = makeScene(name, {});
            RenderSettings s;
            s.width = 40;
            s.height = 30;
            s.threads = 2;
            RayCounts on, forced;
            Image a = renderImage(scene, scene.camera, s, &on);
            s.forceAllEffects = true;
            Image b = renderImage(scene, scene.camera, s, &forced);
            INFO(std::string(name));
            CHECK(bitIdentical(a, b));
            CHECK(on.primary == forced.primary);
            CHECK(on.total() < forced.total());
        }
        // No occluders at all: not one shadow ray; diffuse only: no reflection rays.
        Scene single = makeScene("single-sphere", {});
        RenderSettings s;
        s.width = 40;
        s.height = 30;
        RayCounts c;
        renderImage(single, single.camera, s, &c);
        CHECK(c.shadow == 0);
        CHECK(c.shadowSkipped > 0);
        Scene diffuse = makeScene("diffuse", {});
        RayCounts d;
        renderImage(diffuse, diffuse.camera, s, &d);
        CHECK(d.reflection == 0);
        CHECK(d.refraction == 0);
    }
    TEST_CASE(
        "effects on demand: every built-in scene and shipped mesh bit-identical against "
        "the baseline without analysis") {
        std::vector<std::string> names;
        for (const auto& [name, what] : builtinScenes()) names.push_back(name);
        for (const auto& e : std::filesystem::directory_iterator(test::dataDir() + "/meshes"))
            if (e.path().extension() == ".obj") names.push_back(e.path().string());
        CHECK(names.size() >= 10);  // eight built-in scenes and two shipped meshes
        uint64_t subset = 0;
        for (const std::string& name : names) {
            INFO(name);
            Scene scene = makeScene(name, {test::dataDir()});
            if (scene.hasMesh())
                scene.geometries.push_back(
                    std::make_shared<LabBvhMesh>(scene.mesh, scene.meshMaterial));
            checkEffectsIdentity(scene, 48, 36, 5, subset++);
        }
    }
    TEST_CASE("effects on demand: 200 random scenes bit-identical with fewer or equal rays") {
        std::mt19937_64 rng(20240607);
        uint64_t saved = 0, baseline = 0;
        int skipsChecked = 0;
        for (int i = 0; i < 200; ++i) {
            RandomScene random = randomEffectsScene(rng);
            const Scene& scene = random.scene;
            INFO("random scene " << i);
            checkEffectsIdentity(scene, 20, 15, 1 + i % 5, uint64_t(i));
            skipsChecked += checkAnalysisSound(random, uint64_t(i));
            RenderSettings s;
            s.width = 20;
            s.height = 15;
            s.threads = 1;
            RayCounts on, off;
            renderImage(scene, scene.camera, s, &on);
            s.analysis = AnalysisParts::none();
            renderImage(scene, scene.camera, s, &off);
            saved += off.total() - on.total();
            baseline += off.total();
        }
        // The property is not vacuous: the analysis does skip rays in these scenes.
        INFO(skipsChecked << " skipped shadow rays checked");
        CHECK(saved > 0);
        CHECK(saved < baseline);
        CHECK(skipsChecked > 30);
    }
    TEST_CASE(
        "effects on demand: each part of the analysis saves shadow rays the others do "
        "not") {
        // The street of lamps: a lamp's ball reaches only the spheres near it (occluders per
        // light), the floor lies below every lamp (plane sides), the spheres are convex, and
        // the far lamps are out of range.
        Scene scene = makeScene("small-lights", {});
        RenderSettings s;
        s.width = 40;
        s.height = 30;
        RayCounts all;
        Image reference = renderImage(scene, scene.camera, s, &all);
        for (int part = 0; part < 4; ++part) {
            AnalysisParts allBut;
            (part == 0   ? allBut.occludersPerLight
             : part == 1 ? allBut.planeSides
             : part == 2 ? allBut.convexSelf
                         : allBut.lightRanges) = false;
            s.analysis = allBut;
            RayCounts c;
            Image img = renderImage(scene, scene.camera, s, &c);
            INFO("every part but part " << part);
            CHECK(bitIdentical(img, reference));
            // On this street the lamps' ranges decide: given them, the other parts find
            // nothing more to skip (the effects_parts table shows the same).
            if (part == 3)
                CHECK(c.shadow > all.shadow);
            else
                CHECK(c.shadow >= all.shadow);
        }
    }
    TEST_CASE("finite light radius: within one 8-bit sRGB step and fewer evaluations") {
        // Every built-in scene with its default radii (PointLight::cutoffThreshold: half an
        // sRGB step shared by the lights) against infinite radii: the PNGs differ by at most
        // one step. On the street of lamps most evaluations and shadow rays are skipped.
        for (const char* name :
             {"small-lights", "spheres", "diffuse", "mirrors", "glass", "single-sphere"}) {
            Scene finite = makeScene(name, {});
            Scene infinite = finite;
            for (auto& l : infinite.lights) l.radius = kInfinity<float>;
            RenderSettings s;
            s.width = 80;
            s.height = 60;
            RayCounts cf, ci;
            Image a = renderImage(finite, finite.camera, s, &cf);
            Image b = renderImage(infinite, infinite.camera, s, &ci);
            INFO(std::string(name));
            CHECK(maxStep8(a, b) <= 1);
            CHECK(ci.lightsOutOfRange == 0);
            if (std::string(name) == "small-lights") {
                CHECK(cf.lightsOutOfRange > 0);
                CHECK(cf.shadow < ci.shadow);
            }
        }
    }
    TEST_CASE("hard case: many lights just beyond their radius stay within one step") {
        // The worst case of the bound: n lights straight above a white floor point, each just
        // beyond its radius, so each skipped light gives almost its threshold, and the point
        // is near black, where sRGB is steepest. With the radius shared by n lights the PNG
        // moves by at most one step; with the old rule (half a step in linear light per
        // light) the skipped light adds up to many steps.
        const int n = 8;
        const Vec3 intensity(0.05f);
        auto render = [&](float threshold, bool cut, RayCounts* counts) {
            Scene scene;
            scene.materials = {Material::diffuse(Vec3(1.0f))};
            scene.planes.push_back({{Vec3(0, 1, 0), 0.0f}, 0});
            scene.ambient = Vec3(0.0f);
            float r = PointLight::radiusFor(intensity, threshold);
            for (int i = 0; i < n; ++i)
                scene.lights.push_back(
                    {Vec3(0.0f, 1.001f * r, 0.0f), intensity, cut ? r : kInfinity<float>});
            scene.camera.eye = Vec3(0.0f, 1.0f, 0.0f);
            scene.camera.view = Vec3(0.0f, -1.0f, 0.0f);
            scene.camera.up = Vec3(0, 0, -1);
            scene.camera.fovYDegrees = 10.0f;
            RenderSettings s;
            s.width = s.height = 8;
            return renderImage(scene, scene.camera, s, counts);
        };
        RayCounts c;
        float shared = PointLight::cutoffThreshold(n);
        Image cutShared = render(shared, true, &c);
        CHECK(c.lightsOutOfRange == uint64_t(8 * 8 * n));  // every light skipped everywhere
        Image fullShared = render(shared, false, nullptr);
        CHECK(fullShared.at(4, 4).x > 0.0f);
        CHECK(maxStep8(cutShared, fullShared) <= 1);
        float linear = 0.5f / 255.0f;
        Image cutLinear = render(linear, true, nullptr);
        Image fullLinear = render(linear, false, nullptr);
        CHECK(maxStep8(cutLinear, fullLinear) > 10);  // 8 * 0.5/255 linear: about 21 sRGB steps
    }
    TEST_CASE("bvh mesh: every optimization switch gives the same image") {
        // Step 04's tree (its sweep SAH builder, not an exercise) with the lab's traversal.
        Mesh mesh = loadObj(test::dataDir() + "/meshes/sh1.obj");
        auto cm = std::make_shared<LabBvhMesh>(mesh, 0);
        Scene scene;
        scene.geometries.push_back(cm);
        Bounds3f b(cm->boundsMin(), cm->boundsMax());
        scene.lights.push_back(
            {b.centroid() + glm::length(b.diagonal()) * Vec3(0.6f, 1.2f, 0.9f), Vec3(50.0f)});
        scene.camera = fitCamera(b.min, b.max, 4.0f / 3.0f);
        RenderSettings s;
        s.width = 40;
        s.height = 30;
        Image ref;
        uint64_t tests[2] = {0, 0};
        for (int v = 0; v < 16; ++v) {
            LabMeshOptions o{bool(v & 1), bool(v & 2), bool(v & 4), bool(v & 8), false};
            cm->setOptions(o);
            cm->resetCounters();
            Image img = renderImage(scene, scene.camera, s);
            if (v == 0) ref = img;
            if (v == 0) tests[0] = cm->triangleTests();
            if (v == 15) tests[1] = cm->triangleTests();
            INFO("variant " << v);
            // Division and reciprocal slab tests may differ in the last bit of a box entry;
            // no pixel of this view depends on it.
            CHECK(compareImages(img, ref).pixelsDiffering == 0);
        }
        CHECK(tests[1] < tests[0]);
    }
    TEST_CASE("bvh mesh: nearest hits equal brute force and the early outs test less") {
        Mesh mesh = loadObj(test::dataDir() + "/meshes/sh1.obj");
        LabBvhMesh cm(mesh, 0);
        Bounds3f b(cm.boundsMin(), cm.boundsMax());
        Camera cam = fitCamera(b.min, b.max, 1.0f);
        CameraBasisT<float> basis = cam.basis();
        Vec3 light = b.centroid() + glm::length(b.diagonal()) * Vec3(0.6f, 1.2f, 0.9f);
        uint64_t primary[2] = {0, 0}, shadow[2] = {0, 0};
        int hits = 0;
        for (int y = 0; y < 24; ++y)
            for (int x = 0; x < 24; ++x) {
                Ray ray(cam.eye, cam.directionThrough(basis, x + 0.5f, y + 0.5f, 24, 24));
                // Brute force over every triangle, the same Moller-Trumbore arithmetic.
                float nearest = kInfinity<float>;
                for (size_t t = 0; t < mesh.triangleCount(); ++t) {
                    TriangleVertices v{mesh.vertex(t, 0), mesh.vertex(t, 1), mesh.vertex(t, 2)};
                    if (auto h = intersectFromVertices(ray, v)) nearest = std::min(nearest, h->t);
                }
                for (int skip = 0; skip < 2; ++skip) {
                    LabMeshOptions o;
                    o.robust = false;  // the same Moller-Trumbore as the brute force
                    o.skipBeyondNearest = skip == 1;
                    cm.setOptions(o);
                    cm.resetCounters();
                    SurfaceHit hit;
                    bool found = cm.intersect(ray, hit);
                    primary[skip] += cm.triangleTests();
                    REQUIRE(found == (nearest < kInfinity<float>));
                    if (!found) continue;
                    CHECK(hit.t == nearest);
                    hits += skip;
                    Vec3 d = light - hit.point;
                    Ray shadowRay(offsetOrigin(hit.point, hit.geometricNormal, d), d, 0.0f, 1.0f);
                    bool blocked[2];
                    for (int any = 0; any < 2; ++any) {
                        o.anyHitShadows = any == 1;
                        cm.setOptions(o);
                        cm.resetCounters();
                        blocked[any] = cm.occluded(shadowRay);
                        if (skip) shadow[any] += cm.triangleTests();
                    }
                    CHECK(blocked[0] == blocked[1]);
                }
            }
        // With every switch on (robust: step 04's watertight and conservative tests, not its
        // exercises), the hits equal step 04's watertight brute force.
        cm.setOptions({});
        for (int y = 0; y < 24; ++y)
            for (int x = 0; x < 24; ++x) {
                Ray ray(cam.eye, cam.directionThrough(basis, x + 0.5f, y + 0.5f, 24, 24));
                TraceHit reference = traceBruteForce(mesh, ray);
                SurfaceHit hit;
                bool found = cm.intersect(ray, hit);
                REQUIRE(found == (reference.triangle != kNoPrimitive));
                if (found) CHECK(hit.t == reference.t);
            }
        CHECK(hits > 100);
        CHECK(primary[1] < primary[0]);  // skipping nodes beyond the nearest t tests less
        CHECK(shadow[1] <= shadow[0]);   // any hit never tests more than nearest
    }
    TEST_CASE("preview modes render at the requested size and the full mode equals the render") {
        Scene scene = makeScene("spheres", {});
        RenderSettings s;
        s.width = 40;
        s.height = 30;
        Image full = renderImage(scene, scene.camera, s);
        for (PreviewMode m : kAllPreviewModes) {
            Image img = renderPreview(scene, scene.camera, m, s, 0.5f);
            CHECK(img.width() == 40);
            CHECK(img.height() == 30);
            if (m == PreviewMode::Full) CHECK(bitIdentical(img, full));
        }
    }
    TEST_CASE("schedules: static rows and dynamic rows and tiles give the same image") {
        Scene scene = makeScene("spheres", {});
        RenderSettings s;
        s.width = 50;
        s.height = 37;
        s.threads = 1;
        Renderer r(scene, scene.camera, s);
        Image ref = r.render();
        for (Schedule sch : {Schedule::StaticRows, Schedule::DynamicRows, Schedule::DynamicTiles})
            for (int threads : {1, 2, 3})
                CHECK(bitIdentical(renderScheduled(r, threads, sch), ref));
    }
}

TEST_SUITE("lab 05") {
    // The same kernel under every set of flags: on rays that hit a unit sphere well inside
    // its outline or miss it well outside, every variant finds the hand-worked
    // t = 5 - sqrt(1 - x^2 - y^2), float within 1e-6 relative (a few float roundings of
    // numbers near 4 and 5), double within 1e-14.
    TEST_CASE("language kernels: every variant finds the worked t in float and double") {
        const auto& variants = language::kernelVariants();
        REQUIRE(variants.size() >= 3);
        CHECK(language::referenceVariant().name == "O2");
        std::vector<double> spheres = {0.0, 0.0, 0.0, 1.0, 0.0, 0.0, -40.0, 0.5};
        std::vector<double> rays, exact;
        for (int i = 0; i < 200; ++i) {
            // Radii 0 to 0.9 (hits) and 1.1 to 2 (misses), all around.
            double r = i < 100 ? 0.9 * i / 99.0 : 1.1 + 0.9 * (i - 100) / 99.0;
            double x = r * std::cos(0.37 * i), y = r * std::sin(0.37 * i);
            for (double v : {x, y, 5.0, 0.0, 0.0, -1.0}) rays.push_back(v);
            // Rays within 0.5 of the axis hit the far sphere too: the near hit is the answer.
            exact.push_back(r <= 1.0 ? 5.0 - std::sqrt(1.0 - r * r) : INFINITY);
        }
        std::vector<float> spheresF(spheres.begin(), spheres.end()),
            raysF(rays.begin(), rays.end());
        for (const auto& v : variants) {
            INFO(v.name << " (" << v.flags << ")");
            CHECK(v.flags.find("-ffast-math") == std::string::npos);
            std::vector<float> tf(200);
            std::vector<double> td(200);
            v.nearestFloat(spheresF.data(), 2, raysF.data(), 200, tf.data());
            v.nearestDouble(spheres.data(), 2, rays.data(), 200, td.data());
            for (size_t i = 0; i < 200; ++i) {
                INFO("ray " << i);
                if (std::isinf(exact[i])) {
                    CHECK(std::isinf(tf[i]));
                    CHECK(std::isinf(td[i]));
                } else {
                    CHECK(std::abs(double(tf[i]) - exact[i]) <= 1e-6 * exact[i]);
                    CHECK(std::abs(td[i] - exact[i]) <= 1e-14 * exact[i]);
                }
            }
        }
    }
    TEST_CASE(
        "language table: every variant in float and double and the double O2 row is the "
        "reference") {
        LabOptions o;
        o.quick = true;
        o.repeats = 1;
        Table t = measureLanguage(o);
        CHECK(t.id == "language");
        const size_t type = 2, error = 7, flipped = 8;
        REQUIRE(t.columns[type] == "type");
        REQUIRE(t.columns[error] == "max rel t error");
        REQUIRE(t.columns[flipped] == "flipped");
        const auto& variants = language::kernelVariants();
        REQUIRE(t.rows.size() == 2 * variants.size());
        for (const auto& v : variants)
            for (const char* ty : {"float", "double"}) {
                INFO(v.name << " " << ty);
                int found = 0;
                for (const auto& row : t.rows)
                    if (std::get<std::string>(row[0]) == v.name &&
                        std::get<std::string>(row[type]) == ty) {
                        ++found;
                        double err = std::get<double>(row[error]);
                        CHECK(std::isfinite(err));
                        // Float against double: within float's rounding of t near 10 and
                        // the field's grazing rays (cancellation in b^2 - c).
                        if (std::string(ty) == "float") CHECK(err < 1e-3);
                        // IEEE double without contraction gives the same bits at every
                        // optimization level; contracted to FMA it differs by roundings.
                        if (std::string(ty) == "double" && v.name != "native+fma") {
                            CHECK(err == 0.0);
                            CHECK(std::get<long long>(row[flipped]) == 0);
                        }
                        if (std::string(ty) == "double" && v.name == "native+fma")
                            CHECK(err < 1e-9);
                    }
                CHECK(found == 1);
            }
    }
    TEST_CASE("op cost: every operation in float and double with a positive finite time") {
        LabOptions o;
        o.quick = true;
        o.repeats = 1;
        std::vector<OpCost> costs = measureOpCosts(o);
        for (const char* op : {"sin", "cos", "sqrt", "/", "*", "+", "-"})
            for (const char* type : {"float", "double"}) {
                INFO(op << " " << type);
                int found = 0;
                for (const OpCost& c : costs)
                    if (c.op == op && c.type == type) {
                        ++found;
                        CHECK(std::isfinite(c.nsMedian));
                        CHECK(c.nsMedian > 0.0);
                        CHECK(c.nsMin <= c.nsMedian);
                        CHECK(c.nsMedian <= c.nsMax);
                        // One operation rounds once (sin and cos within about an ulp): its
                        // relative error is a few units of the type's rounding, 2^-24 or 2^-53.
                        double unit = std::string(type) == "float" ? 0x1p-24 : 0x1p-53;
                        CHECK(c.relError <= 4.0 * unit);
                    }
                CHECK(found == 1);
            }
        // The basic operations are correctly rounded: half an ulp at most.
        for (const OpCost& c : costs)
            if (c.op == "sqrt" || c.op == "/" || c.op == "*" || c.op == "+" || c.op == "-") {
                INFO(c.op << " " << c.type);
                CHECK(c.relError <= (c.type == "float" ? 0x1p-24 : 0x1p-53));
            }
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
                             {"--scene nosuchscene", "unknown scene", 1},
                             {"--frobnicate", "frobnicate", 2},
                             {"--width 0", "width", 2},
                             {"--repeats 0", "repeats", 2},
                             {"--budget-ms 0", "budget", 2},
                             {"--eye 1,2,3 --look 1,2,3", "view direction is zero", 1}});
    }
}
