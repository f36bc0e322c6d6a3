#include "03_aabb/aabb.hpp"

#include "core/exercise.hpp"

namespace boxes {

// EXERCISE 3.1: the bounds of a sphere (1 point)
template <typename T>
Bounds3T<T> sphereBounds(const SphereT<T>& sphere) {
    Bounds3T<T> b;
    // BEGIN SOLUTION
    Vec3T<T> r(std::abs(sphere.radius));
    b = Bounds3T<T>(sphere.centre - r, sphere.centre + r);
    // END SOLUTION
    return b;
}

// EXERCISE 3.2: the bounds of a triangle (1 point)
template <typename T>
Bounds3T<T> triangleBounds(const TriangleT<T>& triangle) {
    Bounds3T<T> b;
    // BEGIN SOLUTION
    b.min = glm::min(triangle.a, glm::min(triangle.b, triangle.c));
    b.max = glm::max(triangle.a, glm::max(triangle.b, triangle.c));
    // END SOLUTION
    return b;
}

// EXERCISE 3.3: the bounds of a mesh: the vertices its triangles use (1 point)
Bounds3f meshBounds(const Mesh& mesh) {
    Bounds3f b;
    // BEGIN SOLUTION
    for (const auto& tri : mesh.triangles)
        for (uint32_t index : tri) {
            const Vec3& p = mesh.positions[index];
            b.min = glm::min(b.min, p);
            b.max = glm::max(b.max, p);
        }
    // END SOLUTION
    return b;
}

// EXERCISE 3.4: the union of two boxes, every axis its own (1 point)
template <typename T>
Bounds3T<T> unionBounds(const Bounds3T<T>& a, const Bounds3T<T>& b) {
    Bounds3T<T> r;
    // BEGIN SOLUTION
    for (int k = 0; k < 3; ++k) {
        r.min[k] = std::min(a.min[k], b.min[k]);
        r.max[k] = std::max(a.max[k], b.max[k]);
    }
    // END SOLUTION
    return r;
}

// EXERCISE 3.5: overlap of two closed boxes, both directions on every axis (1 point)
template <typename T>
bool overlaps(const Bounds3T<T>& a, const Bounds3T<T>& b) {
    bool result = false;
    // BEGIN SOLUTION
    result = true;
    for (int k = 0; k < 3; ++k) result = result && a.min[k] <= b.max[k] && b.min[k] <= a.max[k];
    // END SOLUTION
    return result;
}

// EXERCISE 3.6: the robust slab test returning [tnear, tfar] (3 points)
template <typename T>
std::optional<RayInterval<T>> intersectSlabs(const SlabRayT<T>& ray, const Bounds3T<T>& box) {
    std::optional<RayInterval<T>> result;
    // BEGIN SOLUTION
    if (box.isEmpty()) return result;
    T tNear = ray.tmin, tFar = ray.tmax;
    for (int k = 0; k < 3; ++k) {
        // The sign bit of 1/D (the same as D's, also for -0.0) picks the plane met first.
        bool negative = std::signbit(ray.invDirection[k]);
        T nearPlane = negative ? box.max[k] : box.min[k];
        T farPlane = negative ? box.min[k] : box.max[k];
        T t0 = (nearPlane - ray.origin[k]) * ray.invDirection[k];
        T t1 = (farPlane - ray.origin[k]) * ray.invDirection[k];
        // Written so that NaN (0 * inf) is false in the comparison and changes nothing.
        tNear = t0 > tNear ? t0 : tNear;
        tFar = t1 < tFar ? t1 : tFar;
    }
    if (tNear <= tFar) result = RayInterval<T>{tNear, tFar};
    // END SOLUTION
    return result;
}

// EXERCISE 3.7: the conservative slab test, far t widened by 1 + 2 gamma(3) (1 point)
template <typename T>
std::optional<RayInterval<T>> intersectSlabsConservative(const SlabRayT<T>& ray,
                                                         const Bounds3T<T>& box) {
    std::optional<RayInterval<T>> result;
    // BEGIN SOLUTION
    if (box.isEmpty()) return result;
    // Each t carries three roundings (the difference, 1/D, the product): relative error at
    // most gamma(3), so widening the far t by 2 gamma(3) covers both ends (pbrt-v4).
    constexpr T widen = T(1) + T(2) * gammaBound<T>(3);
    T tNear = ray.tmin, tFar = ray.tmax;
    for (int k = 0; k < 3; ++k) {
        bool negative = std::signbit(ray.invDirection[k]);
        T nearPlane = negative ? box.max[k] : box.min[k];
        T farPlane = negative ? box.min[k] : box.max[k];
        T t0 = (nearPlane - ray.origin[k]) * ray.invDirection[k];
        T t1 = (farPlane - ray.origin[k]) * ray.invDirection[k] * widen;
        tNear = t0 > tNear ? t0 : tNear;
        tFar = t1 < tFar ? t1 : tFar;
    }
    if (tNear <= tFar) result = RayInterval<T>{tNear, tFar};
    // END SOLUTION
    return result;
}

// Not exercises: the two fragile variants the measurements compare with (out of line like
// the exercises, so every variant pays the same call).
template <typename T>
std::optional<RayInterval<T>> intersectSlabsNaive(const RayT<T>& ray, const Bounds3T<T>& box,
                                                  bool swapArguments) {
    T t0 = ray.tmin, t1 = ray.tmax;
    for (int k = 0; k < 3; ++k) {
        T a = (box.min[k] - ray.origin[k]) / ray.direction[k];
        T b = (box.max[k] - ray.origin[k]) / ray.direction[k];
        T tNear = swapArguments ? std::min(b, a) : std::min(a, b);
        T tFar = swapArguments ? std::max(b, a) : std::max(a, b);
        t0 = swapArguments ? std::max(tNear, t0) : std::max(t0, tNear);
        t1 = swapArguments ? std::min(tFar, t1) : std::min(t1, tFar);
    }
    if (!(t0 <= t1)) return std::nullopt;
    return RayInterval<T>{t0, t1};
}

template <typename T>
std::optional<RayInterval<T>> intersectSlabsStandIn(const RayT<T>& ray, const Bounds3T<T>& box) {
    T t0 = ray.tmin, t1 = ray.tmax;
    for (int k = 0; k < 3; ++k) {
        T d = ray.direction[k];
        T inv = d == T(0) ? T(1e30) : T(1) / d;
        T a = (box.min[k] - ray.origin[k]) * inv, b = (box.max[k] - ray.origin[k]) * inv;
        t0 = std::max(t0, std::min(a, b));
        t1 = std::min(t1, std::max(a, b));
    }
    if (!(t0 <= t1)) return std::nullopt;
    return RayInterval<T>{t0, t1};
}

#define BOXES_INSTANTIATE(T)                                                                       \
    template Bounds3T<T> sphereBounds(const SphereT<T>&);                                          \
    template Bounds3T<T> triangleBounds(const TriangleT<T>&);                                      \
    template Bounds3T<T> unionBounds(const Bounds3T<T>&, const Bounds3T<T>&);                      \
    template bool overlaps(const Bounds3T<T>&, const Bounds3T<T>&);                                \
    template std::optional<RayInterval<T>> intersectSlabs(const SlabRayT<T>&, const Bounds3T<T>&); \
    template std::optional<RayInterval<T>> intersectSlabsConservative(const SlabRayT<T>&,          \
                                                                      const Bounds3T<T>&);         \
    template std::optional<RayInterval<T>> intersectSlabsNaive(const RayT<T>&, const Bounds3T<T>&, \
                                                               bool);                              \
    template std::optional<RayInterval<T>> intersectSlabsStandIn(const RayT<T>&,                   \
                                                                 const Bounds3T<T>&);
BOXES_INSTANTIATE(float)
BOXES_INSTANTIATE(double)

}  // namespace boxes
