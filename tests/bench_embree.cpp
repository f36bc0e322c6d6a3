// The bench's Embree harness (tools/bench/) against step 04's engine on the same rays: the
// bench's speed ratios mean something only if both tracers find the same hits.
#include <doctest/doctest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <vector>

#include "04_bvh/advanced/batch.hpp"
#include "04_bvh/advanced/build.hpp"
#include "04_bvh/advanced/bvh4.hpp"
#include "04_bvh/advanced/rays.hpp"
#include "embree_tracer.hpp"
#include "support.hpp"

using namespace boxes;

namespace {

struct Agreement {
    size_t rays = 0, hits = 0, sameTriangle = 0, sameT = 0, closeT = 0;
};

// Same triangle, or the same t (an edge or vertex two triangles share); closeT: rays with
// the same triangle whose two t differ by at most 1e-5 relative (Embree's float test and
// the engine's watertight one round differently).
Agreement compare(const std::vector<TraceHit>& embree, const std::vector<TraceHit>& ours) {
    Agreement a;
    a.rays = ours.size();
    for (size_t i = 0; i < ours.size(); ++i) {
        a.hits += ours[i].triangle != kNoPrimitive;
        bool same = embree[i].triangle == ours[i].triangle;
        a.sameTriangle += same;
        a.sameT += !same && embree[i].t == ours[i].t;
        a.closeT += same && (ours[i].triangle == kNoPrimitive ||
                             std::abs(embree[i].t - ours[i].t) <= 1e-5f * ours[i].t);
    }
    return a;
}

}  // namespace

TEST_SUITE("bench") {
    TEST_CASE("Embree and the engine's 8-wide tree find the same hits on the bunny") {
        Mesh mesh = loadObj(test::dataDir() + "/meshes/bunny.obj");
        EmbreeTracer embree(mesh, "threads=1");
        Bvh8 wide = collapseToBvh8(buildEngineBvh(mesh, BvhBuildOptions{}));
        for (RayKind kind : {RayKind::Primary, RayKind::Diffuse, RayKind::Random}) {
            CAPTURE(rayKindName(kind));
            std::vector<Ray> rays = makeRays(mesh, kind, 4000, 5);
            std::vector<TraceHit> theirs, ours;
            embree.trace(rays, theirs, 1);
            traceBatch(wide, rays, ours, 1);
            REQUIRE(theirs.size() == rays.size());
            Agreement a = compare(theirs, ours);
            // Every kind hits the bunny often: a tracer that missed everything would agree too.
            CHECK(a.hits > rays.size() / 20);
            // Embree's non-robust test may slip through an edge a watertight test closes:
            // "nearly every ray", at most 1 in 1000 apart.
            CHECK(a.sameTriangle + a.sameT >= rays.size() - rays.size() / 1000);
            CHECK(a.closeT >= a.sameTriangle - rays.size() / 1000);
        }
    }

    TEST_CASE("Embree on two threads gives the hits of one") {
        Mesh mesh = loadObj(test::dataDir() + "/meshes/sh1.obj");
        EmbreeTracer embree(mesh, "threads=2");
        std::vector<Ray> rays = makeRays(mesh, RayKind::Diffuse, 10000, 3);
        std::vector<TraceHit> one, two;
        embree.trace(rays, one, 1);
        embree.trace(rays, two, 2);
        CHECK(one == two);
    }

    TEST_CASE("embree_trace writes the hits of the engine's trace command for a rays file") {
        test::TempDir dir;
        std::string mesh = test::dataDir() + "/meshes/sh1.obj";
        Mesh loaded = loadObj(mesh);
        writeRays(dir.file("rays.bin"), makeRays(loaded, RayKind::Random, 3000, 9));
        auto embree =
            test::runProgram(BOXES_EMBREE_TRACE,
                             "--mesh '" + mesh + "' --rays rays.bin --hits e.bin --repeat 2", dir);
        REQUIRE(embree.exitCode == 0);
        auto ours = test::runProgram(
            BOXES_PROGRAM_04, "trace --mesh '" + mesh + "' --rays rays.bin --hits o.bin", dir);
        REQUIRE(ours.exitCode == 0);
        nlohmann::json j = nlohmann::json::parse(embree.out);
        CHECK(j["rays"] == 3000);
        CHECK(j["tris"] == 3290);
        CHECK(j["repeat"] == 2);
        CHECK(j["mrays_per_s"].get<double>() > 0.0);
        std::vector<TraceHit> theirs = readHits(dir.file("e.bin")),
                              mine = readHits(dir.file("o.bin"));
        REQUIRE(theirs.size() == 3000);
        REQUIRE(mine.size() == 3000);
        Agreement a = compare(theirs, mine);
        size_t embreeHits = 0;
        for (const TraceHit& h : theirs) embreeHits += h.triangle != kNoPrimitive;
        CHECK(j["hits"] == embreeHits);
        CHECK(a.hits > 300);
        CHECK(a.sameTriangle + a.sameT >= 2997);
        // A bad or missing rays file is one line on stderr and exit 2.
        auto bad = test::runProgram(BOXES_EMBREE_TRACE,
                                    "--mesh '" + mesh + "' --rays missing.bin --hits e.bin", dir);
        CHECK(bad.exitCode == 2);
        CHECK(bad.err.find("missing.bin") != std::string::npos);
    }
}
