// Step 06's measurements: the program's frame against the ray tracer (--compare); primary
// visibility and time per frame of the rasterizer against the ray tracer on a few views,
// the shadow map's bias against acne and peter-panning, the two shadow methods against the
// ray tracer's shadows, affine against perspective-correct interpolation, the vertex work
// precalculated or not, and the textured floor against the ray tracer (--measure).
#pragma once

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "06_raster/compare.hpp"
#include "06_raster/frame.hpp"
#include "core/report.hpp"
#include "core/step.hpp"

namespace boxes {

// A scene with its mesh geometry (step 01's grid) and a camera: one view to measure.
struct MeasureView {
    std::string name;
    Scene scene;
    Camera camera;
};

// The scene with step 01's TriangleGrid as the mesh's geometry (the ray tracer's view of it).
void attachGrid(Scene& scene);

// The built-in views: the bunny and sh1 from outside, and the interior map from inside when
// `interiorMap` (its OBJ file, see findInteriorMap) is not empty.
std::vector<MeasureView> measureViews(const std::string& dataDir, const std::string& interiorMap,
                                      float aspect);

// The interior map oa_thor.obj, which the workbook does not ship: in `folder` when one is
// named (--meshes DIR, else the environment variable BOXES_MESHES), else in the workbook's
// mesh cache (build/meshes/), which tools/bench/meshes.py fills on first use from Debian's
// openarena-088-data. Returns "" when it cannot be had, with the reason in `why`; throws
// InputError when a named folder holds no oa_thor.obj.
std::string findInteriorMap(const std::string& folder, std::string* why = nullptr);

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

// The lecture's "precalculate: vertex shaders": the transform to clip space done once per
// vertex, at every triangle corner, or for every pixel; time per frame against pixels whose
// buffers differ from the once-per-vertex frame's.
Table measureVertexPrecalc(const std::vector<MeasureView>& views, const MeasureSettings& settings);

// The textured floor (texture.hpp): the rasterizer perspective-correct and affine against
// the ray tracer, pixels differing and time per frame; writes the three images next to
// `pngStem` when it is not empty.
Table measureTexture(const MeasureSettings& settings, const std::string& pngStem,
                     std::vector<std::pair<std::string, std::string>>& images);

// The program's --compare: the frame's ids, depths and shadows against the ray tracer's of
// the same view (a "compare" fact, the difference image FILE-diff.png, lines on stdout).
void compareWithRayTracer(const StepRun& run, const RasterView& view, const RasterFrame& frame,
                          Report& report);

// The program's --compare with --floor-texture: the ray tracer's textured floor of the
// same view (FILE-traced.png), the pixels that differ, a "texture" fact, a line on stdout.
struct TexturedFloor;
void compareTextureWithRayTracer(const StepRun& run, const TexturedFloor& floor,
                                 const RasterView& view, const RasterFrame& frame, Report& report);

// The program's --measure: every table above at the image's size, with the bias plot;
// `meshes`: the folder of oa_thor.obj (see findInteriorMap).
void measureRaster(const StepRun& run, Report& report, const std::string& meshes = "");

}  // namespace boxes
