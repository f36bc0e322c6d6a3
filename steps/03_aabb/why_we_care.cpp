#include "03_aabb/why_we_care.hpp"

#include <algorithm>
#include <cstdio>
#include <numeric>
#include <random>
#include <utility>

#include "01_triangle/triangle.hpp"
#include "core/heatmap.hpp"
#include "core/mesh.hpp"
#include "core/render.hpp"

namespace boxes {

namespace {
thread_local TestCounts::OnThread onThread;
}

void TestCounts::add(uint64_t boxes, uint64_t primitives) {
    boxTests.fetch_add(boxes, std::memory_order_relaxed);
    primitiveTests.fetch_add(primitives, std::memory_order_relaxed);
    onThread.boxTests += boxes;
    onThread.primitiveTests += primitives;
}

TestCounts::OnThread TestCounts::take() {
    return std::exchange(onThread, OnThread{});
}

double PixelCosts::boxTestsPerRay() const {
    double r = std::accumulate(rays.begin(), rays.end(), 0.0);
    return std::accumulate(boxTests.begin(), boxTests.end(), 0.0) / std::max(1.0, r);
}

double PixelCosts::primitiveTestsPerRay() const {
    double r = std::accumulate(rays.begin(), rays.end(), 0.0);
    return std::accumulate(primitiveTests.begin(), primitiveTests.end(), 0.0) / std::max(1.0, r);
}

void renderCountingPixels(const Renderer& renderer, Image& image, PixelCosts& costs,
                          std::vector<RayCounts>& perThread, const std::vector<int>& rows,
                          const std::string& label) {
    const int w = image.width(), h = image.height();
    if (costs.width != w || costs.height != h) {
        costs = PixelCosts{w, h, {}, {}, {}};
        for (auto* v : {&costs.boxTests, &costs.primitiveTests, &costs.rays})
            v->assign(size_t(w) * size_t(h), 0.0);
    }
    RenderControl* control = renderer.settings().control;
    if (control) {
        control->rowsDone = 0;
        control->rows = rows.empty() ? h : int(rows.size());
    }
    parallelRows(
        rows.empty() ? h : int(rows.size()), int(perThread.size()),
        [&](int i, int thread) {
            checkCancelled(control);
            int y = rows.empty() ? i : rows[size_t(i)];
            RayCounts& counts = perThread[size_t(thread)];
            TestCounts::take();  // what this thread counted before belongs to no pixel
            for (int x = 0; x < w; ++x) {
                checkCancelled(control);  // within a pixel: a row here can take long
                uint64_t before = counts.total();
                image.at(x, y) = renderer.pixel(x, y, counts);
                TestCounts::OnThread tests = TestCounts::take();
                size_t p = size_t(y) * size_t(w) + size_t(x);
                costs.boxTests[p] = double(tests.boxTests);
                costs.primitiveTests[p] = double(tests.primitiveTests);
                costs.rays[p] = double(counts.total() - before);
            }
            if (control) control->rowsDone.fetch_add(1, std::memory_order_relaxed);
        },
        label);
}

SphereCloud::SphereCloud(std::vector<SceneSphere> spheres, std::shared_ptr<TestCounts> counts)
    : spheres_(std::move(spheres)), counts_(std::move(counts)) {
    for (const SceneSphere& s : spheres_) {
        if (!isFinite(s.shape.centre) || !(s.shape.radius > 0.0f) || !std::isfinite(s.shape.radius))
            throw std::invalid_argument("sphere with a NaN, infinite or non-positive size");
        bounds_.push_back(sphereBounds(s.shape));
        all_ = unionBounds(all_, bounds_.back());
    }
}

std::vector<int> SphereCloud::materialsUsed() const {
    std::vector<int> used;
    for (const SceneSphere& s : spheres_)
        if (std::find(used.begin(), used.end(), s.material) == used.end())
            used.push_back(s.material);
    return used;
}

bool SphereCloud::intersect(const Ray& rayIn, SurfaceHit& hit) const {
    Ray ray = rayIn;
    SlabRay slabRay(ray);
    uint64_t boxTests = 0, tests = 0;
    int found = -1;
    for (size_t i = 0; i < spheres_.size(); ++i) {
        if (pretest_) {
            ++boxTests;
            slabRay.tmax = ray.tmax;
            if (!intersectSlabsConservative(slabRay, bounds_[i])) continue;
        }
        ++tests;
        auto t = intersectSphere(ray, spheres_[i].shape);
        if (!t) continue;
        ray.tmax = *t;
        found = int(i);
    }
    counts_->add(boxTests, tests);
    if (found < 0) return false;
    const Sphere& s = spheres_[size_t(found)].shape;
    hit.t = ray.tmax;
    hit.point = ray.at(hit.t);
    hit.geometricNormal = (hit.point - s.centre) / s.radius;
    hit.shadingNormal = hit.geometricNormal;
    hit.u = hit.v = 0.0f;
    hit.material = spheres_[size_t(found)].material;
    hit.primitive = uint32_t(found);
    hit.kind = SurfaceHit::Kind::Sphere;
    return true;
}

bool SphereCloud::occluded(const Ray& ray) const {
    SlabRay slabRay(ray);
    uint64_t boxTests = 0, tests = 0;
    bool blocked = false;
    for (size_t i = 0; i < spheres_.size() && !blocked; ++i) {
        if (pretest_) {
            ++boxTests;
            if (!intersectSlabsConservative(slabRay, bounds_[i])) continue;
        }
        ++tests;
        blocked = intersectSphere(ray, spheres_[i].shape).has_value();
    }
    counts_->add(boxTests, tests);
    return blocked;
}

namespace {

// Spreads the low 10 bits of v to every third bit (Morton code of 3 x 10 bits).
uint32_t spreadBits(uint32_t v) {
    v &= 0x3FFu;
    v = (v | (v << 16)) & 0x030000FFu;
    v = (v | (v << 8)) & 0x0300F00Fu;
    v = (v | (v << 4)) & 0x030C30C3u;
    v = (v | (v << 2)) & 0x09249249u;
    return v;
}

}  // namespace

TriangleGroups::TriangleGroups(const Mesh& mesh, int material, std::shared_ptr<TestCounts> counts,
                               int groupSize)
    : mesh_(mesh),
      material_(material),
      groupSize_(std::max(1, groupSize)),
      counts_(std::move(counts)) {
    mesh_.validate("mesh");
    meshBox_ = meshBounds(mesh_);
    std::vector<uint32_t> code(mesh_.triangleCount());
    Vec3 extent = glm::max(meshBox_.diagonal(), Vec3(1e-30f));
    for (size_t t = 0; t < mesh_.triangleCount(); ++t) {
        Vec3 c = (mesh_.vertex(t, 0) + mesh_.vertex(t, 1) + mesh_.vertex(t, 2)) / 3.0f;
        Vec3 q = glm::clamp((c - meshBox_.min) / extent, Vec3(0.0f), Vec3(1.0f)) * 1023.0f;
        code[t] = spreadBits(uint32_t(q.x)) | (spreadBits(uint32_t(q.y)) << 1) |
                  (spreadBits(uint32_t(q.z)) << 2);
    }
    order_.resize(mesh_.triangleCount());
    std::iota(order_.begin(), order_.end(), 0u);
    std::stable_sort(order_.begin(), order_.end(),
                     [&](uint32_t a, uint32_t b) { return code[a] < code[b]; });
    for (size_t g = 0; g < order_.size(); g += size_t(groupSize_)) {
        Bounds3f box;
        for (size_t i = g; i < std::min(order_.size(), g + size_t(groupSize_)); ++i) {
            uint32_t t = order_[i];
            box = unionBounds(box, triangleBounds(Triangle{mesh_.vertex(t, 0), mesh_.vertex(t, 1),
                                                           mesh_.vertex(t, 2)}));
        }
        groupBoxes_.push_back(box);
    }
}

bool TriangleGroups::intersect(const Ray& rayIn, SurfaceHit& hit) const {
    Ray ray = rayIn;
    SlabRay slabRay(ray);
    uint64_t boxTests = 0, tests = 0;
    uint32_t found = kNoPrimitive;
    float u = 0.0f, v = 0.0f;
    bool enter = true;
    if (pretest_) {
        ++boxTests;
        enter = intersectSlabsConservative(slabRay, meshBox_).has_value();
    }
    for (size_t g = 0; enter && g < groupBoxes_.size(); ++g) {
        if (pretest_) {
            ++boxTests;
            slabRay.tmax = ray.tmax;
            if (!intersectSlabsConservative(slabRay, groupBoxes_[g])) continue;
        }
        size_t end = std::min(order_.size(), (g + 1) * size_t(groupSize_));
        for (size_t i = g * size_t(groupSize_); i < end; ++i) {
            uint32_t t = order_[i];
            ++tests;
            auto h = intersectWatertight(
                ray, Triangle{mesh_.vertex(t, 0), mesh_.vertex(t, 1), mesh_.vertex(t, 2)});
            if (!h) continue;
            ray.tmax = h->t;
            found = t, u = h->u, v = h->v;
        }
    }
    counts_->add(boxTests, tests);
    if (found == kNoPrimitive) return false;
    hit = triangleHit(mesh_, found, ray, ray.tmax, u, v, material_);
    return true;
}

bool TriangleGroups::occluded(const Ray& ray) const {
    SlabRay slabRay(ray);
    uint64_t boxTests = 0, tests = 0;
    bool blocked = false, enter = true;
    if (pretest_) {
        ++boxTests;
        enter = intersectSlabsConservative(slabRay, meshBox_).has_value();
    }
    for (size_t g = 0; enter && !blocked && g < groupBoxes_.size(); ++g) {
        if (pretest_) {
            ++boxTests;
            if (!intersectSlabsConservative(slabRay, groupBoxes_[g])) continue;
        }
        size_t end = std::min(order_.size(), (g + 1) * size_t(groupSize_));
        for (size_t i = g * size_t(groupSize_); i < end && !blocked; ++i) {
            uint32_t t = order_[i];
            ++tests;
            blocked = intersectWatertight(
                          ray, Triangle{mesh_.vertex(t, 0), mesh_.vertex(t, 1), mesh_.vertex(t, 2)})
                          .has_value();
        }
    }
    counts_->add(boxTests, tests);
    return blocked;
}

Image ManyObjects::View::show(int mode) const {
    if (mode == 0 || costs.width == 0) return image;
    const std::vector<double>& v = mode == 1 ? costs.primitiveTests : costs.boxTests;
    double perRay = mode == 1 ? costs.primitiveTestsPerRay() : costs.boxTestsPerRay();
    char title[96];
    std::snprintf(title, sizeof title, "%s tests per pixel (mean %.1f per ray)",
                  mode == 1 ? "primitive" : "box", perRay);
    return heatMapImage(v, costs.width, costs.height,
                        scaleTop(*std::max_element(v.begin(), v.end())), title);
}

void ManyObjects::setPretest(bool on) {
    if (spheres) spheres->setPretest(on);
    for (auto& m : meshes) m->setPretest(on);
}

ManyObjects::View ManyObjects::render(const Camera& camera, RenderSettings settings, bool pretest) {
    setPretest(pretest);
    counts->reset();
    if (!pretest) {
        settings.width = std::max(1, settings.width / 4);
        settings.height = std::max(1, settings.height / 4);
        settings.progressLabel = "03_aabb: without the pre-test";
    }
    View view;
    view.image = Image(settings.width, settings.height);
    Renderer renderer(scene, camera, settings);
    std::vector<RayCounts> perThread(size_t(resolveThreads(settings.threads)));
    renderCountingPixels(renderer, view.image, view.costs, perThread, {}, settings.progressLabel);
    RayCounts rays;
    for (const RayCounts& c : perThread) rays += c;
    double n = double(std::max<uint64_t>(1, rays.total()));
    view.primitiveTestsPerRay = double(counts->primitiveTests.load()) / n;
    view.boxTestsPerRay = double(counts->boxTests.load()) / n;
    return view;
}

ManyObjects makeManyObjects(const std::string& dataDir, float aspect, size_t sphereCount,
                            size_t triangleCount, bool bunny, uint64_t seed) {
    ManyObjects m;
    m.counts = std::make_shared<TestCounts>();
    Scene& s = m.scene;
    s.name = "many";
    s.materials = {Material::diffuse(Vec3(0.72f, 0.70f, 0.66f)),  // 0 floor
                   Material::diffuse(Vec3(0.80f, 0.25f, 0.20f)),  // 1..4 spheres and triangles
                   Material::diffuse(Vec3(0.25f, 0.45f, 0.80f)),
                   Material::diffuse(Vec3(0.30f, 0.70f, 0.35f)),
                   Material::diffuse(Vec3(0.85f, 0.75f, 0.30f)),
                   Material::diffuse(Vec3(0.82f, 0.80f, 0.76f))};  // 5 bunny
    s.planes.push_back({{Vec3(0, 1, 0), 0.0f}, 0});
    s.lights.push_back({Vec3(-4.0f, 9.0f, 6.0f), Vec3(90.0f), PointLight::radiusFor(Vec3(90.0f))});
    s.ambient = Vec3(0.06f);
    s.camera.eye = Vec3(0.0f, 4.5f, 8.5f);
    s.camera.view = Vec3(0.0f, 0.8f, -1.5f) - s.camera.eye;
    s.camera.fovYDegrees = 50.0f;
    s.camera.aspect = aspect;

    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    // Spheres and triangle clusters scattered over the floor around the bunny.
    auto spot = [&](float lift) {
        for (;;) {
            Vec3 p(-7.0f + 14.0f * u01(rng), lift, -7.0f + 9.5f * u01(rng));
            if (std::abs(p.x) > 1.8f || p.z < -2.8f || p.z > 0.8f) return p;
        }
    };
    std::vector<SceneSphere> spheres;
    for (size_t i = 0; i < sphereCount; ++i) {
        float r = 0.05f + 0.1f * u01(rng);
        spheres.push_back({{spot(r + 1.2f * u01(rng) * u01(rng)), r}, 1 + int(i % 4)});
    }
    m.spheres = std::make_shared<SphereCloud>(spheres, m.counts);
    s.geometries.push_back(m.spheres);
    if (triangleCount > 0) {
        Mesh soup;
        for (size_t c = 0; c * 8 < triangleCount; ++c) {
            Vec3 centre = spot(0.2f + 1.5f * u01(rng));
            for (size_t i = 0; i < 8 && c * 8 + i < triangleCount; ++i) {
                uint32_t base = uint32_t(soup.positions.size());
                for (int v = 0; v < 3; ++v)
                    soup.positions.push_back(centre + 0.18f * Vec3(2 * u01(rng) - 1,
                                                                   2 * u01(rng) - 1,
                                                                   2 * u01(rng) - 1));
                soup.triangles.push_back({base, base + 1, base + 2});
            }
        }
        m.meshes.push_back(std::make_shared<TriangleGroups>(soup, 4, m.counts));
        s.geometries.push_back(m.meshes.back());
    }
    if (bunny) {
        Mesh b = loadObj(dataDir + "/meshes/bunny.obj");
        for (Vec3& p : b.positions) p = 1.5f * p;
        Bounds3f box = meshBounds(b);
        b.translate(Vec3(0.0f, -box.min.y, -1.0f));
        m.meshes.push_back(std::make_shared<TriangleGroups>(b, 5, m.counts));
        s.geometries.push_back(m.meshes.back());
    }
    return m;
}

ManyObjects wrapScene(Scene scene) {
    ManyObjects m;
    m.counts = std::make_shared<TestCounts>();
    m.scene = std::move(scene);
    if (!m.scene.spheres.empty()) {
        m.spheres = std::make_shared<SphereCloud>(m.scene.spheres, m.counts);
        m.scene.spheres.clear();
        m.scene.geometries.push_back(m.spheres);
    }
    if (m.scene.hasMesh()) {
        m.meshes.push_back(
            std::make_shared<TriangleGroups>(m.scene.mesh, m.scene.meshMaterial, m.counts));
        m.scene.geometries.push_back(m.meshes.back());
    }
    return m;
}

}  // namespace boxes
