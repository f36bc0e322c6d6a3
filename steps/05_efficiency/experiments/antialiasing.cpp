// Anti-aliasing: error against a 256 samples per pixel reference, and time per frame.
#include "05_efficiency/experiments/lab_helpers.hpp"
#include "05_efficiency/measure.hpp"
#include "core/timing.hpp"

namespace boxes {

using namespace lab;

Table measureAntiAliasing(const Scene& scene, const LabOptions& o) {
    Table t(
        "antialiasing", "Anti-aliasing: error against a 256 samples per pixel reference, and time",
        {"samples/pixel", "ms/frame", "min ms", "max ms", "RMSE", "max error"},
        "scene '" + scene.name +
            "', 96x72, stratified jittered samples, all threads, median of repeats; "
            "RMSE over all channels in linear units against 256 samples per pixel (another seed)");
    RenderSettings s;
    s.width = sized(o, 96);
    s.height = sized(o, 72);
    s.threads = o.threads;
    s.samplesPerPixel = 256;
    s.seed = o.seed + 1000;
    Image ref = renderImage(scene, scene.camera, s);
    for (int spp : {1, 4, 16, 64}) {
        s.samplesPerPixel = spp;
        s.seed = o.seed;
        Image img;
        Timing tm = measure(o.repeats, [&] { img = renderImage(scene, scene.camera, s); });
        ImageDifference d = compareImages(img, ref);
        t.row({(long long)spp, ms(tm.median), ms(tm.min), ms(tm.max), d.rmse, d.maxError});
    }
    t.timeAndError("ms/frame", "min ms", "max ms", "RMSE");
    return t;
}

}  // namespace boxes
