// Math helpers on GLM shared by every step. Right-handed coordinates, y up.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <glm/glm.hpp>
#include <limits>

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

}  // namespace boxes
