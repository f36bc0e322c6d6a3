// All together: the naive renderer against the optimized one, each optimization added in turn.
#include <memory>

#include "05_efficiency/measure.hpp"
#include "core/timing.hpp"

namespace boxes {

Table measureTotalSpeedup(const Scene& scene, const LabOptions& o) {
    Table t;
    t.id = "total";
    t.title = "All together on the scene: time per frame as each optimization is switched on";
    t.columns = {"variant", "ms/frame", "min ms", "max ms", "ratio to naive"};
    t.note = "scene '" + scene.name +
             "', 160x120, max depth 5, median of repeats interleaved round-robin; the mesh "
             "optimizations "
             "(precomputed data, early out) are in the precalc table";
    Scene infinite = scene;
    for (auto& l : infinite.lights) l.radius = kInfinity<float>;
    struct Variant {
        const char* name;
        const Scene* scene;
        bool force;
        int threads;
    };
    std::vector<Variant> variants = {
        {"naive: every effect forced, infinite light radius, 1 thread", &infinite, true, 1},
        {"+ effects on demand", &infinite, false, 1},
        {"+ finite light radius", &scene, false, 1},
        {"+ all threads", &scene, false, 0}};
    std::vector<std::unique_ptr<Renderer>> renderers;
    std::vector<std::function<void()>> frames;
    for (const Variant& v : variants) {
        RenderSettings s;
        s.width = o.quick ? 40 : 160;
        s.height = o.quick ? 30 : 120;
        s.threads = v.threads;
        s.forceAllEffects = v.force;
        renderers.push_back(std::make_unique<Renderer>(*v.scene, v.scene->camera, s));
        frames.push_back([r = renderers.back().get()] { keepValue(r->render()); });
    }
    std::vector<Timing> times = measureInterleaved(o.repeats, frames);
    for (size_t i = 0; i < variants.size(); ++i)
        t.row({std::string(variants[i].name), times[i].median * 1e3, times[i].min * 1e3,
               times[i].max * 1e3, times[0].median / times[i].median});
    return t;
}

}  // namespace boxes
