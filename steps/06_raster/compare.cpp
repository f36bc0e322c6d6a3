#include "06_raster/compare.hpp"

#include "core/render.hpp"
#include "core/timing.hpp"

namespace boxes {

TracedFrame traceFrame(const Scene& scene, const Camera& camera, int width, int height,
                       bool shadows, int threads) {
    if (width <= 0 || height <= 0) throw InputError("image size must be positive");
    scene.checkRenderable();
    Stopwatch watch;
    TracedFrame f;
    f.width = width;
    f.height = height;
    size_t n = size_t(width) * size_t(height);
    f.ids.assign(n, kNoPrimitive);
    f.depth.assign(n, kInfinity<float>);
    f.litByFirstLight.assign(n, -1);
    const CameraBasisT<float> basis = camera.basis();
    parallelRows(height, threads, [&](int y, int) {
        for (int x = 0; x < width; ++x) {
            Vec3 d =
                camera.directionThrough(basis, float(x) + 0.5f, float(y) + 0.5f, width, height);
            Ray ray(camera.eye, d);
            SurfaceHit hit;
            if (!scene.intersect(ray, hit)) continue;
            size_t i = size_t(y) * size_t(width) + size_t(x);
            if (hit.kind == SurfaceHit::Kind::Triangle) {
                f.ids[i] = hit.primitive;
                f.depth[i] = hit.t * glm::dot(d, basis.forward);
            }
            if (!shadows || scene.lights.empty()) continue;
            // The renderer's own shadow decision for the first light.
            Material m = Material::diffuse(scene.materials[size_t(hit.material)].albedo);
            DirectLight light = directLight(m, scene.lights[0], hit.point, facingNormals(d, hit));
            if (!light.contributes()) continue;
            Ray shadow(offsetOrigin(hit.point, hit.geometricNormal, light.toLight), light.toLight,
                       0.0f, 1.0f - 1e-5f);
            f.litByFirstLight[i] = scene.occluded(shadow) ? 0 : 1;
        }
    });
    f.milliseconds = watch.milliseconds();
    return f;
}

VisibilityComparison compareVisibility(int width, int height,
                                       const std::vector<uint32_t>& rasterIds,
                                       const std::vector<float>& rasterDepth,
                                       const std::vector<uint32_t>& tracedIds,
                                       const std::vector<float>& tracedDepth, const Mesh* mesh) {
    VisibilityComparison c;
    c.pixels = size_t(width) * size_t(height);
    // Is `id` seen within one pixel of (x, y) in `ids`?
    auto near = [&](const std::vector<uint32_t>& ids, int x, int y, uint32_t id) {
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                int u = x + dx, v = y + dy;
                if (u < 0 || v < 0 || u >= width || v >= height) continue;
                if (ids[size_t(v) * size_t(width) + size_t(u)] == id) return true;
            }
        return false;
    };
    auto shareVertex = [&](uint32_t a, uint32_t b) {
        if (!mesh || a == kNoPrimitive || b == kNoPrimitive) return false;
        if (a >= mesh->triangles.size() || b >= mesh->triangles.size()) return false;
        for (uint32_t i : mesh->triangles[a])
            for (uint32_t j : mesh->triangles[b])
                if (i == j || mesh->positions[i] == mesh->positions[j]) return true;
        return false;
    };
    double depthSum = 0.0;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            size_t i = size_t(y) * size_t(width) + size_t(x);
            uint32_t r = rasterIds[i], t = tracedIds[i];
            c.coveredRaster += r != kNoPrimitive;
            c.coveredTraced += t != kNoPrimitive;
            if (r == kNoPrimitive && t == kNoPrimitive) continue;
            ++c.coveredEither;
            if (r == t) {
                ++c.sameTriangle;
                double e = std::abs(double(rasterDepth[i]) - double(tracedDepth[i])) /
                           double(tracedDepth[i]);
                c.maxDepthError = std::max(c.maxDepthError, e);
                depthSum += e;
            } else if (near(tracedIds, x, y, r) || near(rasterIds, x, y, t) || shareVertex(r, t)) {
                ++c.differOnEdge;
            } else {
                ++c.differElsewhere;
            }
        }
    c.meanDepthError = c.sameTriangle ? depthSum / double(c.sameTriangle) : 0.0;
    return c;
}

ShadowComparison compareShadows(const std::vector<uint32_t>& rasterIds,
                                const std::vector<int8_t>& rasterLit,
                                const std::vector<uint32_t>& tracedIds,
                                const std::vector<int8_t>& tracedLit) {
    ShadowComparison c;
    for (size_t i = 0; i < rasterIds.size(); ++i) {
        if (rasterIds[i] == kNoPrimitive || rasterIds[i] != tracedIds[i]) continue;
        if (rasterLit[i] < 0 || tracedLit[i] < 0) continue;
        ++c.compared;
        if (rasterLit[i] == 0 && tracedLit[i] == 1) ++c.acne;
        if (rasterLit[i] == 1 && tracedLit[i] == 0) ++c.leaks;
    }
    return c;
}

Image differenceImage(int width, int height, const std::vector<uint32_t>& rasterIds,
                      const std::vector<uint32_t>& tracedIds) {
    Image image(width, height, Vec3(0.0f));
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            size_t i = size_t(y) * size_t(width) + size_t(x);
            uint32_t r = rasterIds[i], t = tracedIds[i];
            Vec3 c(0.0f);
            if (r == t)
                c = r == kNoPrimitive ? Vec3(0.0f) : Vec3(0.18f);
            else if (t == kNoPrimitive)
                c = Vec3(1.0f, 0.1f, 0.1f);
            else if (r == kNoPrimitive)
                c = Vec3(0.1f, 0.3f, 1.0f);
            else
                c = Vec3(1.0f, 0.9f, 0.1f);
            image.at(x, y) = c;
        }
    return image;
}

}  // namespace boxes
