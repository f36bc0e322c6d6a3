// Step 04's engine: the 04_bvh program's commands. `trace` traces a rays file against a
// mesh with any builder and width and prints one JSON line (so any tracer can be compared
// with this one, ray by ray and in speed); `check` compares every tree with brute force;
// `rays` writes ray sets.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <optional>
#include <string>

#include "04_bvh/bvh.hpp"

namespace boxes {

struct TraceCommandOptions {
    std::string mesh, rays, hits, builder = "sah";
    int threads = 1, repeat = 1, bins = BvhBuildOptions{}.bins, width = 2;
    bool count = false;
    bool chapter = false;  // width 2 through the chapter's traversal, not the engine's copy
};

// `rays`: a ray set written as RAYS.bin, for any tracer (the bench gives the same file to
// Embree and to `trace`). A primary set with --eye uses that camera instead of the framing one.
struct RaysCommandOptions {
    std::string mesh, out, kind = "primary", eye, look, up = "0,1,0";
    size_t count = 10000;
    uint64_t seed = 1;
    float fov = 60.0f;
};

struct CheckCommandOptions {
    std::string mesh, rays, kind = "random";
    size_t count = 10000, cracks = 0;
    int threads = 0;
    uint64_t seed = 1;
};

// The subcommands on the program's command line (at most one of them per run).
class EngineCommands {
public:
    explicit EngineCommands(CLI::App& app);
    EngineCommands(const EngineCommands&) = delete;  // CLI11 writes into the members
    EngineCommands& operator=(const EngineCommands&) = delete;

    // After parsing: runs the subcommand given and returns its exit code, or nothing when
    // the command line named none.
    std::optional<int> run() const;

private:
    TraceCommandOptions trace_;
    CheckCommandOptions check_;
    RaysCommandOptions rays_;
    CLI::App* traceCommand_ = nullptr;
    CLI::App* raysCommand_ = nullptr;
    CLI::App* checkCommand_ = nullptr;
};

}  // namespace boxes
