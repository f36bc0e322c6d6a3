#include "01_triangle/triangle.hpp"

#include <cmath>
#include <limits>
#include <type_traits>

#include "core/exercise.hpp"

namespace boxes {

// EXERCISE 1.1: the triangle's plane: unit normal from the cross product, and d (1 point)
template <typename T>
std::optional<PlaneT<T>> trianglePlane(const TriangleT<T>& tri) {
    // BEGIN SOLUTION
    Vec3T<T> n = glm::cross(tri.b - tri.a, tri.c - tri.a);
    T length = glm::length(n);
    if (!(length > T(0)) || !std::isfinite(length)) return std::nullopt;
    n /= length;
    return PlaneT<T>{n, -glm::dot(n, tri.a)};
    // END SOLUTION
}

// EXERCISE 1.2: ray/plane distance t = -(O.N + d) / (D.N) (1 point)
template <typename T>
std::optional<T> rayPlaneDistance(const RayT<T>& ray, const PlaneT<T>& plane) {
    // BEGIN SOLUTION
    T denominator = glm::dot(ray.direction, plane.normal);
    if (denominator == T(0)) return std::nullopt;  // parallel, or inside the plane
    T t = -(glm::dot(ray.origin, plane.normal) + plane.d) / denominator;
    if (!std::isfinite(t)) return std::nullopt;
    return t;
    // END SOLUTION
}

// EXERCISE 1.3: the inside test against the three edge planes through the ray origin (2 points)
template <typename T>
std::optional<glm::vec<2, T>> insideEdgePlanes(const RayT<T>& ray, const TriangleT<T>& tri) {
    // BEGIN SOLUTION
    // The plane through O, v_i and v_j has the normal (v_i - O) x (v_j - O); the ray passes
    // inside when D lies on the same side of all three. Each value is the volume spanned by
    // D and one edge as seen from O, so normalized they are the barycentric weights.
    Vec3T<T> va = tri.a - ray.origin, vb = tri.b - ray.origin, vc = tri.c - ray.origin;
    T wa = glm::dot(ray.direction, glm::cross(vb, vc));
    T wb = glm::dot(ray.direction, glm::cross(vc, va));
    T wc = glm::dot(ray.direction, glm::cross(va, vb));
    bool anyNegative = wa < T(0) || wb < T(0) || wc < T(0);
    bool anyPositive = wa > T(0) || wb > T(0) || wc > T(0);
    if (anyNegative && anyPositive) return std::nullopt;
    T sum = wa + wb + wc;
    if (sum == T(0) || !std::isfinite(sum)) return std::nullopt;
    return glm::vec<2, T>(wb / sum, wc / sum);
    // END SOLUTION
}

// EXERCISE 1.4: Moller-Trumbore ray/triangle intersection (2 points)
template <typename T>
std::optional<TriangleHit<T>> intersectMollerTrumbore(const RayT<T>& ray, const TriangleT<T>& tri) {
    // BEGIN SOLUTION
    // Solve O + tD = (1 - u - v) a + u b + v c by Cramer's rule (Moller, Trumbore 1997).
    Vec3T<T> e1 = tri.b - tri.a, e2 = tri.c - tri.a;
    Vec3T<T> p = glm::cross(ray.direction, e2);
    T det = glm::dot(e1, p);
    if (det == T(0) || !std::isfinite(det)) return std::nullopt;
    T inv = T(1) / det;
    Vec3T<T> s = ray.origin - tri.a;
    T u = glm::dot(s, p) * inv;
    if (!(u >= T(0) && u <= T(1))) return std::nullopt;
    Vec3T<T> q = glm::cross(s, e1);
    T v = glm::dot(ray.direction, q) * inv;
    if (!(v >= T(0) && u + v <= T(1))) return std::nullopt;
    T t = glm::dot(e2, q) * inv;
    if (!(t >= ray.tmin && t <= ray.tmax)) return std::nullopt;
    return TriangleHit<T>{t, u, v};
    // END SOLUTION
}

// EXERCISE 1.5: watertight ray/triangle intersection (Woop, Benthin, Wald 2013) (3 points)
template <typename T>
std::optional<TriangleHit<T>> intersectWatertight(const RayT<T>& ray, const TriangleT<T>& tri) {
    // BEGIN SOLUTION
    // Permute so that z is the largest direction component, keeping the winding.
    Vec3T<T> absD = glm::abs(ray.direction);
    int kz = maxDimension(absD);
    int kx = (kz + 1) % 3, ky = (kx + 1) % 3;
    if (ray.direction[kz] < T(0)) std::swap(kx, ky);
    // Shear so the ray runs along +z; then the test is 2D edge functions at the origin.
    T sx = ray.direction[kx] / ray.direction[kz];
    T sy = ray.direction[ky] / ray.direction[kz];
    T sz = T(1) / ray.direction[kz];
    Vec3T<T> a = tri.a - ray.origin, b = tri.b - ray.origin, c = tri.c - ray.origin;
    T ax = a[kx] - sx * a[kz], ay = a[ky] - sy * a[kz];
    T bx = b[kx] - sx * b[kz], by = b[ky] - sy * b[kz];
    T cx = c[kx] - sx * c[kz], cy = c[ky] - sy * c[kz];
    T u = cx * by - cy * bx;
    T v = ax * cy - ay * cx;
    T w = bx * ay - by * ax;
    constexpr bool inFloat = std::is_same_v<T, float>;
    if constexpr (inFloat) {
        // An edge function that rounds to exactly zero is recomputed in double (the
        // products of two floats are exact there), so that neighbouring triangles agree
        // on which side of the shared edge the ray passes.
        if (u == 0.0f || v == 0.0f || w == 0.0f) {
            u = T(double(cx) * double(by) - double(cy) * double(bx));
            v = T(double(ax) * double(cy) - double(ay) * double(cx));
            w = T(double(bx) * double(ay) - double(by) * double(ax));
        }
    }
    T det = u + v + w;
    // Far from the ray origin the float products overflow (a triangle 1e21 across: inf -
    // inf = NaN), and the test would miss what it should hit: decide it in double.
    if constexpr (inFloat)
        if (!std::isfinite(det)) return intersectWatertightInDouble(ray, tri);
    if ((u < T(0) || v < T(0) || w < T(0)) && (u > T(0) || v > T(0) || w > T(0)))
        return std::nullopt;
    if (det == T(0) || !std::isfinite(det)) return std::nullopt;
    T az = sz * a[kz], bz = sz * b[kz], cz = sz * c[kz];
    T tScaled = u * az + v * bz + w * cz;
    // Outside float's normal range the products underflow to zeros of either sign (t = -0,
    // a hit at tmin = 0, for a tiny triangle behind a ray with |D| = 1e28) or overflow
    // (t = inf for a triangle 3e38 away): decide those in double too.
    if constexpr (inFloat) {
        T magnitude = std::fabs(tScaled);
        if (!(magnitude >= std::numeric_limits<T>::min() &&
              magnitude <= std::numeric_limits<T>::max()))
            return intersectWatertightInDouble(ray, tri);
    }
    T t = tScaled / det;
    if (!(t >= ray.tmin && t <= ray.tmax && std::isfinite(t))) return std::nullopt;
    return TriangleHit<T>{t, v / det, w / det};
    // END SOLUTION
}

std::optional<TriangleHit<float>> intersectWatertightInDouble(const Ray& ray, const Triangle& tri) {
    auto h =
        intersectWatertight(ray.as<double>(), Triangled{Vec3d(tri.a), Vec3d(tri.b), Vec3d(tri.c)});
    if (!h || !(std::fabs(float(h->t)) <= std::numeric_limits<float>::max())) return std::nullopt;
    return TriangleHit<float>{float(h->t), float(h->u), float(h->v)};
}

// EXERCISE 1.6: interpolate the vertex normals with the barycentrics, normalized (1 point)
Vec3 interpolateNormal(const Vec3& na, const Vec3& nb, const Vec3& nc, float u, float v) {
    // BEGIN SOLUTION
    Vec3 n = (1.0f - u - v) * na + u * nb + v * nc;
    float length = glm::length(n);
    if (!(length > 0.0f) || !std::isfinite(length)) return na;
    return n / length;
    // END SOLUTION
}

const char* triangleTestName(TriangleTest test) {
    switch (test) {
        case TriangleTest::PlaneTest:
            return "plane test";
        case TriangleTest::MollerTrumbore:
            return "Moller-Trumbore";
        default:
            return "watertight";
    }
}

#define BOXES_INSTANTIATE(T)                                                                      \
    template std::optional<PlaneT<T>> trianglePlane(const TriangleT<T>&);                         \
    template std::optional<T> rayPlaneDistance(const RayT<T>&, const PlaneT<T>&);                 \
    template std::optional<glm::vec<2, T>> insideEdgePlanes(const RayT<T>&, const TriangleT<T>&); \
    template std::optional<TriangleHit<T>> intersectMollerTrumbore(const RayT<T>&,                \
                                                                   const TriangleT<T>&);          \
    template std::optional<TriangleHit<T>> intersectWatertight(const RayT<T>&, const TriangleT<T>&);
BOXES_INSTANTIATE(float)
BOXES_INSTANTIATE(double)

}  // namespace boxes
