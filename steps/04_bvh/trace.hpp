// Step 04: a triangle mesh through the hierarchy. One ray's nearest hit (exercise 4.4) and
// any hit (4.5) with the watertight leaf test, brute force to check them, and the mesh as
// the renderer's geometry.
#pragma once

#include <cstdint>
#include <memory>

#include "04_bvh/bvh.hpp"
#include "04_bvh/leaf_test.hpp"
#include "04_bvh/traverse.hpp"
#include "core/hit.hpp"
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

// Does the ray enter the tree's root box (any tree with empty() and rootNode())? Decided
// before the triangle test's per-ray set-up: most rays of a camera framing a mesh miss
// it. The root is read where it lies: a copy on the stack makes the loads through the
// ray's run-time plane offsets wait for the copy's stores.
template <typename Tree>
[[gnu::always_inline]] inline bool entersRoot(const Tree& tree, const TraversalRay& traversal) {
    if (tree.empty()) return false;
    float tEntry;
    return intersectNodeBounds(tree.rootNode(), traversal, traversal.tmax, tEntry);
}

// What the nearest-hit set-up tells a counter: nothing by default (the engine's
// `trace --count` counts the triangle tests).
struct NoTriangleCount {
    void triangles(uint32_t) {}
};

// The nearest triangle of `ray` through `bvh`: the one place where a ray meets the tree.
// The ray is prepared for the boxes (with the tree's margin) and for the triangles, the
// root box decided first, then exercise 4.4 runs with the watertight leaf test, its axis
// order fixed at compile time. Returns the leaf slot (kTraversalMiss on a miss) with t in
// tClosest and, when asked, the barycentrics of b and c. The renderer's geometry below,
// traceNearest, and through it the engine's `trace` command all come here.
template <typename Counter = NoTriangleCount>
inline uint32_t nearestSlot(const Bvh& bvh, const Ray& ray, float& tClosest, float* u = nullptr,
                            float* v = nullptr, Counter counter = {}) {
    tClosest = ray.tmax;
    TraversalRay traversal(ray, bvh);
    if (!entersRoot(bvh, traversal)) return kTraversalMiss;
    WatertightRay watertight(ray);
    const LeafTriangle* tris = bvh.leafTriangles.data();
    return withWatertightAxes(watertight, [&](auto axes) {
        return traverseNearest(bvh, traversal, tClosest, [&](uint32_t s, float& tmax) {
            counter.triangles(1);
            return intersectLeafTriangle(axes, watertight, tris[s], tmax, u, v);
        });
    });
}

template <typename Counter = NoTriangleCount>
inline TraceHit traceNearest(const Bvh& bvh, const Ray& ray, Counter counter = {}) {
    float tClosest;
    uint32_t slot = nearestSlot(bvh, ray, tClosest, nullptr, nullptr, counter);
    if (slot == kTraversalMiss) return {};
    return {tClosest, bvh.primitiveIndices[slot]};
}

// Any triangle in [ray.tmin, ray.tmax] (exercise 4.5): the same set-up.
inline bool traceOccluded(const Bvh& bvh, const Ray& ray) {
    TraversalRay traversal(ray, bvh);
    if (!entersRoot(bvh, traversal)) return false;
    WatertightRay watertight(ray);
    const LeafTriangle* tris = bvh.leafTriangles.data();
    return withWatertightAxes(watertight, [&](auto axes) {
        return traverseAny(bvh, traversal, [&](uint32_t s, float tmax) {
            return intersectLeafTriangle(axes, watertight, tris[s], tmax);
        });
    });
}

// Every triangle, in file order (as leafTriangleOf stores it: one without area is never
// hit); the first of equally near triangles wins.
TraceHit traceBruteForce(const Mesh& mesh, const Ray& ray);

// The mesh as renderer geometry, through the hierarchy.
class MeshBvhGeometry : public Geometry {
public:
    // Builds the hierarchy with an exercise builder.
    MeshBvhGeometry(const Mesh& mesh, int material, const BvhBuildOptions& options);
    // Takes one built elsewhere (the engine's builders: advanced/build.hpp).
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
