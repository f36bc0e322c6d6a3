// Step 03: axis-aligned bounding boxes: the bounds of shapes, union and overlap of boxes,
// and the slab test, made robust. The box itself is core's Bounds3T (closed: [min, max]).
#pragma once

#include <algorithm>
#include <limits>
#include <optional>

#include "01_triangle/triangle.hpp"  // TriangleT, as a data type only
#include "core/bounds.hpp"
#include "core/math.hpp"
#include "core/mesh.hpp"

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

// The lecture's union slide, line for line, typo included: its bmin.y line takes the
// minimum of A.bmin.y and B.bmin.x (every other line is right). The y extent then starts
// at B's x minimum whenever that is below both y minima (too big: only slower), and misses
// the bottom of B whenever B.bmin.y lies below A.bmin.y and B.bmin.x (too small: lost hits).
// Kept for the tests and docs/errata.md.
template <typename T>
Bounds3T<T> unionBoundsSlideTypo(const Bounds3T<T>& A, const Bounds3T<T>& B) {
    Bounds3T<T> box;
    box.min.x = std::min(A.min.x, B.min.x);
    box.max.x = std::max(A.max.x, B.max.x);
    box.min.y = std::min(A.min.y, B.min.x);  // the slide's typo: B.bmin.x where B.bmin.y belongs
    box.max.y = std::max(A.max.y, B.max.y);
    box.min.z = std::min(A.min.z, B.min.z);
    box.max.z = std::max(A.max.z, B.max.z);
    return box;
}

// Exercise 3.5: do two closed boxes overlap? On every axis each box must begin before the
// other ends: a.min <= b.max AND b.min <= a.max. Touching counts.
template <typename T>
bool overlaps(const Bounds3T<T>& a, const Bounds3T<T>& b);

// The lecture's overlap slide as written: (A.bmin.x < B.bmax.x) && (A.bmin.y < B.bmax.y)
// && (A.bmin.z < B.bmax.z). Two errors: half the condition (B.bmin < A.bmax is missing,
// so a B entirely beyond A's max side "overlaps"), and strict < (closed boxes that touch,
// A.bmin = B.bmax, "do not").
template <typename T>
bool overlapsHalfTest(const Bounds3T<T>& A, const Bounds3T<T>& B) {
    return (A.min.x < B.max.x) && (A.min.y < B.max.y) && (A.min.z < B.max.z);
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

// The naive slab test: the slide's pseudo-code completed (all three axes, the ray's
// [tmin, tmax], a hit when tnear <= tfar): divide by D, order the two t per axis with
// std::min and std::max. NaN (origin on a plane, D_k = 0) makes its answer depend on the
// order of the arguments of min and max: `swapArguments` flips that order.
template <typename T>
std::optional<RayInterval<T>> intersectSlabsNaive(const RayT<T>& ray, const Bounds3T<T>& box,
                                                  bool swapArguments = false);

// The lecture's slab pseudo-code, line for line ("r.0" is the origin O): x and y only, no
// z, no t >= 0, and `return tmax >= tmin`. It answers "does the infinite line meet the
// box's x-y rectangle": a ray passing above the box in z, or a box behind the ray, is a hit.
template <typename T>
bool intersectionSlidePseudoCode(const Bounds3T<T>& b, const RayT<T>& r) {
    T tx1 = (b.min.x - r.origin.x) / r.direction.x;
    T tx2 = (b.max.x - r.origin.x) / r.direction.x;

    T tmin = std::min(tx1, tx2);
    T tmax = std::max(tx1, tx2);

    T ty1 = (b.min.y - r.origin.y) / r.direction.y;
    T ty2 = (b.max.y - r.origin.y) / r.direction.y;

    tmin = std::max(tmin, std::min(ty1, ty2));
    tmax = std::min(tmax, std::max(ty1, ty2));

    return tmax >= tmin;
}

// The slab slide's formulas as written: start with t_min = +inf, t_max = -inf, per axis
// t_min = max(t_min, min(t1, t2)) and t_max = min(t_max, max(t1, t2)), a hit if
// t_min < t_max. The start values are swapped, so t_min stays +inf and t_max -inf and no
// ray ever hits. `tminStart` and `tmaxStart` let a test put them right (-inf, +inf) to show
// the other error: the strict < misses a flat box, where t_min = t_max.
template <typename T>
bool intersectionSlideFormulas(const RayT<T>& ray, const Bounds3T<T>& box,
                               T tminStart = std::numeric_limits<T>::infinity(),
                               T tmaxStart = -std::numeric_limits<T>::infinity()) {
    T tmin = tminStart, tmax = tmaxStart;
    for (int k = 0; k < 3; ++k) {
        T t1 = (box.min[k] - ray.origin[k]) / ray.direction[k];
        T t2 = (box.max[k] - ray.origin[k]) / ray.direction[k];
        tmin = std::max(tmin, std::min(t1, t2));
        tmax = std::min(tmax, std::max(t1, t2));
    }
    return tmin < tmax;
}

// A stand-in of 1e30 for 1/0 (a common trick; tinybvh PR #286 removed it): finite, so no
// NaN, but a ray lying in a face plane gets t = 0 there instead of "all t", and misses a box
// it runs along.
template <typename T>
std::optional<RayInterval<T>> intersectSlabsStandIn(const RayT<T>& ray, const Bounds3T<T>& box);

}  // namespace boxes
