// Step 01: ray/triangle intersection, three ways.
#pragma once

#include <optional>

#include "core/math.hpp"

namespace boxes {

template <typename T>
struct TriangleT {
    Vec3T<T> a, b, c;
};
using Triangle = TriangleT<float>;
using Triangled = TriangleT<double>;

// A hit at distance t; the point is (1 - u - v) a + u b + v c.
template <typename T>
struct TriangleHit {
    T t;
    T u, v;
};

// Exercise 1.1: the triangle's plane N.P + d = 0 with the unit normal of the winding
// (b - a) x (c - a). A degenerate triangle (zero area) has no plane: nullopt.
template <typename T>
std::optional<PlaneT<T>> trianglePlane(const TriangleT<T>& tri);

// Exercise 1.2: the ray parameter where the ray meets the plane, t = -(O.N + d) / (D.N),
// whatever its sign; nullopt when the ray is parallel to the plane (also when it lies in it).
template <typename T>
std::optional<T> rayPlaneDistance(const RayT<T>& ray, const PlaneT<T>& plane);

// Exercise 1.3: the lecture's inside test: is the ray on the inner side of the three
// planes through the ray origin and each edge? Returns the barycentrics (u, v) of the
// point where it crosses the triangle, or nullopt.
template <typename T>
std::optional<glm::vec<2, T>> insideEdgePlanes(const RayT<T>& ray, const TriangleT<T>& tri);

// The lecture's test put together: plane (1.1), distance (1.2), inside test (1.3).
template <typename T>
std::optional<TriangleHit<T>> intersectPlaneTest(const RayT<T>& ray, const TriangleT<T>& tri) {
    auto plane = trianglePlane(tri);
    if (!plane) return std::nullopt;
    auto t = rayPlaneDistance(ray, *plane);
    if (!t || *t < ray.tmin || *t > ray.tmax) return std::nullopt;
    auto uv = insideEdgePlanes(ray, tri);
    if (!uv) return std::nullopt;
    return TriangleHit<T>{*t, uv->x, uv->y};
}

// Exercise 1.4: Moller-Trumbore (1997).
template <typename T>
std::optional<TriangleHit<T>> intersectMollerTrumbore(const RayT<T>& ray, const TriangleT<T>& tri);

// Exercise 1.5: the watertight test of Woop, Benthin and Wald (JCGT 2013). In float it
// hands the triangles whose arithmetic leaves float's range to the fallback below.
template <typename T>
std::optional<TriangleHit<T>> intersectWatertight(const RayT<T>& ray, const TriangleT<T>& tri);

// Exercise 1.5's fallback (given): the same test in double, its hit rounded to float; a hit
// beyond float's range (|t| > 3.4e38) has no float t and is a miss.
std::optional<TriangleHit<float>> intersectWatertightInDouble(const Ray& ray, const Triangle& tri);

// Exercise 1.6: the shading normal at barycentric (u, v) from the three vertex normals.
Vec3 interpolateNormal(const Vec3& na, const Vec3& nb, const Vec3& nc, float u, float v);

enum class TriangleTest { PlaneTest, MollerTrumbore, Watertight };
constexpr TriangleTest kAllTriangleTests[] = {TriangleTest::PlaneTest, TriangleTest::MollerTrumbore,
                                              TriangleTest::Watertight};
const char* triangleTestName(TriangleTest test);

template <typename T>
std::optional<TriangleHit<T>> intersectTriangle(TriangleTest test, const RayT<T>& ray,
                                                const TriangleT<T>& tri) {
    switch (test) {
        case TriangleTest::PlaneTest:
            return intersectPlaneTest(ray, tri);
        case TriangleTest::MollerTrumbore:
            return intersectMollerTrumbore(ray, tri);
        default:
            return intersectWatertight(ray, tri);
    }
}

}  // namespace boxes
