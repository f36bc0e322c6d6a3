// Step 03: axis-aligned bounding boxes: the bounds of shapes, union and overlap of boxes,
// and the slab test, made robust. The box itself is core's Bounds3T (closed: [min, max]).
#pragma once

#include <optional>

#include "01_triangle/triangle.hpp"  // TriangleT, as a data type only
#include "core/bounds.hpp"
#include "core/mesh.hpp"
#include "core/ray.hpp"
#include "core/shapes.hpp"

namespace boxes {

// Exercise 3.1: the bounds of a sphere: centre -+ radius on every axis.
template <typename T>
Bounds3T<T> sphereBounds(const SphereT<T>& sphere);

// Exercise 3.2: the bounds of a triangle: the smallest box holding its three vertices.
template <typename T>
Bounds3T<T> triangleBounds(const TriangleT<T>& triangle);

// Exercise 3.3: the bounds of a whole mesh: every vertex that a triangle uses (a mesh
// without triangles has the empty box, Bounds3T's default).
Bounds3f meshBounds(const Mesh& mesh);

// Exercise 3.4: the union of two boxes: the smallest box holding both, axis by axis.
// The union with an empty box (the default) is the other box.
template <typename T>
Bounds3T<T> unionBounds(const Bounds3T<T>& a, const Bounds3T<T>& b);

// The lecture slide's union with its copy-paste typo: the y line repeats the x line, so
// y gets x's extent (kept to show in the tests and the README what it breaks).
template <typename T>
Bounds3T<T> unionBoundsSlideTypo(const Bounds3T<T>& a, const Bounds3T<T>& b) {
    Bounds3T<T> r;
    r.min.x = std::min(a.min.x, b.min.x);
    r.max.x = std::max(a.max.x, b.max.x);
    r.min.y = std::min(a.min.x, b.min.x);  // the typo: .x where .y belongs
    r.max.y = std::max(a.max.x, b.max.x);
    r.min.z = std::min(a.min.z, b.min.z);
    r.max.z = std::max(a.max.z, b.max.z);
    return r;
}

// Exercise 3.5: do two closed boxes overlap? On every axis each box must begin before the
// other ends: a.min <= b.max AND b.min <= a.max. Touching counts.
template <typename T>
bool overlaps(const Bounds3T<T>& a, const Bounds3T<T>& b);

// The slide's half condition (only a.min <= b.max on each axis): reports a false overlap
// whenever b lies entirely beyond a's max side.
template <typename T>
bool overlapsHalfTest(const Bounds3T<T>& a, const Bounds3T<T>& b) {
    return a.min.x <= b.max.x && a.min.y <= b.max.y && a.min.z <= b.max.z;
}

// A ray prepared for many box tests: the reciprocal direction is computed once.
// 1/(+0.0) = +infinity and 1/(-0.0) = -infinity: the sign bit of the direction survives.
template <typename T>
struct SlabRayT {
    Vec3T<T> origin;
    Vec3T<T> invDirection;
    T tmin, tmax;
    explicit SlabRayT(const RayT<T>& ray)
        : origin(ray.origin), invDirection(T(1) / ray.direction), tmin(ray.tmin), tmax(ray.tmax) {}
};
using SlabRay = SlabRayT<float>;

// The part of [tmin, tmax] where the ray is inside the box.
template <typename T>
struct RayInterval {
    T tnear, tfar;
};

// Exercise 3.6: the robust slab test. Per axis the planes min and max give the ray
// parameters (plane - O) * (1/D); which one is near is told by the sign bit of 1/D (never
// by comparing D with 0: -0.0 == 0). Returns [tnear, tfar], clipped to [tmin, tmax], or
// nothing. Documented answers for the hard cases:
//  - D_k = +-0: 1/D_k = +-infinity, and the slab is "all t" or "no t" as it should be;
//  - O_k on the plane min_k or max_k with D_k = +-0: (plane - O) * (1/D) = 0 * inf = NaN,
//    and NaN constrains nothing: the ray lies in the face's plane, which belongs to the
//    closed box (inclusive), whatever the order of the comparisons;
//  - a flat box (min_k = max_k) is hit (tnear <= tfar compares with <=);
//  - an empty box (min > max on some axis) is never hit; a NaN coordinate constrains
//    nothing (conservative: a NaN box never hides what is inside it).
template <typename T>
std::optional<RayInterval<T>> intersectSlabs(const SlabRayT<T>& ray, const Bounds3T<T>& box);

// Exercise 3.7: the conservative slab test: as 3.6, with every far t widened by
// (1 + 2 gamma(3)) so that rounding can never turn a hit into a miss (pbrt-v4, 6.8.2;
// Ize, "Robust BVH Ray Traversal", JCGT 2013). A BVH with a watertight triangle test needs it.
template <typename T>
std::optional<RayInterval<T>> intersectSlabsConservative(const SlabRayT<T>& ray,
                                                         const Bounds3T<T>& box);

// The slab test as the slide has it: divide by D, order the two t per axis with std::min and
// std::max, and narrow [tmin, tmax]. NaN (origin on a plane, D_k = 0) makes its answer depend
// on the order of the arguments of min and max: `swapArguments` flips that order.
template <typename T>
std::optional<RayInterval<T>> intersectSlabsNaive(const RayT<T>& ray, const Bounds3T<T>& box,
                                                  bool swapArguments = false);

// A stand-in of 1e30 for 1/0 (a common trick; tinybvh PR #286 removed it): finite, so no
// NaN, but a ray lying in a face plane gets t = 0 there instead of "all t", and misses a box
// it runs along.
template <typename T>
std::optional<RayInterval<T>> intersectSlabsStandIn(const RayT<T>& ray, const Bounds3T<T>& box);

}  // namespace boxes
