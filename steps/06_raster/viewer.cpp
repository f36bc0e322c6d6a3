#include "06_raster/viewer.hpp"

#include <SDL2/SDL_keycode.h>
#include <imgui.h>

#include "core/timing.hpp"

namespace boxes {

RasterViewer::RasterViewer(const Scene& scene, RasterView& view, const RenderSettings& traced)
    : scene_(scene), view_(view), traced_(traced) {}

std::vector<KeyBinding> RasterViewer::keys() {
    return {{SDLK_r, "switch rasterizer / ray tracer (same view)"},
            {SDLK_d,
             "show where they differ (red: raster only, blue: ray tracer only, yellow: "
             "other triangle)"},
            {SDLK_h, "shadows: none / shadow map / shadow rays"},
            {SDLK_b, "back-face culling on / off"},
            {SDLK_p, "perspective-correct / affine interpolation"},
            {SDLK_c, "checker on the surfaces (shows the interpolation)"},
            {SDLK_f, "frustum culling with step 04's hierarchy on / off"}};
}

bool RasterViewer::onKey(int key) {
    switch (key) {
        case SDLK_r:
            shown_ = shown_ == Shown::Raster ? Shown::Traced : Shown::Raster;
            return true;
        case SDLK_d:
            shown_ = shown_ == Shown::Difference ? Shown::Raster : Shown::Difference;
            return true;
        case SDLK_h:
            view_.shading.shadows = ShadowMode((int(view_.shading.shadows) + 1) % 3);
            return true;
        case SDLK_b:
            view_.raster.backfaceCulling = !view_.raster.backfaceCulling;
            return true;
        case SDLK_p:
            view_.raster.perspectiveCorrect = !view_.raster.perspectiveCorrect;
            return true;
        case SDLK_c:
            view_.shading.checker = !view_.shading.checker;
            return true;
        case SDLK_f:
            view_.culling = !view_.culling;
            return true;
        default:
            return false;
    }
}

Image RasterViewer::render(const Camera& camera) {
    RasterFrame frame = drawFrame(scene_, view_, camera);
    stats_ = frame.stats;
    cull_ = frame.cull;
    rasterMs_ = frame.stats.milliseconds;
    shadeMs_ = frame.shaded.milliseconds;
    if (shown_ == Shown::Raster) return std::move(frame.shaded.image);
    if (shown_ == Shown::Traced) {
        Stopwatch watch;
        Image image = textureFrame ? traceTexturedFloor(scene_, *textureFrame, camera,
                                                        view_.raster.width, view_.raster.height)
                                   : renderImage(scene_, camera, traced_);
        tracedMs_ = watch.milliseconds();
        return image;
    }
    const int w = view_.raster.width, h = view_.raster.height;
    TracedFrame traced = traceFrame(scene_, camera, w, h, false, traced_.threads);
    tracedMs_ = traced.milliseconds;
    std::vector<uint32_t> ids = meshIds(view_.scene, frame.buffers);
    difference_ = compareVisibility(w, h, ids, meshDepths(view_.scene, frame.buffers), traced.ids,
                                    traced.depth, &scene_.mesh);
    return differenceImage(w, h, ids, traced.ids);
}

void RasterViewer::panel() const {
    const char* names[] = {"rasterizer", "ray tracer", "difference"};
    ImGui::Text("showing: %s", names[int(shown_)]);
    ImGui::Text("raster: %.1f ms + shading %.1f ms (1 thread)", rasterMs_, shadeMs_);
    if (shown_ != Shown::Raster) ImGui::Text("ray tracer: %.1f ms", tracedMs_);
    ImGui::Text("triangles drawn %zu of %zu, pixels %zu", stats_.trianglesDrawn,
                view_.scene.triangles.size(), stats_.pixelsCovered);
    if (view_.culling && view_.culler)
        ImGui::Text("frustum culling: %zu boxes culled, %zu kept, %zu triangles kept",
                    cull_.boxesCulled, cull_.boxesKept, cull_.trianglesKept);
    else
        ImGui::Text("frustum culling: off");
    ImGui::Text("shadows: %s, back faces %s, %s", shadowModeName(view_.shading.shadows),
                view_.raster.backfaceCulling ? "culled" : "drawn",
                view_.raster.perspectiveCorrect ? "perspective-correct" : "affine");
    if (shown_ == Shown::Difference)
        ImGui::Text("same triangle %.3f%%, %zu differ on edges, %zu elsewhere",
                    100.0 * difference_.agreement(), difference_.differOnEdge,
                    difference_.differElsewhere);
}

}  // namespace boxes
