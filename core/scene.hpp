// Scenes: the camera, spheres, planes, triangle meshes and step-supplied geometry;
// materials (diffuse, mirror, glass); point lights with a finite radius.
#pragma once

#include <array>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/math.hpp"
#include "core/mesh.hpp"

namespace boxes {

// ---- The camera ----------------------------------------------------------------------------

// The one camera model of the workbook (eye, view direction, up, vertical field of view,
// aspect ratio). The ray tracer and the rasterizer both derive their pixels from it.

template <typename T>
struct CameraBasisT {
    Vec3T<T> right;    // u: screen x grows along it
    Vec3T<T> up;       // v: screen y grows against it (row 0 is the top)
    Vec3T<T> forward;  // w: the normalized view direction
};

// Corners of the virtual screen at distance 1 in front of the eye.
template <typename T>
struct ScreenCornersT {
    Vec3T<T> topLeft, topRight, bottomLeft, bottomRight;
};

template <typename T>
struct CameraT {
    Vec3T<T> eye{0, 0, 0};
    Vec3T<T> view{0, 0, -1};  // need not be unit length
    Vec3T<T> up{0, 1, 0};
    T fovYDegrees = T(60);
    T aspect = T(4) / T(3);  // width / height

    // The camera at `eye` looking at `target`.
    static CameraT lookingAt(Vec3T<T> eye, Vec3T<T> target, Vec3T<T> up, T fovYDegrees, T aspect) {
        return {eye, target - eye, up, fovYDegrees, aspect};
    }

    void validate() const {
        if (!isFinite(eye)) throw std::invalid_argument("camera eye is not finite");
        if (!isFinite(view) || isZero(view))
            throw std::invalid_argument("camera view direction is zero or not finite");
        if (!isFinite(up) || isZero(up))
            throw std::invalid_argument("camera up vector is zero or not finite");
        if (!(fovYDegrees > T(0) && fovYDegrees < T(180)))
            throw std::invalid_argument("camera field of view must be in (0, 180) degrees");
        if (!(aspect > T(0)) || !std::isfinite(aspect))
            throw std::invalid_argument("camera aspect ratio must be positive");
    }

    // Orthonormal, right-handed basis: right = forward x up, up' = right x forward.
    // When the view is parallel to up the cross product vanishes; we then use the world
    // axis least aligned with the view as up, so the basis stays finite and deterministic.
    CameraBasisT<T> basis() const {
        validate();
        Vec3T<T> w = glm::normalize(view);
        Vec3T<T> u = glm::cross(w, glm::normalize(up));
        if (glm::dot(u, u) < T(1e-12)) {
            Vec3T<T> a = glm::abs(w);
            Vec3T<T> fallback = (a.x <= a.y && a.x <= a.z) ? Vec3T<T>(1, 0, 0)
                                : (a.y <= a.z)             ? Vec3T<T>(0, 1, 0)
                                                           : Vec3T<T>(0, 0, 1);
            u = glm::cross(w, fallback);
        }
        u = glm::normalize(u);
        Vec3T<T> v = glm::cross(u, w);
        return {u, v, w};
    }

    T halfHeight() const { return std::tan(glm::radians(fovYDegrees) / T(2)); }

    ScreenCornersT<T> screenCorners() const {
        CameraBasisT<T> b = basis();
        T h = halfHeight();
        T wHalf = aspect * h;
        Vec3T<T> centre = eye + b.forward;
        return {centre - wHalf * b.right + h * b.up, centre + wHalf * b.right + h * b.up,
                centre - wHalf * b.right - h * b.up, centre + wHalf * b.right - h * b.up};
    }

    // Unit direction through the image point (px, py) in pixel units, (0,0) the top-left
    // corner of the image; pixel (x, y) has its centre at (x + 0.5, y + 0.5).
    Vec3T<T> directionThrough(T px, T py, int width, int height) const {
        CameraBasisT<T> b = basis();
        return directionThrough(b, px, py, width, height);
    }
    Vec3T<T> directionThrough(const CameraBasisT<T>& b, T px, T py, int width, int height) const {
        T h = halfHeight();
        T sx = (T(2) * px / T(width) - T(1)) * aspect * h;
        T sy = (T(1) - T(2) * py / T(height)) * h;
        return glm::normalize(b.forward + sx * b.right + sy * b.up);
    }

    RayT<T> primaryRay(int x, int y, int width, int height) const {
        return RayT<T>(eye, directionThrough(T(x) + T(0.5), T(y) + T(0.5), width, height));
    }
};

using Camera = CameraT<float>;
using Camerad = CameraT<double>;

// ---- The scene -----------------------------------------------------------------------------

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
