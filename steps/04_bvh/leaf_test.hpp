// Step 04: the leaf test, the watertight ray/triangle test (Woop, Benthin and Wald, JCGT
// 2013) prepared once per ray. Not an exercise: the hierarchy's hits must not depend on
// step 01's exercise 1.5 (a starter kit's is a stub), and its loop needs the per-ray
// set-up below. tests/reliability.cpp checks it bit for bit against exercise 1.5's
// solution, hard cases included; advanced/bench_leaf_test.cpp measures what the copy buys.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "04_bvh/bvh.hpp"
#include "core/math.hpp"

namespace boxes {

// The ray's part of the test. A performance copy of step 01's exercise 1.5 (which stays
// the teaching version): the permutation and shear are computed once per ray instead of
// per triangle, and the arithmetic per triangle is otherwise the same, operation for
// operation, so the two give bit-identical t. The hierarchy's hot loop calls this one,
// inlined.
struct WatertightRay {
    Vec3 origin;
    int kx, ky, kz;
    float sx, sy, sz;
    float tmin;
    Vec3 direction;  // for the double fallback only

    explicit WatertightRay(const Ray& ray)
        : origin(ray.origin), tmin(ray.tmin), direction(ray.direction) {
        Vec3 absD = glm::abs(ray.direction);
        kz = maxDimension(absD);
        kx = (kz + 1) % 3;
        ky = (kx + 1) % 3;
        if ((&ray.direction.x)[kz] < 0.0f) std::swap(kx, ky);
        const float* d = &ray.direction.x;
        sx = d[kx] / d[kz];
        sy = d[ky] / d[kz];
        sz = 1.0f / d[kz];
    }
};

// The ray's axis order as the test reads it: here the ray's own (RayAxes, three integers);
// the engine's loops fix it at compile time instead (advanced/traverse.hpp), with the
// same arithmetic below.
struct RayAxes {
    int kx, ky, kz;
};

// The same test in double, for the rare triangle whose float arithmetic leaves float's
// range (see the callers below): exercise 1.5's fallback, operation for operation (its
// set-up in double too), so the two agree bit for bit. In double the products of float
// coordinates cannot overflow or underflow; a hit beyond float's range has no float t and
// is a miss.
template <typename Axes>
[[gnu::noinline]] bool intersectLeafTriangleDouble(Axes axes, const WatertightRay& r,
                                                   const LeafTriangle& tri, float& tmax,
                                                   float* uOut, float* vOut) {
    const int kx = axes.kx, ky = axes.ky, kz = axes.kz;
    const glm::dvec3 d(r.direction), o(r.origin);
    const double sx = d[kx] / d[kz], sy = d[ky] / d[kz], sz = 1.0 / d[kz];
    const glm::dvec3 av = glm::dvec3(tri.a) - o, bv = glm::dvec3(tri.b) - o,
                     cv = glm::dvec3(tri.c) - o;
    double ax = av[kx] - sx * av[kz], ay = av[ky] - sy * av[kz];
    double bx = bv[kx] - sx * bv[kz], by = bv[ky] - sy * bv[kz];
    double cx = cv[kx] - sx * cv[kz], cy = cv[ky] - sy * cv[kz];
    double u = cx * by - cy * bx, v = ax * cy - ay * cx, w = bx * ay - by * ax;
    if ((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)) return false;
    double det = u + v + w;
    if (det == 0.0 || !std::isfinite(det)) return false;
    double az = sz * av[kz], bz = sz * bv[kz], cz = sz * cv[kz];
    double t = (u * az + v * bz + w * cz) / det;
    if (!(t >= double(r.tmin) && t <= double(tmax) && std::isfinite(t))) return false;
    if (!(std::fabs(float(t)) <= std::numeric_limits<float>::max())) return false;
    tmax = float(t);
    if (uOut) *uOut = float(v / det);
    if (vOut) *vOut = float(w / det);
    return true;
}

// A hit in [ray.tmin, tmax] lowers tmax to it; (u, v) are the barycentrics of b and c.
// Axes must be the ray's order (r.kx, r.ky, r.kz); the arithmetic is exercise 1.5's.
template <typename Axes>
inline bool intersectLeafTriangle(Axes axes, const WatertightRay& r, const LeafTriangle& tri,
                                  float& tmax, float* uOut = nullptr, float* vOut = nullptr) {
    const int kx = axes.kx, ky = axes.ky, kz = axes.kz;
    const Vec3 av = tri.a - r.origin, bv = tri.b - r.origin, cv = tri.c - r.origin;
    const float *a = &av.x, *b = &bv.x, *c = &cv.x;
    float ax = a[kx] - r.sx * a[kz], ay = a[ky] - r.sy * a[kz];
    float bx = b[kx] - r.sx * b[kz], by = b[ky] - r.sy * b[kz];
    float cx = c[kx] - r.sx * c[kz], cy = c[ky] - r.sy * c[kz];
    float u = cx * by - cy * bx;
    float v = ax * cy - ay * cx;
    float w = bx * ay - by * ax;
    // Exactly zero: recompute in double so neighbours agree on the shared edge.
    if (u == 0.0f || v == 0.0f || w == 0.0f) [[unlikely]] {
        u = float(double(cx) * double(by) - double(cy) * double(bx));
        v = float(double(ax) * double(cy) - double(ay) * double(cx));
        w = float(double(bx) * double(ay) - double(by) * double(ax));
    }
    float det = u + v + w;  // not finite exactly when an edge function overflowed
    if (!std::isfinite(det)) [[unlikely]]
        return intersectLeafTriangleDouble(axes, r, tri, tmax, uOut, vOut);
    // Bitwise | and & on the comparisons: one branch, mostly taken (most tests miss),
    // instead of a chain of unpredictable ones.
    bool negative = (u < 0.0f) | (v < 0.0f) | (w < 0.0f);
    bool positive = (u > 0.0f) | (v > 0.0f) | (w > 0.0f);
    if ((negative & positive) | (det == 0.0f)) return false;
    float az = r.sz * a[kz], bz = r.sz * b[kz], cz = r.sz * c[kz];
    float tScaled = u * az + v * bz + w * cz;
    // Outside the normal range the products may have underflowed to zeros whose signs no
    // longer add up (t = -0 for a triangle behind the ray, |d| = 1e28) or overflowed (t =
    // inf for a triangle 3e38 away): both found by fuzz_rays. Decide in double instead.
    float magnitude = std::fabs(tScaled);
    if (!(magnitude >= std::numeric_limits<float>::min() &&
          magnitude <= std::numeric_limits<float>::max())) [[unlikely]]
        return intersectLeafTriangleDouble(axes, r, tri, tmax, uOut, vOut);
    float t = tScaled / det;
    // A hit beyond the float range (t = +-inf) is a miss: HITS.bin has no t for it.
    if (!(t >= r.tmin && t <= tmax && std::fabs(t) <= std::numeric_limits<float>::max()))
        return false;
    tmax = t;
    if (uOut) *uOut = v / det;
    if (vOut) *vOut = w / det;
    return true;
}

// The test with the ray's own axis order: the one the chapter's loops call.
inline bool intersectLeafTriangle(const WatertightRay& r, const LeafTriangle& tri, float& tmax,
                                  float* uOut = nullptr, float* vOut = nullptr) {
    return intersectLeafTriangle(RayAxes{r.kx, r.ky, r.kz}, r, tri, tmax, uOut, vOut);
}

}  // namespace boxes
