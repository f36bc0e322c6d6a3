#include "core/step.hpp"

#include "core/orbit.hpp"
#include "core/timing.hpp"

namespace boxes {
namespace {

// --headless: the image (ray traced unless the step draws its own), the step's
// measurements, and the report on stdout (and --report, --json).
int runHeadless(const StepProgram& program, StepRun& run) {
    Report report;
    report.program = program.name;
    run.png = headlessPath(run.options, program.name);
    run.camera = run.scene.camera;
    if (program.headlessImage) {
        program.headlessImage(run, report);
    } else {
        std::string caption =
            program.caption ? program.caption(run) : "scene '" + run.scene.name + "'";
        run.image = renderHeadlessImage(run.scene, run.camera, run.settings, run.png, caption,
                                        report, &run.counts);
    }
    if (program.measure) program.measure(run, report);
    writeReport(report, run.options);
    return 0;
}

// The window: the step's view of the orbiting camera, rendered again when it moved or a
// step key was used (or every frame, for a step with its own frame hook).
int runStepWindow(const StepProgram& program, StepRun& run) {
    if (program.openWindow) program.openWindow(run);
    OrbitController orbit(run.scene.camera);
    run.camera = orbit.camera();
    bool dirty = true, moved = true;
    Image image;
    WindowCallbacks cb;
    cb.keys = program.keys;
    cb.onKey = [&](int key) {
        if (!program.onKey || !program.onKey(run, key)) return false;
        return dirty = true;
    };
    orbit.addTo(cb, [&] {
        run.camera = orbit.camera();
        dirty = moved = true;
    });
    cb.frame = [&](double) -> const Image& {
        if (program.frame) {
            bool cameraMoved = moved;
            moved = false;
            return program.frame(run, cameraMoved);
        }
        if (dirty) {
            Stopwatch watch;
            image = program.render ? program.render(run)
                                   : renderImage(run.scene, run.camera, run.settings);
            run.renderMs = watch.milliseconds();
            dirty = false;
        }
        return image;
    };
    if (program.panel) cb.panel = [&] { program.panel(run); };
    runWindow(run.options.windowOptions(program.title), cb);
    return 0;
}

}  // namespace

int runStep(int argc, char** argv, const StepProgram& program) {
    return runMain(program.name, [&] {
        StepRun run;
        CLI::App app{program.description};
        addCommonOptions(app, run.options, program.defaultScene);
        if (program.addOptions) program.addOptions(app);
        parseCommandLine(app, argc, argv);
        if (program.command)
            if (std::optional<int> exitCode = program.command()) return *exitCode;

        run.settings = run.options.renderSettings();
        run.scene =
            program.makeScene ? program.makeScene(run.options) : sceneFromOptions(run.options);
        if (program.addGeometry) program.addGeometry(run);
        return run.options.headless ? runHeadless(program, run) : runStepWindow(program, run);
    });
}

}  // namespace boxes
