#include "02_box/box.hpp"

#include <stdexcept>

#include "core/exercise.hpp"

namespace boxes {

template <typename T>
OrientedBoxT<T> OrientedBoxT<T>::rotated(const Vec3T<T>& centre, const Vec3T<T>& halfExtents,
                                         const Vec3T<T>& about, T radians) {
    Vec3T<T> k = glm::normalize(about);
    T c = std::cos(radians), s = std::sin(radians);
    auto rotate = [&](Vec3T<T> v) {
        return v * c + glm::cross(k, v) * s + k * glm::dot(k, v) * (T(1) - c);
    };
    OrientedBoxT box;
    box.centre = centre;
    box.halfExtents = halfExtents;
    for (int i = 0; i < 3; ++i) box.axes[size_t(i)] = glm::normalize(rotate(box.axes[size_t(i)]));
    return box;
}

template <typename T>
void OrientedBoxT<T>::validate() const {
    if (!isFinite(centre)) throw std::invalid_argument("box centre is not finite");
    if (!isFinite(halfExtents)) throw std::invalid_argument("box half extents are not finite");
    if (halfExtents.x < T(0) || halfExtents.y < T(0) || halfExtents.z < T(0))
        throw std::invalid_argument("box half extent is negative (min > max)");
    for (int i = 0; i < 3; ++i) {
        const Vec3T<T>& a = axes[size_t(i)];
        if (!isFinite(a) || std::abs(glm::length(a) - T(1)) > T(1e-4))
            throw std::invalid_argument("box axis is not a unit vector");
        if (std::abs(glm::dot(a, axes[size_t((i + 1) % 3)])) > T(1e-4))
            throw std::invalid_argument("box axes are not orthogonal");
    }
}

// EXERCISE 2.1: the six face planes of an oriented box, unit outward normals (1 point)
template <typename T>
std::array<PlaneT<T>, 6> boxFacePlanes(const OrientedBoxT<T>& box) {
    std::array<PlaneT<T>, 6> planes;
    // BEGIN SOLUTION
    // Face 2k+1 is N = a_k through c + h_k a_k: N.P + d = 0 with d = -(N.c + h_k);
    // face 2k is N = -a_k through c - h_k a_k, which gives the same form.
    for (int face = 0; face < 6; ++face) {
        int axis = face / 2;
        T sign = (face % 2) ? T(1) : T(-1);
        Vec3T<T> n = sign * box.axes[size_t(axis)];
        planes[size_t(face)] = PlaneT<T>{n, -(glm::dot(n, box.centre) + box.halfExtents[axis])};
    }
    // END SOLUTION
    return planes;
}

// EXERCISE 2.2: the lecture's box test: each plane, inside the other five, the nearest (3 points)
template <typename T>
std::optional<BoxHit<T>> intersectSixPlanes(const RayT<T>& ray,
                                            const std::array<PlaneT<T>, 6>& planes) {
    std::optional<BoxHit<T>> nearest;
    // BEGIN SOLUTION
    for (int i = 0; i < 6; ++i) {
        const PlaneT<T>& p = planes[size_t(i)];
        T denominator = glm::dot(ray.direction, p.normal);
        if (denominator == T(0)) continue;  // parallel: this face is never crossed
        T t = -(glm::dot(ray.origin, p.normal) + p.d) / denominator;
        if (!(t >= ray.tmin && t <= ray.tmax)) continue;  // also rejects NaN
        if (nearest && t >= nearest->t) continue;
        // The hit point must lie on the inner side of the five other planes (closed box:
        // on a plane counts as inside).
        Vec3T<T> point = ray.at(t);
        bool inside = true;
        for (int j = 0; j < 6 && inside; ++j)
            if (j != i)
                inside = glm::dot(planes[size_t(j)].normal, point) + planes[size_t(j)].d <= T(0);
        if (inside) nearest = BoxHit<T>{t, p.normal, i, denominator < T(0)};
    }
    // END SOLUTION
    return nearest;
}

// EXERCISE 2.3: the axis-aligned plane distance t = (x_plane - O_x) / D_x (1 point)
template <typename T>
T axisPlaneDistance(T planeCoordinate, T originComponent, T directionComponent) {
    // BEGIN SOLUTION
    return (planeCoordinate - originComponent) / directionComponent;
    // END SOLUTION
}

// EXERCISE 2.4: the slab method for an oriented box, with the face entered or left (2 points)
template <typename T>
std::optional<BoxHit<T>> intersectBoxSlabs(const RayT<T>& ray, const OrientedBoxT<T>& box) {
    std::optional<BoxHit<T>> result;
    // BEGIN SOLUTION
    // In the box's frame the faces are the planes x_k = -h_k and x_k = +h_k.
    Vec3T<T> offset = ray.origin - box.centre;
    T entry = -kInfinity<T>, exit = kInfinity<T>;
    int entryFace = -1, exitFace = -1;
    for (int k = 0; k < 3; ++k) {
        const Vec3T<T>& axis = box.axes[size_t(k)];
        T o = glm::dot(offset, axis), d = glm::dot(ray.direction, axis), h = box.halfExtents[k];
        if (d == T(0)) {
            // Parallel to both planes of the slab: inside it for every t, or never.
            if (o < -h || o > h) return result;
            continue;
        }
        T tLow = (-h - o) / d, tHigh = (h - o) / d;
        // Moving along +axis the ray enters through the low face; along -axis, the high one.
        T tNear = d > T(0) ? tLow : tHigh, tFar = d > T(0) ? tHigh : tLow;
        int nearFace = d > T(0) ? 2 * k : 2 * k + 1, farFace = d > T(0) ? 2 * k + 1 : 2 * k;
        if (tNear > entry) entry = tNear, entryFace = nearFace;
        if (tFar < exit) exit = tFar, exitFace = farFace;
    }
    if (!(entry <= exit)) return result;
    auto faceNormal = [&](int face) {
        return (face % 2 ? T(1) : T(-1)) * box.axes[size_t(face / 2)];
    };
    if (entry >= ray.tmin && entry <= ray.tmax)
        result = BoxHit<T>{entry, faceNormal(entryFace), entryFace, true};
    else if (exit >= ray.tmin && exit <= ray.tmax)
        result = BoxHit<T>{exit, faceNormal(exitFace), exitFace, false};
    // END SOLUTION
    return result;
}

const char* boxMethodName(BoxMethod method) {
    return method == BoxMethod::SixPlanes ? "six planes" : "slabs";
}

#define BOXES_INSTANTIATE(T)                                                               \
    template struct OrientedBoxT<T>;                                                       \
    template std::array<PlaneT<T>, 6> boxFacePlanes(const OrientedBoxT<T>&);               \
    template std::optional<BoxHit<T>> intersectSixPlanes(const RayT<T>&,                   \
                                                         const std::array<PlaneT<T>, 6>&); \
    template T axisPlaneDistance(T, T, T);                                                 \
    template std::optional<BoxHit<T>> intersectBoxSlabs(const RayT<T>&, const OrientedBoxT<T>&);
BOXES_INSTANTIATE(float)
BOXES_INSTANTIATE(double)
BOXES_INSTANTIATE(long double)  // the measurements' reference

}  // namespace boxes
