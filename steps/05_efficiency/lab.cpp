#include "05_efficiency/lab.hpp"

#include <bit>
#include <cmath>

namespace boxes {

LectureSinTable::LectureSinTable() : table(3600) {
    // The slide: for( int i = 0; i < 3600; i++ ) { sintab[i] = Math.Sin( i / 10 ); ...
    for (int i = 0; i < 3600; ++i) table[size_t(i)] = float(std::sin(double(i / 10)));
}

std::optional<float> LectureSinTable::sin(float degrees) const {
    int index = int(degrees * 10.0f);  // (int)(a * 10): truncation, no wrap
    if (index < 0 || index >= int(table.size())) return std::nullopt;
    return table[size_t(index)];
}

// EXERCISE 5.1: fill the sine table in radians over one full circle (1 point)
std::vector<float> fillSinTable(int n) {
    // BEGIN SOLUTION
    if (n < 2) throw std::invalid_argument("a sine table needs at least 2 entries");
    std::vector<float> table(size_t(n) + 1);
    // In double, then rounded once: each entry is the float nearest to the true sine.
    for (int i = 0; i <= n; ++i) table[size_t(i)] = float(std::sin(2.0 * M_PI * double(i % n) / n));
    return table;
    // END SOLUTION
}

SinTable::SinTable(std::vector<float> entriesPlusOne) : table_(std::move(entriesPlusOne)) {
    if (table_.size() < 3) throw std::invalid_argument("a sine table needs at least 2 entries");
    n_ = int(table_.size()) - 1;
    step_ = float(2.0 * M_PI / n_);
    perStep_ = float(n_ / (2.0 * M_PI));
}

// EXERCISE 5.2: the nearest table entry, index wrapped for any angle in radians (1 point)
float SinTable::sinNearest(float radians) const {
    // BEGIN SOLUTION
    // Round to the nearest entry, then wrap: floor-based, so negative angles wrap too
    // (C++'s % keeps the sign of the dividend).
    long index = long(std::floor(radians * perStep_ + 0.5f));
    if (index < 0 || index >= n_) {  // the common case [0, 2 pi) skips the division
        index %= n_;
        if (index < 0) index += n_;
    }
    return table_[size_t(index)];
    // END SOLUTION
}

// EXERCISE 5.3: linear interpolation between the two entries around the angle (1 point)
float SinTable::sinInterpolated(float radians) const {
    // BEGIN SOLUTION
    float position = radians * perStep_;
    float below = std::floor(position);
    float fraction = position - below;
    long index = long(below);
    if (index < 0 || index >= n_) {
        index %= n_;
        if (index < 0) index += n_;
    }
    // table_[n] repeats table_[0], so index + 1 never needs a wrap.
    float s0 = table_[size_t(index)], s1 = table_[size_t(index) + 1];
    return s0 + fraction * (s1 - s0);
    // END SOLUTION
}

float sinPolynomial(float radians) {
    // Wrap to [-pi, pi], fold to [-pi/2, pi/2], then the degree-7 Taylor polynomial
    // (error below 1.6e-4 at pi/2).
    float x = radians - 2.0f * kPi * std::floor((radians + kPi) / (2.0f * kPi));
    if (x > 0.5f * kPi) x = kPi - x;
    if (x < -0.5f * kPi) x = -kPi - x;
    float x2 = x * x;
    return x * (1.0f - x2 / 6.0f * (1.0f - x2 / 20.0f * (1.0f - x2 / 42.0f)));
}

// EXERCISE 5.5: the finite radius of a point light (1 point)
float finiteLightRadius(Vec3 intensity, float threshold) {
    // BEGIN SOLUTION
    if (!(threshold > 0.0f)) throw std::invalid_argument("the threshold must be positive");
    // intensity / d^2 = threshold  <=>  d = sqrt(intensity / threshold).
    return std::sqrt(maxComponent(intensity) / threshold);
    // END SOLUTION
}

PrecomputedRay precomputeRay(const Ray& ray) {
    PrecomputedRay p;
    p.origin = ray.origin;
    p.invDirection = 1.0f / ray.direction;
    for (int a = 0; a < 3; ++a) p.negative[a] = std::signbit(ray.direction[a]) ? 1 : 0;
    p.tmin = ray.tmin;
    p.tmax = ray.tmax;
    return p;
}

std::optional<float> slabDivision(const Ray& ray, const Bounds3f& box) {
    float t0 = ray.tmin, t1 = ray.tmax;
    for (int a = 0; a < 3; ++a) {
        float tA = (box.min[a] - ray.origin[a]) / ray.direction[a];
        float tB = (box.max[a] - ray.origin[a]) / ray.direction[a];
        float tNear = std::min(tA, tB), tFar = std::max(tA, tB);
        // std::min/max return the first argument when a comparison involves NaN; the
        // comparisons below are false for NaN, so a NaN slab leaves [t0, t1] unchanged.
        if (std::isnan(tA) || std::isnan(tB)) tNear = tFar = std::nanf("");
        if (tNear > t0) t0 = tNear;
        if (tFar < t1) t1 = tFar;
        if (t0 > t1) return std::nullopt;
    }
    return t0;
}

// EXERCISE 5.6: the slab test with a precomputed reciprocal direction and signs (2 points)
std::optional<float> slabReciprocal(const PrecomputedRay& ray, const Bounds3f& box) {
    // BEGIN SOLUTION
    // The sign of D says which plane is entered first, so no min/max; the multiply by
    // 1/D replaces the division (Williams et al., "An Efficient and Robust Ray-Box
    // Intersection Algorithm", JGT 2005).
    const Vec3* bounds[2] = {&box.min, &box.max};
    float t0 = ray.tmin, t1 = ray.tmax;
    for (int a = 0; a < 3; ++a) {
        float tNear = ((*bounds[ray.negative[a]])[a] - ray.origin[a]) * ray.invDirection[a];
        float tFar = ((*bounds[1 - ray.negative[a]])[a] - ray.origin[a]) * ray.invDirection[a];
        if (tNear > t0) t0 = tNear;  // false for NaN: the slab leaves the interval alone
        if (tFar < t1) t1 = tFar;
        if (t0 > t1) return std::nullopt;
    }
    return t0;
    // END SOLUTION
}

namespace {

// Moller-Trumbore given the edges; shared so both forms do the same arithmetic.
inline std::optional<TriangleHitT> mollerTrumbore(const Ray& ray, const Vec3& a, const Vec3& e1,
                                                  const Vec3& e2) {
    Vec3 p = glm::cross(ray.direction, e2);
    float det = glm::dot(e1, p);
    if (det == 0.0f || !std::isfinite(det)) return std::nullopt;
    float inv = 1.0f / det;
    Vec3 s = ray.origin - a;
    float u = glm::dot(s, p) * inv;
    if (u < 0.0f || u > 1.0f) return std::nullopt;
    Vec3 q = glm::cross(s, e1);
    float v = glm::dot(ray.direction, q) * inv;
    if (v < 0.0f || u + v > 1.0f) return std::nullopt;
    float t = glm::dot(e2, q) * inv;
    if (t < ray.tmin || t > ray.tmax) return std::nullopt;
    return TriangleHitT{t, u, v};
}

}  // namespace

std::optional<TriangleHitT> intersectFromVertices(const Ray& ray, const TriangleVertices& tri) {
    return mollerTrumbore(ray, tri.a, tri.b - tri.a, tri.c - tri.a);
}

PrecomputedTriangle precomputeTriangle(const TriangleVertices& tri) {
    Vec3 e1 = tri.b - tri.a, e2 = tri.c - tri.a;
    return {tri.a, e1, e2, glm::cross(e1, e2)};
}

// EXERCISE 5.7: Moller-Trumbore on precomputed edges (2 points)
std::optional<TriangleHitT> intersectPrecomputed(const Ray& ray, const PrecomputedTriangle& tri) {
    // BEGIN SOLUTION
    return mollerTrumbore(ray, tri.a, tri.e1, tri.e2);
    // END SOLUTION
}

}  // namespace boxes
