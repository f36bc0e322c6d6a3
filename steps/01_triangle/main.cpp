// Step 01: a triangle mesh rendered with three ray/triangle tests; measures their speed and
// their cracks on shared edges and vertices.
#include <SDL2/SDL_keycode.h>
#include <imgui.h>

#include <cstdio>
#include <iostream>

#include "01_triangle/measure.hpp"
#include "01_triangle/triangle_grid.hpp"
#include "core/app.hpp"
#include "core/orbit.hpp"
#include "core/render.hpp"
#include "core/timing.hpp"

using namespace boxes;

namespace {

// Pixels where the three tests see different nearest triangles, drawn in magenta.
size_t markDisagreements(const TriangleGrid& grid, const Camera& camera, Image& image,
                         int threads) {
    std::vector<size_t> perRow(size_t(image.height()), 0);
    CameraBasisT<float> basis = camera.basis();
    parallelRows(image.height(), threads, [&](int y, int) {
        for (int x = 0; x < image.width(); ++x) {
            Ray ray(camera.eye, camera.directionThrough(basis, x + 0.5f, y + 0.5f, image.width(),
                                                        image.height()));
            uint32_t a = grid.nearestTriangle(ray, TriangleTest::PlaneTest);
            uint32_t b = grid.nearestTriangle(ray, TriangleTest::MollerTrumbore);
            uint32_t c = grid.nearestTriangle(ray, TriangleTest::Watertight);
            if (a != b || b != c) {
                image.at(x, y) = Vec3(1.0f, 0.0f, 1.0f);
                ++perRow[size_t(y)];
            }
        }
    });
    size_t total = 0;
    for (size_t n : perRow) total += n;
    return total;
}

TriangleTest parseTest(const std::string& name) {
    if (name == "plane") return TriangleTest::PlaneTest;
    if (name == "mt") return TriangleTest::MollerTrumbore;
    return TriangleTest::Watertight;
}

// One row per test and precision: its time per test beside its cracks over every case.
Table accuracyVersusTime(const Table& speed, const Table& cracks) {
    Table t;
    t.id = "accuracy_vs_time";
    t.title =
        "Accuracy against time: each test's speed beside its cracks (all meshes and placements)";
    t.columns = {"variant", "ns/test", "cracks /1M"};
    t.note = "ns/test from the speed table; cracks per million over every crack ray";
    for (size_t i = 0; i < speed.rows.size(); ++i) {
        const auto& row = speed.rows[i];
        std::string name = std::get<std::string>(row[0]) + " " + std::get<std::string>(row[1]);
        double rays = 0.0, missed = 0.0;
        size_t column = 4 + i;  // cracks columns follow the same order of tests and precisions
        for (const auto& c : cracks.rows) {
            double n = double(std::get<long long>(c[3]));
            rays += n;
            missed += std::get<double>(c[column]) * n / 1e6;
        }
        t.row({name, std::get<double>(row[2]), rays > 0 ? missed / rays * 1e6 : 0.0});
    }
    return t;
}

}  // namespace

int main(int argc, char** argv) {
    return runMain("01_triangle", [&] {
        CLI::App app{
            "Step 01: ray/triangle intersection: the plane test, Moller-Trumbore and the "
            "watertight test, side by side."};
        CommonOptions opts;
        addCommonOptions(app, opts, "bunny");
        std::string testName = "watertight";
        app.add_option("--test", testName, "the ray/triangle test to render with")
            ->check(CLI::IsMember({"plane", "mt", "watertight"}))
            ->capture_default_str();
        bool measure = false;
        app.add_flag("--measure", measure, "also measure speed and cracks and print the tables");
        size_t crackRays = 100000;
        app.add_option("--crack-rays", crackRays, "rays per mesh and feature for the crack count")
            ->check(CLI::Range(size_t(1), size_t(10000000)));
        parseCommandLine(app, argc, argv);

        Scene scene = sceneFromOptions(opts);
        std::shared_ptr<TriangleGrid> grid;
        if (scene.hasMesh()) {
            grid =
                std::make_shared<TriangleGrid>(scene.mesh, scene.meshMaterial, parseTest(testName));
            scene.geometries.push_back(grid);
        }
        RenderSettings settings = opts.renderSettings();

        if (opts.headless) {
            Report report;
            report.program = "01_triangle";
            std::string out = headlessPath(opts, report.program);
            Image image = renderHeadlessImage(scene, scene.camera, settings, out,
                                              "scene '" + scene.name + "' with the " +
                                                  triangleTestName(parseTest(testName)) + " test",
                                              report);
            if (measure && grid) {
                Image marked = image;
                size_t differ = markDisagreements(*grid, scene.camera, marked, opts.threads);
                std::string disagreePath = pngWithSuffix(out, "-disagree");
                marked.writePng(disagreePath);
                report.images.push_back(
                    {disagreePath,
                     "magenta: pixels where the three tests pick different triangles"});
                report.facts["pixels_disagreeing"] = differ;
                std::cerr << "01_triangle: measuring speed...\n";
                report.add(measureTriangleSpeed(scene.mesh, opts.seed, 7));
                std::cerr << "01_triangle: counting cracks...\n";
                Mesh sh1 = loadObj(opts.dataDir + "/meshes/sh1.obj");
                Mesh bunny = scene.name == "bunny" ? scene.mesh
                                                   : loadObj(opts.dataDir + "/meshes/bunny.obj");
                Vec3 far(1000.0f, -700.0f, 300.0f);
                report.add(measureCracks({{"bunny", &bunny, Vec3(0.0f)},
                                          {"bunny", &bunny, far},
                                          {"sh1", &sh1, Vec3(0.0f)},
                                          {"sh1", &sh1, far}},
                                         crackRays, opts.seed));
                report.add(accuracyVersusTime(report.tables[0], report.tables[1]));
                report.plots.push_back({{"table", "accuracy_vs_time"},
                                        {"x", "ns/test"},
                                        {"y", "cracks /1M"},
                                        {"series", "variant"},
                                        {"logy", true},
                                        {"title",
                                         "Accuracy against time: cracks per million rays "
                                         "aimed at shared edges and vertices"}});
            }
            writeReport(report, opts);
            return 0;
        }

        // The window: re-render only when something changed.
        OrbitController orbit(scene.camera);
        TriangleTest test = parseTest(testName);
        bool marks = false, dirty = true;
        Image image;
        double renderMs = 0.0;
        size_t differ = 0;
        WindowCallbacks cb;
        cb.keys = {{SDLK_t, "next triangle test (plane / Moller-Trumbore / watertight)"},
                   {SDLK_m, "mark pixels where the tests disagree (magenta)"}};
        cb.onKey = [&](int key) {
            if (key == SDLK_t) {
                test = TriangleTest((int(test) + 1) % 3);
                dirty = true;
                return true;
            }
            if (key == SDLK_m) {
                marks = !marks;
                dirty = true;
                return true;
            }
            return false;
        };
        orbit.addTo(cb, [&] { dirty = true; });
        cb.frame = [&](double) -> const Image& {
            if (dirty) {
                if (grid) grid->setTest(test);
                Stopwatch watch;
                image = renderImage(scene, orbit.camera(), settings);
                if (marks && grid)
                    differ = markDisagreements(*grid, orbit.camera(), image, opts.threads);
                renderMs = watch.milliseconds();
                dirty = false;
            }
            return image;
        };
        cb.panel = [&] {
            ImGui::Text("test: %s", triangleTestName(test));
            ImGui::Text("render: %.1f ms (%dx%d)", renderMs, settings.width, settings.height);
            if (marks) ImGui::Text("pixels where the tests disagree: %zu", differ);
        };
        runWindow(opts.windowOptions("Step 01: triangles"), cb);
        return 0;
    });
}
