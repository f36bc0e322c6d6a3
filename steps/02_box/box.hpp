// Step 02: a box as six planes, intersected the lecture's way, and the axis-aligned
// special case (the slab method) in the box's own frame.
#pragma once

#include <array>
#include <optional>

#include "core/bounds.hpp"
#include "core/math.hpp"

namespace boxes {

// A box with any orientation: centre, three orthonormal axes (right-handed or not) and the
// half extents along them. An axis-aligned box has the world axes. A half extent of 0 makes
// a flat box (a rectangle), which is still a closed set and can be hit.
template <typename T>
struct OrientedBoxT {
    Vec3T<T> centre{0};
    std::array<Vec3T<T>, 3> axes{Vec3T<T>(1, 0, 0), Vec3T<T>(0, 1, 0), Vec3T<T>(0, 0, 1)};
    Vec3T<T> halfExtents{1};

    static OrientedBoxT axisAligned(const Bounds3T<T>& b) {
        return {b.centroid(),
                {Vec3T<T>(1, 0, 0), Vec3T<T>(0, 1, 0), Vec3T<T>(0, 0, 1)},
                T(0.5) * b.diagonal()};
    }
    // The box rotated by `radians` about the unit axis `about` (Rodrigues' formula).
    static OrientedBoxT rotated(const Vec3T<T>& centre, const Vec3T<T>& halfExtents,
                                const Vec3T<T>& about, T radians);

    // Throws std::invalid_argument for NaN or infinite values, a negative half extent, or
    // axes that are not orthonormal (to 1e-4): the intersection routines assume all three.
    void validate() const;
};
using OrientedBox = OrientedBoxT<float>;
using OrientedBoxd = OrientedBoxT<double>;

// Face f of a box: axis f / 2, on the negative side of the axis for even f, the positive
// side for odd f (0: -x, 1: +x, 2: -y, 3: +y, 4: -z, 5: +z in the box's frame).
constexpr int kBoxFaces = 6;

template <typename T>
struct BoxHit {
    T t;
    Vec3T<T> normal;  // unit outward normal of the face hit
    int face;         // 0..5 as above
    bool entering;    // true: the ray enters the box here (D.N < 0); false: it leaves
};

// Exercise 2.1: the six face planes N.P + d = 0 with unit outward normals, in face order.
// A point P is on the inner side of plane i when N_i.P + d_i <= 0.
template <typename T>
std::array<PlaneT<T>, 6> boxFacePlanes(const OrientedBoxT<T>& box);

// Exercise 2.2: the lecture's way. Intersect the ray with every plane, keep the hits whose
// point lies on the inner side of the five other planes, take the nearest in
// [tmin, tmax]. With the origin inside, that is the exit face (entering = false).
template <typename T>
std::optional<BoxHit<T>> intersectSixPlanes(const RayT<T>& ray,
                                            const std::array<PlaneT<T>, 6>& planes);

// Exercise 2.3: the axis-aligned special case. For the plane x = x_plane the general
// t = -(O.N + d) / (D.N) with N = (1,0,0), d = -x_plane becomes t = (x_plane - O_x) / D_x.
// D_x = 0 gives +-infinity (never reached) or NaN (origin in the plane); callers decide.
template <typename T>
T axisPlaneDistance(T planeCoordinate, T originComponent, T directionComponent);

// The sign error to avoid (see the README): dropping the minus sign of -(O.N + d) gives
// t = (O_x - x_plane) / D_x, which mirrors every distance: boxes in front seem behind.
template <typename T>
T axisPlaneDistanceSignError(T planeCoordinate, T originComponent, T directionComponent) {
    return (originComponent - planeCoordinate) / directionComponent;
}

// Exercise 2.4: the slab method for an oriented box: the ray in the box's frame, then per
// axis the two planes at -h and +h with 2.3's formula; entry = largest near t, exit =
// smallest far t. Same answer as 2.2: nearest hit in [tmin, tmax], face, normal, entering.
template <typename T>
std::optional<BoxHit<T>> intersectBoxSlabs(const RayT<T>& ray, const OrientedBoxT<T>& box);

enum class BoxMethod { SixPlanes, Slabs };
const char* boxMethodName(BoxMethod method);

}  // namespace boxes
