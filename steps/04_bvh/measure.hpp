// Step 04's tables (`--measure`): builds, trace speed against brute force, threads, cracks,
// frustum culling counts and build time against trace speed. Part of the program, not of
// the chapter's library: the tables measure the engine's builders and trees beside the
// exercises'.
#pragma once

#include <string>
#include <vector>

#include "04_bvh/advanced/measure.hpp"
#include "04_bvh/trace.hpp"
#include "core/app.hpp"
#include "core/report.hpp"

namespace boxes {

// Per builder: build ms (median), nodes, leaves, leaf sizes, depth, SAH cost and its
// excess over the full-sweep SAH tree. Table id "bvh_build".
Table measureBuilds(const NamedMesh& mesh, int bins, int repeats);

// Per builder and ray kind: Mrays/s on one thread (median of repeats), the tree's SAH cost
// and the rays whose nearest hit differs from brute force on a sample (no build time: that
// is bvh_build's). Table id "bvh_trace".
Table measureTraceSpeed(const NamedMesh& mesh, size_t rays, size_t bruteForceRays, int repeats,
                        uint64_t seed, int bins);

// 1 thread against 2 (binned SAH, primary and diffuse rays). Table id "bvh_threads".
Table measureThreads(const NamedMesh& mesh, size_t rays, int repeats, uint64_t seed);

// Culled / kept / wrongly kept nodes for both tests from cameras around the mesh, close
// enough that the frustum cuts it. Table id "bvh_culling".
Table measureCulling(const NamedMesh& mesh, const Bvh& bvh, int cameras);

// Build time (bvh_build's median) and trace speed per builder (primary rays) beside the rays
// it loses against brute force and its cracks, from measureBuilds's, measureTraceSpeed's and
// measureBvhCracks's tables. Table id "bvh_tradeoff".
Table measureTradeoff(const Table& builds, const Table& traceSpeed, const Table& cracks);

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
// The headless report's part of the tree: its figures (build_ms, nodes, sah_cost) and the
// culling map beside `png`.
void addTreeReport(Report& report, const Scene& scene, const MeshBvhGeometry& geometry,
                   const std::string& png, const CommonOptions& options);
// --measure: addMeasurements on the scene's mesh and the program's tree (seed and data
// folder from `options`), and the heat maps of a ray's cost per builder beside `png`
// (cost_map.hpp).
void measureTree(Report& report, const Scene& scene, const MeshBvhGeometry& geometry,
                 const CommonOptions& options, const MeasureSettings& settings,
                 const std::string& png);
// --measure-rays and --crack-rays into `settings`.
void addMeasureOptions(CLI::App& app, MeasureSettings& settings);

}  // namespace boxes
