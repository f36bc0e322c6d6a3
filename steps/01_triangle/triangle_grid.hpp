// A uniform grid over a mesh's triangles, so step 01 can render a 70k-triangle bunny
// before the workbook reaches bounding volume hierarchies (step 04). Rays walk the cells
// in order (Amanatides & Woo, "A Fast Voxel Traversal Algorithm", 1987) and test the
// triangles listed in each cell with the selected ray/triangle test.
#pragma once

#include <atomic>
#include <vector>

#include "01_triangle/triangle.hpp"
#include "core/scene.hpp"

namespace boxes {

class TriangleGrid : public Geometry {
public:
    TriangleGrid(const Mesh& mesh, int material, TriangleTest test = TriangleTest::Watertight);

    void setTest(TriangleTest test) { test_ = test; }
    TriangleTest test() const { return test_; }
    // Off: shade with each triangle's own normal (no interpolation, exercise 1.6), so a
    // picture shows the hit test alone.
    void setSmoothShading(bool smooth) { smooth_ = smooth; }

    bool intersect(const Ray& ray, SurfaceHit& hit) const override;
    bool occluded(const Ray& ray) const override;
    Vec3 boundsMin() const override { return lo_; }
    Vec3 boundsMax() const override { return hi_; }
    std::vector<int> materialsUsed() const override { return {material_}; }

    // The nearest triangle along the ray with a given test (kNoPrimitive on a miss), its t
    // and barycentrics (u, v) when asked.
    uint32_t nearestTriangle(const Ray& ray, TriangleTest test, float* t = nullptr,
                             float* u = nullptr, float* v = nullptr) const;
    uint64_t trianglesTested() const { return tested_.load(std::memory_order_relaxed); }
    Triangle triangle(uint32_t i) const;
    const Mesh& mesh() const { return mesh_; }

private:
    // Visits cells along the ray; visit(cellIndex, tExitOfCell) returns true to stop.
    template <typename Visit>
    void walk(const Ray& ray, Visit&& visit) const;

    const Mesh& mesh_;
    int material_;
    TriangleTest test_;
    bool smooth_ = true;
    Vec3 lo_, hi_, cellSize_;
    glm::ivec3 res_;
    std::vector<uint32_t> cellStart_;  // prefix sums into cellTriangles_
    std::vector<uint32_t> cellTriangles_;
    mutable std::atomic<uint64_t> tested_{0};
};

}  // namespace boxes
