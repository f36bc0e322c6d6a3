// The mini-core: images, meshes, timing, tables, scenes and the renderer's promise 3.
#include <algorithm>
#include <atomic>
#include <cfenv>
#include <chrono>
#include <cmath>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include "core/heatmap.hpp"
#include "core/image.hpp"
#include "core/mesh.hpp"
#include "core/render.hpp"
#include "core/report.hpp"
#include "core/scene.hpp"
#include "core/timing.hpp"
#include "core/view_render.hpp"
#include "support.hpp"

using namespace boxes;

TEST_SUITE("core") {
    TEST_CASE("test support: GLM vectors print as (x y z) with commas in failure messages") {
        CHECK(doctest::toString(Vec3(1.0f, 2.5f, -3.0f)) == "(1, 2.5, -3)");
        CHECK(doctest::toString(Vec3d(0.1, 0, 0)) == "(0.10000000000000001, 0, 0)");
        CHECK(doctest::toString(glm::ivec2(4, -7)) == "(4, -7)");
        // A name passed to INFO as a string, not as a pointer.
        const char* name = "sh1";
        CHECK(doctest::toString(std::string(name)) == "sh1");
    }
    TEST_CASE("image: PNG round trip keeps size and 8-bit values") {
        test::TempDir dir;
        Image img(5, 3);
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 5; ++x) img.at(x, y) = Vec3(x / 4.0f, y / 2.0f, 0.5f);
        img.writePng(dir.file("a.png"));
        CHECK(test::pngSize(dir.file("a.png")) == std::pair{5, 3});
        Image back = Image::readPng(dir.file("a.png"));
        REQUIRE(back.width() == 5);
        // The round trip is exact after one quantization to 8 bits.
        CHECK(back.toRgb8() == img.toRgb8());
        CHECK(back.at(0, 0).r == 0.0f);
        CHECK(back.at(4, 2).g == 1.0f);
    }
    TEST_CASE("image: sRGB encoding of 8-bit values round-trips exactly") {
        for (int v = 0; v < 256; ++v) CHECK(encodeSrgb8(decodeSrgb8(uint8_t(v))) == v);
        {
            // A NaN pixel on purpose: encoding compares it (an invalid operation), which is
            // the documented robust path (NaN -> 0), so no trap here.
            test::FpTrapsOff nanOnPurpose;
            CHECK(encodeSrgb8(std::nanf("")) == 0);
        }
        CHECK(encodeSrgb8(2.0f) == 255);
    }
    TEST_CASE("image: a failed write leaves no file behind") {
        test::TempDir dir;
        CHECK_THROWS_AS(Image(2, 2).writePng(dir.file("no/such/dir/a.png")), std::runtime_error);
        CHECK(std::filesystem::is_empty(dir.path));
    }
    TEST_CASE("image: zero size is refused") {
        CHECK_THROWS_AS(Image(0, 10), std::invalid_argument);
        CHECK_THROWS_AS(Image(10, -1), std::invalid_argument);
    }
    TEST_CASE("heat map: viridis from dark violet to yellow, counts on a log scale, a labelled bar") {
        // matplotlib's viridis at 0 and 1 (sRGB 68,1,84 and 253,231,37), in linear RGB.
        CHECK(encodeSrgb8(viridis(0.0).x) == 68);
        CHECK(encodeSrgb8(viridis(0.0).z) == 84);
        CHECK(encodeSrgb8(viridis(1.0).x) == 253);
        CHECK(encodeSrgb8(viridis(1.0).y) == 231);
        CHECK(viridis(-1.0) == viridis(0.0));
        for (double t = 0.0; t < 1.0; t += 0.05)  // brighter all the way: green rises
            CHECK(viridis(t + 0.05).y > viridis(t).y);
        CHECK(scaleTop(0.0) == 1.0);
        CHECK(scaleTop(1.0) == 1.0);
        CHECK(scaleTop(1.5) == 2.0);
        CHECK(scaleTop(37.0) == 50.0);
        CHECK(scaleTop(2000.0) == 2000.0);
        CHECK(scaleTop(71853.9) == 100000.0);
        std::vector<double> counts(40 * 30, 0.0);
        counts[0] = 99.0;     // the top-left pixel at the top of a scale to 99
        counts[41] = 9.0;     // log(10) / log(100): half way
        Image map = heatMapImage(counts, 40, 30, 99.0, "box tests");
        REQUIRE(map.width() > 40);
        REQUIRE(map.height() > 30);
        int top = 0;  // the map's first row, under the title's line
        while (top < map.height() && !(map.at(5, top) == viridis(0.0))) ++top;
        REQUIRE(top > 5);  // room for the title
        REQUIRE(top + 30 <= map.height());
        CHECK(map.at(0, top) == viridis(1.0));
        CHECK(map.at(1, top + 1).y == doctest::Approx(viridis(0.5).y).epsilon(1e-5));
        CHECK(map.at(5, top + 5) == viridis(0.0));
        // The bar's top and bottom, and ink (the title, the ticks) in the margins.
        int inkTitle = 0, inkTicks = 0;
        for (int y = 0; y < top; ++y)
            for (int x = 0; x < map.width(); ++x) inkTitle += map.at(x, y) == Vec3(0.0f);
        for (int y = top; y < map.height(); ++y)
            for (int x = 40; x < map.width(); ++x) inkTicks += map.at(x, y) == Vec3(0.0f);
        CHECK(inkTitle > 20);
        CHECK(inkTicks > 20);
        CHECK_THROWS_AS(heatMapImage(counts, 41, 30, 99.0, ""), std::invalid_argument);
        CHECK(textWidth("10") > textWidth("1"));
    }
    TEST_CASE("image: RMSE and max error of a known difference") {
        Image a(2, 1, Vec3(0.5f)), b(2, 1, Vec3(0.5f));
        b.at(1, 0) = Vec3(0.5f, 0.5f, 0.9f);  // one channel of six differs by 0.4
        ImageDifference d = compareImages(a, b);
        CHECK(d.maxError == doctest::Approx(0.4).epsilon(1e-6));
        CHECK(d.rmse == doctest::Approx(std::sqrt(0.16 / 6.0)).epsilon(1e-6));
        CHECK(d.pixelsDiffering == 1);
        CHECK_THROWS(compareImages(a, Image(1, 1)));
    }
    TEST_CASE("mesh: OBJ polygons are fan-triangulated in file order") {
        Mesh m = parseObj(
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nvn 0 1 "
            "0\nvn 1 0 0\nf 1 2 3 4\nf 1/1/1 2/2/2 5/3/3\nf -1 -2 -3\n");
        REQUIRE(m.triangleCount() == 4);
        CHECK(m.triangles[0] == std::array<uint32_t, 3>{0, 1, 2});
        CHECK(m.triangles[1] == std::array<uint32_t, 3>{0, 2, 3});
        CHECK(m.triangles[2] == std::array<uint32_t, 3>{0, 1, 4});
        CHECK(m.triangles[3] == std::array<uint32_t, 3>{4, 3, 2});  // negative: relative to the end
        CHECK(m.normals.size() == 5);
        CHECK(glm::length(m.normals[2]) == doctest::Approx(1.0f));
    }
    TEST_CASE("mesh: malformed files are refused with one line naming the problem") {
        auto message = [](const std::string& text) {
            try {
                parseObj(text, "x.obj");
            } catch (const InputError& e) {
                return std::string(e.what());
            }
            return std::string("(accepted)");
        };
        CHECK(message("").find("empty") != std::string::npos);
        CHECK(message("v 0 0 0\nv 1 0 0\n").find("no triangles") != std::string::npos);
        CHECK(message("v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n").find("not a number") !=
              std::string::npos);
        CHECK(message("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n").find("range") != std::string::npos);
        CHECK(message("v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n").find("3 coordinates") !=
              std::string::npos);
        CHECK(message("v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n").find("range") !=
              std::string::npos);
        CHECK(message("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n").find("non-finite") !=
              std::string::npos);
        for (const std::string& m : {message(""), message("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")})
            CHECK(m.find('\n') == std::string::npos);
        CHECK_THROWS_AS(loadObj("/nonexistent/file.obj"), InputError);
    }
    TEST_CASE("timing: median and min and max of samples") {
        Timing t = summarize({3.0, 1.0, 2.0, 10.0, 4.0});
        CHECK(t.median == 3.0);
        CHECK(t.min == 1.0);
        CHECK(t.max == 10.0);
        Timing even = summarize({4.0, 1.0, 2.0, 3.0}, 2);
        CHECK(even.median == 1.25);  // (2 + 3) / 2 per repeat, 2 calls each
    }
    TEST_CASE("report: a table prints aligned text and JSON rows") {
        Table t("x", "T", {"name", "value"});
        t.row({std::string("a"), 1.5}).row({std::string("bb"), (long long)42});
        nlohmann::json j = t.toJson();
        CHECK(j["rows"].size() == 2);
        CHECK(j["rows"][0][1] == 1.5);
        CHECK(j["rows"][1][1] == 42);
        std::ostringstream out;
        t.print(out);
        CHECK(out.str().find("bb") != std::string::npos);
    }
    TEST_CASE("threads: every thread index once with thread 0 the caller and kept workers") {
        // The kept workers grow, shrink and are reused between the calls.
        for (int threads : {1, 2, 3, 4, 2, 2, 0}) {
            INFO("threads " << threads);
            int n = resolveThreads(threads);
            std::vector<std::atomic<int>> ran(size_t(n) + 1);
            std::atomic<bool> zeroOnCaller{false};
            const auto caller = std::this_thread::get_id();
            runOnThreads(threads, [&](int t) {
                ran[size_t(std::clamp(t, 0, n))]++;
                if (t == 0) zeroOnCaller = std::this_thread::get_id() == caller;
            });
            for (int t = 0; t < n; ++t) CHECK(ran[size_t(t)] == 1);
            CHECK(ran[size_t(n)] == 0);
            CHECK(zeroOnCaller);
        }
        CHECK(resolveThreads(0) >= 1);
        CHECK(resolveThreads(3) == 3);
        // A call from inside a task (the workers are busy) runs on threads of its own.
        std::atomic<int> inner{0};
        runOnThreads(2, [&](int) { runOnThreads(3, [&](int) { inner++; }); });
        CHECK(inner == 6);
    }
    TEST_CASE("threads: every worker runs in the caller's floating-point environment") {
        // A kept worker started under another rounding mode; thread 0 waits so the other
        // thread's task surely runs while the caller is inside runOnThreads.
        runOnThreads(2, [](int) {});
        for (int mode : {FE_UPWARD, FE_DOWNWARD, FE_TONEAREST}) {
            std::fesetround(mode);
            std::atomic<int> wrong{0};
            runOnThreads(2, [&](int t) {
                if (t == 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
                wrong += std::fegetround() != mode;
            });
            std::fesetround(FE_TONEAREST);
            CHECK(wrong == 0);
        }
    }
    TEST_CASE(
        "threads: parallelRows runs every row once and an exception stops it and reaches "
        "the caller") {
        for (int threads : {1, 2, 3}) {
            INFO("threads " << threads);
            std::vector<std::atomic<int>> seen(500);
            std::atomic<int> badThread{0};
            parallelRows(500, threads, [&](int row, int thread) {
                seen[size_t(row)]++;
                badThread += thread < 0 || thread >= threads;
            });
            CHECK(std::all_of(seen.begin(), seen.end(), [](const auto& s) { return s == 1; }));
            CHECK(badThread == 0);
            std::atomic<int> rows{0};
            CHECK_THROWS_WITH_AS(parallelRows(100000, threads,
                                              [&](int row, int) {
                                                  if (row == 10) throw std::runtime_error("row 10");
                                                  rows++;
                                              }),
                                 "row 10", std::runtime_error);
            CHECK(rows < 100000 - 1);  // the others stopped early
            std::atomic<int> after{0};
            parallelRows(64, threads, [&](int, int) { after++; });
            CHECK(after == 64);
        }
    }
    TEST_CASE("scene: the nearest of spheres and planes") {
        Scene s;
        s.spheres.push_back({{Vec3(0, 0, -5), 1.0f}, 0});
        s.spheres.push_back({{Vec3(0, 0, -3), 0.5f}, 0});
        s.planes.push_back({{Vec3(0, 0, 1), 10.0f}, 0});  // z = -10
        SurfaceHit hit;
        REQUIRE(s.intersect(Ray(Vec3(0), Vec3(0, 0, -1)), hit));
        CHECK(hit.t == doctest::Approx(2.5f));
        CHECK(hit.object == 1);
        REQUIRE(s.intersect(Ray(Vec3(3, 0, 0), Vec3(0, 0, -1)), hit));
        CHECK(hit.t == doctest::Approx(10.0f));
        CHECK(hit.kind == SurfaceHit::Kind::Plane);
        CHECK(s.occluded(Ray(Vec3(0), Vec3(0, 0, -1), 0.0f, 2.6f)));
        CHECK_FALSE(s.occluded(Ray(Vec3(0), Vec3(0, 0, -1), 0.0f, 2.4f)));
    }
    TEST_CASE("light radius: where intensity / d^2 falls to half an 8-bit sRGB step") {
        // Half a step of the encoded image is 0.5 / 255 / 12.92 in linear light (sRGB's slope
        // at black). I = 2: d = sqrt(2 * 255 * 2 * 12.92) = sqrt(13178.4).
        CHECK(PointLight::radiusFor(Vec3(2.0f, 1.0f, 0.5f)) == doctest::Approx(std::sqrt(13178.4)));
        // Shared by 4 lights: each gets a quarter, the radius doubles.
        CHECK(PointLight::cutoffThreshold(4) == doctest::Approx(0.5 / 255.0 / 12.92 / 4.0));
        CHECK(PointLight::radiusFor(Vec3(2.0f), PointLight::cutoffThreshold(4)) ==
              doctest::Approx(2.0 * std::sqrt(13178.4)));
        // A linear change below the threshold moves the 8-bit sRGB value by at most one step.
        for (float v : {0.0f, 1e-4f, 0.0031f, 0.01f, 0.2f, 0.99f})
            CHECK(int(encodeSrgb8(v + PointLight::kHalfStep8)) - int(encodeSrgb8(v)) <= 1);
        Scene scene = makeScene("spheres", {});
        for (const PointLight& l : scene.lights)
            CHECK(l.radius == doctest::Approx(PointLight::radiusFor(
                                  l.intensity, PointLight::cutoffThreshold(scene.lights.size()))));
    }
}

TEST_SUITE("renderer") {
    TEST_CASE("effects on demand: every scene kind renders the identical image with fewer rays") {
        for (const char* name :
             {"spheres", "diffuse", "mirrors", "glass", "single-sphere", "small-lights"}) {
            INFO(std::string(name));
            Scene scene = makeScene(name, SceneOptions{test::dataDir(), 4.0f / 3.0f});
            auto c = test::renderBothWays(scene, 40, 30, 4);
            CHECK(c.identical);
            CHECK(c.lean.total() < c.forced.total());
            CHECK(c.lean.primary == c.forced.primary);
        }
    }
    TEST_CASE("effects on demand: what each scene needs") {
        auto counts = [](const char* name) {
            Scene scene = makeScene(name, SceneOptions{test::dataDir(), 4.0f / 3.0f});
            RenderSettings s;
            s.width = 40;
            s.height = 30;
            RayCounts c;
            renderImage(scene, scene.camera, s, &c);
            return c;
        };
        RayCounts single = counts("single-sphere");
        CHECK(single.shadow == 0);  // one convex object: nothing can cast a shadow
        CHECK(single.reflection == 0);
        CHECK(single.shadowSkipped > 0);
        RayCounts diffuse = counts("diffuse");
        CHECK(diffuse.reflection == 0);
        CHECK(diffuse.refraction == 0);
        CHECK(diffuse.shadow > 0);
        RayCounts mirrors = counts("mirrors");
        CHECK(mirrors.reflection > 0);
        CHECK(mirrors.refraction == 0);
        RayCounts glass = counts("glass");
        CHECK(glass.refraction > 0);
        RayCounts small = counts("small-lights");
        CHECK(small.lightsOutOfRange > 0);
    }
    TEST_CASE("renderer: a glass sphere's refraction and a mirror's reflection show up") {
        Scene scene = makeScene("spheres", SceneOptions{test::dataDir(), 1.0f});
        RenderSettings s;
        s.width = s.height = 32;
        Image with = renderImage(scene, scene.camera, s);
        s.maxDepth = 0;
        Image without = renderImage(scene, scene.camera, s);
        CHECK(compareImages(with, without).pixelsDiffering > 20);
    }
    TEST_CASE("renderer: a control counts the rows done and stops the render when asked") {
        Scene scene = makeScene("spheres", SceneOptions{test::dataDir(), 4.0f / 3.0f});
        RenderSettings s;
        s.width = 40;
        s.height = 30;
        RenderControl control;
        s.control = &control;
        Image image = renderImage(scene, scene.camera, s);
        CHECK(control.rowsDone == 30);
        CHECK(control.rows == 30);
        CHECK(control.progress() == 1.0);
        // The same image as without a control.
        s.control = nullptr;
        CHECK(compareImages(image, renderImage(scene, scene.camera, s)).pixelsDiffering == 0);
        control.cancel = true;  // a stop asked for before the first row: no row is rendered
        s.control = &control;
        CHECK_THROWS_AS(renderImage(scene, scene.camera, s), RenderCancelled);
        CHECK(control.rowsDone == 0);
        CHECK_NOTHROW(checkCancelled(nullptr));
    }
    TEST_CASE("view render: coarse passes first, the full size last, a stop within a row") {
        ViewRender view;
        std::vector<int> widths;
        std::mutex widthsMutex;
        RenderSettings full;
        full.width = 160;
        full.height = 120;
        auto solid = [&](const RenderSettings& s) {
            {
                std::lock_guard<std::mutex> lock(widthsMutex);
                widths.push_back(s.width);
            }
            return Image(s.width, s.height, Vec3(0.5f));
        };
        view.start(solid, full);
        // Waits for the passes (no time is asserted: a loaded machine only makes it longer).
        Image shown;
        for (int i = 0; i < 6000 && !view.complete(); ++i)
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        REQUIRE(view.complete());
        view.stop();
        CHECK(view.take(shown));
        CHECK(shown.width() == 160);
        CHECK_FALSE(view.take(shown));  // given once
        CHECK(widths == std::vector<int>{20, 80, 160});
        CHECK(view.progress().first < 0.0);  // nothing under way

        // A render that goes on row by row until it is stopped: stop() returns, nothing new.
        std::atomic<bool> started{false};
        view.start(
            [&](const RenderSettings& s) {
                started = true;
                for (;;) {
                    checkCancelled(s.control);
                    std::this_thread::sleep_for(std::chrono::milliseconds(1));
                }
                return Image();
            },
            full);
        while (!started) std::this_thread::sleep_for(std::chrono::milliseconds(1));
        CHECK(view.busy());
        CHECK(view.progress().second == "rendering 1/8 size");
        view.stop();
        CHECK_FALSE(view.busy());
        CHECK_FALSE(view.take(shown));

        // What a render throws reaches the window's thread.
        view.start([](const RenderSettings&) -> Image { throw std::runtime_error("no mesh"); },
                   full);
        view.stop();
        CHECK_THROWS_WITH(view.take(shown), "no mesh");
    }
    TEST_CASE("renderer: a scene with a mesh but no geometry for it is refused") {
        Scene scene;
        scene.mesh = parseObj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
        RenderSettings s;
        CHECK_THROWS_AS(renderImage(scene, scene.camera, s), std::logic_error);
    }
}

// The check every step's "program NN" suite runs on its JSON report (test::checkVariantTables)
// on a small fixture: sound as written, and a problem for each column taken away.
TEST_SUITE("core") {
    TEST_CASE("variant tables: the check fails on a table without its time or its error column") {
        const nlohmann::json sound = nlohmann::json::parse(R"({"tables": [{
            "id": "t", "note": "error: pixels differing from the double-precision image",
            "columns": ["variant", "median ms", "low ms", "high ms", "pixels differing"],
            "time": {"median": "median ms", "low": "low ms", "high": "high ms"},
            "error": "pixels differing",
            "rows": [["float", 1.0, 0.9, 1.2, 3], ["double", 2.5, 2.4, 2.7, 0]]}]})");
        CHECK(test::variantTableProblems(sound, {"t"}).empty());
        auto problems = [&](const std::function<void(nlohmann::json&)>& edit) {
            nlohmann::json report = sound;
            edit(report["tables"][0]);
            return test::variantTableProblems(report, {"t"});
        };
        using Problems = std::vector<std::string>;
        CHECK(problems([](nlohmann::json& t) { t.erase("time"); }) ==
              Problems{"t: no time column"});
        CHECK(problems([](nlohmann::json& t) { t.erase("error"); }) ==
              Problems{"t: no error column"});
        CHECK(problems([](nlohmann::json& t) {
                  t.erase("time");
                  t.erase("error");
              }) == Problems{"t: no time column", "t: no error column"});
        // The column named but gone from the columns, or from a row.
        CHECK(problems([](nlohmann::json& t) { t["columns"][4] = "error"; }) ==
              Problems{"t: no column \"pixels differing\""});
        CHECK(problems([](nlohmann::json& t) { t["columns"][2] = "min ms"; }) ==
              Problems{"t: no column \"low ms\""});
        CHECK(problems([](nlohmann::json& t) { t["rows"][1].erase(4); }).size() == 1);
        CHECK(problems([](nlohmann::json& t) { t["rows"][0][4] = nullptr; }).size() == 1);
        // A median outside its spread, no note, no rows, no table.
        CHECK(problems([](nlohmann::json& t) { t["rows"][0][1] = 5.0; }).size() == 1);
        CHECK(problems([](nlohmann::json& t) { t.erase("note"); }) ==
              Problems{"t: no note stating the reference"});
        CHECK(problems([](nlohmann::json& t) { t["rows"] = nlohmann::json::array(); }) ==
              Problems{"t: no rows"});
        CHECK(test::variantTableProblems(sound, {"t", "u"}) == Problems{"u: no such table"});
    }
}
