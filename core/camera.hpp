// The one camera model of the workbook (eye, view direction, up, vertical field of view,
// aspect ratio). The ray tracer and the rasterizer both derive their pixels from it.
#pragma once

#include <array>
#include <stdexcept>

#include "core/math.hpp"
#include "core/ray.hpp"

namespace boxes {

template <typename T>
struct CameraBasisT {
    Vec3T<T> right;    // u: screen x grows along it
    Vec3T<T> up;       // v: screen y grows against it (row 0 is the top)
    Vec3T<T> forward;  // w: the normalized view direction
};

// Corners of the virtual screen at distance 1 in front of the eye.
template <typename T>
struct ScreenCornersT {
    Vec3T<T> topLeft, topRight, bottomLeft, bottomRight;
};

template <typename T>
struct CameraT {
    Vec3T<T> eye{0, 0, 0};
    Vec3T<T> view{0, 0, -1};  // need not be unit length
    Vec3T<T> up{0, 1, 0};
    T fovYDegrees = T(60);
    T aspect = T(4) / T(3);  // width / height

    // The camera at `eye` looking at `target`.
    static CameraT lookingAt(Vec3T<T> eye, Vec3T<T> target, Vec3T<T> up, T fovYDegrees, T aspect) {
        return {eye, target - eye, up, fovYDegrees, aspect};
    }

    void validate() const {
        if (!isFinite(eye)) throw std::invalid_argument("camera eye is not finite");
        if (!isFinite(view) || isZero(view))
            throw std::invalid_argument("camera view direction is zero or not finite");
        if (!isFinite(up) || isZero(up))
            throw std::invalid_argument("camera up vector is zero or not finite");
        if (!(fovYDegrees > T(0) && fovYDegrees < T(180)))
            throw std::invalid_argument("camera field of view must be in (0, 180) degrees");
        if (!(aspect > T(0)) || !std::isfinite(aspect))
            throw std::invalid_argument("camera aspect ratio must be positive");
    }

    // Orthonormal, right-handed basis: right = forward x up, up' = right x forward.
    // When the view is parallel to up the cross product vanishes; we then use the world
    // axis least aligned with the view as up, so the basis stays finite and deterministic.
    CameraBasisT<T> basis() const {
        validate();
        Vec3T<T> w = glm::normalize(view);
        Vec3T<T> u = glm::cross(w, glm::normalize(up));
        if (glm::dot(u, u) < T(1e-12)) {
            Vec3T<T> a = glm::abs(w);
            Vec3T<T> fallback = (a.x <= a.y && a.x <= a.z) ? Vec3T<T>(1, 0, 0)
                                : (a.y <= a.z)             ? Vec3T<T>(0, 1, 0)
                                                           : Vec3T<T>(0, 0, 1);
            u = glm::cross(w, fallback);
        }
        u = glm::normalize(u);
        Vec3T<T> v = glm::cross(u, w);
        return {u, v, w};
    }

    T halfHeight() const { return std::tan(glm::radians(fovYDegrees) / T(2)); }

    ScreenCornersT<T> screenCorners() const {
        CameraBasisT<T> b = basis();
        T h = halfHeight();
        T wHalf = aspect * h;
        Vec3T<T> centre = eye + b.forward;
        return {centre - wHalf * b.right + h * b.up, centre + wHalf * b.right + h * b.up,
                centre - wHalf * b.right - h * b.up, centre + wHalf * b.right - h * b.up};
    }

    // Unit direction through the image point (px, py) in pixel units, (0,0) the top-left
    // corner of the image; pixel (x, y) has its centre at (x + 0.5, y + 0.5).
    Vec3T<T> directionThrough(T px, T py, int width, int height) const {
        CameraBasisT<T> b = basis();
        return directionThrough(b, px, py, width, height);
    }
    Vec3T<T> directionThrough(const CameraBasisT<T>& b, T px, T py, int width, int height) const {
        T h = halfHeight();
        T sx = (T(2) * px / T(width) - T(1)) * aspect * h;
        T sy = (T(1) - T(2) * py / T(height)) * h;
        return glm::normalize(b.forward + sx * b.right + sy * b.up);
    }

    RayT<T> primaryRay(int x, int y, int width, int height) const {
        return RayT<T>(eye, directionThrough(T(x) + T(0.5), T(y) + T(0.5), width, height));
    }
};

using Camera = CameraT<float>;
using Camerad = CameraT<double>;

}  // namespace boxes
