// Self-intersection acne: shadow rays from the hit point against the core's offset origin.
#include "05_efficiency/experiments/lab_helpers.hpp"
#include "05_efficiency/measure.hpp"
#include "core/timing.hpp"

namespace boxes {

using namespace lab;

Table measureAcne(const LabOptions& o) {
    Table t("acne",
            "Self-intersection acne: lit pixels whose shadow ray hits the surface it starts on",
            {"offset", "shadow ray origin", "lit pixels", "acne pixels", "ns/shadow ray", "min ns",
             "max ns"});
    t.note =
        "the 'diffuse' spheres scene moved by offset*(1,-0.7,0.3) (float), 160x120 primary hits "
        "facing a light; a convex surface cannot shadow itself, so any hit of the shadow ray on "
        "its own object in (0, distance to light) is acne; robust offset: core offsetOrigin "
        "(1e-4 * (1 + max |p|) along the normal); acne pixels: the error, against the exact "
        "answer 0; time: the scene's any-hit test of every lit pixel's shadow ray, one thread, "
        "median of repeats interleaved round-robin, per ray (the offset included)";
    for (double offset : {0.0, 1e3, 1e4, 1e5}) {
        Scene scene = makeScene("diffuse", {});
        Vec3 shift(float(offset), float(-0.7 * offset), float(0.3 * offset));
        for (auto& s : scene.spheres) s.shape.centre += shift;
        for (auto& p : scene.planes) p.shape.d = -glm::dot(p.shape.normal, shift) + p.shape.d;
        for (auto& l : scene.lights) l.position += shift;
        scene.camera.eye += shift;
        const int w = sized(o, 160), h = sized(o, 120);
        CameraBasisT<float> basis = scene.camera.basis();
        long long lit = 0, acneRaw = 0, acneOffset = 0;
        std::vector<std::pair<Vec3, Vec3>> lits;  // (hit point, geometric normal) facing the light
        auto selfHit = [&](const Ray& r, const SurfaceHit& hit) {
            if (hit.kind == SurfaceHit::Kind::Sphere)
                return intersectSphere(r, scene.spheres[hit.primitive].shape).has_value();
            return intersectPlane(r, scene.planes[hit.primitive].shape).has_value();
        };
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                Ray ray(scene.camera.eye,
                        scene.camera.directionThrough(basis, x + 0.5f, y + 0.5f, w, h));
                SurfaceHit hit;
                if (!scene.intersect(ray, hit)) continue;
                const Vec3 toLight = scene.lights[0].position - hit.point;
                Vec3 n = glm::dot(hit.geometricNormal, ray.direction) < 0 ? hit.geometricNormal
                                                                          : -hit.geometricNormal;
                if (glm::dot(n, toLight) <= 0.0f) continue;
                ++lit;
                lits.emplace_back(hit.point, hit.geometricNormal);
                acneRaw += selfHit(Ray(hit.point, toLight, 0.0f, 1.0f), hit);
                Ray off(offsetOrigin(hit.point, hit.geometricNormal, toLight), toLight, 0.0f, 1.0f);
                acneOffset += selfHit(off, hit);
            }
        const Vec3 light = scene.lights[0].position;
        auto shadows = [&](bool robust) {
            return [&, robust] {
                int blocked = 0;
                for (const auto& [p, n] : lits) {
                    Vec3 d = light - p;
                    Vec3 origin = robust ? offsetOrigin(p, n, d) : p;
                    blocked += scene.occluded(Ray(origin, d, 0.0f, 1.0f));
                }
                keepValue(blocked);
            };
        };
        std::vector<Timing> tm = measureInterleaved(o.repeats, {shadows(false), shadows(true)});
        const double per = 1e9 / double(std::max<long long>(1, lit));
        t.row({offset, std::string("on the hit point"), lit, acneRaw, tm[0].median * per,
               tm[0].min * per, tm[0].max * per});
        t.row({offset, std::string("robust offset"), lit, acneOffset, tm[1].median * per,
               tm[1].min * per, tm[1].max * per});
    }
    t.timeAndError("ns/shadow ray", "min ns", "max ns", "acne pixels");
    return t;
}

}  // namespace boxes
