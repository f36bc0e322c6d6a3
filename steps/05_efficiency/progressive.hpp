// Perceived performance: a preview while the camera moves, and a stationary camera whose
// image refines line by line within a time budget per frame, so the window never stalls.
#pragma once

#include <functional>
#include <string>

#include "core/image.hpp"
#include "core/render.hpp"
#include "core/scene.hpp"

namespace boxes {

// Seconds from some fixed start, never decreasing. The window passes a steady clock; the
// tests pass a fake one that advances by a given cost per line, so frame budgets are
// checked exactly instead of against the machine's speed.
using Clock = std::function<double()>;
Clock steadyClock();

// Renders one row of the image (all its pixels).
using LineRenderer = std::function<void(Image& image, int row)>;

class IncrementalRenderer {
public:
    IncrementalRenderer(int width, int height, LineRenderer renderLine, Clock clock);

    // Starts over from the first line (the camera moved). The rows not refined yet show
    // `background` (a preview) when it has the image's size.
    void restart(const Image& background = Image());
    // Exercise 5.9: renders lines until the next one would not fit into the budget, at
    // least one line per call; returns the number of lines rendered.
    int advance(double budgetSeconds);

    bool complete() const { return nextRow_ >= image_.height(); }
    int linesDone() const { return nextRow_; }
    double progress() const { return double(nextRow_) / double(image_.height()); }
    double secondsPerLine() const { return lastLineSeconds_; }
    const Image& image() const { return image_; }

private:
    Image image_;
    LineRenderer renderLine_;
    Clock clock_;
    int nextRow_ = 0;
    double lastLineSeconds_ = 0.0;  // the cost of the last line: the estimate of the next
};

// Chooses the resolution scale (of width and height) that holds a target frame time
// while the camera moves. The cost of a frame grows with its pixel count, scale^2.
class AdaptiveResolution {
public:
    explicit AdaptiveResolution(double targetSeconds, float minScale = 0.125f,
                                float maxScale = 1.0f);
    float scale() const { return scale_; }
    double target() const { return target_; }
    // Exercise 5.10: after a frame at scale() took frameSeconds, choose the next scale.
    void update(double frameSeconds);

private:
    double target_;
    float minScale_, maxScale_;
    float scale_;
};

// What the window shows while the camera moves (keys 1-6), and the full render (0).
enum class PreviewMode {
    Depth,             // distance along the primary ray, grey
    DepthMaterial,     // the material's colour, darkened with distance and by the slope
    NoRecursion,       // direct light and shadows only (maxDepth 0)
    LimitedRecursion,  // one bounce of reflection and refraction (maxDepth 1)
    HalfResolution,    // full shading on a quarter of the pixels
    Adaptive,          // full shading at the resolution that holds the target frame time
    Full
};
const char* previewModeName(PreviewMode mode);
constexpr PreviewMode kAllPreviewModes[] = {PreviewMode::Depth,
                                            PreviewMode::DepthMaterial,
                                            PreviewMode::NoRecursion,
                                            PreviewMode::LimitedRecursion,
                                            PreviewMode::HalfResolution,
                                            PreviewMode::Adaptive,
                                            PreviewMode::Full};

// Renders a preview at settings.width x settings.height (scale < 1: rendered smaller and
// enlarged with nearest-neighbour, as HalfResolution and Adaptive do).
Image renderPreview(const Scene& scene, const Camera& camera, PreviewMode mode,
                    const RenderSettings& settings, float scale = 1.0f,
                    RayCounts* counts = nullptr);

// Nearest-neighbour enlargement to width x height.
Image enlargeNearest(const Image& small, int width, int height);

}  // namespace boxes
