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
    CLI::Option *nearOption = nullptr, *farOption = nullptr;
    double nearFlag = 0.0, farFlag = 0.0;
    std::string idsPath, depthPath, shadows = "rays", meshesDir;
    bool affine = false, compare = false, measure = false, noCull = false, floorTexture = false;
    std::optional<TexturedFloor> floor;  // with --floor-texture
    RasterSettings rs;
    ShadeSettings shading;
    RasterView view;  // the scene as triangles, its culler, the settings (frame.hpp)
    RasterFrame frame;
    std::unique_ptr<RasterViewer> viewer;

    StepProgram step;
    step.name = "06_raster";
    step.description =
        "Step 06: the same scene and camera drawn by rasterization (software, CPU), compared "
        "with the ray tracer pixel for pixel.";
    step.title = "Step 06: rasterization";
    step.defaultScene = "bunny";
    step.addOptions = [&](CLI::App& app) {
        nearOption = app.add_option("--near", nearFlag,
                                    "near plane distance along the view (default: from the scene)");
        farOption = app.add_option("--far", farFlag,
                                   "far plane distance along the view (default: from the scene)");
        app.add_option("--ids", idsPath,
                       "write the visible triangle per pixel: uint32, row-major, row 0 at the top, "
                       "0xFFFFFFFF where nothing");
        app.add_option("--depth", depthPath,
                       "write the depth per pixel: float32 distance along the view direction, +inf "
                       "where nothing");
        app.add_option("--shadows", shadows, "shadows: none, map (shadow map) or rays (hybrid)")
            ->check(CLI::IsMember({"none", "map", "rays"}))
            ->capture_default_str();
        app.add_option("--bias", shading.mapBias,
                       "shadow map depth bias in world units (0: 2e-3 of the scene's diagonal)")
            ->check(CLI::Range(0.0, 1e30));
        app.add_option("--map-size", shading.mapSize, "shadow map size in texels")
            ->check(CLI::Range(16, 8192));
        app.add_flag("--backface", rs.backfaceCulling, "cull back faces");
        app.add_flag("--no-cull", noCull,
                     "draw every triangle (no frustum culling with step 04's hierarchy)");
        app.add_flag("--affine", affine,
                     "interpolate affinely in screen space (warps) instead of with 1/w");
        app.add_flag("--checker", shading.checker,
                     "modulate the surfaces with a checker (shows interpolation)");
        app.add_flag("--floor-texture", floorTexture,
                     "draw the textured floor instead of --scene: a 20 x 20 texel checker from "
                     "texture coordinates on a quad seen at a low angle (with --affine: the "
                     "screen-linear version; with --compare: FILE-traced.png, the ray tracer's)");
        app.add_flag(
            "--compare", compare,
            "also ray trace the view and print how the two agree (and write FILE-diff.png)");
        app.add_flag("--measure", measure, "run the step's measurements and print the tables");
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
        view = RasterView(run.scene);
        if (floor) attachTexcoords(view.scene, floor->frame);
        setClipPlanes(rs, nearOption->count() ? std::optional(nearFlag) : std::nullopt,
                      farOption->count() ? std::optional(farFlag) : std::nullopt);
        rs.width = run.options.width;
        rs.height = run.options.height;
        rs.perspectiveCorrect = !affine;
        nearFarFor(view.scene, run.scene.camera, rs);  // bad --near/--far: an error before output
        view.raster = rs;
        shading.shadows = shadows == "none"  ? ShadowMode::None
                          : shadows == "map" ? ShadowMode::Map
                                             : ShadowMode::Rays;
        shading.texture = shading.texture || floorTexture;
        view.shading = shading;
        view.culling = !noCull;
    };
    // Headless, the image is the rasterizer's, not the ray tracer's.
    step.headlessImage = [&](StepRun& run, Report& report) {
        frame = drawFrame(run.scene, view, run.camera);
        frame.shaded.image.writePng(run.png);
        report.images.push_back({run.png, "scene '" + run.scene.name + "' rasterized, shadows: " +
                                              shadowModeName(view.shading.shadows)});
        writeFrameBuffers(view, frame, idsPath, depthPath);
        reportFrame(view, frame, run.png, report);
    };
    step.measure = [&](StepRun& run, Report& report) {
        if (compare) compareWithRayTracer(run, view, frame, report);
        if (compare && floor) compareTextureWithRayTracer(run, *floor, view, frame, report);
        if (measure) measureRaster(run, report, meshesDir);
    };

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
