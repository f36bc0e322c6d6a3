// Scenes: spheres, planes, triangle meshes and step-supplied geometry; materials
// (diffuse, mirror, glass); point lights with a finite radius; a default camera.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/camera.hpp"
#include "core/hit.hpp"
#include "core/mesh.hpp"
#include "core/shapes.hpp"

namespace boxes {

struct Material {
    enum class Kind { Diffuse, Mirror, Glass };
    Kind kind = Kind::Diffuse;
    Vec3 albedo{0.75f};        // diffuse colour; the tint of a mirror
    float reflectance = 0.0f;  // mirror: share of light reflected
    float ior = 1.5f;          // glass: index of refraction

    static Material diffuse(Vec3 albedo) { return {Kind::Diffuse, albedo, 0.0f, 1.0f}; }
    static Material mirror(Vec3 tint, float reflectance) {
        return {Kind::Mirror, tint, reflectance, 1.0f};
    }
    static Material glass(float ior) { return {Kind::Glass, Vec3(1.0f), 0.0f, ior}; }
};

// A point light whose irradiance falls off as intensity / distance^2 and is zero beyond
// `radius`. radiusFor() gives the distance where it drops below a threshold.
struct PointLight {
    Vec3 position{0.0f};
    Vec3 intensity{1.0f};
    float radius = kInfinity<float>;

    // Half of one 8-bit step of the sRGB-encoded image, in linear light. The sRGB curve is
    // steepest at black, where it is linear with slope 12.92 (beyond 0.0031308 its slope is
    // smaller), so a linear change below this moves the encoded value by less than half a
    // step anywhere on the curve. (Half a step in linear light, 0.5 / 255, is 12.92 times
    // too coarse near black: it moved the PNG of 'small-lights' by 2 steps.)
    static constexpr float kHalfStep8 = 0.5f / 255.0f / 12.92f;

    // The threshold per light when the cut-offs of `lightCount` lights may add up at one
    // point: each skipped contribution is below kHalfStep8 / lightCount, so together they
    // are below half a step, and the 8-bit image differs from the render without radii by
    // at most one step. This assumes a pixel is a weighted sum of direct light with weights
    // summing to at most 1 (albedo, mirror reflectance and Fresnel weights at most 1).
    static float cutoffThreshold(size_t lightCount) {
        return kHalfStep8 / float(lightCount > 0 ? lightCount : 1);
    }

    // Distance at which the largest channel of intensity / d^2 falls to `threshold` (an
    // albedo-1 surface lit head-on receives at most intensity / d^2).
    static float radiusFor(Vec3 intensity, float threshold = kHalfStep8) {
        return std::sqrt(maxComponent(intensity) / threshold);
    }
};

struct SceneSphere {
    Sphere shape;
    int material = 0;
};
struct ScenePlane {
    Plane shape;  // unit normal
    int material = 0;
};

// Geometry the core does not intersect itself: a step supplies it (triangles through
// step 01's tests or step 04's hierarchy, boxes through step 02's tests).
class Geometry {
public:
    virtual ~Geometry() = default;
    // Nearest hit in [ray.tmin, ray.tmax]; fills t, point, normals, material, primitive, kind.
    virtual bool intersect(const Ray& ray, SurfaceHit& hit) const = 0;
    // Any hit in [ray.tmin, ray.tmax].
    virtual bool occluded(const Ray& ray) const = 0;
    // Bounds, for the renderer's scene analysis (which lights the geometry can shadow).
    virtual Vec3 boundsMin() const = 0;
    virtual Vec3 boundsMax() const = 0;
    // A convex object cannot cast a shadow on itself.
    virtual bool convex() const { return false; }
    // Materials the geometry uses (indices into Scene::materials).
    virtual std::vector<int> materialsUsed() const = 0;
};

struct Scene {
    std::string name;
    std::vector<Material> materials{Material::diffuse(Vec3(0.75f))};
    std::vector<SceneSphere> spheres;
    std::vector<ScenePlane> planes;
    std::vector<std::shared_ptr<const Geometry>> geometries;
    std::vector<PointLight> lights;
    Vec3 background{0.05f, 0.06f, 0.09f};
    Vec3 ambient{0.04f};
    Camera camera;  // the scene's default view

    // A triangle mesh that a step turns into a Geometry (see Scene::geometries).
    Mesh mesh;
    int meshMaterial = 0;
    bool hasMesh() const { return !mesh.triangles.empty(); }

    int objectCount() const { return int(spheres.size() + planes.size() + geometries.size()); }

    // Nearest hit over every object; false when nothing is hit in [tmin, tmax].
    bool intersect(const Ray& ray, SurfaceHit& hit) const;
    bool occluded(const Ray& ray) const;
    // A scene with a mesh but no geometry for it cannot be rendered (logic_error); NaN or
    // infinite spheres, planes, lights or mesh vertices are refused (InputError).
    void checkRenderable() const;
    // Every light's radius for PointLight::cutoffThreshold(lights.size()): the image is then
    // within one 8-bit step of the render with infinite radii.
    void setLightRadii();
};

// Fits the camera to look at the box [lo, hi] from the direction `from`, the whole box
// in view (its bounding sphere inside the vertical field of view).
Camera fitCamera(Vec3 lo, Vec3 hi, float aspect, Vec3 from = Vec3(0.45f, 0.35f, 1.0f),
                 Vec3 up = Vec3(0, 1, 0), float fovYDegrees = 45.0f);

struct SceneOptions {
    std::string dataDir;  // where built-in meshes live
    float aspect = 4.0f / 3.0f;
};

// Built-in scene names, with one line each for --help.
std::vector<std::pair<std::string, std::string>> builtinScenes();

// A built-in scene by name, or an OBJ file drawn as given (default material, a light
// above the mesh, camera fitted to its bounds). Throws InputError for an unknown name or a
// bad file.
Scene makeScene(const std::string& nameOrPath, const SceneOptions& options);

}  // namespace boxes
