// The rays file of step 04's `trace` command (steps/04_bvh/advanced/rays.cpp parseRays,
// the bytes readRays reads). Promise: the rays, or an InputError of one line that names the
// file; a small accepted file is then traced against a tiny mesh through three hierarchies
// (SAH, midpoint, 4-wide), each hit agreeing with brute force and lying in the ray's
// interval (tmin > tmax: a miss), and HITS.bin written atomically and read back unchanged.
#include <unistd.h>

#include <cstring>
#include <filesystem>

#include "04_bvh/advanced/bvh4.hpp"
#include "04_bvh/advanced/rays.hpp"
#include "core/exercise.hpp"
#include "fuzz/fuzz_common.hpp"

namespace {

using namespace boxes;

// A cube (two triangles a face: shared edges and vertices), a zero-area triangle and two
// coplanar overlapping triangles (equally near hits).
Mesh tinyMesh() {
    Mesh mesh;
    mesh.positions = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}, {-1, -1, 1},
                      {1, -1, 1},   {1, 1, 1},   {-1, 1, 1}, {0, 0, 3},   {1, 1, 3},
                      {2, 2, 3},    {3, 0, 2},   {3, 2, 2},  {5, 0, 2}};
    mesh.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 7, 6},  {4, 6, 5},    {0, 4, 5},
                      {0, 5, 1}, {1, 5, 6}, {1, 6, 2},  {2, 6, 7},    {2, 7, 3},
                      {4, 0, 3}, {4, 3, 7}, {8, 9, 10}, {11, 12, 13}, {11, 13, 12}};
    mesh.computeVertexNormals();
    return mesh;
}

struct Fixture {
    Mesh mesh = tinyMesh();
    Bvh sah, midpoint;
    Bvh4 wide;   // the 4-wide SSE tree collapsed from the SAH tree
    Bvh8 wide8;  // and the 8-wide one
    std::string hitsPath;
    Fixture() {
        BvhBuildOptions options;
        options.maxLeafSize = 2;
        sah = buildBvh(mesh, options);
        wide = collapseToBvh4(sah);
        wide8 = collapseToBvh8(sah);
        options.builder = BvhBuilder::Midpoint;
        options.leafSize = 1;
        midpoint = buildBvh(mesh, options);
        hitsPath = (std::filesystem::temp_directory_path() /
                    ("boxes-fuzz-rays-" + std::to_string(getpid()) + ".bin"))
                       .string();
    }
};

// nullptr in a starter kit, where the hierarchy's exercises are not solved yet: then
// only the reading is checked.
Fixture* fixture() {
    static Fixture* f = []() -> Fixture* {
        try {
            return new Fixture;
        } catch (const NotImplemented& e) {
            std::fprintf(stderr, "fuzz_rays: tracing skipped (%s)\n", e.what());
            return nullptr;
        }
    }();
    return f;
}

void checkHit(const Ray& ray, const TraceHit& hit, const TraceHit& reference, size_t triangles,
              const char* which) {
    if (hit.triangle == kNoPrimitive) {
        if (hit.t != kInfinity<float>) fuzz::fail(std::string(which) + ": a miss with finite t");
    } else {
        if (hit.triangle >= triangles) fuzz::fail(std::string(which) + ": triangle out of range");
        if (!(hit.t >= ray.tmin && hit.t <= ray.tmax))
            fuzz::fail(std::string(which) + ": hit outside [tmin, tmax]");
        if (ray.tmin > ray.tmax) fuzz::fail(std::string(which) + ": hit in an empty interval");
    }
    if (!hitsAgree(hit, reference)) fuzz::fail(std::string(which) + ": disagrees with brute force");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::vector<Ray> rays;
    try {
        rays = parseRays(data, size, "rays file 'fuzz.bin'");
    } catch (const InputError& e) {
        fuzz::checkMessage(e.what());
        if (std::string(e.what()).rfind("rays file 'fuzz.bin'", 0) != 0)
            fuzz::fail(std::string("message does not name the file: ") + e.what());
        return 0;
    }
    if (rays.size() * sizeof(RayRecord) != size) fuzz::fail("a ray was dropped");
    for (const Ray& r : rays)
        if (!isFinite(r.origin) || !isFinite(r.direction) || isZero(r.direction) ||
            std::isnan(r.tmin) || std::isnan(r.tmax))
            fuzz::fail("an invalid ray was accepted");
    if (rays.size() > 64 || !fixture()) return 0;  // tracing: small files only, to be fast

    Fixture& f = *fixture();
    std::vector<TraceHit> reference, sah, midpoint, wide, wide8;
    traceBatchBruteForce(f.mesh, rays, reference, 1);
    traceBatch(f.sah, rays, sah, 1);
    traceBatch(f.midpoint, rays, midpoint, 1);
    traceBatch(f.wide, rays, wide, 1);
    traceBatch(f.wide8, rays, wide8, 1);
    for (size_t i = 0; i < rays.size(); ++i) {
        // Every ray, however far its origin: the leaf test's double fallbacks and the box
        // margin (it grows with the distance) keep the hierarchy equal to brute force.
        const TraceHit& want = reference[i];
        checkHit(rays[i], want, want, f.mesh.triangleCount(), "brute force");
        checkHit(rays[i], sah[i], want, f.mesh.triangleCount(), "SAH hierarchy");
        checkHit(rays[i], midpoint[i], want, f.mesh.triangleCount(), "midpoint hierarchy");
        checkHit(rays[i], wide[i], want, f.mesh.triangleCount(), "4-wide hierarchy");
        checkHit(rays[i], wide8[i], want, f.mesh.triangleCount(), "8-wide hierarchy");
        // traceBatch runs its AVX2 loop where the CPU has it; traceNearest is the baseline
        // code: the same bits.
        TraceHit baseSah = traceNearest(f.sah, rays[i]), baseWide = traceNearest(f.wide, rays[i]),
                 baseWide8 = traceNearest(f.wide8, rays[i]);
        if (std::memcmp(&baseSah, &sah[i], sizeof(TraceHit)) != 0 ||
            std::memcmp(&baseWide, &wide[i], sizeof(TraceHit)) != 0 ||
            std::memcmp(&baseWide8, &wide8[i], sizeof(TraceHit)) != 0)
            fuzz::fail("the batch loop and traceNearest differ");
        if (traceOccluded(f.wide, rays[i]) != (want.triangle != kNoPrimitive))
            fuzz::fail("4-wide occlusion disagrees with the nearest hit");
        if (traceOccluded(f.wide8, rays[i]) != (want.triangle != kNoPrimitive))
            fuzz::fail("8-wide occlusion disagrees with the nearest hit");
        if (traceOccluded(f.sah, rays[i]) != (want.triangle != kNoPrimitive))
            fuzz::fail("occlusion disagrees with the nearest hit");
    }
    writeHits(f.hitsPath, sah);
    std::vector<TraceHit> back = readHits(f.hitsPath);
    if (back.size() != sah.size() ||
        (!sah.empty() && std::memcmp(back.data(), sah.data(), sah.size() * sizeof(TraceHit)) != 0))
        fuzz::fail("HITS.bin did not read back unchanged");
    std::filesystem::remove(f.hitsPath);
    return 0;
}
