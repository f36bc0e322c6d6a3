#include "02_box/box_scene.hpp"

#include <stdexcept>

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
    if (method == BoxMethod::SixPlanes && planes_.size() != boxes_.size())
        throw std::logic_error("BoxSet: setMethod(SixPlanes) prepares the planes; call it first");
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

}  // namespace boxes
