// Step 04: the hierarchy seen from above, its boxes coloured by the culling test of a
// camera's frustum (grey culled, green kept, red wrongly kept, with a legend in the
// picture): the window's right half and the headless run's -cull.png. Culled boxes are outside the image by definition,
// hence a map rather than outlines over the rendered view.
#pragma once

#include <string>
#include <vector>

#include "04_bvh/frustum.hpp"
#include "04_bvh/trace.hpp"
#include "core/app.hpp"
#include "core/image.hpp"
#include "core/report.hpp"
#include "core/window.hpp"

namespace boxes {

// The culling camera for view `index` of `count` around the mesh (the tables' views and
// the headless map): near the surface, far plane at the mesh's centre.
struct CullingView {
    Camera camera;
    float nearDistance, farDistance;
};
CullingView cullingView(const Bounds3f& bounds, int index, int count, float aspect);

// Draws the hierarchy's boxes at `level` (leaves above it too) seen from above (along
// `up`), coloured by the test's verdict, and the frustum's outline, into the columns
// [x0, x0 + width) of the image.
void drawCullingMap(Image& image, int x0, int width, const Bvh& bvh, const Frustum& frustum,
                    CullTest test, int level, Vec3 up);

// The headless run's map: depth 6 in the first measuring view, written beside `png`
// (suffix "-cull") and added to the report.
void addCullingMap(Report& report, const Bvh& bvh, const std::string& png, int width, int height,
                   Vec3 up);
// The headless report's part of the tree: its figures (build_ms, nodes, sah_cost) and the
// culling map beside `png`.
void addTreeReport(Report& report, const Scene& scene, const MeshBvhGeometry& geometry,
                   const std::string& png, const CommonOptions& options);

// The window's map: its keys (C, L, K, F), the counts of both tests for the current view,
// and the panel's lines.
class CullingMapWindow {
public:
    static std::vector<KeyBinding> keys();
    bool onKey(int key);  // true when the key changed the map
    // The map of `camera`'s frustum into the image's columns from x0 on. The far plane runs
    // through the mesh's centre (or 3x as far), so the frustum cuts the mesh.
    void draw(Image& image, int x0, const Bvh& bvh, const Camera& camera, Vec3 up);
    std::vector<std::string> status() const;

private:
    CullTest test_ = CullTest::Planes;
    int level_ = 6;
    float farScale_ = 1.0f;
    CullCounts counts_[2];  // planes, planes + corners
};

}  // namespace boxes
