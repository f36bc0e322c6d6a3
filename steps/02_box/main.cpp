// Step 02: a scene of boxes, axis-aligned and rotated, intersected as six planes (the
// lecture's way) or with the slab method; measures both and counts where they disagree.
#include <SDL2/SDL_keycode.h>
#include <imgui.h>

#include "02_box/box_scene.hpp"
#include "02_box/measure.hpp"
#include "core/render.hpp"
#include "core/step.hpp"

using namespace boxes;

int main(int argc, char** argv) {
    std::string methodName = "slabs";
    size_t raysPerBox = 1000;
    BoxMethod method = BoxMethod::Slabs;
    std::vector<SceneBox> boxList;
    std::shared_ptr<BoxSet> set;  // every box of the scene, through the selected method

    // What the step is, for the shell (core/step.hpp): every main fills the same fields,
    // then adds its own flags, tables and keys.
    StepProgram step;
    step.name = "02_box";
    step.description =
        "Step 02: boxes as six planes (the lecture's way) and the slab method, side by side.";
    step.title = "Step 02: boxes";
    step.defaultScene = "boxes";
    step.measures = "both methods";
    step.addOptions = [&](CLI::App& app) {
        app.get_option("--scene")->description(
            "'boxes' (this step's scene), or a core scene / OBJ file drawn as boxes (each sphere "
            "as its cube, a mesh as its bounding box)");
        app.add_option("--method", methodName, "the ray/box test to render with")
            ->check(CLI::IsMember({"planes", "slabs"}))
            ->capture_default_str();
        app.add_option("--rays-per-box", raysPerBox, "measurement rays per random box (64 boxes)")
            ->check(CLI::Range(size_t(10), size_t(100000)));
    };
    // This step's scene, or any other one with its spheres and mesh turned into boxes.
    step.makeScene = [&](const CommonOptions& o) {
        if (o.scene != "boxes") {
            Scene scene = sceneFromOptions(o);
            boxList = boxesFromScene(scene);
            return scene;
        }
        Scene scene = makeBoxScene(o.aspect());
        scene.camera = cameraFromOptions(o, scene.camera);
        boxList = boxStepBoxes();
        return scene;
    };
    step.addGeometry = [&](StepRun& run) {
        method = methodName == "planes" ? BoxMethod::SixPlanes : BoxMethod::Slabs;
        set = std::make_shared<BoxSet>(boxList, method);
        run.scene.geometries.push_back(set);
    };
    step.caption = [&](const StepRun& run) {
        return "scene '" + run.scene.name + "' (" + std::to_string(boxList.size()) +
               " boxes) with the " + boxMethodName(method) + " method";
    };
    step.measure = [&](StepRun& run, Report& report) {
        measureBoxTests(run, *set, raysPerBox, report);
    };

    // The window: M switches the method, D marks where the two disagree.
    bool marks = false;
    PixelComparison pixels;
    step.keys = {{SDLK_m, "switch method: six planes / slabs"},
                 {SDLK_d, "mark pixels where the two methods disagree (magenta)"}};
    step.onKey = [&](StepRun&, int key) {
        if (key == SDLK_m)
            method = method == BoxMethod::Slabs ? BoxMethod::SixPlanes : BoxMethod::Slabs;
        if (key == SDLK_d) marks = !marks;
        if (key == SDLK_d && marks) set->setMethod(BoxMethod::SixPlanes);  // its planes ready
        return key == SDLK_m || key == SDLK_d;
    };
    step.render = [&](StepRun& run) {
        set->setMethod(method);
        Image image = renderImage(run.scene, run.camera, run.settings);
        if (marks) pixels = markDisagreements(*set, run.camera, image, run.options.threads);
        return image;
    };
    step.panel = [&](StepRun& run) {
        ImGui::Text("method: %s", boxMethodName(method));
        ImGui::Text("render: %.1f ms (%dx%d, %zu boxes)", run.renderMs, run.settings.width,
                    run.settings.height, boxList.size());
        if (marks) ImGui::Text("pixels where the methods disagree: %lld", pixels.differ);
    };
    return runStep(argc, argv, step);
}
