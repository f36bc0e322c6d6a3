// What step 05's window shows, for perceived performance: a preview while the camera moves
// (keys 1-6; 0: the full render every frame), the image refined line by line within a time
// budget per frame once it stops (exercise 5.9), and the photograph mode (P: deep
// recursion and anti-aliasing, refined the same way and saved to a PNG; Esc cancels it).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "05_efficiency/progressive.hpp"
#include "core/window.hpp"

namespace boxes {

struct ViewerOptions {
    double budgetMs = 15.0;  // refinement budget per frame
    int photoSpp = 16, photoDepth = 12;
};

class ProgressiveViewer {
public:
    ProgressiveViewer(const Scene& scene, const RenderSettings& settings,
                      const ViewerOptions& options);

    static std::vector<KeyBinding> keys();
    // True when the key was used; P photographs `camera`.
    bool onKey(int key, const Camera& camera);
    // The image to show this frame; `moved`: the camera moved since the last frame.
    const Image& frame(const Camera& camera, bool moved);
    void panel() const;  // the mode, the refinement's or the photograph's progress

private:
    const Scene& scene_;
    RenderSettings settings_;
    ViewerOptions options_;
    Clock clock_ = steadyClock();
    PreviewMode mode_ = PreviewMode::Adaptive;
    AdaptiveResolution adaptive_{1.0 / 30.0};
    bool restart_ = true;  // render a preview and refine again from the first line
    double previewMs_ = 0.0;
    std::unique_ptr<Renderer> refiner_;  // full recursion, for the current camera
    IncrementalRenderer refinement_;
    // Photograph mode: deep recursion and stratified samples, also line by line.
    std::unique_ptr<Renderer> photographer_;
    std::unique_ptr<IncrementalRenderer> photo_;
    Image photoShown_;
    int photoIndex_ = 0;
    std::string photoMessage_;
};

}  // namespace boxes
