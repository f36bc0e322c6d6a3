#include "05_efficiency/viewer.hpp"

#include <SDL2/SDL_keycode.h>
#include <imgui.h>

#include <iostream>
#include <utility>

#include "core/timing.hpp"

namespace boxes {

namespace {

// A photograph renders this long per frame, so the window stays responsive meanwhile.
constexpr double kPhotoBudgetSeconds = 0.03;

const std::pair<int, PreviewMode> kModeKeys[] = {{SDLK_1, PreviewMode::Depth},
                                                 {SDLK_2, PreviewMode::DepthMaterial},
                                                 {SDLK_3, PreviewMode::NoRecursion},
                                                 {SDLK_4, PreviewMode::LimitedRecursion},
                                                 {SDLK_5, PreviewMode::HalfResolution},
                                                 {SDLK_6, PreviewMode::Adaptive},
                                                 {SDLK_0, PreviewMode::Full}};

}  // namespace

ProgressiveViewer::ProgressiveViewer(const Scene& scene, const RenderSettings& settings,
                                     const ViewerOptions& options)
    : scene_(scene),
      settings_(settings),
      options_(options),
      refinement_(
          settings.width, settings.height,
          [this](Image& img, int row) {
              RayCounts c;
              refiner_->renderRows(img, row, row + 1, c);
          },
          clock_) {}

std::vector<KeyBinding> ProgressiveViewer::keys() {
    return {{SDLK_1, "preview while moving: depth map"},
            {SDLK_2, "preview: depth + material colour"},
            {SDLK_3, "preview: no recursion"},
            {SDLK_4, "preview: limited recursion (1 bounce)"},
            {SDLK_5, "preview: half resolution"},
            {SDLK_6, "preview: adaptive resolution (30 fps target)"},
            {SDLK_0, "preview: full render every frame"},
            {SDLK_p, "photograph: deep recursion, anti-aliasing, saves a PNG"},
            {SDLK_ESCAPE, "cancel the photograph (quits when none runs)"}};
}

bool ProgressiveViewer::onKey(int key, const Camera& camera) {
    if (photo_ && key == SDLK_ESCAPE) {
        photo_.reset();
        photoShown_ = Image();
        photoMessage_ = "photograph cancelled";
        std::cout << "05_efficiency: photograph cancelled" << std::endl;
        return true;
    }
    for (auto [k, m] : kModeKeys)
        if (key == k) {
            mode_ = m;
            restart_ = true;
            return true;
        }
    if (key != SDLK_p) return false;
    RenderSettings photoSettings = settings_;
    photoSettings.samplesPerPixel = options_.photoSpp;
    photoSettings.maxDepth = options_.photoDepth;
    photographer_ = std::make_unique<Renderer>(scene_, camera, photoSettings);
    photo_ = std::make_unique<IncrementalRenderer>(
        settings_.width, settings_.height,
        [this](Image& img, int row) {
            RayCounts c;
            photographer_->renderRows(img, row, row + 1, c);
        },
        clock_);
    photo_->restart(refinement_.image());
    photoMessage_.clear();
    return true;
}

const Image& ProgressiveViewer::frame(const Camera& camera, bool moved) {
    if (moved) {
        photoShown_ = Image();  // a moved camera leaves the photograph
        restart_ = true;
    }
    if (photo_) {
        photo_->advance(kPhotoBudgetSeconds);
        if (!photo_->complete()) return photo_->image();
        std::string path = "05_efficiency-photo-" + std::to_string(++photoIndex_) + ".png";
        photo_->image().writePng(path);
        std::cout << "05_efficiency: photograph saved to " << path << std::endl;
        photoMessage_ = "saved " + path;
        photoShown_ = photo_->image();
        photo_.reset();
    }
    if (!photoShown_.empty()) return photoShown_;
    if (restart_) {
        Stopwatch watch;
        Image preview = renderPreview(scene_, camera, mode_, settings_, adaptive_.scale());
        previewMs_ = watch.milliseconds();
        if (mode_ == PreviewMode::Adaptive) adaptive_.update(previewMs_ * 1e-3);
        refiner_ = std::make_unique<Renderer>(scene_, camera, settings_);
        refinement_.restart(preview);
        restart_ = false;
        return refinement_.image();
    }
    // Stationary: refine with full recursion, at most the budget per frame.
    if (!refinement_.complete()) refinement_.advance(options_.budgetMs * 1e-3);
    return refinement_.image();
}

void ProgressiveViewer::panel() const {
    ImGui::Text("preview: %s (%.1f ms)", previewModeName(mode_), previewMs_);
    if (mode_ == PreviewMode::Adaptive) ImGui::Text("adaptive scale: %.2f", adaptive_.scale());
    if (photo_) {
        ImGui::Text("photograph: %d spp, depth %d (Esc cancels)", options_.photoSpp,
                    options_.photoDepth);
        ImGui::ProgressBar(float(photo_->progress()));
    } else if (refinement_.complete()) {
        ImGui::Text("refined: complete (full recursion)");
    } else {
        ImGui::Text("refining: line %d of %d, %.0f ms budget per frame", refinement_.linesDone(),
                    settings_.height, options_.budgetMs);
        ImGui::ProgressBar(float(refinement_.progress()));
    }
    if (!photoMessage_.empty()) ImGui::TextUnformatted(photoMessage_.c_str());
}

}  // namespace boxes
