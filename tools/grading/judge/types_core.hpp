// The core's types as they cross the call protocol, field by field (judge/codec.hpp).
#pragma once

#include <memory>

#include "core/bounds.hpp"
#include "core/image.hpp"
#include "core/math.hpp"
#include "core/mesh.hpp"
#include "core/scene.hpp"
#include "judge/codec.hpp"

namespace boxes::judge {

// A ray's constructor refuses a zero direction: the placeholder has one, get() overwrites it.
template <typename T>
struct Make<RayT<T>> {
    static RayT<T> make() { return RayT<T>(Vec3T<T>(0), Vec3T<T>(0, 0, 1)); }
};
template <typename T>
struct Fields<RayT<T>> {
    static auto of(RayT<T>& x) { return std::tie(x.origin, x.direction, x.tmin, x.tmax); }
};
template <typename T>
struct Fields<PlaneT<T>> {
    static auto of(PlaneT<T>& x) { return std::tie(x.normal, x.d); }
};
template <typename T>
struct Fields<SphereT<T>> {
    static auto of(SphereT<T>& x) { return std::tie(x.centre, x.radius); }
};
template <typename T>
struct Fields<Bounds3T<T>> {
    static auto of(Bounds3T<T>& x) { return std::tie(x.min, x.max); }
};
template <typename T>
struct Fields<CameraT<T>> {
    static auto of(CameraT<T>& x) {
        return std::tie(x.eye, x.view, x.up, x.fovYDegrees, x.aspect);
    }
};
template <>
struct Fields<Mesh> {
    static auto of(Mesh& x) { return std::tie(x.positions, x.normals, x.triangles); }
};
template <>
struct Fields<Material> {
    static auto of(Material& x) { return std::tie(x.kind, x.albedo, x.reflectance, x.ior); }
};
template <>
struct Fields<PointLight> {
    static auto of(PointLight& x) { return std::tie(x.position, x.intensity, x.radius); }
};
template <>
struct Fields<SceneSphere> {
    static auto of(SceneSphere& x) { return std::tie(x.shape, x.material); }
};
template <>
struct Fields<ScenePlane> {
    static auto of(ScenePlane& x) { return std::tie(x.shape, x.material); }
};
template <>
struct Fields<SurfaceHit> {
    static auto of(SurfaceHit& x) {
        return std::tie(x.t, x.point, x.geometricNormal, x.shadingNormal, x.u, x.v, x.material,
                        x.primitive, x.object, x.kind);
    }
};
template <>
struct Fields<Scene> {
    static auto of(Scene& x) {
        return std::tie(x.name, x.materials, x.spheres, x.planes, x.geometries, x.lights,
                        x.background, x.ambient, x.camera, x.mesh, x.meshMaterial);
    }
};

// An image by its public interface: the size, then the pixels.
template <>
struct Codec<Image> {
    static constexpr size_t kMin = 16;
    static void put(Writer& w, const Image& img) {
        w.pod(int32_t(img.width()));
        w.pod(int32_t(img.height()));
        judge::put(w, img.pixels());
    }
    static void get(Reader& r, Image& img) {
        int32_t width = r.pod<int32_t>(), height = r.pod<int32_t>();
        std::vector<Vec3> pixels;
        judge::get(r, pixels);
        if (width < 0 || height < 0 || pixels.size() != size_t(width) * size_t(height))
            throw Malformed("an image whose size is not its pixel count");
        if (pixels.empty()) {
            img = Image();
            return;
        }
        img = Image(width, height);
        img.pixels() = std::move(pixels);
    }
};

// A scene's geometry (a mesh's hierarchy, say) stays in the checker: the worker's copy asks
// it through callbacks, as the renderer would call its virtual functions.
class RemoteGeometry : public Geometry {
public:
    explicit RemoteGeometry(uint32_t first)
        : intersect_(first), occluded_(first + 1), boundsMin_(first + 2),
          boundsMax_(first + 3), convex_(first + 4), materialsUsed_(first + 5) {}
    bool intersect(const Ray& ray, SurfaceHit& hit) const override { return intersect_(ray, hit); }
    bool occluded(const Ray& ray) const override { return occluded_(ray); }
    Vec3 boundsMin() const override { return boundsMin_(); }
    Vec3 boundsMax() const override { return boundsMax_(); }
    bool convex() const override { return convex_(); }
    std::vector<int> materialsUsed() const override { return materialsUsed_(); }

private:
    RemoteFunction<bool(const Ray&, SurfaceHit&)> intersect_;
    RemoteFunction<bool(const Ray&)> occluded_;
    RemoteFunction<Vec3()> boundsMin_, boundsMax_;
    RemoteFunction<bool()> convex_;
    RemoteFunction<std::vector<int>()> materialsUsed_;
};

template <>
struct Codec<std::shared_ptr<const Geometry>> {
    static constexpr size_t kMin = 1;
    static void put(Writer& w, const std::shared_ptr<const Geometry>& g) {
        if (Session::get().worker || !g) {  // the checker keeps its own on the way back
            w.pod(uint8_t(0));
            return;
        }
        const Geometry* p = g.get();
        w.pod(uint8_t(1));
        w.pod(registerCallback<bool, const Ray&, SurfaceHit&>(
            [p](const Ray& ray, SurfaceHit& hit) { return p->intersect(ray, hit); }));
        registerCallback<bool, const Ray&>([p](const Ray& ray) { return p->occluded(ray); });
        registerCallback<Vec3>([p] { return p->boundsMin(); });
        registerCallback<Vec3>([p] { return p->boundsMax(); });
        registerCallback<bool>([p] { return p->convex(); });
        registerCallback<std::vector<int>>([p] { return p->materialsUsed(); });
    }
    static void get(Reader& r, std::shared_ptr<const Geometry>& g) {
        uint8_t has = r.pod<uint8_t>();
        if (has > 1) throw Malformed("a geometry that is neither there nor absent");
        if (!Session::get().worker) return;
        g = has ? std::make_shared<RemoteGeometry>(r.pod<uint32_t>()) : nullptr;
    }
};

}  // namespace boxes::judge
