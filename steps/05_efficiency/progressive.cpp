#include "05_efficiency/progressive.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/exercise.hpp"

namespace boxes {

Clock steadyClock() {
    auto start = std::chrono::steady_clock::now();
    return [start] {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
}

IncrementalRenderer::IncrementalRenderer(int width, int height, LineRenderer renderLine,
                                         Clock clock)
    : image_(width, height), renderLine_(std::move(renderLine)), clock_(std::move(clock)) {
    if (width <= 0 || height <= 0) throw std::invalid_argument("image size must be positive");
}

void IncrementalRenderer::restart(const Image& background) {
    nextRow_ = 0;
    if (background.width() == image_.width() && background.height() == image_.height())
        image_ = background;
}

// EXERCISE 5.9: refine line by line within a time budget per frame (3 points)
int IncrementalRenderer::advance(double budgetSeconds) {
    // BEGIN SOLUTION
    // Predict the next line's cost by the last one's (neighbouring lines cost alike) and
    // stop before a line that would overrun the budget; always render one, so the image
    // progresses even when a single line costs more than the budget.
    const double start = clock_();
    int lines = 0;
    while (!complete()) {
        if (lines > 0 && (clock_() - start) + lastLineSeconds_ > budgetSeconds) break;
        const double lineStart = clock_();
        renderLine_(image_, nextRow_);
        lastLineSeconds_ = clock_() - lineStart;
        ++nextRow_;
        ++lines;
    }
    return lines;
    // END SOLUTION
}

AdaptiveResolution::AdaptiveResolution(double targetSeconds, float minScale, float maxScale)
    : target_(targetSeconds), minScale_(minScale), maxScale_(maxScale), scale_(maxScale) {
    if (!(targetSeconds > 0.0)) throw std::invalid_argument("target frame time must be positive");
    if (!(minScale > 0.0f && minScale <= maxScale))
        throw std::invalid_argument("resolution scales must satisfy 0 < min <= max");
}

// EXERCISE 5.10: adapt the resolution to hold a target frame time (2 points)
void AdaptiveResolution::update(double frameSeconds) {
    // BEGIN SOLUTION
    if (!(frameSeconds > 0.0) || !std::isfinite(frameSeconds)) return;
    // Time ~ pixels ~ scale^2, so the scale that would have hit the target is
    // scale * sqrt(target / time). A fixed cost per frame makes this undershoot the change
    // it needs, so it converges from one side without oscillating. At most a factor 2 per
    // frame, so one odd frame (a page fault, another process) cannot throw it far.
    double factor = std::sqrt(target_ / frameSeconds);
    factor = std::clamp(factor, 0.5, 2.0);
    scale_ = std::clamp(float(scale_ * factor), minScale_, maxScale_);
    // END SOLUTION
}

// One case per value and no default: -Wswitch names a value added without its name.
const char* previewModeName(PreviewMode mode) {
    switch (mode) {
        case PreviewMode::Depth:
            return "depth";
        case PreviewMode::DepthMaterial:
            return "depth + material";
        case PreviewMode::NoRecursion:
            return "no recursion";
        case PreviewMode::LimitedRecursion:
            return "limited recursion (1 bounce)";
        case PreviewMode::HalfResolution:
            return "half resolution";
        case PreviewMode::Adaptive:
            return "adaptive resolution";
        case PreviewMode::Full:
            return "full";
    }
    return "?";
}

Image enlargeNearest(const Image& small, int width, int height) {
    if (small.width() == width && small.height() == height) return small;
    Image out(width, height);
    for (int y = 0; y < height; ++y) {
        int sy = std::min(small.height() - 1, y * small.height() / height);
        for (int x = 0; x < width; ++x)
            out.at(x, y) = small.at(std::min(small.width() - 1, x * small.width() / width), sy);
    }
    return out;
}

namespace {

// One primary ray per pixel, shaded from the hit alone: no lights, no secondary rays.
Image renderFromPrimaryHits(const Scene& scene, const Camera& camera, const RenderSettings& s,
                            bool withMaterial, RayCounts* counts) {
    Image image(s.width, s.height);
    CameraBasisT<float> basis = camera.basis();
    // Grey levels fall off over the distance from the eye to the point it looks at.
    const float focus =
        std::max(1e-6f, glm::length(camera.view)) * (glm::length(camera.view) < 1.5f ? 8.0f : 1.5f);
    std::vector<uint64_t> perRow(size_t(s.height), 0);
    parallelRows(s.height, s.threads, [&](int y, int) {
        for (int x = 0; x < s.width; ++x) {
            Ray ray(camera.eye,
                    camera.directionThrough(basis, x + 0.5f, y + 0.5f, s.width, s.height));
            ++perRow[size_t(y)];
            SurfaceHit hit;
            if (!scene.intersect(ray, hit)) {
                image.at(x, y) = withMaterial ? scene.background : Vec3(0.0f);
                continue;
            }
            float depth = std::exp(-hit.t / focus);
            if (!withMaterial) {
                image.at(x, y) = Vec3(depth);
                continue;
            }
            const Material& m = scene.materials[size_t(hit.material)];
            Vec3 colour = m.kind == Material::Kind::Glass ? Vec3(0.6f, 0.8f, 0.9f) : m.albedo;
            float facing = std::abs(glm::dot(hit.shadingNormal, ray.direction));
            image.at(x, y) = colour * (0.3f + 0.7f * facing) * (0.35f + 0.65f * depth);
        }
    });
    if (counts)
        for (uint64_t n : perRow) counts->primary += n;
    return image;
}

}  // namespace

Image renderPreview(const Scene& scene, const Camera& camera, PreviewMode mode,
                    const RenderSettings& settings, float scale, RayCounts* counts) {
    RenderSettings s = settings;
    if (mode == PreviewMode::Depth || mode == PreviewMode::DepthMaterial)
        return renderFromPrimaryHits(scene, camera, s, mode == PreviewMode::DepthMaterial, counts);
    if (mode == PreviewMode::NoRecursion) s.maxDepth = 0;
    if (mode == PreviewMode::LimitedRecursion) s.maxDepth = std::min(settings.maxDepth, 1);
    if (mode == PreviewMode::HalfResolution) scale = 0.5f;
    if (mode != PreviewMode::HalfResolution && mode != PreviewMode::Adaptive) scale = 1.0f;
    s.width = std::max(1, int(std::lround(settings.width * scale)));
    s.height = std::max(1, int(std::lround(settings.height * scale)));
    Image image = renderImage(scene, camera, s, counts);
    return enlargeNearest(image, settings.width, settings.height);
}

}  // namespace boxes
