#include "core/step.hpp"

#include <chrono>
#include <iostream>

namespace boxes {
namespace {

// The scene ray traced from run.camera (progress on stderr), timed, its rays counted; the
// time and the ray count go into the report as render_ms and rays.
Image rayTrace(const StepProgram& program, StepRun& run, Report& report, double& seconds) {
    RenderSettings settings = run.settings;
    settings.progressLabel = program.name + ": rendering";
    auto start = std::chrono::steady_clock::now();
    Image image = renderImage(run.scene, run.camera, settings, &run.counts);
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    report.facts["render_ms"] = seconds * 1e3;
    report.facts["rays"] = run.counts.total();
    return image;
}

// --headless: the image written to the PNG (--out, else NAME.png), the step's facts and,
// with --measure, its measurements; then the report on stdout (and --report, --json).
int runHeadless(const StepProgram& program, StepRun& run) {
    Report report;
    report.program = program.name;
    run.png = run.options.out.empty() ? program.name + ".png" : run.options.out;
    run.camera = run.scene.camera;
    double seconds = -1.0;
    run.image = program.draw ? program.draw(run) : rayTrace(program, run, report, seconds);
    run.image.writePng(run.png);
    report.images.push_back(
        {run.png, program.caption ? program.caption(run) : "scene '" + run.scene.name + "'"});
    std::cerr << program.name << ": wrote " << run.png << " (" << run.image.width() << "x"
              << run.image.height() << (seconds < 0.0 ? "" : ", " + formatSeconds(seconds))
              << ")\n";
    if (program.afterImage) program.afterImage(run, report);
    if (run.measure && program.measure) program.measure(run, report);
    // With --json the JSON goes to stdout and the tables (and the JSON to --report) to
    // stderr, so stdout stays one JSON document.
    const CommonOptions& o = run.options;
    report.write(o.json ? std::cerr : std::cout, o.json ? "-" : o.reportPath);
    if (o.json && !o.reportPath.empty()) report.write(std::cerr, o.reportPath);
    return 0;
}

}  // namespace

int runStep(int argc, char** argv, const StepProgram& program) {
    return runMain(program.name, [&] {
        StepRun run;
        CLI::App app{program.description};
        addCommonOptions(app, run.options, program.defaultScene);
        app.add_flag("--measure", run.measure,
                     "headless: also run " + program.measures + " and print the tables");
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
