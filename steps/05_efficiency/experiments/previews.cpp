// Preview modes: time per frame while the camera moves against the preview's error.
#include "05_efficiency/experiments/lab_helpers.hpp"
#include "05_efficiency/measure.hpp"
#include "05_efficiency/progressive.hpp"
#include "core/timing.hpp"

namespace boxes {

using namespace lab;

Table measurePreviews(const Scene& scene, const LabOptions& o) {
    Table t("previews",
            "Preview modes: time per frame while the camera moves, against the full render",
            {"mode", "ms/frame", "min ms", "max ms", "rays/frame", "RMSE against full"},
            "scene '" + scene.name +
                "', 320x240, all threads, median of repeats; adaptive at the scale it "
                "settles on for a 1/30 s target");
    RenderSettings s;
    s.width = sized(o, 320);
    s.height = sized(o, 240);
    s.threads = o.threads;
    Image full = renderImage(scene, scene.camera, s);
    AdaptiveResolution adaptive(1.0 / 30.0);
    for (int i = 0; i < 6; ++i) {
        Stopwatch w;
        renderPreview(scene, scene.camera, PreviewMode::Adaptive, s, adaptive.scale());
        adaptive.update(w.seconds());
    }
    for (PreviewMode m : kAllPreviewModes) {
        RayCounts c;
        Image img = renderPreview(scene, scene.camera, m, s, adaptive.scale(), &c);
        Timing tm = measure(o.repeats, [&] {
            keepValue(renderPreview(scene, scene.camera, m, s, adaptive.scale()));
        });
        std::string name = previewModeName(m);
        if (m == PreviewMode::Adaptive)
            name += " (scale " + std::to_string(adaptive.scale()).substr(0, 4) + ")";
        t.row({name, ms(tm.median), ms(tm.min), ms(tm.max), (long long)c.total(),
               compareImages(img, full).rmse});
    }
    t.timeAndError("ms/frame", "min ms", "max ms", "RMSE against full");
    return t;
}

}  // namespace boxes
