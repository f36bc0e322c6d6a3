// A flat list of boxes over small clusters of triangles (no hierarchy: that is step 04),
// with each optimization of the primer as a switch, so the lab can render the same
// frame with and without it and count the work: box tests and triangle tests per ray.
#pragma once

#include <atomic>
#include <vector>

#include "05_efficiency/lab.hpp"
#include "core/scene.hpp"

namespace boxes {

struct ClusterMeshOptions {
    bool reciprocal = true;            // slab test with 1/D and signs computed once per ray
    bool precomputedTriangles = true;  // edges stored with the triangle
    bool skipFarClusters = true;       // nearest hit: skip boxes entered beyond the nearest t
    bool anyHitShadows = true;         // shadow rays stop at the first occluder
};

class ClusterMesh : public Geometry {
  public:
    // Triangles sorted along a Morton curve of their centroids, then cut into clusters.
    ClusterMesh(const Mesh& mesh, int material, int clusterSize = 32);

    void setOptions(const ClusterMeshOptions& options) { options_ = options; }
    const ClusterMeshOptions& options() const { return options_; }

    bool intersect(const Ray& ray, SurfaceHit& hit) const override;
    bool occluded(const Ray& ray) const override;
    Vec3 boundsMin() const override { return bounds_.min; }
    Vec3 boundsMax() const override { return bounds_.max; }
    std::vector<int> materialsUsed() const override { return {material_}; }

    size_t clusterCount() const { return clusters_.size(); }
    uint64_t boxTests() const { return boxTests_.load(std::memory_order_relaxed); }
    uint64_t triangleTests() const { return triangleTests_.load(std::memory_order_relaxed); }
    void resetCounters() {
        boxTests_ = 0;
        triangleTests_ = 0;
    }

  private:
    struct Cluster {
        Bounds3f box;
        uint32_t begin, end;  // into the sorted triangle arrays
    };
    // Nearest triangle (sorted index) in [ray.tmin, ray.tmax], or -1.
    long nearest(const Ray& ray, TriangleHitT& best) const;
    std::optional<float> boxTest(const Ray& ray, const PrecomputedRay& pre,
                                 const Bounds3f& box) const;
    std::optional<TriangleHitT> triangleTest(const Ray& ray, uint32_t i) const;

    const Mesh& mesh_;
    int material_;
    ClusterMeshOptions options_;
    Bounds3f bounds_;
    std::vector<Cluster> clusters_;
    std::vector<uint32_t> order_;  // sorted index -> mesh triangle
    std::vector<TriangleVertices> vertices_;
    std::vector<PrecomputedTriangle> precomputed_;
    mutable std::atomic<uint64_t> boxTests_{0}, triangleTests_{0};
};

}  // namespace boxes
