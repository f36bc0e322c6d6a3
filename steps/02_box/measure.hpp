// Step 02's measurements: six planes against slabs on random rays at oriented boxes (time
// per test, wrong answers against an extended-precision reference, where the two disagree)
// and on the primary rays of an image.
#pragma once

#include <cstdint>
#include <vector>

#include "02_box/box_scene.hpp"
#include "core/report.hpp"
#include "core/step.hpp"

namespace boxes {

// Random rays at random oriented boxes: aimed at face points, at edges, near the box, and
// a few from inside. Each ray goes with the box it was made for.
struct BoxRay {
    Ray ray;
    uint32_t box;
};
struct BoxRaySet {
    std::vector<OrientedBox> boxes;
    std::vector<BoxRay> rays;
};
BoxRaySet makeBoxRays(size_t boxCount, size_t raysPerBox, uint64_t seed);

// Time per test for both methods in float and double, and each one's wrong answers against
// the long double slab method (hit or miss, face, t). Tables "box_speed", "box_accuracy".
std::vector<Table> measureBoxMethods(const BoxRaySet& set, int repeats);

// Six planes against slabs, both in float, ray by ray: hit/miss, face, t. Table row cells.
struct Disagreement {
    long long rays = 0, hitMiss = 0, face = 0;
    double maxRelativeT = 0.0;  // max |t_planes - t_slabs| / |t| where both hit
};
Disagreement compareMethods(const BoxRaySet& set);

// Pixels whose primary ray finds another box, face or hit/miss with the other method
// (ringed in magenta on the image greyed, markPixels), and the largest relative difference
// in t where both agree. Six planes need their planes: set.setMethod(SixPlanes) once before.
struct PixelComparison {
    long long pixels = 0, differ = 0;
    double maxRelativeT = 0.0;
};
PixelComparison markDisagreements(const BoxSet& set, const Camera& camera, Image& image,
                                  int threads);

// The program's --measure: the disagreement image beside the PNG (FILE-disagree.png), the
// speed and accuracy tables on `raysPerBox` rays at each of 64 random boxes, where the two
// methods disagree, and the plots.
void measureBoxTests(const StepRun& run, BoxSet& set, size_t raysPerBox, Report& report);

}  // namespace boxes
