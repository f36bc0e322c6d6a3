// The exam's own worked solutions of what the steps leave to the student (ray/triangle,
// the slab test, box overlap, the p-vertex culling test). The practice program must work
// in a starter kit, where the steps' versions throw NotImplemented, so it never calls them.
#pragma once

#include <optional>

#include "core/bounds.hpp"
#include "core/math.hpp"

namespace boxes::exam {

struct TriangleHitd {
    double t, u, v;  // P = (1 - u - v) A + u B + v C
};

// Moller-Trumbore in double: solve O + tD = A + u (B - A) + v (C - A) by Cramer's rule.
std::optional<TriangleHitd> rayTriangle(const Rayd& ray, const Vec3d& a, const Vec3d& b,
                                        const Vec3d& c);

struct Interval {
    double enter, exit;
};

// The slab test: the parameter interval of the line inside the closed box, when the ray
// (t >= 0) meets it. Zero direction components give +-infinity, as in IEEE arithmetic.
std::optional<Interval> raySlabs(const Rayd& ray, const Bounds3d& box);

// Closed boxes overlap when their intervals overlap on every axis (touching counts).
bool boxesOverlap(const Bounds3d& a, const Bounds3d& b);

// The p-vertex: the box corner farthest along the plane normal n.
Vec3d positiveVertex(const Bounds3d& box, const Vec3d& n);

// Culled by the plane n.p + d = 0 (inside where n.p + d >= 0) when even the p-vertex is
// outside.
bool culledByPlane(const Bounds3d& box, const Vec3d& n, double d);

}  // namespace boxes::exam
