// Step 04: a triangle mesh through the hierarchy. One ray's nearest hit (exercise 4.4) and
// any hit (4.5) with the watertight leaf test, brute force to check them, and the mesh as
// the renderer's geometry. The engine's fast copies are in advanced/traverse.hpp.
#pragma once

#include <cstdint>
#include <memory>

#include "04_bvh/bvh.hpp"
#include "04_bvh/leaf_test.hpp"
#include "04_bvh/traverse.hpp"
#include "core/math.hpp"
#include "core/scene.hpp"

namespace boxes {

// The nearest hit of one ray: t (+infinity on a miss) and the triangle in file order.
struct TraceHit {
    float t = kInfinity<float>;
    uint32_t triangle = kNoPrimitive;
    bool operator==(const TraceHit&) const = default;
};
static_assert(sizeof(TraceHit) == 8, "the HITS.bin record");

// Does a hierarchy's hit agree with brute force: the same triangle, or the same t (two
// triangles sharing the hit point)?
inline bool hitsAgree(const TraceHit& a, const TraceHit& b) {
    return a.triangle == b.triangle || a.t == b.t;
}

// The nearest triangle of `ray` through `bvh`: exercise 4.4 with the watertight leaf
// test (trace.cpp). Returns the leaf slot (kTraversalMiss on a miss) with t in tClosest
// and, when asked, the barycentrics of b and c.
uint32_t nearestSlot(const Bvh& bvh, const Ray& ray, float& tClosest, float* u = nullptr,
                     float* v = nullptr);
// The same as a hit: t and the triangle in file order.
TraceHit traceNearest(const Bvh& bvh, const Ray& ray);
// Any triangle in [ray.tmin, ray.tmax] (exercise 4.5).
bool traceOccluded(const Bvh& bvh, const Ray& ray);

// Every triangle, in file order (as leafTriangleOf stores it: one without area is never
// hit); the first of equally near triangles wins.
TraceHit traceBruteForce(const Mesh& mesh, const Ray& ray);

// The mesh as renderer geometry, through the hierarchy.
class MeshBvhGeometry : public Geometry {
public:
    // Builds the hierarchy with an exercise builder.
    MeshBvhGeometry(const Mesh& mesh, int material, const BvhBuildOptions& options);
    // Takes one built elsewhere (a test's reference builder, the engine's builders).
    MeshBvhGeometry(const Mesh& mesh, int material, Bvh bvh, const BvhBuildStats& stats);
    bool intersect(const Ray& ray, SurfaceHit& hit) const override;
    bool occluded(const Ray& ray) const override;
    Vec3 boundsMin() const override { return bvh_.bounds().min; }
    Vec3 boundsMax() const override { return bvh_.bounds().max; }
    std::vector<int> materialsUsed() const override { return {material_}; }
    const Bvh& bvh() const { return bvh_; }
    const BvhBuildStats& stats() const { return stats_; }

private:
    const Mesh& mesh_;
    int material_;
    BvhBuildStats stats_;  // before bvh_: the build fills it
    Bvh bvh_;
};

// The scene's mesh as its one geometry, through a hierarchy of an exercise builder
// (options.builder); none for a scene without a mesh.
std::shared_ptr<MeshBvhGeometry> addMeshBvh(Scene& scene, const BvhBuildOptions& options);

}  // namespace boxes
