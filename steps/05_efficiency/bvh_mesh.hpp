// A triangle mesh through step 04's hierarchy, traversed by the lab's own loop with each
// optimization of the primer as a switch, so the lab can render the same frame with and
// without it and count the work: box (node) tests and triangle tests per ray.
//
// The tree is step 04's Bvh, built with its full-sweep SAH builder: that builder is not one
// of step 04's exercises, so this works in a starter kit where they are unsolved. The
// traversal here is not step 04's either (exercises 4.4 and 4.5): it has the switches and
// the counters, and its tests are this step's.
#pragma once

#include <atomic>
#include <vector>

#include "04_bvh/bvh.hpp"
#include "04_bvh/trace.hpp"
#include "05_efficiency/lab.hpp"
#include "core/scene.hpp"

namespace boxes {

struct LabMeshOptions {
    bool reciprocal = true;            // slab test with 1/D and signs once per ray (5.6)
    bool precomputedTriangles = true;  // edges stored with the triangle (5.7)
    bool skipBeyondNearest = true;     // nearest hit: nearer child first, skip nodes beyond t
    bool anyHitShadows = true;         // shadow rays stop at the first occluder (5.4)
    // Step 04's watertight triangle test and conservative box test (not its exercises)
    // instead of the two above: Moller-Trumbore lets a ray through the edge two triangles
    // share miss both (a dark speck of floor through the bunny); renders use this, the
    // precalc table switches it off to time 5.6 and 5.7.
    bool robust = true;
};

class LabBvhMesh : public Geometry {
public:
    // Builds the hierarchy (full-sweep SAH, leaves of at most 8 triangles).
    LabBvhMesh(const Mesh& mesh, int material);

    void setOptions(const LabMeshOptions& options) { options_ = options; }
    const LabMeshOptions& options() const { return options_; }

    bool intersect(const Ray& ray, SurfaceHit& hit) const override;
    bool occluded(const Ray& ray) const override;
    Vec3 boundsMin() const override { return bvh_.bounds().min; }
    Vec3 boundsMax() const override { return bvh_.bounds().max; }
    std::vector<int> materialsUsed() const override { return {material_}; }

    const Bvh& bvh() const { return bvh_; }
    const BvhBuildStats& buildStats() const { return stats_; }
    uint64_t boxTests() const { return boxTests_.load(std::memory_order_relaxed); }
    uint64_t triangleTests() const { return triangleTests_.load(std::memory_order_relaxed); }
    void resetCounters() {
        boxTests_ = 0;
        triangleTests_ = 0;
    }

private:
    // Nearest triangle (leaf slot) in [ray.tmin, ray.tmax], or -1.
    long nearest(const Ray& ray, TriangleHitT& best) const;
    // What a traversal prepares once per ray for the tests below.
    struct RayData {
        const Ray& ray;
        PrecomputedRay pre;
        TraversalRay traversal;
        WatertightRay watertight;
    };
    RayData prepare(const Ray& ray) const;
    bool boxTest(RayData& r, const BvhNode& node, float tmax, float& tEntry) const;
    std::optional<TriangleHitT> triangleTest(const RayData& r, const Ray& ray, uint32_t slot) const;

    const Mesh& mesh_;
    int material_;
    LabMeshOptions options_;
    BvhBuildStats stats_;
    Bvh bvh_;
    std::vector<TriangleVertices> vertices_;        // per leaf slot
    std::vector<PrecomputedTriangle> precomputed_;  // per leaf slot
    mutable std::atomic<uint64_t> boxTests_{0}, triangleTests_{0};
};

}  // namespace boxes
