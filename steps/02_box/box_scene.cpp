#include "02_box/box_scene.hpp"

#include <algorithm>
#include <random>

#include "core/timing.hpp"

namespace boxes {

BoxSet::BoxSet(std::vector<SceneBox> boxes, BoxMethod method)
    : boxes_(std::move(boxes)), method_(method) {
    for (const SceneBox& b : boxes_) {
        b.box.validate();
        for (int corner = 0; corner < 8; ++corner) {
            Vec3 p = b.box.centre;
            for (int k = 0; k < 3; ++k)
                p += ((corner >> k) & 1 ? 1.0f : -1.0f) * b.box.halfExtents[k] *
                     b.box.axes[size_t(k)];
            lo_ = glm::min(lo_, p);
            hi_ = glm::max(hi_, p);
        }
    }
    setMethod(method);
}

void BoxSet::setMethod(BoxMethod method) {
    method_ = method;
    if (method == BoxMethod::SixPlanes && planes_.size() != boxes_.size()) {
        planes_.clear();
        for (const SceneBox& b : boxes_) planes_.push_back(boxFacePlanes(b.box));
    }
}

std::vector<int> BoxSet::materialsUsed() const {
    std::vector<int> used;
    for (const SceneBox& b : boxes_)
        if (std::find(used.begin(), used.end(), b.material) == used.end())
            used.push_back(b.material);
    return used;
}

BoxSet::Nearest BoxSet::nearest(const Ray& rayIn, BoxMethod method) const {
    Ray ray = rayIn;
    Nearest best;
    for (size_t i = 0; i < boxes_.size(); ++i) {
        auto h = method == BoxMethod::SixPlanes ? intersectSixPlanes(ray, planes_[i])
                                                : intersectBoxSlabs(ray, boxes_[i].box);
        if (!h) continue;
        ray.tmax = h->t;
        best = {int(i), *h};
    }
    return best;
}

bool BoxSet::intersect(const Ray& ray, SurfaceHit& hit) const {
    Nearest n = nearest(ray, method_);
    if (n.box < 0) return false;
    hit.t = n.hit.t;
    hit.point = ray.at(n.hit.t);
    hit.geometricNormal = n.hit.normal;
    hit.shadingNormal = n.hit.normal;
    hit.u = hit.v = 0.0f;
    hit.material = boxes_[size_t(n.box)].material;
    hit.primitive = uint32_t(n.box);
    hit.kind = SurfaceHit::Kind::Plane;  // a face of a box
    return true;
}

bool BoxSet::occluded(const Ray& ray) const {
    for (size_t i = 0; i < boxes_.size(); ++i) {
        bool h = method_ == BoxMethod::SixPlanes
                     ? intersectSixPlanes(ray, planes_[i]).has_value()
                     : intersectBoxSlabs(ray, boxes_[i].box).has_value();
        if (h) return true;
    }
    return false;
}

Scene makeBoxScene(float aspect) {
    Scene s;
    s.name = "boxes";
    s.materials = {Material::diffuse(Vec3(0.72f, 0.70f, 0.66f)),  // 0 floor
                   Material::diffuse(Vec3(0.80f, 0.25f, 0.20f)),  // 1 red
                   Material::diffuse(Vec3(0.25f, 0.45f, 0.80f)),  // 2 blue
                   Material::diffuse(Vec3(0.30f, 0.70f, 0.35f)),  // 3 green
                   Material::diffuse(Vec3(0.85f, 0.75f, 0.30f)),  // 4 yellow
                   Material::mirror(Vec3(0.95f), 0.85f),          // 5 mirror
                   Material::glass(1.5f)};                        // 6 glass
    s.planes.push_back({{Vec3(0, 1, 0), 0.0f}, 0});
    s.lights.push_back({Vec3(-3.0f, 7.0f, 5.0f), Vec3(60.0f), PointLight::radiusFor(Vec3(60.0f))});
    s.lights.push_back(
        {Vec3(5.0f, 5.0f, 2.0f), Vec3(18.0f, 16.0f, 13.0f), PointLight::radiusFor(Vec3(18.0f))});
    s.camera.eye = Vec3(0.0f, 5.0f, 9.5f);
    s.camera.view = Vec3(0.0f, 0.4f, -1.2f) - s.camera.eye;
    s.camera.fovYDegrees = 45.0f;
    s.camera.aspect = aspect;
    return s;
}

std::vector<SceneBox> boxStepBoxes() {
    // A 5 x 3 grid: every other box axis-aligned, the rest turned about y, some also tipped.
    std::vector<SceneBox> boxes;
    const int materials[] = {1, 2, 3, 4, 5, 1, 6, 2, 3, 4, 2, 5, 4, 6, 3};
    int n = 0;
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 5; ++i, ++n) {
            Vec3 half(0.55f, 0.35f + 0.25f * float((i + 2 * j) % 3), 0.55f);
            Vec3 centre(-4.0f + 2.0f * float(i), half.y, -3.0f + 2.0f * float(j));
            OrientedBox box = OrientedBox::axisAligned(Bounds3f(centre - half, centre + half));
            if (n % 2) {
                bool tipped = n % 4 == 1;
                Vec3 axis = tipped ? glm::normalize(Vec3(1.0f, 1.5f, 0.5f)) : Vec3(0, 1, 0);
                float angle = glm::radians(20.0f + 13.0f * float(n));
                centre.y = tipped ? glm::length(half) : half.y;
                box = OrientedBox::rotated(centre, half, axis, angle);
            }
            boxes.push_back({box, materials[n]});
        }
    return boxes;
}

std::vector<SceneBox> boxesFromScene(Scene& scene) {
    std::vector<SceneBox> boxes;
    for (const SceneSphere& s : scene.spheres) {
        Vec3 r(s.shape.radius);
        boxes.push_back({OrientedBox::axisAligned(Bounds3f(s.shape.centre - r, s.shape.centre + r)),
                         s.material});
    }
    scene.spheres.clear();
    if (scene.hasMesh()) {
        Bounds3f b;
        for (const auto& tri : scene.mesh.triangles)
            for (uint32_t v : tri) b.extend(scene.mesh.positions[v]);
        boxes.push_back({OrientedBox::axisAligned(b), scene.meshMaterial});
        scene.mesh = Mesh{};
    }
    return boxes;
}

BoxRaySet makeBoxRays(size_t boxCount, size_t raysPerBox, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    auto sym = [&] { return 2.0f * u01(rng) - 1.0f; };
    auto unit = [&] {
        for (;;) {
            Vec3 v(sym(), sym(), sym());
            float l = glm::length(v);
            if (l > 0.1f && l <= 1.0f) return v / l;
        }
    };
    BoxRaySet set;
    for (size_t b = 0; b < boxCount; ++b) {
        Vec3 centre(10.0f * sym(), 10.0f * sym(), 10.0f * sym());
        Vec3 half(0.1f + 1.9f * u01(rng), 0.1f + 1.9f * u01(rng), 0.1f + 1.9f * u01(rng));
        OrientedBox box = b % 4 == 0
                              ? OrientedBox::axisAligned(Bounds3f(centre - half, centre + half))
                              : OrientedBox::rotated(centre, half, unit(), 6.2831853f * u01(rng));
        set.boxes.push_back(box);
        auto local = [&](Vec3 p) {
            return box.centre + p.x * box.axes[0] + p.y * box.axes[1] + p.z * box.axes[2];
        };
        for (size_t i = 0; i < raysPerBox; ++i) {
            int kind = int(i % 10);
            Vec3 p(sym() * half.x, sym() * half.y, sym() * half.z);
            if (kind < 6) {  // a point on a face
                int k = int(rng() % 3);
                p[k] = (rng() & 1 ? 1.0f : -1.0f) * half[k];
            } else if (kind < 8) {  // a point on an edge
                int k = int(rng() % 3), m = (k + 1) % 3;
                p[k] = (rng() & 1 ? 1.0f : -1.0f) * half[k];
                p[m] = (rng() & 1 ? 1.0f : -1.0f) * half[m];
            } else if (kind == 8) {  // near the box: hits and misses
                p *= 1.5f;
            }
            Vec3 target = local(p);
            Vec3 origin;
            if (kind == 9) {  // from inside the box
                origin = local(0.9f * Vec3(sym() * half.x, sym() * half.y, sym() * half.z));
                target = origin + unit();
            } else {
                origin = target + (2.0f + 6.0f * u01(rng)) * maxComponent(half) * unit();
            }
            set.rays.push_back({Ray(origin, target - origin), uint32_t(b)});
        }
    }
    return set;
}

namespace {

template <typename T>
OrientedBoxT<T> castBox(const OrientedBox& b) {
    return {Vec3T<T>(b.centre),
            {Vec3T<T>(b.axes[0]), Vec3T<T>(b.axes[1]), Vec3T<T>(b.axes[2])},
            Vec3T<T>(b.halfExtents)};
}

using Real = long double;  // the reference: the slab method in x87 extended precision

}  // namespace

std::vector<Table> measureBoxMethods(const BoxRaySet& set, int repeats) {
    Table speed;
    speed.id = "box_speed";
    speed.title = "Time per ray/box test: the six-plane method against the slab method";
    speed.columns = {"method", "precision", "ns/test", "min ns", "max ns", "hits"};
    speed.note = "median of repeats over " + std::to_string(set.rays.size()) +
                 " rays at random oriented boxes (faces, edges, near misses, from inside); one "
                 "thread; six planes use precomputed planes (exercise 2.1)";
    Table accuracy;
    accuracy.id = "box_accuracy";
    accuracy.title =
        "Accuracy against time: wrong answers of each method against a long double reference";
    accuracy.columns = {"method",         "precision",  "ns/test",
                        "wrong hit/miss", "wrong face", "max rel t error"};
    accuracy.note =
        "reference: the slab method in long double (64-bit mantissa) on the same "
        "float rays and boxes; a face counts as wrong only when the reference puts "
        "that face's plane at another t (on an edge both faces are right)";

    // Reference answers, and the reference t of every face plane for the face check.
    std::vector<std::optional<BoxHit<Real>>> reference;
    std::vector<std::array<PlaneT<Real>, 6>> refPlanes;
    for (const OrientedBox& b : set.boxes) refPlanes.push_back(boxFacePlanes(castBox<Real>(b)));
    for (const BoxRay& r : set.rays)
        reference.push_back(intersectBoxSlabs(r.ray.as<Real>(), castBox<Real>(set.boxes[r.box])));

    auto run = [&](BoxMethod method, auto precision) {
        using T = decltype(precision);
        std::vector<RayT<T>> rays;
        std::vector<OrientedBoxT<T>> boxes;
        std::vector<std::array<PlaneT<T>, 6>> planes;
        for (const BoxRay& r : set.rays) rays.push_back(r.ray.as<T>());
        for (const OrientedBox& b : set.boxes) {
            boxes.push_back(castBox<T>(b));
            planes.push_back(boxFacePlanes(boxes.back()));
        }
        std::vector<std::optional<BoxHit<T>>> answers(rays.size());
        auto test = [&](size_t i) {
            return method == BoxMethod::SixPlanes
                       ? intersectSixPlanes(rays[i], planes[set.rays[i].box])
                       : intersectBoxSlabs(rays[i], boxes[set.rays[i].box]);
        };
        long long hits = 0;
        Timing timing = measureBatched(repeats, [&] {
            long long h = 0;
            for (size_t i = 0; i < rays.size(); ++i) h += test(i).has_value();
            keepValue(h);
            hits = h;
        });
        for (size_t i = 0; i < rays.size(); ++i) answers[i] = test(i);
        long long wrongHit = 0, wrongFace = 0;
        double maxT = 0.0;
        for (size_t i = 0; i < rays.size(); ++i) {
            const auto& ref = reference[i];
            const auto& got = answers[i];
            if (ref.has_value() != got.has_value()) {
                ++wrongHit;
                continue;
            }
            if (!ref) continue;
            Real tRef = ref->t;
            if (got->face != ref->face) {
                RayT<Real> ray = set.rays[i].ray.as<Real>();
                const PlaneT<Real>& p = refPlanes[set.rays[i].box][size_t(got->face)];
                Real denom = glm::dot(ray.direction, p.normal);
                Real tFace =
                    denom == 0 ? kInfinity<Real> : -(glm::dot(ray.origin, p.normal) + p.d) / denom;
                if (!(std::abs(tFace - tRef) <= Real(1e-6) * std::max(Real(1), std::abs(tRef))))
                    ++wrongFace;
            }
            maxT = std::max(maxT, double(std::abs(Real(got->t) - tRef) /
                                         std::max(std::abs(tRef), Real(1e-30))));
        }
        double scale = 1e9 / double(rays.size());
        std::string name = boxMethodName(method), prec = sizeof(T) == 4 ? "float" : "double";
        speed.row(
            {name, prec, timing.median * scale, timing.min * scale, timing.max * scale, hits});
        accuracy.row({name, prec, timing.median * scale, wrongHit, wrongFace, maxT});
    };
    for (BoxMethod m : {BoxMethod::SixPlanes, BoxMethod::Slabs}) {
        run(m, 0.0f);
        run(m, 0.0);
    }
    return {speed, accuracy};
}

Disagreement compareMethods(const BoxRaySet& set) {
    Disagreement d;
    std::vector<std::array<Plane, 6>> planes;
    for (const OrientedBox& b : set.boxes) planes.push_back(boxFacePlanes(b));
    for (const BoxRay& r : set.rays) {
        auto a = intersectSixPlanes(r.ray, planes[r.box]);
        auto b = intersectBoxSlabs(r.ray, set.boxes[r.box]);
        ++d.rays;
        if (a.has_value() != b.has_value()) {
            ++d.hitMiss;
            continue;
        }
        if (!a) continue;
        if (a->face != b->face && std::abs(a->t - b->t) > 1e-5f * std::max(1.0f, std::abs(a->t)))
            ++d.face;
        d.maxRelativeT = std::max(d.maxRelativeT, double(std::abs(a->t - b->t)) /
                                                      std::max(double(std::abs(b->t)), 1e-30));
    }
    return d;
}

}  // namespace boxes
