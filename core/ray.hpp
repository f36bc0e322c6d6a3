// A ray P(t) = O + t D with hits accepted in the closed interval [tmin, tmax].
#pragma once

#include <stdexcept>

#include "core/math.hpp"

namespace boxes {

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

}  // namespace boxes
