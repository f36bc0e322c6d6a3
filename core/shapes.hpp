// Spheres and planes, and their ray intersections: the analytic shapes of the lecture.
#pragma once

#include <cmath>
#include <optional>

#include "core/ray.hpp"

namespace boxes {

template <typename T>
struct SphereT {
    Vec3T<T> centre{0};
    T radius = T(1);
};

// The plane N.P + d = 0 (N need not be unit length for the distance t).
template <typename T>
struct PlaneT {
    Vec3T<T> normal{0, 1, 0};
    T d = T(0);
};

// The renderer's planes (the scenes' floors): the nearest hit inside [tmin, tmax], nothing
// when the ray is parallel. The general ray/plane distance, any sign, is exercise 1.2's
// (step 01), which the core does not give away.
template <typename T>
std::optional<T> intersectPlane(const RayT<T>& ray, const PlaneT<T>& plane) {
    T denom = glm::dot(ray.direction, plane.normal);
    if (denom == T(0)) return std::nullopt;
    T t = -(glm::dot(ray.origin, plane.normal) + plane.d) / denom;
    if (std::isfinite(t) && t >= ray.tmin && t <= ray.tmax) return t;
    return std::nullopt;
}

// Both roots of |O + tD - C|^2 = r^2, t0 <= t1. The discriminant is formed as
// r^2 - |f - (f.d)d|^2 with f = O - C, which keeps its precision for far spheres
// (Haines et al., "Precision Improvements for Ray/Sphere Intersection", Ray Tracing Gems 2019).
template <typename T>
bool sphereRoots(const RayT<T>& ray, const SphereT<T>& s, T& t0, T& t1) {
    Vec3T<T> f = ray.origin - s.centre;
    T a = glm::dot(ray.direction, ray.direction);
    T bHalf = -glm::dot(f, ray.direction);  // -b/2
    Vec3T<T> l = f + (bHalf / a) * ray.direction;
    T disc = a * (s.radius * s.radius - glm::dot(l, l));
    if (disc < T(0)) return false;
    T c = glm::dot(f, f) - s.radius * s.radius;
    T q = bHalf + std::copysign(std::sqrt(disc), bHalf);
    if (q == T(0)) {  // ray starts at the centre's tangent point or a = 0 degenerate
        t0 = t1 = T(0);
        return c <= T(0);
    }
    t0 = c / q;
    t1 = q / a;
    if (t0 > t1) std::swap(t0, t1);
    return true;
}

// Nearest sphere hit inside [tmin, tmax]: the entry point, or the exit point when the ray
// starts inside.
template <typename T>
std::optional<T> intersectSphere(const RayT<T>& ray, const SphereT<T>& s) {
    T t0, t1;
    if (!sphereRoots(ray, s, t0, t1)) return std::nullopt;
    if (t0 >= ray.tmin && t0 <= ray.tmax) return t0;
    if (t1 >= ray.tmin && t1 <= ray.tmax) return t1;
    return std::nullopt;
}

using Sphere = SphereT<float>;
using Plane = PlaneT<float>;

}  // namespace boxes
