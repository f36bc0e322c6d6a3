#include "core/triangle_hit.hpp"

namespace boxes {

SurfaceHit triangleSurface(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                           const std::array<uint32_t, 3>& triangle, float u, float v) {
    const Vec3 &a = positions[triangle[0]], &b = positions[triangle[1]],
               &c = positions[triangle[2]];
    const float w = 1.0f - u - v;
    SurfaceHit hit;
    hit.point = w * a + u * b + v * c;
    Vec3 n = glm::cross(b - a, c - a);
    float length = glm::length(n);
    hit.geometricNormal = length > 0.0f ? n / length : Vec3(0, 1, 0);
    hit.shadingNormal = hit.geometricNormal;
    if (normals.size() == positions.size()) {
        Vec3 s = w * normals[triangle[0]] + u * normals[triangle[1]] + v * normals[triangle[2]];
        float sLength = glm::length(s);
        if (sLength > 0.0f) hit.shadingNormal = s / sLength;
    }
    hit.u = u;
    hit.v = v;
    hit.kind = SurfaceHit::Kind::Triangle;
    return hit;
}

SurfaceHit triangleHit(const Mesh& mesh, uint32_t index, const Ray& ray, float t, float u, float v,
                       int material) {
    SurfaceHit hit = triangleSurface(mesh.positions, mesh.normals, mesh.triangles[index], u, v);
    hit.t = t;
    hit.point = ray.at(t);
    hit.material = material;
    hit.primitive = index;
    return hit;
}

}  // namespace boxes
