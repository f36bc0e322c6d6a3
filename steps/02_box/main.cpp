// Step 02: a scene of boxes, axis-aligned and rotated, intersected as six planes (the
// lecture's way) or with the slab method; measures both and counts where they disagree.
#include <SDL2/SDL_keycode.h>
#include <imgui.h>

#include <iostream>

#include "02_box/box_scene.hpp"
#include "core/app.hpp"
#include "core/orbit.hpp"
#include "core/render.hpp"
#include "core/timing.hpp"

using namespace boxes;

namespace {

// Pixels whose primary ray finds another box, face or hit/miss with the other method
// (magenta), and the largest relative difference in t where both agree.
struct PixelComparison {
    long long pixels = 0, differ = 0;
    double maxRelativeT = 0.0;
};
PixelComparison markDisagreements(const BoxSet& set, const Camera& camera, Image& image,
                                  int threads) {
    std::vector<long long> perRow(size_t(image.height()), 0);
    std::vector<double> maxT(size_t(image.height()), 0.0);
    CameraBasisT<float> basis = camera.basis();
    parallelRows(image.height(), threads, [&](int y, int) {
        for (int x = 0; x < image.width(); ++x) {
            Ray ray(camera.eye, camera.directionThrough(basis, x + 0.5f, y + 0.5f, image.width(),
                                                        image.height()));
            BoxSet::Nearest a = set.nearest(ray, BoxMethod::SixPlanes);
            BoxSet::Nearest b = set.nearest(ray, BoxMethod::Slabs);
            bool tie = a.box >= 0 && b.box >= 0 &&
                       std::abs(a.hit.t - b.hit.t) <= 1e-5f * std::max(1.0f, std::abs(b.hit.t));
            if (a.box != b.box || (a.box >= 0 && a.hit.face != b.hit.face && !tie)) {
                image.at(x, y) = Vec3(1.0f, 0.0f, 1.0f);
                ++perRow[size_t(y)];
            } else if (a.box >= 0) {
                double rel = std::abs(double(a.hit.t) - double(b.hit.t)) /
                             std::max(1e-30, double(std::abs(b.hit.t)));
                maxT[size_t(y)] = std::max(maxT[size_t(y)], rel);
            }
        }
    });
    PixelComparison c;
    c.pixels = (long long)image.width() * image.height();
    for (size_t y = 0; y < perRow.size(); ++y) {
        c.differ += perRow[y];
        c.maxRelativeT = std::max(c.maxRelativeT, maxT[y]);
    }
    return c;
}

}  // namespace

int main(int argc, char** argv) {
    return runMain("02_box", [&] {
        CLI::App app{
            "Step 02: boxes as six planes (the lecture's way) and the slab method, side by side."};
        CommonOptions opts;
        addCommonOptions(app, opts, "boxes");
        app.get_option("--scene")->description(
            "'boxes' (this step's scene), or a core scene / OBJ file drawn as boxes (each sphere "
            "as its cube, a mesh as its bounding box)");
        std::string methodName = "slabs";
        app.add_option("--method", methodName, "the ray/box test to render with")
            ->check(CLI::IsMember({"planes", "slabs"}))
            ->capture_default_str();
        bool measure = false;
        app.add_flag("--measure", measure, "also measure both methods and print the tables");
        size_t raysPerBox = 1000;
        app.add_option("--rays-per-box", raysPerBox, "measurement rays per random box (64 boxes)")
            ->check(CLI::Range(size_t(10), size_t(100000)));
        parseCommandLine(app, argc, argv);

        Scene scene;
        std::vector<SceneBox> boxList;
        if (opts.scene == "boxes") {
            scene = makeBoxScene(opts.aspect());
            scene.camera = cameraFromOptions(opts, scene.camera);
            boxList = boxStepBoxes();
        } else {
            scene = sceneFromOptions(opts);
            boxList = boxesFromScene(scene);
        }
        BoxMethod method = methodName == "planes" ? BoxMethod::SixPlanes : BoxMethod::Slabs;
        auto set = std::make_shared<BoxSet>(boxList, method);
        scene.geometries.push_back(set);
        RenderSettings settings = opts.renderSettings();

        if (opts.headless) {
            Report report;
            report.program = "02_box";
            std::string out = headlessPath(opts, report.program);
            Image image = renderHeadlessImage(
                scene, scene.camera, settings, out,
                "scene '" + scene.name + "' (" + std::to_string(boxList.size()) +
                    " boxes) with the " + boxMethodName(method) + " method",
                report);
            if (measure) {
                set->setMethod(BoxMethod::SixPlanes);  // both methods' data ready
                set->setMethod(method);
                Image marked = image;
                PixelComparison pixels =
                    markDisagreements(*set, scene.camera, marked, opts.threads);
                std::string disagreePath = pngWithSuffix(out, "-disagree");
                marked.writePng(disagreePath);
                report.images.push_back(
                    {disagreePath,
                     "magenta: pixels where six planes and slabs see another box or face"});
                std::cerr << "02_box: measuring both methods...\n";
                BoxRaySet rays = makeBoxRays(64, raysPerBox, opts.seed);
                for (Table& t : measureBoxMethods(rays, 11)) report.add(std::move(t));
                Disagreement d = compareMethods(rays);
                Table dis;
                dis.id = "method_disagreement";
                dis.title = "Where six planes and slabs disagree (both in float)";
                dis.columns = {"rays", "count", "hit/miss differ", "face differs",
                               "max rel t difference"};
                dis.note =
                    "a face counts only when the t differ too (on an edge both faces are right); "
                    "t compared where both hit";
                dis.row({std::string("random rays at oriented boxes"), d.rays, d.hitMiss, d.face,
                         d.maxRelativeT});
                dis.row({std::string("primary rays of the image"), pixels.pixels, pixels.differ,
                         0LL, pixels.maxRelativeT});
                report.add(dis);
                report.facts["pixels_disagreeing"] = pixels.differ;
                report.plots.push_back(
                    {{"table", "box_accuracy"},
                     {"x", "ns/test"},
                     {"y", "wrong hit/miss"},
                     {"series", "variant"},
                     {"logy", true},
                     {"title",
                      "Six planes against slabs: time per test and wrong hit/miss answers"}});
                report.plots.push_back(
                    {{"table", "box_accuracy"},
                     {"x", "ns/test"},
                     {"y", "max rel t error"},
                     {"series", "variant"},
                     {"logy", true},
                     {"title", "Six planes against slabs: time per test and the error of t"}});
            }
            writeReport(report, opts);
            return 0;
        }

        OrbitController orbit(scene.camera);
        bool marks = false, dirty = true;
        Image image;
        double renderMs = 0.0;
        PixelComparison pixels;
        WindowCallbacks cb;
        cb.keys = {{SDLK_m, "switch method: six planes / slabs"},
                   {SDLK_d, "mark pixels where the two methods disagree (magenta)"}};
        cb.onKey = [&](int key) {
            if (key == SDLK_m) {
                method = method == BoxMethod::Slabs ? BoxMethod::SixPlanes : BoxMethod::Slabs;
                return dirty = true;
            }
            if (key == SDLK_d) {
                marks = !marks;
                if (marks) set->setMethod(BoxMethod::SixPlanes);
                return dirty = true;
            }
            return false;
        };
        orbit.addTo(cb, [&] { dirty = true; });
        cb.frame = [&](double) -> const Image& {
            if (dirty) {
                set->setMethod(method);
                Stopwatch watch;
                image = renderImage(scene, orbit.camera(), settings);
                renderMs = watch.milliseconds();
                if (marks) pixels = markDisagreements(*set, orbit.camera(), image, opts.threads);
                dirty = false;
            }
            return image;
        };
        cb.panel = [&] {
            ImGui::Text("method: %s", boxMethodName(method));
            ImGui::Text("render: %.1f ms (%dx%d, %zu boxes)", renderMs, settings.width,
                        settings.height, boxList.size());
            if (marks) ImGui::Text("pixels where the methods disagree: %lld", pixels.differ);
        };
        runWindow(opts.windowOptions("Step 02: boxes"), cb);
        return 0;
    });
}
