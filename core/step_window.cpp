// The window half of the step shell: the step's view of the orbiting camera, made again
// beside the window when the camera moved or a step key was used (or every frame, for a
// step with its own frame hook), with the step's keys and panel.
#include <imgui.h>

#include <algorithm>
#include <sstream>

#include "core/orbit.hpp"
#include "core/step.hpp"
#include "core/view_render.hpp"

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
    // The view is made beside the window, coarse first (core/view_render.hpp), so the window
    // answers at once. The step's hooks never run while it is made: a key or a move of the
    // camera stops it first (within a row), and a new one starts after the hook.
    ViewRender view;
    RenderSettings target = run.settings;  // the full size; the passes render smaller first
    auto stopView = [&] {
        view.stop();
        run.settings = target;
    };
    WindowCallbacks cb;
    cb.keys = program.keys;
    cb.onKey = [&](int key) {
        // Only the keys the step lists are its: Escape quits without waiting for the view.
        bool listed = std::any_of(program.keys.begin(), program.keys.end(),
                                  [&](const KeyBinding& k) { return k.key == key; });
        if (!program.onKey || !listed) return false;
        stopView();
        bool used = program.onKey(run, key);
        target = run.settings;
        // Also when the step did not use the key: the stopped view starts again.
        dirty = true;
        return used;
    };
    orbit.addTo(cb, [&] {
        stopView();
        run.camera = orbit.camera();
        dirty = moved = true;
    });
    const int scriptedFrames = run.options.frames;
    int frameCount = 0;
    cb.frame = [&](double) -> const Image& {
        ++frameCount;
        if (program.frame) {  // a view that refines itself, frame by frame (step 05)
            bool cameraMoved = moved;
            moved = false;
            return program.frame(run, cameraMoved);
        }
        if (dirty) {
            dirty = false;
            view.start(
                [&](const RenderSettings& settings) {
                    run.settings = settings;
                    return program.render ? program.render(run)
                                          : renderImage(run.scene, run.camera, run.settings);
                },
                target);
        }
        // A scripted run's last frame shows the finished view (its screenshot is compared).
        if (scriptedFrames > 0 && frameCount >= scriptedFrames) view.finish();
        if (view.take(image) && view.complete()) run.renderMs = view.fullMs();
        return image;
    };
    cb.progress = [&] { return view.progress(); };
    // The step's lines read what its hooks wrote: shown once the view is made.
    if (program.panel)
        cb.panel = [&] {
            if (view.busy())
                ImGui::TextUnformatted("(the step's figures once the view is made)");
            else
                program.panel(run);
        };
    cb.onClose = stopView;
    runWindow(windowOptions(run.options, program.title), cb);
    return 0;
}

}  // namespace boxes
