// The exact answer to "does the ray meet the closed box in [tmin, tmax]?" for float rays and
// boxes on a dyadic grid, and a set of hard rays to grade slab tests against it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/bounds.hpp"
#include "core/math.hpp"

namespace boxes {

// Every coordinate of the hard rays and boxes is a multiple of 2^-kGridBits with magnitude
// below 16, and tmax a multiple of 2^-10 (or infinite), so scaled by 2^kGridBits they are
// integers below 2^25 and the reference decides with exact 64-bit integer products.
constexpr int kGridBits = 20;

// Exact: per axis the t where the ray is inside the slab is a fraction with an integer
// numerator and denominator (or all t, or none, when D_k = 0); the ray meets the box when
// every lower end is <= every upper end, tmin and tmax included. Throws
// std::invalid_argument when a value is not on the grid.
bool exactRayMeetsBox(const Ray& ray, const Bounds3f& box);

struct HardSlabRay {
    Ray ray;
    Bounds3f box;
    int category;  // index into hardSlabCategories()
    bool exact;    // exactRayMeetsBox(ray, box)
};
const std::vector<std::string>& hardSlabCategories();

// Rays through edges and corners, just past them, along face planes, with +-0 components,
// from inside, at flat boxes, behind, and ending just before or exactly at the box.
std::vector<HardSlabRay> makeHardSlabRays(size_t perCategory, uint64_t seed);

}  // namespace boxes
