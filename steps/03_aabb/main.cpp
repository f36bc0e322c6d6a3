// Step 03: bounding boxes. A scene of thousands of spheres and triangles plus the bunny,
// rendered with and without a box pre-test; the slab tests' speed against their wrong
// answers on hard rays.
#include <SDL2/SDL_keycode.h>
#include <imgui.h>

#include <iostream>

#include "03_aabb/measure.hpp"
#include "core/app.hpp"
#include "core/orbit.hpp"
#include "core/render.hpp"
#include "core/timing.hpp"

using namespace boxes;

int main(int argc, char** argv) {
    return runMain("03_aabb", [&] {
        CLI::App app{
            "Step 03: bounding boxes: bounds, union, overlap, the robust slab test, and a "
            "scene rendered with and without a box pre-test."};
        CommonOptions opts;
        addCommonOptions(app, opts, "many");
        app.get_option("--scene")->description(
            "'many' (this step's scene: spheres, triangles and the bunny), or a core scene / OBJ "
            "file whose spheres and mesh get boxes");
        size_t sphereCount = 3000, triangleCount = 4000;
        app.add_option("--spheres", sphereCount, "spheres in the 'many' scene")
            ->check(CLI::Range(size_t(0), size_t(1000000)));
        app.add_option("--triangles", triangleCount, "small triangles in the 'many' scene")
            ->check(CLI::Range(size_t(0), size_t(1000000)));
        std::string pretestName = "on";
        app.add_option("--pretest", pretestName, "the bounding-box pre-test in the headless image")
            ->check(CLI::IsMember({"on", "off"}))
            ->capture_default_str();
        bool measure = false;
        app.add_flag("--measure", measure,
                     "also measure (slab tests on hard rays, the pre-test) and print the tables");
        int measureWidth = 64, measureHeight = 48;
        app.add_option("--measure-width", measureWidth,
                       "image width of the with/without pre-test frames")
            ->check(CLI::Range(1, 4096));
        app.add_option("--measure-height", measureHeight,
                       "image height of the with/without pre-test frames")
            ->check(CLI::Range(1, 4096));
        size_t hardRays = 5000;
        app.add_option("--hard-rays", hardRays, "hard rays per category for the slab table")
            ->check(CLI::Range(size_t(1), size_t(1000000)));
        parseCommandLine(app, argc, argv);

        ManyObjects objects;
        if (opts.scene == "many") {
            objects = makeManyObjects(opts.dataDir, opts.aspect(), sphereCount, triangleCount, true,
                                      opts.seed);
            objects.scene.camera = cameraFromOptions(opts, objects.scene.camera);
        } else {
            objects = wrapScene(sceneFromOptions(opts));
        }
        Scene& scene = objects.scene;
        bool pretest = pretestName == "on";
        objects.setPretest(pretest);
        RenderSettings settings = opts.renderSettings();

        if (opts.headless) {
            Report report;
            report.program = "03_aabb";
            RayCounts counts;
            objects.counts->reset();
            renderHeadlessImage(scene, scene.camera, settings, headlessPath(opts, report.program),
                                "scene '" + scene.name + "', box pre-test " + pretestName, report,
                                &counts);
            report.facts["primitive_tests_per_ray"] =
                double(objects.counts->primitiveTests.load()) /
                double(std::max<uint64_t>(1, counts.total()));
            if (measure) {
                std::cerr << "03_aabb: slab tests on hard rays...\n";
                for (Table& t : measureSlabTests(makeHardSlabRays(hardRays, opts.seed), 15))
                    report.add(std::move(t));
                RenderSettings small = settings;
                small.width = measureWidth;
                small.height = measureHeight;
                Camera camera = scene.camera;
                camera.aspect = float(measureWidth) / float(measureHeight);
                PretestResult p = measurePretest(objects, camera, small);
                report.add(p.table);
                report.facts["pretest_pixels_differing"] = p.pixelsDiffering;
                report.plots.push_back(
                    {{"table", "slab_accuracy"},
                     {"x", "ns/test"},
                     {"y", "wrong /1M"},
                     {"series", "variant"},
                     {"logy", true},
                     {"title", "Slab tests: time per test and wrong answers on hard rays"}});
                report.plots.push_back(
                    {{"table", "pretest"},
                     {"x", "ms/frame"},
                     {"y", "primitive tests/ray"},
                     {"series", "pre-test"},
                     {"logx", true},
                     {"logy", true},
                     {"title", "A box pre-test: time per frame and primitive tests per ray"}});
            }
            writeReport(report, opts);
            return 0;
        }

        // Without the pre-test every ray tests every primitive: the window then renders at a
        // quarter of the size so a frame takes seconds rather than minutes.
        OrbitController orbit(scene.camera);
        bool dirty = true;
        Image image;
        double renderMs = 0.0, testsPerRay = 0.0, boxesPerRay = 0.0;
        WindowCallbacks cb;
        cb.keys = {{SDLK_b, "bounding-box pre-test on / off (off: quarter resolution)"}};
        cb.onKey = [&](int key) {
            if (key == SDLK_b) {
                pretest = !pretest;
                return dirty = true;
            }
            return false;
        };
        orbit.addTo(cb, [&] { dirty = true; });
        cb.frame = [&](double) -> const Image& {
            if (dirty) {
                objects.setPretest(pretest);
                objects.counts->reset();
                RenderSettings s = settings;
                if (!pretest) {
                    s.width = std::max(1, settings.width / 4);
                    s.height = std::max(1, settings.height / 4);
                    s.progressLabel = "03_aabb: without the pre-test";
                }
                RayCounts counts;
                Stopwatch watch;
                image = renderImage(scene, orbit.camera(), s, &counts);
                renderMs = watch.milliseconds();
                double n = double(std::max<uint64_t>(1, counts.total()));
                testsPerRay = double(objects.counts->primitiveTests.load()) / n;
                boxesPerRay = double(objects.counts->boxTests.load()) / n;
                dirty = false;
            }
            return image;
        };
        cb.panel = [&] {
            ImGui::Text("pre-test: %s", pretest ? "on" : "off (quarter resolution)");
            ImGui::Text("render: %.1f ms (%dx%d)", renderMs, image.width(), image.height());
            ImGui::Text("primitive tests/ray: %.1f, box tests/ray: %.1f", testsPerRay, boxesPerRay);
        };
        runWindow(opts.windowOptions("Step 03: bounding boxes"), cb);
        return 0;
    });
}
