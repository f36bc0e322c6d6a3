#include "core/scene.hpp"

#include <filesystem>

namespace boxes {

bool Scene::intersect(const Ray& rayIn, SurfaceHit& hit) const {
    Ray ray = rayIn;
    bool found = false;
    int object = 0;
    for (size_t i = 0; i < spheres.size(); ++i, ++object) {
        auto t = intersectSphere(ray, spheres[i].shape);
        if (!t) continue;
        found = true;
        ray.tmax = *t;
        hit.t = *t;
        hit.point = ray.at(*t);
        hit.geometricNormal = (hit.point - spheres[i].shape.centre) / spheres[i].shape.radius;
        hit.shadingNormal = hit.geometricNormal;
        hit.material = spheres[i].material;
        hit.primitive = uint32_t(i);
        hit.object = object;
        hit.kind = SurfaceHit::Kind::Sphere;
        hit.u = hit.v = 0.0f;
    }
    for (size_t i = 0; i < planes.size(); ++i, ++object) {
        auto t = intersectPlane(ray, planes[i].shape);
        if (!t) continue;
        found = true;
        ray.tmax = *t;
        hit.t = *t;
        hit.point = ray.at(*t);
        hit.geometricNormal = planes[i].shape.normal;
        hit.shadingNormal = hit.geometricNormal;
        hit.material = planes[i].material;
        hit.primitive = uint32_t(i);
        hit.object = object;
        hit.kind = SurfaceHit::Kind::Plane;
        hit.u = hit.v = 0.0f;
    }
    for (const auto& geometry : geometries) {
        if (geometry->intersect(ray, hit)) {
            found = true;
            ray.tmax = hit.t;
            hit.object = object;
        }
        ++object;
    }
    return found;
}

bool Scene::occluded(const Ray& ray) const {
    for (const auto& s : spheres)
        if (intersectSphere(ray, s.shape)) return true;
    for (const auto& p : planes)
        if (intersectPlane(ray, p.shape)) return true;
    for (const auto& g : geometries)
        if (g->occluded(ray)) return true;
    return false;
}

void Scene::checkRenderable() const {
    if (hasMesh() && geometries.empty())
        throw std::logic_error("scene '" + name + "' has a mesh but no geometry to intersect it");
    auto checkMaterial = [&](int m) {
        if (m < 0 || size_t(m) >= materials.size())
            throw std::logic_error("scene '" + name + "' uses a material that does not exist");
    };
    // NaN or infinite geometry or lights would make NaN pixels (or trap): refuse them
    // with a message naming the object.
    auto bad = [&](const std::string& what, size_t i) {
        return InputError("scene '" + printable(name) + "': " + what + " " + std::to_string(i) +
                          " has a non-finite or invalid value");
    };
    for (size_t i = 0; i < spheres.size(); ++i) {
        const Sphere& sphere = spheres[i].shape;
        if (!isFinite(sphere.centre) || !std::isfinite(sphere.radius) || !(sphere.radius > 0.0f))
            throw bad("sphere", i);
    }
    for (size_t i = 0; i < planes.size(); ++i)
        if (!isFinite(planes[i].shape.normal) || isZero(planes[i].shape.normal) ||
            !std::isfinite(planes[i].shape.d))
            throw bad("plane", i);
    for (size_t i = 0; i < lights.size(); ++i)
        if (!isFinite(lights[i].position) || !isFinite(lights[i].intensity) ||
            std::isnan(lights[i].radius) || !(lights[i].radius >= 0.0f))
            throw bad("light", i);
    if (hasMesh()) mesh.validate("scene '" + printable(name) + "' mesh");
    for (const auto& s : spheres) checkMaterial(s.material);
    for (const auto& p : planes) checkMaterial(p.material);
    for (const auto& g : geometries)
        for (int m : g->materialsUsed()) checkMaterial(m);
}

Camera fitCamera(Vec3 lo, Vec3 hi, float aspect, Vec3 from, Vec3 up, float fovYDegrees) {
    Vec3 centre = 0.5f * (lo + hi);
    float radius = 0.5f * glm::length(hi - lo);
    if (!(radius > 0.0f)) radius = 1.0f;
    float halfFov = glm::radians(fovYDegrees) * 0.5f;
    // The bounding sphere fits both the vertical and the horizontal field of view.
    float halfFovX = std::atan(std::tan(halfFov) * aspect);
    float distance = radius / std::sin(std::min(halfFov, halfFovX)) * 1.02f;
    Camera camera;
    camera.view = -glm::normalize(from);
    camera.eye = centre - distance * camera.view;
    camera.up = up;
    camera.fovYDegrees = fovYDegrees;
    camera.aspect = aspect;
    return camera;
}

namespace {

// The radius is set by Scene::setLightRadii once the scene has all its lights.
PointLight lightAt(Vec3 position, Vec3 intensity) {
    return {position, intensity, kInfinity<float>};
}

Scene classicSpheres() {
    Scene s;
    s.name = "spheres";
    s.materials = {Material::diffuse(Vec3(0.72f, 0.70f, 0.66f)),  // 0 floor
                   Material::diffuse(Vec3(0.80f, 0.25f, 0.20f)),  // 1 red
                   Material::diffuse(Vec3(0.25f, 0.45f, 0.80f)),  // 2 blue
                   Material::mirror(Vec3(0.95f), 0.85f),          // 3 mirror
                   Material::glass(1.5f)};                        // 4 glass
    s.planes.push_back({{Vec3(0, 1, 0), 0.0f}, 0});
    s.spheres.push_back({{Vec3(-1.6f, 0.7f, -0.6f), 0.7f}, 1});
    s.spheres.push_back({{Vec3(1.7f, 0.6f, -0.9f), 0.6f}, 2});
    s.spheres.push_back({{Vec3(0.0f, 1.0f, -1.8f), 1.0f}, 3});
    s.spheres.push_back({{Vec3(0.3f, 0.55f, 0.8f), 0.55f}, 4});
    s.lights.push_back(lightAt(Vec3(-3.0f, 6.0f, 4.0f), Vec3(40.0f)));
    s.lights.push_back(lightAt(Vec3(4.0f, 4.0f, 2.0f), Vec3(12.0f, 11.0f, 9.0f)));
    s.camera.eye = Vec3(0.0f, 2.2f, 6.0f);
    s.camera.view = Vec3(0.0f, -0.9f, -6.0f);
    s.camera.fovYDegrees = 45.0f;
    return s;
}

Scene diffuseOnly() {
    Scene s = classicSpheres();
    s.name = "diffuse";
    s.materials[3] = Material::diffuse(Vec3(0.3f, 0.75f, 0.35f));
    s.materials[4] = Material::diffuse(Vec3(0.85f, 0.8f, 0.3f));
    return s;
}

Scene mirrorsOnly() {
    Scene s = classicSpheres();
    s.name = "mirrors";
    s.materials[4] = Material::mirror(Vec3(0.9f, 0.85f, 0.6f), 0.7f);
    return s;
}

Scene glassOnly() {
    Scene s = classicSpheres();
    s.name = "glass";
    s.materials[3] = Material::glass(1.33f);
    return s;
}

Scene singleSphere() {
    Scene s;
    s.name = "single-sphere";
    s.materials = {Material::diffuse(Vec3(0.8f, 0.5f, 0.3f))};
    s.spheres.push_back({{Vec3(0.0f), 1.0f}, 0});
    s.lights.push_back(lightAt(Vec3(3.0f, 4.0f, 5.0f), Vec3(50.0f)));
    s.camera.eye = Vec3(0, 0, 4.5f);
    s.camera.view = Vec3(0, 0, -1);
    return s;
}

// A street of 20 weak lamps (two rows of 10 along -z, 30 apart) over diffuse spheres. With
// 1 / d^2 falloff a light's radius (below half an 8-bit sRGB step shared by 20 lights) is
// about 36 times the distance where it falls to 0.01; only lights far apart put most of
// them beyond it for most points.
Scene smallLights() {
    Scene s = diffuseOnly();
    s.name = "small-lights";
    s.lights.clear();
    s.spheres.clear();
    s.ambient = Vec3(0.005f);
    s.background = Vec3(0.01f, 0.012f, 0.02f);  // night
    for (int i = 0; i < 10; ++i) {
        float z = 1.0f - 30.0f * float(i);
        for (int side = 0; side < 2; ++side) {
            Vec3 colour(0.6f + 0.1f * float(i % 3), 0.7f, 0.6f + 0.1f * float((i + side) % 3));
            s.lights.push_back(lightAt(Vec3(side ? 3.0f : -3.0f, 1.0f, z), 0.2f * colour));
        }
        // A sphere by every lamp post, on alternate sides.
        s.spheres.push_back({{Vec3(i % 2 ? 1.8f : -1.8f, 0.6f, z - 1.5f), 0.6f}, 1 + i % 4});
    }
    s.camera.eye = Vec3(0.0f, 3.0f, 8.0f);
    s.camera.view = Vec3(0.0f, -0.36f, -1.0f);
    s.camera.fovYDegrees = 45.0f;
    return s;
}

Scene meshScene(const std::string& name, const std::string& path, float aspect, bool floor) {
    Scene s;
    s.name = name;
    s.mesh = loadObj(path);
    Vec3 lo(kInfinity<float>), hi(-kInfinity<float>);
    for (const Vec3& p : s.mesh.positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    float diagonal = glm::length(hi - lo);
    if (!(diagonal > 0.0f) || !std::isfinite(diagonal)) diagonal = 1.0f;
    s.materials = {Material::diffuse(Vec3(0.78f, 0.74f, 0.68f)),
                   Material::diffuse(Vec3(0.45f, 0.5f, 0.55f))};
    s.meshMaterial = 0;
    Vec3 centre = 0.5f * (lo + hi);
    Vec3 lightPos = centre + diagonal * Vec3(0.6f, 1.2f, 0.9f);
    Vec3 intensity(1.6f * diagonal * diagonal);
    s.lights.push_back(lightAt(lightPos, intensity));
    s.ambient = Vec3(0.05f);
    if (floor) s.planes.push_back({{Vec3(0, 1, 0), -lo.y}, 1});
    s.camera = fitCamera(lo, hi, aspect);
    return s;
}

}  // namespace

void Scene::setLightRadii() {
    const float threshold = PointLight::cutoffThreshold(lights.size());
    for (PointLight& light : lights)
        light.radius = PointLight::radiusFor(light.intensity, threshold);
}

std::vector<std::pair<std::string, std::string>> builtinScenes() {
    return {{"spheres", "spheres on a floor: diffuse, a mirror and glass, two lights"},
            {"diffuse", "the same spheres, all diffuse (no reflection or refraction rays)"},
            {"mirrors", "the same spheres with two mirrors and no glass"},
            {"glass", "the same spheres with two glass balls and no mirror"},
            {"single-sphere", "one diffuse sphere and one light (nothing can cast a shadow)"},
            {"small-lights",
             "a street of 20 weak lamps over diffuse spheres (the far ones out of range)"},
            {"bunny", "the Stanford bunny (data/meshes/bunny.obj) on a floor"},
            {"sh1", "a closed CAD shape (data/meshes/sh1.obj)"}};
}

Scene makeScene(const std::string& nameOrPath, const SceneOptions& options) {
    Scene s;
    const std::string meshes = options.dataDir + "/meshes/";
    if (nameOrPath == "spheres")
        s = classicSpheres();
    else if (nameOrPath == "diffuse")
        s = diffuseOnly();
    else if (nameOrPath == "mirrors")
        s = mirrorsOnly();
    else if (nameOrPath == "glass")
        s = glassOnly();
    else if (nameOrPath == "single-sphere")
        s = singleSphere();
    else if (nameOrPath == "small-lights")
        s = smallLights();
    else if (nameOrPath == "bunny")
        s = meshScene("bunny", meshes + "bunny.obj", options.aspect, true);
    else if (nameOrPath == "sh1")
        s = meshScene("sh1", meshes + "sh1.obj", options.aspect, false);
    else if (nameOrPath.size() > 4 && nameOrPath.ends_with(".obj"))
        s = meshScene(nameOrPath, nameOrPath, options.aspect, false);
    else {
        std::string names;
        for (const auto& [n, _] : builtinScenes()) names += (names.empty() ? "" : ", ") + n;
        throw UsageError("unknown scene '" + printable(nameOrPath) + "' (built-in: " + names +
                         "; or a path ending in .obj)");
    }
    s.camera.aspect = options.aspect;
    s.setLightRadii();
    return s;
}

}  // namespace boxes
