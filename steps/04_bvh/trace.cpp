#include "04_bvh/trace.hpp"

#include <utility>

namespace boxes {

TraceHit traceBruteForce(const Mesh& mesh, const Ray& ray) {
    WatertightRay watertight(ray);
    TraceHit best;
    float tClosest = ray.tmax;
    withWatertightAxes(watertight, [&](auto axes) {
        for (size_t i = 0; i < mesh.triangles.size(); ++i) {
            LeafTriangle tri = leafTriangleOf(mesh, i);
            float t = tClosest;
            // Strictly nearer only: the first of equally near triangles stays.
            if (intersectLeafTriangle(axes, watertight, tri, t) &&
                (best.triangle == kNoPrimitive || t < tClosest)) {
                tClosest = t;
                best = {t, uint32_t(i)};
            }
        }
    });
    return best;
}

MeshBvhGeometry::MeshBvhGeometry(const Mesh& mesh, int material, const BvhBuildOptions& options)
    : mesh_(mesh), material_(material), stats_(), bvh_(buildBvh(mesh, options, &stats_)) {}

MeshBvhGeometry::MeshBvhGeometry(const Mesh& mesh, int material, Bvh bvh,
                                 const BvhBuildStats& stats)
    : mesh_(mesh), material_(material), stats_(stats), bvh_(std::move(bvh)) {}

bool MeshBvhGeometry::intersect(const Ray& ray, SurfaceHit& hit) const {
    float tClosest, u = 0.0f, v = 0.0f;
    uint32_t slot = nearestSlot(bvh_, ray, tClosest, &u, &v);
    if (slot == kTraversalMiss) return false;
    uint32_t tri = bvh_.primitiveIndices[slot];
    const auto& idx = mesh_.triangles[tri];
    const LeafTriangle& lt = bvh_.leafTriangles[slot];
    Vec3 n = glm::cross(lt.b - lt.a, lt.c - lt.a);
    float len = glm::length(n);
    hit.t = tClosest;
    hit.point = ray.at(tClosest);
    hit.geometricNormal = len > 0.0f ? n / len : Vec3(0, 1, 0);
    hit.u = u;
    hit.v = v;
    if (mesh_.normals.size() == mesh_.positions.size()) {
        Vec3 s = (1.0f - u - v) * mesh_.normals[idx[0]] + u * mesh_.normals[idx[1]] +
                 v * mesh_.normals[idx[2]];
        float sl = glm::length(s);
        hit.shadingNormal = sl > 0.0f ? s / sl : hit.geometricNormal;
    } else {
        hit.shadingNormal = hit.geometricNormal;
    }
    hit.material = material_;
    hit.primitive = tri;
    hit.kind = SurfaceHit::Kind::Triangle;
    return true;
}

bool MeshBvhGeometry::occluded(const Ray& ray) const {
    return traceOccluded(bvh_, ray);
}

}  // namespace boxes
