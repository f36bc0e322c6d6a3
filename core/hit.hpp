// What an intersection reports to the renderer.
#pragma once

#include <cstdint>

#include "core/math.hpp"

namespace boxes {

constexpr uint32_t kNoPrimitive = 0xFFFFFFFFu;

struct SurfaceHit {
    float t = kInfinity<float>;
    Vec3 point{0.0f};
    Vec3 geometricNormal{0.0f};  // unit, as the primitive defines it (winding, outward)
    Vec3 shadingNormal{0.0f};    // unit, interpolated where the primitive has vertex normals
    float u = 0.0f, v = 0.0f;    // barycentric coordinates (triangles) or 0
    int material = 0;
    uint32_t primitive = kNoPrimitive;  // triangle index in file order, or sphere/plane index
    int object = -1;                    // the scene object: spheres, then planes, then geometries
    enum class Kind : uint8_t { None, Sphere, Plane, Triangle } kind = Kind::None;
};

}  // namespace boxes
