// Step 05's lab: every trade-off of the optimization primer measured side by side, as
// time against error (each function returns one table of the report).
#pragma once

#include <cstdint>

#include "core/render.hpp"
#include "core/report.hpp"
#include "core/scene.hpp"

namespace boxes {

struct LabOptions {
    int repeats = 5;  // timed repeats per variant (medians of these)
    int threads = 0;  // for the threads table only: every other table is one thread
    uint64_t seed = 1;
    std::string dataDir;
};

Table measureMeasuring(const LabOptions& o);    // one call per sample against batches
Table measureFloatDouble(const LabOptions& o);  // ray/triangle and ray/sphere, far scenes
Table measureAcne(const LabOptions& o);         // shadow ray self-intersection in pixels
Table measureSinCos(const LabOptions& o);       // std::sin against tables and a polynomial
Table measureEarlyOut(const Mesh& mesh, const LabOptions& o);
Table measureLightRadius(const LabOptions& o);
Table measureEffects(const LabOptions& o);  // effects on demand: analysis on / forced
Table measurePrecalculation(const Mesh& mesh, const LabOptions& o);
Table measureExpensiveOps(const LabOptions& o);  // sqrt and division per ray
Table measureInverseSqrt(const LabOptions& o);
Table measureThreads(const Scene& scene, const LabOptions& o);
Table measureAntiAliasing(const Scene& scene, const LabOptions& o);
Table measurePreviews(const Scene& scene, const LabOptions& o);

// How work is handed to threads.
enum class Schedule { StaticRows, DynamicRows, DynamicTiles };
const char* scheduleName(Schedule s);
Image renderScheduled(const Renderer& renderer, int threads, Schedule schedule);

}  // namespace boxes
