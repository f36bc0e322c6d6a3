// Step 04's engine: batches of rays on threads, the rays and hits files, and the program
// (its window and headless run, the trace and check commands).
#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <cfenv>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <thread>
#include <vector>

#include "04_bvh/advanced/batch.hpp"
#include "04_bvh/advanced/build.hpp"
#include "04_bvh/advanced/bvh4.hpp"
#include "04_bvh/advanced/rays.hpp"
#include "step04_support.hpp"

using namespace boxes;
using namespace boxes::test04;

TEST_SUITE("trace 04") {
    TEST_CASE("rays and hits files round-trip") {
        test::TempDir dir;
        std::vector<Ray> rays = {Ray(Vec3(1, 2, 3), Vec3(0, -0.0f, 1), 0.5f, 7.0f),
                                 Ray(Vec3(-1e30f, 0, 0), Vec3(1e-30f, 2, 0))};
        writeRays(dir.file("r.bin"), rays);
        CHECK(std::filesystem::file_size(dir.file("r.bin")) == 64);
        std::vector<Ray> back = readRays(dir.file("r.bin"));
        REQUIRE(back.size() == 2);
        for (size_t i = 0; i < 2; ++i) {
            CHECK(back[i].origin == rays[i].origin);
            CHECK(back[i].direction == rays[i].direction);
            CHECK(back[i].tmin == rays[i].tmin);
            CHECK(back[i].tmax == rays[i].tmax);
        }
        CHECK(std::signbit(back[0].direction.y));
        std::vector<TraceHit> hits = {{1.5f, 7u}, {}};
        writeHits(dir.file("h.bin"), hits);
        CHECK(readHits(dir.file("h.bin")) == hits);
        // The bytes: little-endian float32 1.5 = 0x3FC00000, then uint32 7; a miss is
        // +infinity (0x7F800000) and 0xFFFFFFFF.
        std::string bytes = test::readText(dir.file("h.bin"));
        REQUIRE(bytes.size() == 16);
        CHECK(bytes.substr(0, 8) == std::string("\x00\x00\xC0\x3F\x07\x00\x00\x00", 8));
        CHECK(bytes.substr(8, 8) == std::string("\x00\x00\x80\x7F\xFF\xFF\xFF\xFF", 8));
    }
    TEST_CASE("bad rays files are refused with the reason") {
        test::TempDir dir;
        std::ofstream(dir.file("short.bin"), std::ios::binary) << std::string(33, '\0');
        CHECK_THROWS_WITH_AS(readRays(dir.file("short.bin")), doctest::Contains("multiple of 32"),
                             InputError);
        float nan[8] = {0, 0, 0, 0, 1, std::nanf(""), 0, 1};
        std::ofstream(dir.file("nan.bin"), std::ios::binary)
            .write(reinterpret_cast<const char*>(nan), sizeof(nan));
        CHECK_THROWS_WITH_AS(readRays(dir.file("nan.bin")), doctest::Contains("NaN"), InputError);
        CHECK_THROWS_AS(readRays(dir.file("none.bin")), InputError);
    }
    TEST_CASE("the hierarchy equals brute force on a real mesh") {
        Mesh sh1 = loadObj(test::dataDir() + "/meshes/sh1.obj");
        for (BvhBuilder b : kExerciseBuilders) {
            Bvh bvh = buildBvh(sh1, optionsFor(b));
            for (RayKind kind : {RayKind::Primary, RayKind::Diffuse, RayKind::Random}) {
                INFO(std::string(bvhBuilderName(b)) << " " << std::string(rayKindName(kind)));
                std::vector<Ray> rays = makeRays(sh1, kind, 400, 19);
                size_t differ = 0, hits = 0;
                for (const Ray& r : rays) {
                    TraceHit tree = traceNearest(bvh, r), brute = traceBruteForce(sh1, r);
                    differ += !hitsAgree(tree, brute);
                    hits += brute.triangle != kNoPrimitive;
                    CHECK(traceOccluded(bvh, r) == (brute.triangle != kNoPrimitive));
                }
                CHECK(differ == 0);
                CHECK(hits > 40);
            }
        }
    }
    TEST_CASE("batch tracing on threads: every chunk once and the hits of one thread") {
        // 10,000 indices are 10 chunks of 1,024; the pool of workers grows, shrinks and is
        // reused between the calls.
        constexpr size_t kCount = 10000;
        for (int threads : {1, 2, 3, 4, 2, 2, 0}) {
            INFO("threads " << threads);
            std::vector<std::atomic<int>> seen(kCount);
            forEachRayChunk(kCount, threads, [&](size_t begin, size_t end) {
                for (size_t i = begin; i < end; ++i) seen[i]++;
            });
            CHECK(std::all_of(seen.begin(), seen.end(), [](const auto& s) { return s == 1; }));
        }
        // A batch started from inside a batch (the pool is busy) runs on threads of its own.
        std::atomic<size_t> inner{0};
        forEachRayChunk(3000, 2, [&](size_t begin, size_t end) {
            forEachRayChunk(end - begin, 2, [&](size_t b, size_t e) { inner += e - b; });
        });
        CHECK(inner == 3000);
        // Every thread works in the caller's floating-point environment (here its rounding
        // mode), as a thread started for the batch would; the first chunk waits so that
        // the other thread takes chunks too.
        for (int mode : {FE_UPWARD, FE_TONEAREST}) {
            std::fesetround(mode);
            std::atomic<int> other{0}, chunks{0};
            forEachRayChunk(8192, 2, [&](size_t begin, size_t) {
                if (begin == 0) std::this_thread::sleep_for(std::chrono::milliseconds(20));
                other += std::fegetround() != mode;
                chunks++;
            });
            std::fesetround(FE_TONEAREST);
            CHECK(chunks == 8);
            CHECK(other == 0);
        }
        Mesh sh1 = loadObj(test::dataDir() + "/meshes/sh1.obj");
        Bvh bvh = buildBvh(sh1, BvhBuildOptions{});
        std::vector<Ray> rays = makeRays(sh1, RayKind::Diffuse, 5000, 23);
        std::vector<TraceHit> one, three;
        traceBatch(bvh, rays, one, 1);
        traceBatch(bvh, rays, three, 3);
        CHECK(one == three);
    }
    TEST_CASE("batch tracing on threads: an exception in a chunk reaches the caller") {
        for (int threads : {1, 2}) {
            std::atomic<size_t> done{0};
            CHECK_THROWS_WITH_AS(forEachRayChunk(8192, threads,
                                                 [&](size_t begin, size_t end) {
                                                     if (begin == 4096)
                                                         throw std::runtime_error("chunk 4");
                                                     done += end - begin;
                                                 }),
                                 "chunk 4", std::runtime_error);
            CHECK(done < 8192);
            // The pool still works afterwards.
            std::atomic<size_t> after{0};
            forEachRayChunk(8192, threads, [&](size_t begin, size_t end) { after += end - begin; });
            CHECK(after == 8192);
        }
    }
    TEST_CASE("the fast leaf test agrees with a double-precision reference") {
        Mesh m = triangleSoup(300, 20, 0.3f);
        size_t hits = 0;
        for (const Ray& r : randomRays(300, 21)) {
            TraceHit fast = traceBruteForce(m, r);
            double t;
            uint32_t ref = bruteWithReference(m, r, t);
            hits += ref != kNoPrimitive;
            if (fast.triangle != ref)
                CHECK(std::abs(double(fast.t) - t) < 1e-4 * (1.0 + t));
            else if (ref != kNoPrimitive)
                CHECK(double(fast.t) == doctest::Approx(t).epsilon(1e-5));
        }
        CHECK(hits > 50);
    }
}

namespace {

// A HITS.bin the trace command wrote: one hit per ray, each agreeing with brute force.
// Returns how many rays hit.
size_t checkHitsFileAgainstBruteForce(const std::string& path, const Mesh& mesh,
                                      const std::vector<Ray>& rays) {
    std::vector<TraceHit> hits = readHits(path);
    REQUIRE(hits.size() == rays.size());
    size_t hitCount = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
        CHECK(hitsAgree(hits[i], traceBruteForce(mesh, rays[i])));
        hitCount += hits[i].triangle != kNoPrimitive;
    }
    return hitCount;
}

}  // namespace

TEST_SUITE("program 04") {
    const std::string program = test::stepProgram();

    TEST_CASE("headless render writes a PNG of the requested size and the culling map") {
        test::TempDir dir;
        test::runHeadless(program, dir, 64, 40, "--scene sh1");
        CHECK(test::pngSize(dir.file("a-cull.png")) == std::pair{64, 40});
    }
    TEST_CASE("measurements: the JSON report has the step tables") {
        test::TempDir dir;
        test::runHeadless(
            program, dir, 32, 24,
            "--scene sh1 --measure --measure-rays 400 --crack-rays 100 --report r.json");
        test::checkReportTables(dir.file("r.json"), {"bvh_build", "bvh_trace", "bvh_threads",
                                                     "bvh_cracks", "bvh_culling", "bvh_tradeoff"});
        test::checkVariantTables(dir.file("r.json"), {"bvh_build", "bvh_trace", "bvh_cracks",
                                                      "bvh_culling", "bvh_tradeoff"});
        test::checkParetoPlot(dir.file("r.json"), "bvh_tradeoff");
        // One build time per builder: the trade-off's is bvh_build's median.
        auto report = nlohmann::json::parse(test::readText(dir.file("r.json")));
        std::map<std::string, nlohmann::json> tables;
        for (const auto& t : report["tables"]) tables[t["id"]] = t;
        for (const auto& row : tables["bvh_tradeoff"]["rows"])
            for (const auto& build : tables["bvh_build"]["rows"])
                if (build[0] == row[0]) CHECK(row[1] == build[1]);
        CHECK_FALSE(report["facts"].contains("build_ms"));
        // The heat maps of a ray's cost: per builder, the mean over the pixels is the
        // table's count per ray over the same rays.
        REQUIRE(tables["bvh_cost"]["rows"].size() == 3);
        for (const auto& row : tables["bvh_cost"]["rows"]) {
            std::string builder = row[0];
            INFO(builder);
            CHECK(row[1] == 32 * 24);
            CHECK(report["facts"]["heat_box_tests_per_ray_" + builder].get<double>() ==
                  doctest::Approx(row[2].get<double>()).epsilon(1e-12));
            CHECK(report["facts"]["heat_triangle_tests_per_ray_" + builder].get<double>() ==
                  doctest::Approx(row[3].get<double>()).epsilon(1e-12));
            CHECK(row[2].get<double>() >= 1.0);  // every ray tests the root's box
            CHECK(test::pngSize(dir.file("a-heat-" + builder + ".png")).first > 2 * 32);
        }
    }
    TEST_CASE("trace command: hits equal brute force and the JSON line") {
        test::TempDir dir;
        Mesh sh1 = loadObj(test::dataDir() + "/meshes/sh1.obj");
        std::vector<Ray> rays = makeRays(sh1, RayKind::Primary, 900, 3);
        writeRays(dir.file("rays.bin"), rays);
        for (const char* builder : {"midpoint", "median", "sah"}) {
            INFO(std::string(builder));
            auto run =
                test::runProgram(program,
                                 "trace --mesh " + test::dataDir() +
                                     "/meshes/sh1.obj "
                                     "--rays rays.bin --hits hits.bin --repeat 2 --builder " +
                                     builder,
                                 dir);
            INFO(run.err);
            REQUIRE(run.exitCode == 0);
            CHECK(test::lineCount(run.out) == 1);
            for (const char* key : {"\"tris\":3290", "\"rays\":900", "\"build_ms\"", "\"trace_ms\"",
                                    "\"mrays_per_s\"", "\"hits\"", "\"threads\":1", "\"builder\""})
                CHECK(run.out.find(key) != std::string::npos);
            size_t hitCount = checkHitsFileAgainstBruteForce(dir.file("hits.bin"), sh1, rays);
            CHECK(hitCount > 100);
            CHECK(run.out.find("\"hits\":" + std::to_string(hitCount)) != std::string::npos);
        }
    }
    TEST_CASE("trace command: the 4- and 8-wide variants equal brute force") {
        test::TempDir dir;
        Mesh sh1 = loadObj(test::dataDir() + "/meshes/sh1.obj");
        std::vector<Ray> rays = makeRays(sh1, RayKind::Diffuse, 600, 4);
        writeRays(dir.file("rays.bin"), rays);
        Bvh binary = buildEngineBvh(sh1, BvhBuildOptions{});
        const Bvh4 wide4 = collapseToBvh4(binary);
        const Bvh8 wide8 = collapseToBvh8(binary);
        for (int width : {4, 8}) {
            std::string w = std::to_string(width), hits = "hits" + w + ".bin";
            auto run = test::runProgram(program,
                                        "trace --mesh " + test::dataDir() +
                                            "/meshes/sh1.obj --rays rays.bin --hits " + hits +
                                            " --builder sah --width " + w + " --count",
                                        dir);
            INFO(run.err);
            REQUIRE(run.exitCode == 0);
            CHECK(run.out.find("\"width\":" + w) != std::string::npos);
            // The JSON names the traced tree's node count beside the binary one's.
            BvhWideStats ws = width == 4 ? bvhWideStats(wide4) : bvhWideStats(wide8);
            CHECK(run.out.find("\"nodes_" + w + "wide\":" + std::to_string(ws.nodes)) !=
                  std::string::npos);
            // --count: the work per ray, as countWork counts it on the same tree and rays.
            TraversalCounts c = width == 4 ? countWork(wide4, rays) : countWork(wide8, rays);
            nlohmann::json j = nlohmann::json::parse(run.out);
            CHECK(ws.nodeSahCost > 1.0);  // the root and more
            CHECK(j["sah_cost_" + w + "wide"].get<double>() ==
                  doctest::Approx(ws.nodeSahCost + ws.leafSahCost));
            CHECK(j["nodes_per_ray"].get<double>() == doctest::Approx(double(c.nodes) / 600));
            CHECK(j["packets_per_ray"].get<double>() == doctest::Approx(double(c.packets) / 600));
            CHECK(j["triangles_per_ray"].get<double>() ==
                  doctest::Approx(double(c.triangles) / 600));
            CHECK(c.nodes > 600);
            CHECK(checkHitsFileAgainstBruteForce(dir.file(hits), sh1, rays) > 100);
        }
        auto bad = test::runProgram(program,
                                    "trace --mesh " + test::dataDir() +
                                        "/meshes/sh1.obj --rays rays.bin --hits h3.bin --width 3",
                                    dir);
        CHECK(bad.exitCode != 0);
        CHECK_FALSE(std::filesystem::exists(dir.file("h3.bin")));
    }
    TEST_CASE("rays command: the generator's rays and a camera placed inside") {
        test::TempDir dir;
        std::string mesh = test::dataDir() + "/meshes/sh1.obj";
        auto run = test::runProgram(
            program, "rays --mesh '" + mesh + "' --kind diffuse --count 500 --seed 4 --out d.bin",
            dir);
        REQUIRE(run.exitCode == 0);
        CHECK(nlohmann::json::parse(run.out)["rays"] == 500);
        std::vector<Ray> written = readRays(dir.file("d.bin"));
        std::vector<Ray> made = makeRays(loadObj(mesh), RayKind::Diffuse, 500, 4);
        REQUIRE(written.size() == 500);
        for (size_t i = 0; i < 500; i += 97) {
            CHECK(written[i].origin == made[i].origin);
            CHECK(written[i].direction == made[i].direction);
            CHECK(written[i].tmin == made[i].tmin);
        }
        // 4 rays (2 x 2 pixels) from (0, 0, 0) looking down -z with a 90 degree view: the
        // pixel centres are at +-0.5 of the half-width 1, so each direction is
        // (+-1, +-1, -2) / sqrt(6), row 0 at the top.
        run = test::runProgram(
            program,
            "rays --mesh '" + mesh + "' --count 4 --eye 0,0,0 --look 0,0,-1 --fov 90 --out p.bin",
            dir);
        REQUIRE(run.exitCode == 0);
        std::vector<Ray> camera = readRays(dir.file("p.bin"));
        REQUIRE(camera.size() == 4);
        float c = 1.0f / std::sqrt(6.0f);
        CHECK(camera[0].origin == Vec3(0.0f));
        CHECK(camera[0].direction.x == doctest::Approx(-c));
        CHECK(camera[0].direction.y == doctest::Approx(c));
        CHECK(camera[0].direction.z == doctest::Approx(-2 * c));
        CHECK(camera[3].direction.x == doctest::Approx(c));
        CHECK(camera[3].direction.y == doctest::Approx(-c));
        auto bad = test::runProgram(
            program, "rays --mesh '" + mesh + "' --kind random --eye 0,0,0 --out x.bin", dir);
        CHECK(bad.exitCode != 0);
        CHECK(bad.err.find("--eye") != std::string::npos);
    }
    TEST_CASE("check command: real meshes against brute force with crack rays") {
        test::TempDir dir;
        auto run = test::runProgram(program,
                                    "check --mesh " + test::dataDir() +
                                        "/meshes/sh1.obj "
                                        "--kind random --count 2000 --cracks 300",
                                    dir);
        INFO(run.out << run.err);
        CHECK(run.exitCode == 0);
        CHECK(run.out.find("\"ok\":true") != std::string::npos);
        CHECK(run.out.find("\"sah-4wide\":{\"differ\":0}") != std::string::npos);
        CHECK(run.out.find("\"sah-8wide\":{\"differ\":0}") != std::string::npos);
        auto bunny = test::runProgram(program,
                                      "check --mesh " + test::dataDir() +
                                          "/meshes/bunny.obj "
                                          "--kind diffuse --count 200 --cracks 100",
                                      dir);
        INFO(bunny.out << bunny.err);
        CHECK(bunny.exitCode == 0);
        CHECK(bunny.out.find("\"cracks\":0") != std::string::npos);
    }
    TEST_CASE("window: scripted frames with key presses under the offscreen video driver") {
        test::TempDir dir;
        test::runWindowScript(program, dir, "--scene sh1 --width 96 --height 48", 5,
                              "b,c,l,f,Left");
    }
    TEST_CASE("bad input: one clear line and a non-zero exit") {
        test::TempDir dir;
        std::string mesh = test::dataDir() + "/meshes/sh1.obj";
        std::ofstream(dir.file("short.bin"), std::ios::binary) << std::string(40, '\0');
        float nan[8] = {0, 0, 0, 0, 1, 0, std::nanf(""), 1};
        std::ofstream(dir.file("nan.bin"), std::ios::binary)
            .write(reinterpret_cast<const char*>(nan), sizeof(nan));
        float good[8] = {0, 0, 0, 0, 1, 0, 0, 1};
        std::ofstream(dir.file("good.bin"), std::ios::binary)
            .write(reinterpret_cast<const char*>(good), sizeof(good));
        test::checkBadInput(
            program, dir,
            {{"trace --mesh " + mesh + " --rays short.bin --hits bad.bin", "multiple of 32", 1},
             {"trace --mesh " + mesh + " --rays nan.bin --hits bad.bin", "NaN", 1},
             {"trace --mesh missing.obj --rays good.bin --hits bad.bin", "no such file", 1},
             {"trace --mesh " + mesh + " --rays none.bin --hits bad.bin", "no such file", 1},
             {"trace --mesh " + mesh + " --rays good.bin --hits bad.bin --builder x", "builder", 2},
             {"trace --mesh " + mesh + " --rays good.bin --hits bad.bin --threads 0", "threads", 2},
             {"--headless --out bad.png --scene missing.obj", "no such file", 1},
             {"--headless --out bad.png --bins 1", "bins", 2}},
            "", {"bad.bin", "bad.png"});
    }
}
