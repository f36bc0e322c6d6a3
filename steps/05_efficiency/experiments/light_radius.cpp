// Lights with a finite radius (exercise 5.5): time saved against the largest pixel error.
#include <algorithm>
#include <functional>
#include <memory>

#include "05_efficiency/experiments/lab_helpers.hpp"
#include "05_efficiency/measure.hpp"
#include "core/timing.hpp"

namespace boxes {

using namespace lab;

Table measureLightRadius(const LabOptions& o) {
    Table t("light_radius",
            "Lights with a finite radius: time saved and the largest pixel difference",
            {"scene", "radius rule", "largest radius", "ms/frame", "min ms", "max ms", "speed-up",
             "light evaluations skipped/pixel", "shadow rays/pixel", "max diff (8-bit sRGB)",
             "max diff (linear, 1/255 units)"});
    t.note =
        "160x120, one thread, median of repeats interleaved round-robin; radius = sqrt(I_max / "
        "threshold) (exercise 5.5); differences against the same scene with infinite radii, in "
        "steps of the 8-bit sRGB image (the PNG) and in linear light; 'linear half step': the "
        "threshold 0.5/255 in linear light, 12.92x too coarse near black; 'sRGB half step': "
        "0.5/255/12.92 per light (n lights may add up to n half steps); 'sRGB half step / n' (the "
        "scenes' default, PointLight::cutoffThreshold): guaranteed within one step";
    struct Rule {
        const char* name;
        float threshold;  // 0: infinite radius
    };
    for (const char* name : {"small-lights", "spheres"}) {
        Scene base = makeScene(name, {});
        const size_t n = base.lights.size();
        const Rule rules[] = {{"infinite (reference)", 0.0f},
                              {"linear half step 0.5/255", 0.5f / 255.0f},
                              {"sRGB half step per light", PointLight::kHalfStep8},
                              {"sRGB half step / n (default)", PointLight::cutoffThreshold(n)}};
        std::vector<Scene> scenes;
        for (const Rule& rule : rules) {
            Scene s = base;
            for (auto& l : s.lights)
                l.radius = rule.threshold > 0.0f
                               ? PointLight::radiusFor(l.intensity, rule.threshold)
                               : kInfinity<float>;
            scenes.push_back(std::move(s));
        }
        const int w = sized(o, 160), h = sized(o, 120);
        std::vector<std::unique_ptr<Renderer>> renderers;
        std::vector<std::function<void()>> frames;
        for (const Scene& s : scenes) {
            renderers.push_back(std::make_unique<Renderer>(s, s.camera, oneThread(w, h)));
            frames.push_back([r = renderers.back().get()] { keepValue(r->render()); });
        }
        std::vector<Timing> times = measureInterleaved(o.repeats, frames);
        Image ref;
        for (size_t i = 0; i < scenes.size(); ++i) {
            RayCounts c;
            Image img = renderers[i]->render(&c);
            if (i == 0) ref = img;
            float largest = 0.0f;
            for (const auto& l : scenes[i].lights) largest = std::max(largest, l.radius);
            ImageDifference d = compareImages(img, ref);
            const double px = double(w * h);
            t.row({std::string(name), std::string(rules[i].name), double(largest),
                   ms(times[i].median), ms(times[i].min), ms(times[i].max),
                   times[0].median / times[i].median, double(c.lightsOutOfRange) / px,
                   double(c.shadow) / px, maxStep8(img, ref), d.maxError * 255.0});
        }
    }
    t.timeAndError("ms/frame", "min ms", "max ms", "max diff (8-bit sRGB)");
    return t;
}

}  // namespace boxes
