// Step 03's measurements: the slab tests' speed against their wrong answers on hard rays,
// and a scene rendered with and without a bounding-box pre-test.
#pragma once

#include <vector>

#include "03_aabb/slab_reference.hpp"
#include "03_aabb/why_we_care.hpp"
#include "core/render.hpp"
#include "core/report.hpp"
#include "core/step.hpp"

namespace boxes {

enum class SlabVariant { Naive, NaiveSwapped, StandIn, Robust, Conservative };
constexpr SlabVariant kAllSlabVariants[] = {SlabVariant::Naive, SlabVariant::NaiveSwapped,
                                            SlabVariant::StandIn, SlabVariant::Robust,
                                            SlabVariant::Conservative};
const char* slabVariantName(SlabVariant v);
bool slabHit(SlabVariant v, const Ray& ray, const SlabRay& slabRay, const Bounds3f& box);

// "slab_accuracy" (ns/test, false misses, false hits per variant) and "slab_hard_rays"
// (wrong answers per category of hard ray and variant).
std::vector<Table> measureSlabTests(const std::vector<HardSlabRay>& rays, int repeats);

// Renders the scene with and without the pre-test: time per frame, tests per ray, and
// the pixels that differ. Table "pretest".
struct PretestResult {
    Table table;
    Image with, without;
    size_t pixelsDiffering = 0;
    PixelCosts withCosts, withoutCosts;  // each pixel's tests in those same frames
};
PretestResult measurePretest(ManyObjects& objects, const Camera& camera,
                             const RenderSettings& settings);

// The heat maps of the pretest table's frames beside the PNG (-heat-without, -heat-with:
// primitive tests per pixel on one log scale; -heat-boxes: box tests), and their means per
// ray as facts, which equal the table's counts per ray.
void addHeatMaps(const StepRun& run, const PretestResult& p, Report& report);

// The program's --measure: the slab tests on `hardRays` hard rays per category, and the
// scene's frames with and without the pre-test at `frameWidth` x `frameHeight`, with the
// plots.
void measureBoundingBoxes(const StepRun& run, ManyObjects& objects, size_t hardRays, int frameWidth,
                          int frameHeight, Report& report);

}  // namespace boxes
