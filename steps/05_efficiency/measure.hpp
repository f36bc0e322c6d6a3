// Step 05's lab: every trade-off of the optimization primer measured side by side, as
// time against error. Each function returns one table of the report and lives in its own
// file under experiments/.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "core/render.hpp"
#include "core/report.hpp"
#include "core/scene.hpp"
#include "core/step.hpp"
#include "core/timing.hpp"

namespace boxes {

class LabBvhMesh;

struct LabOptions {
    int repeats = 5;  // timed repeats per variant (medians of these)
    int threads = 0;  // for the threads table only: every other table is one thread
    uint64_t seed = 1;
    std::string dataDir;
    bool quick = false;             // a quarter of the image sizes and far fewer samples (tests)
    int width = 640, height = 480;  // the run's image size (the identity check of effects)
};

Table measureMeasuring(const LabOptions& o);    // one call per sample against batches
Table measureFloatDouble(const LabOptions& o);  // ray/triangle and ray/sphere, far scenes
Table measureAcne(const LabOptions& o);         // shadow ray self-intersection in pixels
Table measureSinCos(const LabOptions& o);       // std::sin against tables and a polynomial
Table measureEarlyOut(LabBvhMesh& mesh, const LabOptions& o);  // step 04's tree
Table measureLightRadius(const LabOptions& o);
// Effects on demand against the fair baseline (zero-weight rays skipped, no analysis):
// rays and time; each part of the analysis alone and all but it; and every built-in scene
// and shipped mesh at the run's size, bit-identical (else std::runtime_error).
Table measureEffects(const LabOptions& o);
Table measureEffectParts(const LabOptions& o);
Table measureEffectIdentity(const LabOptions& o);
// The scenes of the first two: every built-in scene of spheres and planes, and the bunny.
const std::vector<std::string>& effectsSceneNames();
Table measurePrecalculation(LabBvhMesh& mesh, const LabOptions& o);
Table measureExpensiveOps(const LabOptions& o);  // sqrt and division per ray
Table measureInverseSqrt(const LabOptions& o);
// The cost of one operation (the primer's list: sin, cos, sqrt, /, *, +, -) in float and
// double: ns per operation in a dependent chain, and the largest relative error of one
// operation against long double.
struct OpCost {
    std::string op, type;  // "sqrt", "float"
    double nsMedian, nsMin, nsMax;
    double relError;
};
std::vector<OpCost> measureOpCosts(const LabOptions& o);
Table measureOpCost(const LabOptions& o);
// The choice of language: one kernel under different compiler flags (language.hpp).
Table measureLanguage(const LabOptions& o);
Table measureThreads(const Scene& scene, const LabOptions& o);
Table measureAntiAliasing(const Scene& scene, const LabOptions& o);
Table measurePreviews(const Scene& scene, const LabOptions& o);
Table measureTotalSpeedup(const Scene& scene, const LabOptions& o);  // all together

// The program's --measure: every table above in the primer's order, the mesh tables on
// `mesh` (the bunny when it is null), with their plots and the total speed-up as a fact.
void measureLab(const Scene& scene, LabBvhMesh* mesh, const LabOptions& o, Report& report);

// The headless run's other images: every preview mode beside the PNG (FILE-depth.png, ...),
// and the image refined line by line in frames of budgetMs, which must be bit-identical to
// run.image (else std::runtime_error).
void writePreviews(const StepRun& run, double budgetMs, Report& report);

// Times each function `repeats` times, one call of each per round (round-robin), so a
// drift in the machine's load is shared by all of them. One Timing per function.
std::vector<Timing> measureInterleaved(int repeats, const std::vector<std::function<void()>>& fns);
// The same, the raw samples: samples[i][round] in seconds (for ratios taken per round).
std::vector<std::vector<double>> sampleInterleaved(int repeats,
                                                   const std::vector<std::function<void()>>& fns);

// How work is handed to threads.
enum class Schedule { StaticRows, DynamicRows, DynamicTiles };
const char* scheduleName(Schedule s);
Image renderScheduled(const Renderer& renderer, int threads, Schedule schedule);

}  // namespace boxes
