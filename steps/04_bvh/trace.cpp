#include "04_bvh/trace.hpp"

#include <utility>

#include "core/mesh.hpp"

namespace boxes {

uint32_t nearestSlot(const Bvh& bvh, const Ray& ray, float& tClosest, float* u, float* v) {
    tClosest = ray.tmax;
    TraversalRay boxes(ray, bvh);  // for the box tests, with the tree's margin
    WatertightRay triangles(ray);  // the triangle test's set-up, once per ray
    return traverseNearest(bvh, boxes, tClosest, [&](uint32_t slot, float& tmax) {
        return intersectLeafTriangle(triangles, bvh.leafTriangles[slot], tmax, u, v);
    });
}

TraceHit traceNearest(const Bvh& bvh, const Ray& ray) {
    float tClosest;
    uint32_t slot = nearestSlot(bvh, ray, tClosest);
    if (slot == kTraversalMiss) return {};
    return {tClosest, bvh.primitiveIndices[slot]};
}

bool traceOccluded(const Bvh& bvh, const Ray& ray) {
    TraversalRay boxes(ray, bvh);
    WatertightRay triangles(ray);
    return traverseAny(bvh, boxes, [&](uint32_t slot, float tmax) {
        return intersectLeafTriangle(triangles, bvh.leafTriangles[slot], tmax);
    });
}

TraceHit traceBruteForce(const Mesh& mesh, const Ray& ray) {
    WatertightRay watertight(ray);
    TraceHit best;
    float tClosest = ray.tmax;
    for (size_t i = 0; i < mesh.triangles.size(); ++i) {
        LeafTriangle tri = leafTriangleOf(mesh, i);
        float t = tClosest;
        // Strictly nearer only: the first of equally near triangles stays.
        if (intersectLeafTriangle(watertight, tri, t) &&
            (best.triangle == kNoPrimitive || t < tClosest)) {
            tClosest = t;
            best = {t, uint32_t(i)};
        }
    }
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
    hit = triangleHit(mesh_, bvh_.primitiveIndices[slot], ray, tClosest, u, v, material_);
    return true;
}

bool MeshBvhGeometry::occluded(const Ray& ray) const {
    return traceOccluded(bvh_, ray);
}

std::shared_ptr<MeshBvhGeometry> addMeshBvh(Scene& scene, const BvhBuildOptions& options) {
    scene.geometries.clear();
    if (!scene.hasMesh()) return nullptr;
    auto geometry = std::make_shared<MeshBvhGeometry>(scene.mesh, scene.meshMaterial, options);
    scene.geometries.push_back(geometry);
    return geometry;
}

}  // namespace boxes
