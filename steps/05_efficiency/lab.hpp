// Step 05: the optimization primer's building blocks, each an exercise: a sine table done
// right, early out, lights with a finite radius, precalculation (reciprocal directions,
// precomputed triangles) and a cheap reciprocal square root.
#pragma once

#include <bit>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <vector>

#include "core/bounds.hpp"
#include "core/exercise.hpp"
#include "core/math.hpp"
#include "core/scene.hpp"

namespace boxes {

// ---- Sine and cosine from a table -------------------------------------------------------

// What the lecture's code does, transcribed to C++ so a test can show it: the table is
// filled with `sintab[i] = Math.Sin( i / 10 );` (integer division, and degrees fed to a function that wants
// radians) and read with table[(int)(a * 10)] for an angle a in degrees (no wrap). Where
// the lecture would read outside the table (negative angles, 360 degrees and more) this
// returns nullopt instead of undefined behaviour.
struct LectureSinTable {
    std::vector<float> table;
    LectureSinTable();
    std::optional<float> sin(float degrees) const;
};

// Exercise 5.1: n entries sin(2 pi i / n), i = 0..n-1, plus one more entry equal to the
// first (so interpolation never needs a wrap for its second entry).
std::vector<float> fillSinTable(int n);

// A table of sines over one full circle; the argument is in radians, any value (wrapped).
class SinTable {
public:
    explicit SinTable(std::vector<float> entriesPlusOne);
    static SinTable make(int n) { return SinTable(fillSinTable(n)); }

    int size() const { return n_; }
    float step() const { return step_; }
    // Exercise 5.2: the nearest entry, with the index wrapped into [0, n).
    float sinNearest(float radians) const;
    // Exercise 5.3: linear interpolation between the two entries around the angle.
    float sinInterpolated(float radians) const;
    float cosNearest(float radians) const { return sinNearest(radians + 0.5f * kPi); }
    float cosInterpolated(float radians) const { return sinInterpolated(radians + 0.5f * kPi); }

    // Largest error of each way over the circle (plus float rounding of the angle and
    // entries): nearest: |sin'| <= 1 times half a step; interpolated: step^2 / 8 (the
    // error of linear interpolation, max |f''| h^2 / 8).
    double nearestErrorBound() const { return 0.5 * double(step_) + 4e-6; }
    double interpolatedErrorBound() const { return double(step_) * double(step_) / 8.0 + 4e-6; }

    const std::vector<float>& entries() const { return table_; }

private:
    std::vector<float> table_;
    int n_;
    float step_;     // 2 pi / n
    float perStep_;  // n / (2 pi), hoisted: one multiply instead of a division per call
};

// A small odd polynomial for sin on [-pi, pi] after wrapping (for the variants table).
float sinPolynomial(float radians);

// ---- Early out ---------------------------------------------------------------------------

// Exercise 5.4: any-hit for shadow rays. blocks(i) tests primitive i; stop at the first
// primitive that blocks the ray. `tests` counts the calls made.
// EXERCISE 5.4: any-hit: a shadow ray stops at the first occluder (1 point)
template <typename Blocks>
bool anyHit(size_t count, Blocks&& blocks, uint64_t& tests) {
    // BEGIN SOLUTION
    // Any occluder will do: the light is blocked, whichever blocks it first.
    for (size_t i = 0; i < count; ++i) {
        ++tests;
        if (blocks(i)) return true;
    }
    return false;
    // END SOLUTION
}

// ---- Lights with a finite radius --------------------------------------------------------

// Exercise 5.5: the distance beyond which a point light of this intensity (largest
// channel) falls below `threshold`: intensity / d^2 = threshold. The default is half an
// 8-bit step of the sRGB-encoded output (PointLight::kHalfStep8, 0.5 / 255 / 12.92 in
// linear light); with n lights, PointLight::cutoffThreshold(n) shares that half step.
float finiteLightRadius(Vec3 intensity, float threshold = PointLight::kHalfStep8);

// ---- Precalculation: the ray ---------------------------------------------------------

// Everything a slab test needs from the ray, computed once per ray instead of once per box.
struct PrecomputedRay {
    Vec3 origin;
    Vec3 invDirection;  // 1 / D per component (+-infinity for a zero component)
    int negative[3];    // 1 when the component of D is negative (the far slab is min)
    float tmin, tmax;
};
PrecomputedRay precomputeRay(const Ray& ray);

// The slab test in its division form: t = (plane - O) / D per axis, every time. Returns
// the entry distance in [tmin, tmax] (closed box) or nullopt. NaN (origin on a slab plane
// with a zero direction component) leaves the interval unchanged.
std::optional<float> slabDivision(const Ray& ray, const Bounds3f& box);

// Exercise 5.6: the same test with the reciprocal direction and the signs precomputed:
// no division, no min/max to order the two planes.
std::optional<float> slabReciprocal(const PrecomputedRay& ray, const Bounds3f& box);

// ---- Precalculation: the triangle ----------------------------------------------------

// Moller-Trumbore from the three vertices (the edges are recomputed by every test).
struct TriangleVertices {
    Vec3 a, b, c;
};
struct TriangleHitT {
    float t, u, v;
};
std::optional<TriangleHitT> intersectFromVertices(const Ray& ray, const TriangleVertices& tri);

// The data the test needs, computed once per triangle when the scene is built.
struct PrecomputedTriangle {
    Vec3 a;       // first vertex
    Vec3 e1, e2;  // b - a, c - a
    Vec3 normal;  // e1 x e2 (not normalized): the plane, for shading and culling
};
PrecomputedTriangle precomputeTriangle(const TriangleVertices& tri);

// Exercise 5.7: Moller-Trumbore on the precomputed data; bit for bit the same result as
// intersectFromVertices (same operations in the same order, minus the edge subtractions).
std::optional<TriangleHitT> intersectPrecomputed(const Ray& ray, const PrecomputedTriangle& tri);

// ---- Expensive operations ------------------------------------------------------------

// Exercise 5.8: 1/sqrt(x) from the bit trick (Lomont 2003, "Fast inverse square root") and
// one Newton step y (1.5 - 0.5 x y^2). Relative error below 0.18% for positive normal x.
// Inline, so the measurement compares it with 1/std::sqrt on equal terms (no call).
// EXERCISE 5.8: approximate 1/sqrt(x): the bit trick and one Newton step (1 point)
inline float approxInverseSqrt(float x) {
    // BEGIN SOLUTION
    // Halving the exponent bits of x (shift right) and negating them approximates
    // x^(-1/2) in the logarithmic domain; 0x5f3759df corrects the bias (Lomont 2003).
    uint32_t bits = std::bit_cast<uint32_t>(x);
    float y = std::bit_cast<float>(0x5f3759dfu - (bits >> 1));
    // One Newton step on f(y) = 1/y^2 - x.
    return y * (1.5f - 0.5f * x * y * y);
    // END SOLUTION
}

}  // namespace boxes
