// Step 05: efficiency. The optimization lab (--measure prints every trade-off as time
// against error) and perceived performance in the window: previews while the camera
// moves, line-by-line refinement within a frame budget when it stops, a photograph mode.
#include <SDL2/SDL_keycode.h>
#include <imgui.h>

#include <cstdio>
#include <iostream>
#include <memory>

#include "05_efficiency/bvh_mesh.hpp"
#include "05_efficiency/measure.hpp"
#include "05_efficiency/progressive.hpp"
#include "core/app.hpp"
#include "core/orbit.hpp"
#include "core/render.hpp"
#include "core/timing.hpp"

using namespace boxes;

namespace {

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
        default:
            return "full";
    }
}

// What the optimizations bought on this scene: the naive renderer (every effect traced,
// lights without a radius, one thread) against the optimized one, step by step.
Table totalSpeedup(const Scene& scene, int repeats, bool quick) {
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
        s.width = quick ? 40 : 160;
        s.height = quick ? 30 : 120;
        s.threads = v.threads;
        s.forceAllEffects = v.force;
        renderers.push_back(std::make_unique<Renderer>(*v.scene, v.scene->camera, s));
        frames.push_back([r = renderers.back().get()] { keepValue(r->render()); });
    }
    std::vector<Timing> times = measureInterleaved(repeats, frames);
    for (size_t i = 0; i < variants.size(); ++i)
        t.row({std::string(variants[i].name), times[i].median * 1e3, times[i].min * 1e3,
               times[i].max * 1e3, times[0].median / times[i].median});
    return t;
}

}  // namespace

int main(int argc, char** argv) {
    return runMain("05_efficiency", [&] {
        CLI::App app{
            "Step 05: efficiency: the optimization lab as accuracy-against-time tables, effects on "
            "demand, and perceived performance (previews, refinement, photograph mode)."};
        CommonOptions opts;
        addCommonOptions(app, opts, "spheres");
        bool measure = false;
        app.add_flag("--measure", measure, "also run the lab and print its tables");
        int repeats = 5;
        app.add_option("--repeats", repeats, "timed repeats per variant in the lab")
            ->check(CLI::Range(1, 101))
            ->capture_default_str();
        double budgetMs = 15.0;
        app.add_option("--budget-ms", budgetMs, "refinement time budget per frame (window)")
            ->check(CLI::Range(1.0, 1000.0))
            ->capture_default_str();
        bool noPreviews = false;
        app.add_flag("--no-previews", noPreviews,
                     "headless: only the full render (no preview PNGs, no line-by-line check); for "
                     "profiling one render");
        bool quick = false;
        app.add_flag("--quick", quick, "a quick lab: smaller images and fewer samples (for tests)");
        int photoSpp = 16, photoDepth = 12;
        app.add_option("--photo-spp", photoSpp, "photograph mode: samples per pixel")
            ->check(CLI::Range(1, 1024))
            ->capture_default_str();
        app.add_option("--photo-depth", photoDepth, "photograph mode: maximum recursion depth")
            ->check(CLI::Range(0, 64))
            ->capture_default_str();
        parseCommandLine(app, argc, argv);

        Scene scene = sceneFromOptions(opts);
        // Meshes through step 04's hierarchy (see bvh_mesh.hpp), every optimization on.
        std::shared_ptr<LabBvhMesh> sceneMesh;
        if (scene.hasMesh()) {
            sceneMesh = std::make_shared<LabBvhMesh>(scene.mesh, scene.meshMaterial);
            scene.geometries.push_back(sceneMesh);
        }
        Camera camera = cameraFromOptions(opts, scene.camera);
        scene.camera = camera;
        RenderSettings settings = opts.renderSettings();

        if (opts.headless) {
            Report report;
            report.program = "05_efficiency";
            std::string out = headlessPath(opts, report.program);
            Image image = renderHeadlessImage(scene, camera, settings, out,
                                              "scene '" + scene.name + "', full render", report);
            if (!noPreviews) {
                // The same image line by line, as the window refines it: must be bit-identical.
                Renderer renderer(scene, camera, settings);
                RayCounts lineCounts;
                IncrementalRenderer incremental(
                    settings.width, settings.height,
                    [&](Image& img, int row) {
                        renderer.renderRows(img, row, row + 1, lineCounts);
                    },
                    steadyClock());
                int frames = 0;
                while (!incremental.complete()) incremental.advance(budgetMs * 1e-3), ++frames;
                bool identical = compareImages(incremental.image(), image).maxError == 0.0;
                for (PreviewMode m : kAllPreviewModes) {
                    if (m == PreviewMode::Full) continue;
                    std::string path = pngWithSuffix(out, "-" + slug(m));
                    renderPreview(scene, camera, m, settings, 0.25f).writePng(path);
                    report.images.push_back({path, std::string("preview: ") + previewModeName(m)});
                }
                report.facts["refinement_frames"] = frames;
                report.facts["refinement_budget_ms"] = budgetMs;
                report.facts["refined_image_bit_identical"] = identical;
                std::cerr << "05_efficiency: wrote " << report.images.size() - 1
                          << " previews; refined line by line in " << frames << " frames of "
                          << budgetMs << " ms: " << (identical ? "bit-identical" : "NOT identical")
                          << " to the direct render\n";
                if (!identical)
                    throw std::runtime_error("the refined image differs from the direct render");
            }
            if (measure) {
                LabOptions lab;
                lab.repeats = repeats;
                lab.threads = opts.threads;
                lab.seed = opts.seed;
                lab.dataDir = opts.dataDir;
                lab.quick = quick;
                // The mesh tables use the scene's mesh, else the bunny, in step 04's tree.
                Mesh bunny;
                std::shared_ptr<LabBvhMesh> labMesh = sceneMesh;
                if (!labMesh) {
                    bunny = loadObj(opts.dataDir + "/meshes/bunny.obj");
                    labMesh = std::make_shared<LabBvhMesh>(bunny, 0);
                }
                auto step = [&](const char* what, auto&& f) {
                    std::cerr << "05_efficiency: " << what << "...\n";
                    report.add(f());
                };
                step("measuring the measurement", [&] { return measureMeasuring(lab); });
                step("float against double", [&] { return measureFloatDouble(lab); });
                step("acne", [&] { return measureAcne(lab); });
                step("sine tables", [&] { return measureSinCos(lab); });
                step("early out", [&] { return measureEarlyOut(*labMesh, lab); });
                step("finite light radius", [&] { return measureLightRadius(lab); });
                step("effects on demand", [&] { return measureEffects(lab); });
                step("precalculation", [&] { return measurePrecalculation(*labMesh, lab); });
                step("expensive operations", [&] { return measureExpensiveOps(lab); });
                step("reciprocal square root", [&] { return measureInverseSqrt(lab); });
                step("threads", [&] { return measureThreads(scene, lab); });
                step("anti-aliasing", [&] { return measureAntiAliasing(scene, lab); });
                step("previews", [&] { return measurePreviews(scene, lab); });
                step("all together", [&] { return totalSpeedup(scene, repeats, quick); });
                const Table& total = report.tables.back();
                report.facts["total_speedup"] = std::get<double>(total.rows.back().back());
                auto plot = [&](const char* table, const char* x, const char* y, const char* series,
                                const char* title, bool logx, bool logy, bool lines = false) {
                    report.plots.push_back({{"table", table},
                                            {"x", x},
                                            {"y", y},
                                            {"series", series},
                                            {"title", title},
                                            {"logx", logx},
                                            {"logy", logy},
                                            {"lines", lines}});
                };
                plot("float_double", "offset", "max rel t error", "variant",
                     "Float against double: the largest relative error in t as the scene moves "
                     "away from the origin",
                     true, true, true);
                plot("float_double", "ns/test", "max rel t error", "variant",
                     "Float against double: time per test against the error in t", false, true);
                plot("sincos", "ns/call", "max abs error", "variant",
                     "Sine: time per call against the largest error over the circle", false, true);
                plot("antialiasing", "ms/frame", "RMSE", "",
                     "Anti-aliasing: error against time for 1, 4, 16, 64 samples per pixel", true,
                     true, true);
                plot("threads", "threads", "speed-up", "schedule",
                     "Threads: speed-up over one thread", false, false, true);
                plot("precalc", "ms/frame", "triangle tests/pixel", "variant",
                     "Precalculation and early out: time per frame against the work per pixel",
                     false, false);
                plot("rsqrt", "ns/call", "max relative error", "variant",
                     "Reciprocal square root: time against error", false, true);
                plot("previews", "ms/frame", "RMSE against full", "mode",
                     "Preview modes: time per frame against the error of the preview", false,
                     false);
                plot("total", "ms/frame", "ratio to naive", "variant",
                     "All together: time per frame of the default scene", false, false);
            }
            writeReport(report, opts);
            return 0;
        }

        // ---- The window ---------------------------------------------------------------
        OrbitController orbit(camera);
        PreviewMode mode = PreviewMode::Adaptive;
        AdaptiveResolution adaptive(1.0 / 30.0);
        bool moved = true;
        Image preview;
        double previewMs = 0.0;
        std::unique_ptr<Renderer> refiner;  // full recursion, for the current camera
        Clock clock = steadyClock();
        IncrementalRenderer refinement(
            settings.width, settings.height,
            [&](Image& img, int row) {
                RayCounts c;
                refiner->renderRows(img, row, row + 1, c);
            },
            clock);
        // Photograph mode: deep recursion and stratified samples, also line by line.
        std::unique_ptr<Renderer> photographer;
        std::unique_ptr<IncrementalRenderer> photo;
        Image photoShown;
        int photoIndex = 0;
        std::string photoMessage;
        const double photoBudget = 0.03;

        WindowCallbacks cb;
        cb.keys = {{SDLK_1, "preview while moving: depth map"},
                   {SDLK_2, "preview: depth + material colour"},
                   {SDLK_3, "preview: no recursion"},
                   {SDLK_4, "preview: limited recursion (1 bounce)"},
                   {SDLK_5, "preview: half resolution"},
                   {SDLK_6, "preview: adaptive resolution (30 fps target)"},
                   {SDLK_0, "preview: full render every frame"},
                   {SDLK_p, "photograph: deep recursion, anti-aliasing, saves a PNG"},
                   {SDLK_ESCAPE, "cancel the photograph (quits when none runs)"}};
        cb.onKey = [&](int key) {
            if (photo && key == SDLK_ESCAPE) {
                photo.reset();
                photoShown = Image();
                photoMessage = "photograph cancelled";
                std::cout << "05_efficiency: photograph cancelled" << std::endl;
                return true;
            }
            const std::pair<int, PreviewMode> modes[] = {{SDLK_1, PreviewMode::Depth},
                                                         {SDLK_2, PreviewMode::DepthMaterial},
                                                         {SDLK_3, PreviewMode::NoRecursion},
                                                         {SDLK_4, PreviewMode::LimitedRecursion},
                                                         {SDLK_5, PreviewMode::HalfResolution},
                                                         {SDLK_6, PreviewMode::Adaptive},
                                                         {SDLK_0, PreviewMode::Full}};
            for (auto [k, m] : modes)
                if (key == k) {
                    mode = m;
                    moved = true;
                    return true;
                }
            if (key == SDLK_p) {
                RenderSettings ps = settings;
                ps.samplesPerPixel = photoSpp;
                ps.maxDepth = photoDepth;
                photographer = std::make_unique<Renderer>(scene, orbit.camera(), ps);
                photo = std::make_unique<IncrementalRenderer>(
                    settings.width, settings.height,
                    [&](Image& img, int row) {
                        RayCounts c;
                        photographer->renderRows(img, row, row + 1, c);
                    },
                    clock);
                photo->restart(refinement.image());
                photoMessage.clear();
                return true;
            }
            return false;
        };
        orbit.addTo(cb, [&] {
            photoShown = Image();  // a moved camera leaves the photograph
            moved = true;
        });
        cb.frame = [&](double) -> const Image& {
            if (photo) {
                photo->advance(photoBudget);
                if (!photo->complete()) return photo->image();
                std::string path = "05_efficiency-photo-" + std::to_string(++photoIndex) + ".png";
                photo->image().writePng(path);
                std::cout << "05_efficiency: photograph saved to " << path << std::endl;
                photoMessage = "saved " + path;
                photoShown = photo->image();
                photo.reset();
            }
            if (!photoShown.empty()) return photoShown;
            if (moved) {
                Stopwatch watch;
                preview = renderPreview(scene, orbit.camera(), mode, settings, adaptive.scale());
                previewMs = watch.milliseconds();
                if (mode == PreviewMode::Adaptive) adaptive.update(previewMs * 1e-3);
                refiner = std::make_unique<Renderer>(scene, orbit.camera(), settings);
                refinement.restart(preview);
                moved = false;
                return refinement.image();
            }
            // Stationary: refine with full recursion, at most the budget per frame.
            if (!refinement.complete()) refinement.advance(budgetMs * 1e-3);
            return refinement.image();
        };
        cb.panel = [&] {
            ImGui::Text("preview: %s (%.1f ms)", previewModeName(mode), previewMs);
            if (mode == PreviewMode::Adaptive)
                ImGui::Text("adaptive scale: %.2f", adaptive.scale());
            if (photo) {
                ImGui::Text("photograph: %d spp, depth %d (Esc cancels)", photoSpp, photoDepth);
                ImGui::ProgressBar(float(photo->progress()));
            } else if (refinement.complete()) {
                ImGui::Text("refined: complete (full recursion)");
            } else {
                ImGui::Text("refining: line %d of %d, %.0f ms budget per frame",
                            refinement.linesDone(), settings.height, budgetMs);
                ImGui::ProgressBar(float(refinement.progress()));
            }
            if (!photoMessage.empty()) ImGui::TextUnformatted(photoMessage.c_str());
        };
        runWindow(opts.windowOptions("Step 05: efficiency"), cb);
        return 0;
    });
}
