// The step shell. A step program describes itself in a StepProgram (its name, its flags,
// its scene and geometry, what it measures, its keys and panel) and hands it to runStep,
// which does the rest the same way for every step: the command line (core/app.hpp), then
// either the headless image, the measurements of --measure and the report (core/step.cpp),
// or the window (core/step_window.cpp). runStep reads from top to bottom as the main of
// every step program.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/app.hpp"
#include "core/render.hpp"
#include "core/report.hpp"
#include "core/scene.hpp"
#include "core/window.hpp"

namespace boxes {

// What runStep made from the command line. Every hook of the step gets it.
struct StepRun {
    CommonOptions options;    // the flags every step has (core/app.hpp)
    bool measure = false;     // --measure: the step's measurements after the image
    Scene scene;              // the scene, with the step's geometry
    RenderSettings settings;  // --width --height --threads --seed
    Camera camera;            // the view: the scene's headless, the orbiting one in the window
    // Headless: the PNG written, its pixels, and (when ray traced) its ray counts.
    std::string png;
    Image image;
    RayCounts counts;
    // Window: how long the last render hook took.
    double renderMs = 0.0;
};

// A step program. Only name, description, title and defaultScene are needed; every hook
// left empty does the default named beside it. The hooks are listed in the order runStep
// calls them.
struct StepProgram {
    std::string name;          // e.g. "01_triangle": prefixes errors, names the default PNG
    std::string description;   // the first line of --help
    std::string title;         // the window's title
    std::string defaultScene;  // --scene when the flag is not given
    std::string measures = "the step's measurements";  // what --measure adds, for --help

    // ---- The command line and the scene ------------------------------------------------
    // The step's own flags, added after the common ones (default: none).
    std::function<void(CLI::App& app)> addOptions;
    // Runs a subcommand instead of the image: its exit code, or nullopt to go on.
    std::function<std::optional<int>()> command;
    // The scene, camera flags applied (default: sceneFromOptions).
    std::function<Scene(const CommonOptions&)> makeScene;
    // Adds the step's geometry to run.scene, and builds what else the step needs from it.
    // run.scene stays where it is from here on, so a geometry may keep a reference to its
    // mesh.
    std::function<void(StepRun&)> addGeometry;

    // ---- Headless (--headless): the image, then the report -----------------------------
    // The image's caption in the report (default: the scene's name).
    std::function<std::string(const StepRun&)> caption;
    // The step's own image of run.camera's view (default: the scene ray traced from its
    // camera, timed and its rays counted in the report as render_ms and rays).
    std::function<Image(StepRun&)> draw;
    // After the PNG, in every headless run: the step's facts and other files.
    std::function<void(StepRun&, Report&)> afterImage;
    // With --measure only: the step's measurements, tables and their files.
    std::function<void(StepRun&, Report&)> measure;

    // ---- The window: the step's view, the camera orbiting (core/orbit.hpp) --------------
    std::vector<KeyBinding> keys;  // listed on screen, before the orbit's keys
    // A key was pressed: true when the step used it (the view is then rendered again).
    std::function<bool(StepRun&, int key)> onKey;
    // Before the window opens: may change run.settings and run.scene.camera, where the
    // orbit starts.
    std::function<void(StepRun&)> openWindow;
    // The image of run.camera's view, called when the camera moved or a key was used
    // (default: the scene ray traced, renderImage).
    std::function<Image(StepRun&)> render;
    // Instead of render, for a view that changes by itself (a refinement): called every
    // frame; `moved` says the camera moved since the last call (true on the first).
    std::function<const Image&(StepRun&, bool moved)> frame;
    // The step's lines on the panel, under the keys.
    std::function<void(StepRun&)> panel;
};

// Runs the step program: parses the command line (the common flags, --measure, then the
// step's), makes the scene and the step's geometry, then writes the headless image and the
// report, or opens the window. Returns the exit code (runMain's, core/app.hpp).
int runStep(int argc, char** argv, const StepProgram& program);

// The window half of runStep (core/step_window.cpp): the step's view of an orbiting camera.
int runStepWindow(const StepProgram& program, StepRun& run);

}  // namespace boxes
