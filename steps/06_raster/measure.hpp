// Step 06's measurements: primary visibility and time per frame of the rasterizer against
// the ray tracer on a few views, the shadow map's bias against acne and peter-panning,
// the two shadow methods against the ray tracer's shadows, and affine against
// perspective-correct interpolation.
#pragma once

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "06_raster/compare.hpp"
#include "core/report.hpp"

namespace boxes {

// A scene with its mesh geometry (step 01's grid) and a camera: one view to measure.
struct MeasureView {
    std::string name;
    Scene scene;
    Camera camera;
};

// The scene with step 01's TriangleGrid as the mesh's geometry (the ray tracer's view of it).
void attachGrid(Scene& scene);

// The built-in views: the bunny from outside, the bunny seen from inside itself, and
// oa_thor from inside when `sharedMeshes` (../shared/data/meshes) holds it.
std::vector<MeasureView> measureViews(const std::string& dataDir, const std::string& sharedMeshes,
                                      float aspect);

// Where ../shared/data/meshes is, relative to the source tree or the working directory;
// empty when it is not there.
std::string findSharedMeshes(const std::string& dataDir);

struct MeasureSettings {
    int width = 640, height = 480;
    int repeats = 3;
    // Shadow map size: four texels per pixel of the image's larger side, 256 to 2048 (the
    // bias sweep also tries half of it).
    int mapSize() const { return std::clamp(4 * std::max(width, height), 256, 2048); }
};

Table measureVisibility(const std::vector<MeasureView>& views, const MeasureSettings& settings);
Table measureFrameTimes(const std::vector<MeasureView>& views, const MeasureSettings& settings);
// The shadow map's bias swept on one view; and both methods against the ray tracer.
Table measureShadowBias(const MeasureView& view, const MeasureSettings& settings);
Table measureShadowMethods(const MeasureView& view, const MeasureSettings& settings);
// Frustum culling with step 04's hierarchy: boxes culled and kept, triangles drawn, time
// per frame, and whether the image is identical to the unculled one.
Table measureCulling(const std::vector<MeasureView>& views, const MeasureSettings& settings);

// Affine against perspective-correct weights: the interpolated position's error against
// the ray tracer's hit point, on a floor seen at a grazing angle and on the bunny; writes
// the two checker images next to `pngStem` when it is not empty.
Table measureInterpolation(const MeasureView& bunny, const MeasureSettings& settings,
                           const std::string& pngStem,
                           std::vector<std::pair<std::string, std::string>>& images);

}  // namespace boxes
