// One frame of step 06's program: the scene as triangles with the frustum culler of its mesh
// and the settings the flags and keys change, drawn by the pipeline (culled, rasterized,
// shaded), and the frame's figures for the report.
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <optional>
#include <string>

#include "06_raster/culling.hpp"
#include "06_raster/pipeline.hpp"
#include "06_raster/texture.hpp"
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

// The program's flags that set up the view: --near --far --shadows --bias --map-size
// --backface --no-cull --affine --checker.
struct ViewFlags {
    CLI::Option *nearOption = nullptr, *farOption = nullptr;
    double near = 0.0, far = 0.0;
    std::string shadows = "rays";
    bool affine = false, noCull = false;
    RasterSettings raster;
    ShadeSettings shading;

    void add(CLI::App& app);
    // The view of `scene` (width x height) they ask for, with the floor's texture
    // coordinates when there is one. A bad --near or --far is an InputError here, before
    // anything is written.
    RasterView view(const Scene& scene, int width, int height,
                    const TexturedFloor* floor = nullptr) const;
};

// Culls (when view.culling), rasterizes and shades the camera's view of the scene.
RasterFrame drawFrame(const Scene& scene, const RasterView& view, const Camera& camera);

// The --ids and --depth files (meshIds, meshDepths; an empty path: not written).
void writeFrameBuffers(const RasterView& view, const RasterFrame& frame, const std::string& idsPath,
                       const std::string& depthPath);

// The frame's counts and times as report facts, and one line on stderr saying what was
// drawn.
void reportFrame(const RasterView& view, const RasterFrame& frame, Report& report);

}  // namespace boxes
