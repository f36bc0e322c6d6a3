// Step 04's tables (`--measure`): builds, trace speed against brute force, threads, cracks,
// frustum culling counts and build time against trace speed; and the top-down picture of
// the culled hierarchy. Part of the program, not of the chapter's library: the tables
// measure the engine's builders and trees beside the exercises'.
#pragma once

#include <string>
#include <vector>

#include "04_bvh/advanced/measure.hpp"
#include "04_bvh/frustum.hpp"
#include "04_bvh/trace.hpp"
#include "core/image.hpp"
#include "core/report.hpp"

namespace boxes {

// Per builder: build ms (median), nodes, leaves, leaf sizes, depth, SAH cost and its
// excess over the full-sweep SAH tree. Table id "bvh_build".
Table measureBuilds(const NamedMesh& mesh, int bins, int repeats);

// Per builder and ray kind: Mrays/s on one thread (median of repeats) and the rays whose
// nearest hit differs from brute force on a sample. Table id "bvh_trace".
Table measureTraceSpeed(const NamedMesh& mesh, size_t rays, size_t bruteForceRays, int repeats,
                        uint64_t seed, int bins);

// 1 thread against 2 (binned SAH, primary and diffuse rays). Table id "bvh_threads".
Table measureThreads(const NamedMesh& mesh, size_t rays, int repeats, uint64_t seed);

// Culled / kept / wrongly kept nodes for both tests from cameras around the mesh, close
// enough that the frustum cuts it. Table id "bvh_culling".
Table measureCulling(const NamedMesh& mesh, const Bvh& bvh, int cameras);

// Build time against trace speed per builder (primary rays), from measureTraceSpeed's
// table. Table id "bvh_tradeoff".
Table measureTradeoff(const Table& traceSpeed);

// The whole `--measure` run on the scene's mesh and `bvh` (the program's tree), with the
// crack count on the bunny and sh1 from dataDir, and the trade-off's plot.
struct MeasureSettings {
    int bins = 16;
    size_t traceRays = 100000, crackRays = 5000;
    uint64_t seed = 1;
    std::string dataDir;
};
void addMeasurements(Report& report, const NamedMesh& mesh, const Bvh& bvh,
                     const MeasureSettings& settings);

// The culling camera for view `index` of `count` around the mesh (used by the measure run
// and the window's starting view): near the surface, far plane at the mesh's centre.
struct CullingView {
    Camera camera;
    float nearDistance, farDistance;
};
CullingView cullingView(const Bounds3f& bounds, int index, int count, float aspect);

// Draws the hierarchy's boxes at `level` (leaves above it too) seen from above (along
// `up`), coloured by the test's verdict, and the frustum's outline.
void drawCullingMap(Image& image, int x0, int width, const Bvh& bvh, const Frustum& frustum,
                    CullTest test, int level, Vec3 up);

// The headless run's culling map: the hierarchy from above (depth 6) in the first measuring
// view, written beside `png` (suffix "-cull") and added to the report.
void addCullingMap(Report& report, const Bvh& bvh, const std::string& png, int width, int height,
                   Vec3 up);

}  // namespace boxes
