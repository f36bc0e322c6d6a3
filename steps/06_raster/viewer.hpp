// What step 06's window shows on the same moving camera: the rasterizer's frame, the ray
// tracer's, or where the two see different triangles; keys switch the shadows, back-face
// culling, the interpolation, a checker and frustum culling.
#pragma once

#include <vector>

#include "06_raster/compare.hpp"
#include "06_raster/frame.hpp"
#include "06_raster/texture.hpp"
#include "core/render.hpp"
#include "core/window.hpp"

namespace boxes {

class RasterViewer {
public:
    // `traced`: the ray tracer's settings (size, threads); the keys change `view`.
    RasterViewer(const Scene& scene, RasterView& view, const RenderSettings& traced);

    static std::vector<KeyBinding> keys();
    bool onKey(int key);  // true when the key was used
    Image render(const Camera& camera);
    void panel() const;
    // With the textured floor: the ray tracer's view is its textured image (texture.hpp).
    const TangentFrame* textureFrame = nullptr;

private:
    enum class Shown { Raster, Traced, Difference };
    const Scene& scene_;
    RasterView& view_;
    RenderSettings traced_;
    Shown shown_ = Shown::Raster;
    double rasterMs_ = 0.0, shadeMs_ = 0.0, tracedMs_ = 0.0;
    FrameStats stats_;
    CullStats cull_;
    VisibilityComparison difference_;
};

}  // namespace boxes
