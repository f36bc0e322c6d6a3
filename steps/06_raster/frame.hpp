// One frame of step 06's program: the scene as triangles with the frustum culler of its mesh
// and the settings the flags and keys change, drawn by the pipeline (culled, rasterized,
// shaded), and the frame's figures for the report.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "06_raster/culling.hpp"
#include "06_raster/pipeline.hpp"
#include "core/report.hpp"

namespace boxes {

struct RasterView {
    RasterScene scene;
    std::unique_ptr<FrustumCuller> culler;  // over the scene's mesh; null without one
    RasterSettings raster;
    ShadeSettings shading;
    bool culling = true;  // frustum culling with step 04's hierarchy

    // The scene's triangles, and the culler when it has a mesh.
    explicit RasterView(const Scene& scene);
    RasterView() = default;
};

struct RasterFrame {
    FrameBuffers buffers;
    FrameStats stats;
    CullStats cull;
    ShadedFrame shaded;
};

// --near and --far, when given, into the settings: near > 0, far > near (and > 0), else
// InputError naming the flag.
void setClipPlanes(RasterSettings& settings, std::optional<double> near, std::optional<double> far);

// Culls (when view.culling), rasterizes and shades the camera's view of the scene.
RasterFrame drawFrame(const Scene& scene, const RasterView& view, const Camera& camera);

// The --ids and --depth files (meshIds, meshDepths; an empty path: not written).
void writeFrameBuffers(const RasterView& view, const RasterFrame& frame, const std::string& idsPath,
                       const std::string& depthPath);

// The frame's counts and times as report facts, and one line on stderr saying what was
// drawn into `png`.
void reportFrame(const RasterView& view, const RasterFrame& frame, const std::string& png,
                 Report& report);

}  // namespace boxes
