#include "06_raster/frame.hpp"

#include <CLI/CLI.hpp>
#include <cmath>
#include <iostream>

namespace boxes {

RasterView::RasterView(const Scene& scene) : scene(RasterScene::fromScene(scene)) {
    if (scene.hasMesh()) culler = std::make_unique<FrustumCuller>(scene.mesh);
}

namespace {

// --near and --far, when given, into the settings: near > 0, far > near (and > 0), else
// InputError naming the flag.
void setClipPlanes(RasterSettings& settings, std::optional<double> near,
                   std::optional<double> far) {
    if (near) {
        if (!(*near > 0.0) || !std::isfinite(*near))
            throw UsageError("--near must be greater than 0");
        settings.near = *near;
    }
    if (far) {
        if (!(*far > 0.0) || !std::isfinite(*far) ||
            (settings.near > 0.0 && !(*far > settings.near)))
            throw UsageError("--far must be greater than --near (and than 0)");
        settings.far = *far;
    }
}

}  // namespace

void ViewFlags::add(CLI::App& app) {
    nearOption = app.add_option("--near", near,
                                "near plane distance along the view (default: from the scene)");
    farOption =
        app.add_option("--far", far, "far plane distance along the view (default: from the scene)");
    app.add_option("--shadows", shadows, "shadows: none, map (shadow map) or rays (hybrid)")
        ->check(CLI::IsMember({"none", "map", "rays"}))
        ->capture_default_str();
    app.add_option("--bias", shading.mapBias,
                   "shadow map depth bias in world units (0: 2e-3 of the scene's diagonal)")
        ->check(CLI::Range(0.0, 1e30));
    app.add_option("--map-size", shading.mapSize, "shadow map size in texels")
        ->check(CLI::Range(16, 8192));
    app.add_flag("--backface", raster.backfaceCulling, "cull back faces");
    app.add_flag("--no-cull", noCull,
                 "draw every triangle (no frustum culling with step 04's hierarchy)");
    app.add_flag("--affine", affine,
                 "interpolate affinely in screen space (warps) instead of with 1/w");
    app.add_flag("--checker", shading.checker,
                 "modulate the surfaces with a checker (shows interpolation)");
}

RasterView ViewFlags::view(const Scene& scene, int width, int height,
                           const TexturedFloor* floor) const {
    RasterView v(scene);
    if (floor) attachTexcoords(v.scene, floor->frame);
    v.raster = raster;
    setClipPlanes(v.raster, nearOption->count() ? std::optional(near) : std::nullopt,
                  farOption->count() ? std::optional(far) : std::nullopt);
    v.raster.width = width;
    v.raster.height = height;
    v.raster.perspectiveCorrect = !affine;
    nearFarFor(v.scene, scene.camera, v.raster);  // checks --near and --far
    v.shading = shading;
    v.shading.shadows = shadows == "none"  ? ShadowMode::None
                        : shadows == "map" ? ShadowMode::Map
                                           : ShadowMode::Rays;
    v.shading.texture = v.shading.texture || floor;
    v.culling = !noCull;
    return v;
}

RasterFrame drawFrame(const Scene& scene, const RasterView& view, const Camera& camera) {
    RasterFrame f;
    const FrustumCuller* culler = view.culling ? view.culler.get() : nullptr;
    f.stats = rasterizeCulled(view.scene, culler, camera, view.raster, f.buffers, f.cull);
    f.shaded = shadeFrame(scene, view.scene, camera, f.buffers, view.shading);
    return f;
}

void writeFrameBuffers(const RasterView& view, const RasterFrame& frame, const std::string& idsPath,
                       const std::string& depthPath) {
    if (!idsPath.empty()) {
        std::vector<uint32_t> ids = meshIds(view.scene, frame.buffers);
        writeFileAtomically(idsPath, ids.data(), ids.size() * sizeof(uint32_t));
    }
    if (!depthPath.empty()) {
        std::vector<float> depths = meshDepths(view.scene, frame.buffers);
        writeFileAtomically(depthPath, depths.data(), depths.size() * sizeof(float));
    }
}

void reportFrame(const RasterView& view, const RasterFrame& frame, Report& report) {
    const FrameStats& stats = frame.stats;
    const CullStats& cull = frame.cull;
    report.facts["triangles"] = view.scene.triangles.size();
    report.facts["triangles_after_culling"] = stats.trianglesIn;
    report.facts["triangles_drawn"] = stats.trianglesDrawn;
    const size_t frustumCulled =
        view.culling && view.culler ? view.scene.meshTriangles - cull.trianglesKept : 0;
    report.facts["triangles_culled"] = frustumCulled + stats.culledOutside + stats.culledBackface;
    report.facts["triangles_frustum_culled"] = frustumCulled;
    report.facts["boxes_visited"] = cull.boxesVisited;
    report.facts["boxes_culled"] = cull.boxesCulled;
    report.facts["boxes_kept"] = cull.boxesKept;
    report.facts["cull_ms"] = cull.milliseconds;
    report.facts["triangles_outside"] = stats.culledOutside;
    report.facts["triangles_backface_or_empty"] = stats.culledBackface;
    report.facts["triangles_clipped"] = stats.clipped;
    report.facts["fragments"] = stats.fragments;
    report.facts["pixels_covered"] = stats.pixelsCovered;
    report.facts["raster_ms"] = stats.milliseconds;
    report.facts["shade_ms"] = frame.shaded.milliseconds;
    report.facts["frame_ms"] = stats.milliseconds + frame.shaded.milliseconds;
    std::cerr << "06_raster: " << stats.trianglesDrawn << " of " << view.scene.triangles.size()
              << " triangles drawn, " << stats.pixelsCovered << " pixels covered, raster "
              << formatSeconds(stats.milliseconds * 1e-3) << ", shading "
              << formatSeconds(frame.shaded.milliseconds * 1e-3) << "\n";
}

}  // namespace boxes
