// Step 04's tables (`--measure`) and the engine's commands on the program's command line:
// part of the program, not of the chapter. The tables (builds, trace speed against brute
// force, threads, cracks, frustum culling, build time against trace speed) measure the
// engine's builders and trees (advanced/) beside the exercises', and `trace`, `check` and
// `rays` are the engine's; this header names nothing of the engine, so the chapter's
// main.cpp includes nothing under advanced/.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "04_bvh/trace.hpp"
#include "core/app.hpp"
#include "core/report.hpp"

namespace boxes {

struct MeasureSettings {
    int bins = 16;
    size_t traceRays = 100000, crackRays = 5000;
    uint64_t seed = 1;
    std::string dataDir;
};
// --measure-rays and --crack-rays into `settings`.
void addMeasureOptions(CLI::App& app, MeasureSettings& settings);

// --measure: the tables on the scene's mesh and the program's tree (seed and data folder
// from `options`), with the crack count on the bunny and sh1, and the plots; and the heat
// maps of a ray's cost per builder beside `png` (cost_map.hpp).
void measureTree(Report& report, const Scene& scene, const MeshBvhGeometry& geometry,
                 const CommonOptions& options, const MeasureSettings& settings,
                 const std::string& png);

// The engine's subcommands (trace, check, rays: advanced/commands.hpp) added to `app`; the
// function returned runs the one the command line named, after parsing, and returns its
// exit code, or nullopt when it named none.
std::function<std::optional<int>()> addEngineCommands(CLI::App& app);

}  // namespace boxes
