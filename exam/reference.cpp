#include "exam/reference.hpp"

#include <algorithm>

namespace boxes::exam {

std::optional<TriangleHitd> rayTriangle(const Rayd& ray, const Vec3d& a, const Vec3d& b,
                                        const Vec3d& c) {
    Vec3d e1 = b - a, e2 = c - a;
    Vec3d p = glm::cross(ray.direction, e2);
    double det = glm::dot(e1, p);
    if (det == 0.0) return std::nullopt;  // parallel to the plane, or degenerate
    Vec3d s = ray.origin - a;
    double u = glm::dot(s, p) / det;
    Vec3d q = glm::cross(s, e1);
    double v = glm::dot(ray.direction, q) / det;
    double t = glm::dot(e2, q) / det;
    if (u < 0.0 || v < 0.0 || u + v > 1.0 || t < ray.tmin || t > ray.tmax) return std::nullopt;
    return TriangleHitd{t, u, v};
}

std::optional<Interval> raySlabs(const Rayd& ray, const Bounds3d& box) {
    double enter = -kInfinity<double>, exit = kInfinity<double>;
    for (int axis = 0; axis < 3; ++axis) {
        double o = ray.origin[axis], d = ray.direction[axis];
        if (d == 0.0) {
            // Parallel to this slab: inside it or never (the question avoids o on a plane).
            if (o < box.min[axis] || o > box.max[axis]) return std::nullopt;
            continue;
        }
        double t0 = (box.min[axis] - o) / d, t1 = (box.max[axis] - o) / d;
        if (t0 > t1) std::swap(t0, t1);
        enter = std::max(enter, t0);
        exit = std::min(exit, t1);
    }
    if (enter > exit || exit < ray.tmin || enter > ray.tmax) return std::nullopt;
    return Interval{enter, exit};
}

bool boxesOverlap(const Bounds3d& a, const Bounds3d& b) {
    for (int axis = 0; axis < 3; ++axis)
        if (a.min[axis] > b.max[axis] || b.min[axis] > a.max[axis]) return false;
    return true;
}

Vec3d positiveVertex(const Bounds3d& box, const Vec3d& n) {
    return {n.x >= 0.0 ? box.max.x : box.min.x, n.y >= 0.0 ? box.max.y : box.min.y,
            n.z >= 0.0 ? box.max.z : box.min.z};
}

bool culledByPlane(const Bounds3d& box, const Vec3d& n, double d) {
    return glm::dot(n, positiveVertex(box, n)) + d < 0.0;
}

}  // namespace boxes::exam
