// Why bounding boxes matter: scene objects that can test a ray against a box before they
// test it against what is inside (per sphere, per small group of triangles, per mesh),
// counting the tests, and a scene of thousands of spheres and triangles plus the bunny.
#pragma once

#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "03_aabb/aabb.hpp"
#include "core/render.hpp"
#include "core/scene.hpp"

namespace boxes {

// Tests made by the objects below, summed over every ray (one atomic add per ray and object),
// and on the calling thread since its last take (the cost of one pixel, for a heat map).
struct TestCounts {
    std::atomic<uint64_t> boxTests{0}, primitiveTests{0};
    void reset() {
        boxTests = 0;
        primitiveTests = 0;
    }
    void add(uint64_t boxes, uint64_t primitives);
    struct OnThread {
        uint64_t boxTests = 0, primitiveTests = 0;
    };
    // The tests this thread made since its last take, and zero again.
    static OnThread take();
};

// Spheres, each with its box (exercise 3.1) tested first when the pre-test is on.
class SphereCloud : public Geometry {
public:
    SphereCloud(std::vector<SceneSphere> spheres, std::shared_ptr<TestCounts> counts);
    void setPretest(bool on) { pretest_ = on; }

    bool intersect(const Ray& ray, SurfaceHit& hit) const override;
    bool occluded(const Ray& ray) const override;
    Vec3 boundsMin() const override { return all_.min; }
    Vec3 boundsMax() const override { return all_.max; }
    std::vector<int> materialsUsed() const override;
    size_t size() const { return spheres_.size(); }

private:
    std::vector<SceneSphere> spheres_;
    std::vector<Bounds3f> bounds_;
    Bounds3f all_;
    std::shared_ptr<TestCounts> counts_;
    bool pretest_ = true;
};

// Triangles intersected with step 01's watertight test. With the pre-test on, a ray first
// meets the box of the whole mesh (exercise 3.3), then the box of each group of
// `groupSize` triangles (exercises 3.2 and 3.4), and only then the triangles of the groups
// it enters. Groups are runs of triangles sorted along a Morton curve of their centroids,
// so a group's box is small. The boxes use the conservative slab test (exercise 3.7), so
// the image is the same with and without the pre-test.
class TriangleGroups : public Geometry {
public:
    TriangleGroups(const Mesh& mesh, int material, std::shared_ptr<TestCounts> counts,
                   int groupSize = 8);
    void setPretest(bool on) { pretest_ = on; }

    bool intersect(const Ray& ray, SurfaceHit& hit) const override;
    bool occluded(const Ray& ray) const override;
    Vec3 boundsMin() const override { return meshBox_.min; }
    Vec3 boundsMax() const override { return meshBox_.max; }
    std::vector<int> materialsUsed() const override { return {material_}; }
    size_t size() const { return order_.size(); }
    size_t groups() const { return groupBoxes_.size(); }

private:
    Mesh mesh_;
    int material_;
    std::vector<uint32_t> order_;  // triangle indices, Morton order
    std::vector<Bounds3f> groupBoxes_;
    int groupSize_;
    Bounds3f meshBox_;
    std::shared_ptr<TestCounts> counts_;
    bool pretest_ = true;
};

// What each pixel's rays cost: their box and primitive tests and the rays themselves, rows top
// to bottom. The means per ray are the sums' ratios (as the pretest table counts them).
struct PixelCosts {
    int width = 0, height = 0;
    std::vector<double> boxTests, primitiveTests, rays;
    double boxTestsPerRay() const;
    double primitiveTestsPerRay() const;
};
// Renders `image` (its size) with `renderer`, row by row on the render threads, counting each
// pixel's tests with `counts` (the scene's objects' TestCounts) and its rays; `rows` lists the
// rows to render (all when empty), the rest of `costs` is left as it is. A control in the
// renderer's settings stops it between rows.
void renderCountingPixels(const Renderer& renderer, Image& image, PixelCosts& costs,
                          std::vector<RayCounts>& perThread, const std::vector<int>& rows = {},
                          const std::string& label = "");

// The step's scene: a floor, `spheres` small spheres, `triangles` small triangles in
// clusters of 8, and the bunny (data/meshes/bunny.obj, scaled by 1.5 and set on the floor).
struct ManyObjects {
    Scene scene;
    std::shared_ptr<TestCounts> counts;
    std::shared_ptr<SphereCloud> spheres;
    std::vector<std::shared_ptr<TriangleGroups>> meshes;
    void setPretest(bool on);

    // The window's view, with the pre-test on or off (off: at a quarter of the size, so a
    // frame takes seconds rather than minutes), the tests it made per ray, and per pixel
    // (every ray of the pixel: primary, shadow, reflected).
    struct View {
        Image image;
        double primitiveTestsPerRay = 0.0, boxTestsPerRay = 0.0;
        PixelCosts costs;
        // 0: the picture; 1, 2: a heat map of its primitive, box tests per pixel, with the
        // mean per ray in its title (core/heatmap.hpp).
        Image show(int mode) const;
    };
    View render(const Camera& camera, RenderSettings settings, bool pretest);
};
ManyObjects makeManyObjects(const std::string& dataDir, float aspect, size_t spheres = 3000,
                            size_t triangles = 4000, bool bunny = true, uint64_t seed = 1);
// Any core scene with its spheres and mesh moved into the objects above.
ManyObjects wrapScene(Scene scene);

}  // namespace boxes
