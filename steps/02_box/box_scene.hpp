// Step 02's scene objects (boxes as core Geometry, intersected with either method) and its
// scenes.
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include "02_box/box.hpp"
#include "core/report.hpp"
#include "core/scene.hpp"

namespace boxes {

struct SceneBox {
    OrientedBox box;
    int material = 0;
};

// A set of boxes the renderer sees as one Geometry; every ray tests every box with the
// selected method (six planes: exercises 2.1 and 2.2; slabs: exercise 2.4).
class BoxSet : public Geometry {
public:
    // Throws std::invalid_argument for an invalid box (OrientedBoxT::validate).
    explicit BoxSet(std::vector<SceneBox> boxes, BoxMethod method = BoxMethod::Slabs);

    // Not thread-safe: switch between frames only.
    void setMethod(BoxMethod method);
    BoxMethod method() const { return method_; }

    bool intersect(const Ray& ray, SurfaceHit& hit) const override;
    bool occluded(const Ray& ray) const override;
    Vec3 boundsMin() const override { return lo_; }
    Vec3 boundsMax() const override { return hi_; }
    std::vector<int> materialsUsed() const override;

    struct Nearest {
        int box = -1;
        BoxHit<float> hit{};
    };
    // The nearest box along the ray with a given method (box = -1 on a miss). Six planes
    // need their planes: setMethod(SixPlanes) once before (else std::logic_error).
    Nearest nearest(const Ray& ray, BoxMethod method) const;
    const std::vector<SceneBox>& boxes() const { return boxes_; }

private:
    std::vector<SceneBox> boxes_;
    std::vector<std::array<Plane, 6>> planes_;  // filled when six planes are first used
    BoxMethod method_;
    Vec3 lo_{kInfinity<float>}, hi_{-kInfinity<float>};
};

// The step's own scene: axis-aligned and rotated boxes on a floor, diffuse, mirror and glass.
Scene makeBoxScene(float aspect);
// The boxes of that scene (15: axis-aligned, turned about y, and tipped).
std::vector<SceneBox> boxStepBoxes();
// Any core scene drawn as boxes: each sphere becomes the cube around it, a mesh its
// bounding box; planes and lights stay. Returns the boxes (the caller adds the BoxSet).
std::vector<SceneBox> boxesFromScene(Scene& scene);

}  // namespace boxes
