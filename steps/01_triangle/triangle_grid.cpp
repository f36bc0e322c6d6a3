#include "01_triangle/triangle_grid.hpp"

#include <algorithm>
#include <cstdint>

#include "core/mesh.hpp"

namespace boxes {

TriangleGrid::TriangleGrid(const Mesh& mesh, int material, TriangleTest test)
    : mesh_(mesh), material_(material), test_(test) {
    mesh.validate("mesh");
    lo_ = Vec3(kInfinity<float>);
    hi_ = Vec3(-kInfinity<float>);
    for (const Vec3& p : mesh.positions) {
        lo_ = glm::min(lo_, p);
        hi_ = glm::max(hi_, p);
    }
    // Pad the bounds so points on the boundary fall inside, and flat meshes have volume.
    Vec3 extent = hi_ - lo_;
    float pad = 1e-4f * std::max(maxComponent(extent), 1e-6f);
    lo_ -= Vec3(pad);
    hi_ += Vec3(pad);
    extent = hi_ - lo_;
    // About two triangles per cell (the usual rule: cells ~ density * N, Wald's notes).
    float volume = extent.x * extent.y * extent.z;
    float cellEdge = std::cbrt(volume / (2.0f * float(mesh.triangleCount())));
    for (int i = 0; i < 3; ++i)
        res_[i] = std::clamp(int(std::ceil(extent[i] / std::max(cellEdge, 1e-30f))), 1, 256);

    auto cellOf = [&](Vec3 p) {
        glm::ivec3 c = glm::ivec3(glm::floor((p - lo_) / cellSize_));
        return glm::clamp(c, glm::ivec3(0), res_ - 1);
    };
    // Bound the cell references: when triangles overlap many cells each (large or many
    // identical triangles), N x cells entries would exhaust memory and overflow the 32-bit
    // counts (10^5 copies of one large triangle would ask for about 10^10). Coarsen the grid
    // until the references fit a budget proportional to N.
    const size_t budget =
        std::min<size_t>(16 * mesh.triangleCount() + (size_t(1) << 20), UINT32_MAX);
    for (;;) {
        cellSize_ = extent / Vec3(res_);
        size_t references = 0;
        for (size_t t = 0; t < mesh.triangleCount() && references <= budget; ++t) {
            Vec3 a = mesh.vertex(t, 0), b = mesh.vertex(t, 1), c = mesh.vertex(t, 2);
            glm::ivec3 span = cellOf(glm::max(a, glm::max(b, c)) + Vec3(pad)) -
                              cellOf(glm::min(a, glm::min(b, c)) - Vec3(pad)) + 1;
            references += size_t(span.x) * size_t(span.y) * size_t(span.z);
        }
        if (references <= budget || res_ == glm::ivec3(1)) break;
        res_ = glm::max(res_ / 2, glm::ivec3(1));
    }
    size_t cells = size_t(res_.x) * res_.y * res_.z;
    std::vector<uint32_t> counts(cells + 1, 0);
    auto forCells = [&](size_t tri, auto&& f) {
        Vec3 a = mesh.vertex(tri, 0), b = mesh.vertex(tri, 1), c = mesh.vertex(tri, 2);
        glm::ivec3 c0 = cellOf(glm::min(a, glm::min(b, c)) - Vec3(pad));
        glm::ivec3 c1 = cellOf(glm::max(a, glm::max(b, c)) + Vec3(pad));
        for (int z = c0.z; z <= c1.z; ++z)
            for (int y = c0.y; y <= c1.y; ++y)
                for (int x = c0.x; x <= c1.x; ++x) f((size_t(z) * res_.y + y) * res_.x + x);
    };
    for (size_t t = 0; t < mesh.triangleCount(); ++t)
        forCells(t, [&](size_t cell) { ++counts[cell + 1]; });
    for (size_t i = 1; i <= cells; ++i) counts[i] += counts[i - 1];
    cellStart_ = counts;
    cellTriangles_.resize(counts[cells]);
    for (size_t t = 0; t < mesh.triangleCount(); ++t)
        forCells(t, [&](size_t cell) { cellTriangles_[counts[cell]++] = uint32_t(t); });
}

Triangle TriangleGrid::triangle(uint32_t i) const {
    return {mesh_.vertex(i, 0), mesh_.vertex(i, 1), mesh_.vertex(i, 2)};
}

template <typename Visit>
void TriangleGrid::walk(const Ray& ray, Visit&& visit) const {
    // Clip the ray to the grid's box (the slab test that step 03 studies in depth).
    float t0 = ray.tmin, t1 = ray.tmax;
    Vec3 inv = 1.0f / ray.direction;
    for (int i = 0; i < 3; ++i) {
        float tNear = (lo_[i] - ray.origin[i]) * inv[i];
        float tFar = (hi_[i] - ray.origin[i]) * inv[i];
        if (tNear > tFar) std::swap(tNear, tFar);
        // NaN (origin on a slab plane, zero direction) leaves the interval unchanged.
        t0 = tNear > t0 ? tNear : t0;
        t1 = tFar < t1 ? tFar : t1;
    }
    if (t0 > t1) return;
    Vec3 p = ray.at(t0);
    glm::ivec3 cell =
        glm::clamp(glm::ivec3(glm::floor((p - lo_) / cellSize_)), glm::ivec3(0), res_ - 1);
    glm::ivec3 step;
    Vec3 tNext, tDelta;
    for (int i = 0; i < 3; ++i) {
        if (ray.direction[i] > 0.0f) {
            step[i] = 1;
            tNext[i] = (lo_[i] + float(cell[i] + 1) * cellSize_[i] - ray.origin[i]) * inv[i];
            tDelta[i] = cellSize_[i] * inv[i];
        } else if (ray.direction[i] < 0.0f) {
            step[i] = -1;
            tNext[i] = (lo_[i] + float(cell[i]) * cellSize_[i] - ray.origin[i]) * inv[i];
            tDelta[i] = -cellSize_[i] * inv[i];
        } else {
            step[i] = 0;
            tNext[i] = kInfinity<float>;
            tDelta[i] = kInfinity<float>;
        }
    }
    for (;;) {
        int axis = (tNext.x < tNext.y) ? (tNext.x < tNext.z ? 0 : 2) : (tNext.y < tNext.z ? 1 : 2);
        float tExit = std::min(tNext[axis], t1);
        size_t index = (size_t(cell.z) * res_.y + cell.y) * res_.x + cell.x;
        if (visit(index, tExit)) return;
        if (tNext[axis] > t1) return;
        cell[axis] += step[axis];
        if (cell[axis] < 0 || cell[axis] >= res_[axis]) return;
        tNext[axis] += tDelta[axis];
    }
}

uint32_t TriangleGrid::nearestTriangle(const Ray& rayIn, TriangleTest test, float* tOut,
                                       float* uOut, float* vOut) const {
    Ray ray = rayIn;
    uint32_t best = kNoPrimitive;
    float u = 0.0f, v = 0.0f;
    uint64_t tested = 0;
    walk(ray, [&](size_t cell, float tExit) {
        for (uint32_t k = cellStart_[cell]; k < cellStart_[cell + 1]; ++k) {
            uint32_t tri = cellTriangles_[k];
            ++tested;
            auto h = intersectTriangle(test, ray, triangle(tri));
            // Equal t: keep the lower index, so the answer does not depend on cell order.
            if (h && (h->t < ray.tmax || (h->t == ray.tmax && tri < best))) {
                ray.tmax = h->t;
                best = tri;
                u = h->u;
                v = h->v;
            }
        }
        // A hit inside this cell cannot be beaten by a later cell.
        return best != kNoPrimitive && ray.tmax <= tExit;
    });
    tested_.fetch_add(tested, std::memory_order_relaxed);
    if (tOut) *tOut = ray.tmax;
    if (uOut) *uOut = u;
    if (vOut) *vOut = v;
    return best;
}

bool TriangleGrid::intersect(const Ray& ray, SurfaceHit& hit) const {
    float t = 0.0f, u = 0.0f, v = 0.0f;
    uint32_t tri = nearestTriangle(ray, test_, &t, &u, &v);
    if (tri == kNoPrimitive) return false;
    hit = triangleHit(mesh_, tri, ray, t, u, v, material_);
    // The shading normal: exercise 1.6's interpolation (smooth), or the triangle's own.
    const auto& idx = mesh_.triangles[tri];
    hit.shadingNormal = smooth_ ? interpolateNormal(mesh_.normals[idx[0]], mesh_.normals[idx[1]],
                                                    mesh_.normals[idx[2]], u, v)
                                : hit.geometricNormal;
    return true;
}

bool TriangleGrid::occluded(const Ray& ray) const {
    bool found = false;
    uint64_t tested = 0;
    walk(ray, [&](size_t cell, float) {
        for (uint32_t k = cellStart_[cell]; k < cellStart_[cell + 1]; ++k) {
            ++tested;
            if (intersectTriangle(test_, ray, triangle(cellTriangles_[k]))) {
                found = true;
                return true;
            }
        }
        return false;
    });
    tested_.fetch_add(tested, std::memory_order_relaxed);
    return found;
}

}  // namespace boxes
