#include "05_efficiency/measure.hpp"

#include <iostream>
#include <memory>

#include "05_efficiency/bvh_mesh.hpp"
#include "05_efficiency/progressive.hpp"
#include "core/timing.hpp"

namespace boxes {

std::vector<std::vector<double>> sampleInterleaved(int repeats,
                                                   const std::vector<std::function<void()>>& fns) {
    std::vector<std::vector<double>> samples(fns.size());
    for (int r = 0; r < repeats; ++r)
        for (size_t i = 0; i < fns.size(); ++i) {
            Stopwatch watch;
            fns[i]();
            samples[i].push_back(watch.seconds());
        }
    return samples;
}

std::vector<Timing> measureInterleaved(int repeats, const std::vector<std::function<void()>>& fns) {
    std::vector<Timing> out;
    for (auto& s : sampleInterleaved(repeats, fns)) out.push_back(summarize(s));
    return out;
}

void measureLab(const Scene& scene, LabBvhMesh* mesh, const LabOptions& o, Report& report) {
    Mesh bunny;
    std::unique_ptr<LabBvhMesh> bunnyMesh;
    if (!mesh) {
        bunny = loadObj(o.dataDir + "/meshes/bunny.obj");
        bunnyMesh = std::make_unique<LabBvhMesh>(bunny, 0);
        mesh = bunnyMesh.get();
    }
    auto step = [&](const char* what, auto&& f) {
        std::cerr << "05_efficiency: " << what << "...\n";
        report.add(f());
    };
    step("measuring the measurement", [&] { return measureMeasuring(o); });
    step("float against double", [&] { return measureFloatDouble(o); });
    step("acne", [&] { return measureAcne(o); });
    step("sine tables", [&] { return measureSinCos(o); });
    step("early out", [&] { return measureEarlyOut(*mesh, o); });
    step("finite light radius", [&] { return measureLightRadius(o); });
    step("effects on demand", [&] { return measureEffects(o); });
    step("effects on demand, part by part", [&] { return measureEffectParts(o); });
    step("effects on demand at the run's size", [&] { return measureEffectIdentity(o); });
    step("precalculation", [&] { return measurePrecalculation(*mesh, o); });
    step("expensive operations", [&] { return measureExpensiveOps(o); });
    step("reciprocal square root", [&] { return measureInverseSqrt(o); });
    step("the cost of one operation", [&] { return measureOpCost(o); });
    step("compiler flags, float and double", [&] { return measureLanguage(o); });
    step("threads", [&] { return measureThreads(scene, o); });
    step("anti-aliasing", [&] { return measureAntiAliasing(scene, o); });
    step("previews", [&] { return measurePreviews(scene, o); });
    step("all together", [&] { return measureTotalSpeedup(scene, o); });
    const Table& total = report.tables.back();
    report.facts["total_speedup"] = std::get<double>(total.rows.back()[4]);
    auto plot = [&](const char* table, const char* x, const char* y, const char* series,
                    const char* title, bool logx, bool logy, bool lines = false,
                    bool pareto = false) {
        report.plots.push_back({{"table", table},
                                {"x", x},
                                {"y", y},
                                {"series", series},
                                {"title", title},
                                {"logx", logx},
                                {"logy", logy},
                                {"lines", lines},
                                {"pareto", pareto}});
    };
    // The step's picture: the preview modes, error against time, the Pareto front drawn.
    plot("previews", "ms/frame", "RMSE against full", "mode",
         "Preview modes: error against time per frame; the Pareto front joins the modes no "
         "other beats on both",
         false, false, false, true);
    plot("float_double", "offset", "max rel t error", "variant",
         "Float against double: the largest relative error in t as the scene moves away from the "
         "origin",
         true, true, true);
    plot("float_double", "ns/test", "max rel t error", "variant",
         "Float against double: time per test against the error in t", false, true);
    report.plots.back()["point_label"] = "offset";  // each point one distance from the origin
    plot("sincos", "ns/call", "max abs error", "variant",
         "Sine: time per call against the largest error over the circle", false, true);
    plot("op_cost", "ns/op", "max rel error", "type",
         "The cost of one operation: ns per operation against its relative error, float and "
         "double",
         true, true);
    plot("language", "ns/ray", "max rel t error", "type",
         "One kernel under different compiler flags: time per ray against the error in t "
         "(against double -O2; 0: the same bits)",
         true, false);
    plot("antialiasing", "ms/frame", "RMSE", "",
         "Anti-aliasing: error against time for 1, 4, 16, 64 samples per pixel", true, true, true);
    plot("threads", "threads", "speed-up", "schedule", "Threads: speed-up over one thread", false,
         false, true);
    plot("precalc", "ms/frame", "triangle tests/pixel", "variant",
         "Precalculation and early out: time per frame against the work per pixel", false, false);
    plot("rsqrt", "ns/call", "max relative error", "variant",
         "Reciprocal square root: time against error", false, true);
    plot("total", "ms/frame", "max 8-bit error", "variant",
         "All together: time per frame of the default scene against the largest change of the "
         "PNG from the naive render",
         false, false, false, true);
}

namespace {

// The preview's file name suffix, e.g. "depth-material".
// One case per value and no default: -Wswitch names a value added without its name.
std::string slug(PreviewMode m) {
    switch (m) {
        case PreviewMode::Depth:
            return "depth";
        case PreviewMode::DepthMaterial:
            return "depth-material";
        case PreviewMode::NoRecursion:
            return "no-recursion";
        case PreviewMode::LimitedRecursion:
            return "limited-recursion";
        case PreviewMode::HalfResolution:
            return "half-resolution";
        case PreviewMode::Adaptive:
            return "adaptive";
        case PreviewMode::Full:
            return "full";
    }
    return "?";
}

}  // namespace

void writePreviews(const StepRun& run, double budgetMs, Report& report) {
    const Scene& scene = run.scene;
    const RenderSettings& settings = run.settings;
    // The same image line by line, as the window refines it: must be bit-identical.
    Renderer renderer(scene, scene.camera, settings);
    RayCounts lineCounts;
    IncrementalRenderer incremental(
        settings.width, settings.height,
        [&](Image& img, int row) { renderer.renderRows(img, row, row + 1, lineCounts); },
        steadyClock());
    int frames = 0;
    while (!incremental.complete()) incremental.advance(budgetMs * 1e-3), ++frames;
    bool identical = compareImages(incremental.image(), run.image).maxError == 0.0;
    for (PreviewMode m : kAllPreviewModes) {
        if (m == PreviewMode::Full) continue;
        std::string path = pngWithSuffix(run.png, "-" + slug(m));
        renderPreview(scene, scene.camera, m, settings, 0.25f).writePng(path);
        report.images.push_back({path, std::string("preview: ") + previewModeName(m)});
    }
    report.facts["refinement_frames"] = frames;
    report.facts["refinement_budget_ms"] = budgetMs;
    report.facts["refined_image_bit_identical"] = identical;
    std::cerr << "05_efficiency: wrote " << report.images.size() - 1
              << " previews; refined line by line in " << frames << " frames of " << budgetMs
              << " ms: " << (identical ? "bit-identical" : "NOT identical")
              << " to the direct render\n";
    if (!identical) throw std::runtime_error("the refined image differs from the direct render");
}

}  // namespace boxes
