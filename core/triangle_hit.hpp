// A hit on a mesh triangle, filled the same way by every mesh geometry of the steps (the
// idea of pbrt-v4's Triangle::InteractionFromIntersection): the geometric normal is the
// unit normal of the winding, (b - a) x (c - a); the shading normal interpolates the
// vertex normals with the barycentrics, (1 - u - v) na + u nb + v nc, normalized.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/hit.hpp"
#include "core/mesh.hpp"
#include "core/ray.hpp"

namespace boxes {

// The surface at barycentrics (u, v) of one triangle, given as vertex indices into
// positions and normals (the layout of Mesh): the point (1 - u - v) a + u b + v c, both
// normals, u, v, and the kind. A zero-area triangle (hit only edge-on) gets the normal +y;
// without vertex normals (normals not one per position), or where they cancel out, the
// shading normal is the geometric one.
SurfaceHit triangleSurface(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                           const std::array<uint32_t, 3>& triangle, float u, float v);

// A ray's hit at t on triangle `index` of `mesh`, with barycentrics (u, v): the surface as
// above, the point on the ray, t, the material and the triangle's index as the primitive.
SurfaceHit triangleHit(const Mesh& mesh, uint32_t index, const Ray& ray, float t, float u, float v,
                       int material);

}  // namespace boxes
