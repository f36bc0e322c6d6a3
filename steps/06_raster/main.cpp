// Step 06: the same scene and camera drawn by rasterization, in software on the CPU, and
// compared with the ray tracer pixel for pixel. SDL2 only shows the image.
#include <memory>
#include <optional>

#include "06_raster/frame.hpp"
#include "06_raster/measure.hpp"
#include "06_raster/texture.hpp"
#include "06_raster/viewer.hpp"
#include "core/step.hpp"

using namespace boxes;

int main(int argc, char** argv) {
    ViewFlags viewFlags;  // --near, --far, --shadows, ... (frame.hpp)
    std::string idsPath, depthPath, meshesDir;
    bool compare = false, floorTexture = false;
    std::optional<TexturedFloor> floor;  // with --floor-texture
    RasterView view;  // the scene as triangles, its culler, the settings (frame.hpp)
    RasterFrame frame;
    std::unique_ptr<RasterViewer> viewer;

    // What the step is, for the shell (core/step.hpp): every main fills the same fields,
    // then adds its own flags, tables and keys.
    StepProgram step;
    step.name = "06_raster";
    step.description =
        "Step 06: the same scene and camera drawn by rasterization (software, CPU), compared "
        "with the ray tracer pixel for pixel.";
    step.title = "Step 06: rasterization";
    step.defaultScene = "bunny";
    step.addOptions = [&](CLI::App& app) {
        viewFlags.add(app);
        app.add_option("--ids", idsPath,
                       "write the visible triangle per pixel: uint32, row-major, row 0 at the top, "
                       "0xFFFFFFFF where nothing");
        app.add_option("--depth", depthPath,
                       "write the depth per pixel: float32 distance along the view direction, +inf "
                       "where nothing");
        app.add_flag("--floor-texture", floorTexture,
                     "draw the textured floor instead of --scene: a 20 x 20 texel checker from "
                     "texture coordinates on a quad seen at a low angle (with --affine: the "
                     "screen-linear version; with --compare: FILE-traced.png, the ray tracer's)");
        app.add_flag(
            "--compare", compare,
            "also ray trace the view and print how the two agree (and write FILE-diff.png)");
        app.add_option("--meshes", meshesDir,
                       "--measure: the folder of oa_thor.obj, the interior map (default: "
                       "$BOXES_MESHES, else build/meshes/, made by tools/bench/meshes.py)");
    };
    // --floor-texture: the floor's scene and camera (the camera flags still apply).
    step.makeScene = [&](const CommonOptions& o) {
        if (!floorTexture) return sceneFromOptions(o);
        floor = texturedFloor(o.aspect());
        Scene scene = floor->scene;
        scene.camera = cameraFromOptions(o, scene.camera);
        return scene;
    };
    // The ray tracer sees the mesh through step 01's grid; the rasterizer its triangles.
    step.addGeometry = [&](StepRun& run) {
        attachGrid(run.scene);
        view = viewFlags.view(run.scene, run.options.width, run.options.height,
                              floor ? &*floor : nullptr);
    };
    // Headless, the image is the rasterizer's, not the ray tracer's.
    step.draw = [&](StepRun& run) {
        frame = drawFrame(run.scene, view, run.camera);
        return frame.shaded.image;
    };
    step.caption = [&](const StepRun& run) {
        return "scene '" + run.scene.name +
               "' rasterized, shadows: " + shadowModeName(view.shading.shadows);
    };
    step.afterImage = [&](StepRun& run, Report& report) {
        writeFrameBuffers(view, frame, idsPath, depthPath);
        reportFrame(view, frame, report);
        if (compare) compareWithRayTracer(run, view, frame, report);
        if (compare && floor) compareTextureWithRayTracer(run, *floor, view, frame, report);
    };
    step.measure = [&](StepRun& run, Report& report) { measureRaster(run, report, meshesDir); };

    // The window: rasterizer, ray tracer, or their difference (viewer.hpp).
    step.openWindow = [&](StepRun& run) {
        viewer = std::make_unique<RasterViewer>(run.scene, view, run.settings);
        if (floor) viewer->textureFrame = &floor->frame;
    };
    step.keys = RasterViewer::keys();
    step.onKey = [&](StepRun&, int key) { return viewer->onKey(key); };
    step.render = [&](StepRun& run) { return viewer->render(run.camera); };
    step.panel = [&](StepRun&) { viewer->panel(); };
    return runStep(argc, argv, step);
}
