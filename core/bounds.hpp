// An axis-aligned box [min, max] (closed: points on a face are inside). The data type is
// shared by every step; what the lecture asks of boxes (bounds of shapes, union, overlap,
// the slab test) is step 03's exercises.
#pragma once

#include "core/math.hpp"

namespace boxes {

template <typename T>
struct Bounds3T {
    // Empty by default: min > max, so extending by the first point makes it that point.
    Vec3T<T> min{kInfinity<T>};
    Vec3T<T> max{-kInfinity<T>};

    Bounds3T() = default;
    Bounds3T(const Vec3T<T>& lo, const Vec3T<T>& hi) : min(lo), max(hi) {}

    bool isEmpty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
    void extend(const Vec3T<T>& p) {
        min = glm::min(min, p);
        max = glm::max(max, p);
    }
    Vec3T<T> diagonal() const { return max - min; }
    Vec3T<T> centroid() const { return T(0.5) * (min + max); }
    T surfaceArea() const {
        if (isEmpty()) return T(0);
        Vec3T<T> d = diagonal();
        return T(2) * (d.x * d.y + d.y * d.z + d.z * d.x);
    }
    int maxExtentAxis() const { return maxDimension(diagonal()); }
    bool contains(const Vec3T<T>& p) const {
        return p.x >= min.x && p.x <= max.x && p.y >= min.y && p.y <= max.y && p.z >= min.z &&
               p.z <= max.z;
    }
    bool operator==(const Bounds3T&) const = default;
};

using Bounds3f = Bounds3T<float>;
using Bounds3d = Bounds3T<double>;

}  // namespace boxes
