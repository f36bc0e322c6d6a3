// Step 05: efficiency. The optimization lab (--measure prints every trade-off as time
// against error) and perceived performance in the window: previews while the camera
// moves, line-by-line refinement within a frame budget when it stops, a photograph mode.
#include <memory>

#include "05_efficiency/bvh_mesh.hpp"
#include "05_efficiency/measure.hpp"
#include "05_efficiency/viewer.hpp"
#include "core/step.hpp"

using namespace boxes;

int main(int argc, char** argv) {
    bool noPreviews = false, quick = false;
    int repeats = 5;
    ViewerOptions view;
    std::shared_ptr<LabBvhMesh> mesh;  // the scene's mesh, if any
    std::unique_ptr<ProgressiveViewer> viewer;

    // What the step is, for the shell (core/step.hpp): every main fills the same fields,
    // then adds its own flags, tables and keys.
    StepProgram step;
    step.name = "05_efficiency";
    step.description =
        "Step 05: efficiency: the optimization lab as accuracy-against-time tables, effects on "
        "demand, and perceived performance (previews, refinement, photograph mode).";
    step.title = "Step 05: efficiency";
    step.defaultScene = "spheres";
    step.measures = "the lab";
    step.addOptions = [&](CLI::App& app) {
        app.add_option("--repeats", repeats, "timed repeats per variant in the lab")
            ->check(CLI::Range(1, 101))
            ->capture_default_str();
        app.add_option("--budget-ms", view.budgetMs, "refinement time budget per frame (window)")
            ->check(CLI::Range(1.0, 1000.0))
            ->capture_default_str();
        app.add_flag("--no-previews", noPreviews,
                     "headless: only the full render (no preview PNGs, no line-by-line check); for "
                     "profiling one render");
        app.add_flag("--quick", quick, "a quick lab: smaller images and fewer samples (for tests)");
        app.add_option("--photo-spp", view.photoSpp, "photograph mode: samples per pixel")
            ->check(CLI::Range(1, 1024))
            ->capture_default_str();
        app.add_option("--photo-depth", view.photoDepth, "photograph mode: maximum recursion depth")
            ->check(CLI::Range(0, 64))
            ->capture_default_str();
    };
    // Meshes through step 04's hierarchy (see bvh_mesh.hpp), every optimization on.
    step.addGeometry = [&](StepRun& run) {
        if (!run.scene.hasMesh()) return;
        mesh = std::make_shared<LabBvhMesh>(run.scene.mesh, run.scene.meshMaterial);
        run.scene.geometries.push_back(mesh);
    };
    step.caption = [&](const StepRun& run) {
        return "scene '" + run.scene.name + "', full render";
    };
    step.afterImage = [&](StepRun& run, Report& report) {
        if (!noPreviews) writePreviews(run, view.budgetMs, report);
    };
    step.measure = [&](StepRun& run, Report& report) {
        LabOptions lab;
        lab.repeats = repeats;
        lab.threads = run.options.threads;
        lab.seed = run.options.seed;
        lab.dataDir = run.options.dataDir;
        lab.quick = quick;
        lab.width = run.settings.width;
        lab.height = run.settings.height;
        measureLab(run.scene, mesh.get(), lab, report);
    };

    // The window: previews, refinement and photographs (viewer.hpp).
    step.openWindow = [&](StepRun& run) {
        viewer = std::make_unique<ProgressiveViewer>(run.scene, run.settings, view);
    };
    step.keys = ProgressiveViewer::keys();
    step.onKey = [&](StepRun& run, int key) { return viewer->onKey(key, run.camera); };
    step.frame = [&](StepRun& run, bool moved) -> const Image& {
        return viewer->frame(run.camera, moved);
    };
    step.panel = [&](StepRun&) { viewer->panel(); };
    return runStep(argc, argv, step);
}
