// Effects on demand: rays traced per kind with the scene analysis on and forced off.
#include "05_efficiency/experiments/lab_helpers.hpp"
#include "05_efficiency/measure.hpp"
#include "core/timing.hpp"

namespace boxes {

using namespace lab;

Table measureEffects(const LabOptions& o) {
    Table t;
    t.id = "effects";
    t.title = "Effects on demand: rays traced per kind with the scene analysis on and forced off";
    t.columns = {"scene",      "analysis",   "primary",  "shadow",       "shadow skipped",
                 "reflection", "refraction", "ms/frame", "bit-identical"};
    t.note =
        "160x120, max depth 5, one thread, median of repeats; 'forced': "
        "RenderSettings::forceAllEffects "
        "traces every shadow, reflection and refraction ray; bit-identical: the float images equal";
    for (const char* name :
         {"single-sphere", "diffuse", "mirrors", "glass", "spheres", "small-lights"}) {
        Scene scene = makeScene(name, {});
        Image on;
        for (bool force : {false, true}) {
            RenderSettings s = oneThread(sized(o, 160), sized(o, 120));
            s.forceAllEffects = force;
            Renderer r(scene, scene.camera, s);
            RayCounts c;
            Image img = r.render(&c);
            if (!force) on = img;
            Timing tm = measure(o.repeats, [&] { keepValue(r.render()); });
            t.row({std::string(name), std::string(force ? "forced" : "on"), (long long)c.primary,
                   (long long)c.shadow, (long long)c.shadowSkipped, (long long)c.reflection,
                   (long long)c.refraction, ms(tm.median),
                   std::string(identical(img, on) ? "yes" : "NO")});
        }
    }
    return t;
}

}  // namespace boxes
