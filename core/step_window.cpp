// The window half of the step shell: the step's view of the orbiting camera, rendered again
// when the camera moved or a step key was used (or every frame, for a step with its own
// frame hook), with the step's keys and panel.
#include <sstream>

#include "core/orbit.hpp"
#include "core/step.hpp"
#include "core/timing.hpp"

namespace boxes {
namespace {

// The window's title, and the scripted run of --frames, --keys and --screenshot.
WindowOptions windowOptions(const CommonOptions& o, const std::string& title) {
    WindowOptions w;
    w.title = title;
    w.scriptedFrames = o.frames;
    std::stringstream list(o.keys);
    for (std::string key; std::getline(list, key, ',');)
        if (!key.empty()) w.scriptedKeys.push_back(key);
    w.screenshotPath = o.screenshot;
    return w;
}

}  // namespace

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
    runWindow(windowOptions(run.options, program.title), cb);
    return 0;
}

}  // namespace boxes
