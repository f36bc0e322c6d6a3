// The language note's kernel, compiled once per variant (CMakeLists.txt): BOXES_LANGUAGE_NS
// names the copy, BOXES_LANGUAGE_FLAGS its compile options. Everything else is in an
// unnamed namespace, and the square root is the compiler's builtin: no inline function
// shared with the rest of the program, whose one copy the linker would pick from any of
// the variants.
#include "05_efficiency/language.hpp"

#if !defined(BOXES_LANGUAGE_NS) || !defined(BOXES_LANGUAGE_FLAGS)
#error "compiled by boxes_language_variant in steps/05_efficiency/CMakeLists.txt"
#endif

namespace boxes::language::BOXES_LANGUAGE_NS {

namespace {

// A small vector type, as a ray tracer has one: at -O0 every operator is a call.
template <typename T>
struct V3 {
    T x, y, z;
};
template <typename T>
V3<T> operator-(V3<T> a, V3<T> b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <typename T>
T dot(V3<T> a, V3<T> b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline float root(float x) {
    return __builtin_sqrtf(x);
}
inline double root(double x) {
    return __builtin_sqrt(x);
}

// Every ray against every sphere, |d| = 1: t = -b -+ sqrt(b^2 - c), the nearest t > 0.
template <typename T>
void nearest(const T* spheres, size_t sphereCount, const T* rays, size_t rayCount, T* out) {
    for (size_t i = 0; i < rayCount; ++i) {
        const T* r = rays + 6 * i;
        V3<T> o{r[0], r[1], r[2]}, d{r[3], r[4], r[5]};
        T best = T(__builtin_inf());
        for (size_t j = 0; j < sphereCount; ++j) {
            const T* s = spheres + 4 * j;
            V3<T> oc = o - V3<T>{s[0], s[1], s[2]};
            T b = dot(oc, d), c = dot(oc, oc) - s[3] * s[3];
            T disc = b * b - c;
            if (disc < T(0)) continue;
            T h = root(disc);
            T t = -b - h;
            if (t <= T(0)) t = -b + h;
            if (t > T(0) && t < best) best = t;
        }
        out[i] = best;
    }
}

}  // namespace

const char* flags() {
    return BOXES_LANGUAGE_FLAGS;
}
void nearestFloat(const float* spheres, size_t sphereCount, const float* rays, size_t rayCount,
                  float* t) {
    nearest(spheres, sphereCount, rays, rayCount, t);
}
void nearestDouble(const double* spheres, size_t sphereCount, const double* rays, size_t rayCount,
                   double* t) {
    nearest(spheres, sphereCount, rays, rayCount, t);
}

}  // namespace boxes::language::BOXES_LANGUAGE_NS
