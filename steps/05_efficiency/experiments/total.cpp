// All together: the naive renderer against the optimized one, each optimization added in turn.
#include <memory>

#include "05_efficiency/experiments/lab_helpers.hpp"
#include "05_efficiency/measure.hpp"
#include "core/timing.hpp"

namespace boxes {

Table measureTotalSpeedup(const Scene& scene, const LabOptions& o) {
    Table t("total",
            "All together on the scene: time per frame as each optimization is switched on",
            {"variant", "ms/frame", "min ms", "max ms", "ratio to naive", "max 8-bit error",
             "pixels changed"},
            "scene '" + scene.name +
                "', 160x120, max depth 5, median of repeats interleaved round-robin; the mesh "
                "optimizations "
                "(precomputed data, early out) are in the precalc table; error: largest difference "
                "of the PNG from the naive render's in 8-bit sRGB steps, and the pixels whose PNG "
                "value differs (the finite light radius may move a pixel by one step)");
    Scene infinite = scene;
    for (auto& l : infinite.lights) l.radius = kInfinity<float>;
    struct Variant {
        const char* name;
        const Scene* scene;
        bool force;
        AnalysisParts parts;
        int threads;
    };
    const AnalysisParts none = AnalysisParts::none(), all;
    std::vector<Variant> variants = {
        {"naive: every ray, infinite light radius, 1 thread", &infinite, true, none, 1},
        {"+ zero-weight rays skipped", &infinite, false, none, 1},
        {"+ scene analysis (effects on demand)", &infinite, false, all, 1},
        {"+ finite light radius", &scene, false, all, 1},
        {"+ all threads", &scene, false, all, 0}};
    std::vector<std::unique_ptr<Renderer>> renderers;
    std::vector<std::function<void()>> frames;
    std::vector<std::vector<uint8_t>> images;
    for (const Variant& v : variants) {
        RenderSettings s;
        s.width = o.quick ? 40 : 160;
        s.height = o.quick ? 30 : 120;
        s.threads = v.threads;
        s.forceAllEffects = v.force;
        s.analysis = v.parts;
        renderers.push_back(std::make_unique<Renderer>(*v.scene, v.scene->camera, s));
        images.push_back(renderers.back()->render().toRgb8());
        frames.push_back([r = renderers.back().get()] { keepValue(r->render()); });
    }
    std::vector<Timing> times = measureInterleaved(o.repeats, frames);
    for (size_t i = 0; i < variants.size(); ++i) {
        long long worst = 0, changed = 0;
        const auto &a = images[i], &b = images[0];
        for (size_t p = 0; p < a.size(); p += 3) {
            int d = 0;
            for (size_t c = 0; c < 3; ++c) d = std::max(d, std::abs(int(a[p + c]) - int(b[p + c])));
            worst = std::max<long long>(worst, d);
            changed += d > 0;
        }
        t.row({std::string(variants[i].name), times[i].median * 1e3, times[i].min * 1e3,
               times[i].max * 1e3, times[0].median / times[i].median, worst, changed});
    }
    t.timeAndError("ms/frame", "min ms", "max ms", "max 8-bit error");
    return t;
}

}  // namespace boxes
