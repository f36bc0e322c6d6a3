// The vocabulary every step shares, on GLM (right-handed coordinates, y up): vectors and
// float helpers, the ray, what a hit reports, and the lecture's analytic shapes (spheres
// and planes) with their ray intersections.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <glm/glm.hpp>
#include <limits>
#include <optional>
#include <stdexcept>

namespace boxes {

template <typename T>
using Vec3T = glm::vec<3, T, glm::defaultp>;
using Vec3 = glm::vec3;
using Vec3d = glm::dvec3;
using Vec2 = glm::vec2;

template <typename T>
constexpr T kInfinity = std::numeric_limits<T>::infinity();
constexpr float kPi = 3.14159265358979323846f;

template <typename T>
bool isFinite(const Vec3T<T>& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

template <typename T>
bool isZero(const Vec3T<T>& v) {
    return v.x == T(0) && v.y == T(0) && v.z == T(0);
}

template <typename T>
T maxComponent(const Vec3T<T>& v) {
    return std::max(v.x, std::max(v.y, v.z));
}

template <typename T>
int maxDimension(const Vec3T<T>& v) {
    return (v.x > v.y) ? (v.x > v.z ? 0 : 2) : (v.y > v.z ? 1 : 2);
}

// Mirror direction of d about the normal n (n unit length): d - 2 (d.n) n.
template <typename T>
Vec3T<T> reflect(const Vec3T<T>& d, const Vec3T<T>& n) {
    return d - T(2) * glm::dot(d, n) * n;
}

// Refraction of the unit direction d through the unit normal n (pointing against d) with
// eta = n_from / n_to (Snell: n_from sin(theta_i) = n_to sin(theta_t)). Returns false on
// total internal reflection.
template <typename T>
bool refract(const Vec3T<T>& d, const Vec3T<T>& n, T eta, Vec3T<T>& refracted) {
    T cosI = -glm::dot(d, n);
    T sin2T = eta * eta * (T(1) - cosI * cosI);
    if (sin2T > T(1)) return false;
    T cosT = std::sqrt(T(1) - sin2T);
    refracted = eta * d + (eta * cosI - cosT) * n;
    return true;
}

// Schlick's approximation of the Fresnel reflectance (Schlick 1994).
template <typename T>
T fresnelSchlick(T cosTheta, T nFrom, T nTo) {
    T r0 = (nFrom - nTo) / (nFrom + nTo);
    r0 *= r0;
    T m = T(1) - cosTheta;
    return r0 + (T(1) - r0) * m * m * m * m * m;
}

// Exact Fresnel reflectance for unpolarised light; 1 on total internal reflection.
template <typename T>
T fresnelDielectric(T cosI, T nFrom, T nTo) {
    T eta = nFrom / nTo;
    T sin2T = eta * eta * (T(1) - cosI * cosI);
    if (sin2T >= T(1)) return T(1);
    T cosT = std::sqrt(T(1) - sin2T);
    T rs = (nFrom * cosI - nTo * cosT) / (nFrom * cosI + nTo * cosT);
    T rp = (nFrom * cosT - nTo * cosI) / (nFrom * cosT + nTo * cosI);
    return T(0.5) * (rs * rs + rp * rp);
}

// Neighbouring floats, for conservative bounds (pbrt-v4, section 6.8).
inline float nextFloatUp(float v) {
    return std::nextafter(v, kInfinity<float>);
}
inline float nextFloatDown(float v) {
    return std::nextafter(v, -kInfinity<float>);
}

// Bound on the relative error of n floating-point operations (Higham; pbrt's gamma(n)).
template <typename T>
constexpr T gammaBound(int n) {
    constexpr T eps = std::numeric_limits<T>::epsilon() * T(0.5);
    return (n * eps) / (T(1) - n * eps);
}

// Keeps the optimizer from discarding a computed value in measurements.
template <typename T>
inline void keepValue(const T& value) {
    asm volatile("" : : "r,m"(value) : "memory");
}

// ---- Rays ----------------------------------------------------------------------------------

// A ray P(t) = O + t D with hits accepted in the closed interval [tmin, tmax].
template <typename T>
struct RayT {
    Vec3T<T> origin;
    Vec3T<T> direction;
    T tmin = T(0);
    T tmax = kInfinity<T>;

    // A zero or non-finite direction has no meaning: refuse it here, once, instead of
    // letting NaN flow through every intersection routine.
    RayT(const Vec3T<T>& o, const Vec3T<T>& d, T tMin = T(0), T tMax = kInfinity<T>)
        : origin(o), direction(d), tmin(tMin), tmax(tMax) {
        if (!isFinite(d)) throw std::invalid_argument("ray direction is not finite");
        if (isZero(d)) throw std::invalid_argument("ray direction is zero");
        if (!isFinite(o)) throw std::invalid_argument("ray origin is not finite");
        if (std::isnan(tMin) || std::isnan(tMax))
            throw std::invalid_argument("ray interval is NaN");
    }

    Vec3T<T> at(T t) const { return origin + t * direction; }

    template <typename U>
    RayT<U> as() const {
        return RayT<U>(Vec3T<U>(origin), Vec3T<U>(direction), U(tmin), U(tmax));
    }
};

using Ray = RayT<float>;
using Rayd = RayT<double>;

// ---- What a hit reports --------------------------------------------------------------------

// What an intersection reports to the renderer.
constexpr uint32_t kNoPrimitive = 0xFFFFFFFFu;

struct SurfaceHit {
    float t = kInfinity<float>;
    Vec3 point{0.0f};
    Vec3 geometricNormal{0.0f};  // unit, as the primitive defines it (winding, outward)
    Vec3 shadingNormal{0.0f};    // unit, interpolated where the primitive has vertex normals
    float u = 0.0f, v = 0.0f;    // barycentric coordinates (triangles) or 0
    int material = 0;
    uint32_t primitive = kNoPrimitive;  // triangle index in file order, or sphere/plane index
    int object = -1;                    // the scene object: spheres, then planes, then geometries
    enum class Kind : uint8_t { None, Sphere, Plane, Triangle } kind = Kind::None;
};

// ---- Spheres and planes, the analytic shapes of the lecture --------------------------------

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
