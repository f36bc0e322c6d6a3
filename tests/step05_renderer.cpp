// Step 05's renderer: effects on demand (identical images with fewer rays, on every scene
// kind and 200 random scenes), the finite light radius, the mesh hierarchy's switches, the
// previews and the schedules.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "05_efficiency/bvh_mesh.hpp"
#include "05_efficiency/lab.hpp"
#include "05_efficiency/measure.hpp"
#include "05_efficiency/progressive.hpp"
#include "core/render.hpp"
#include "core/scene.hpp"
#include "support.hpp"

using namespace boxes;

namespace {

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

}  // namespace

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
