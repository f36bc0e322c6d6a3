#include "05_efficiency/cluster_mesh.hpp"

#include <algorithm>
#include <numeric>

namespace boxes {

namespace {

// Spreads the low 10 bits of v so two zero bits follow each (for a 30-bit Morton code).
uint32_t spreadBits(uint32_t v) {
    v = (v | (v << 16)) & 0x030000FFu;
    v = (v | (v << 8)) & 0x0300F00Fu;
    v = (v | (v << 4)) & 0x030C30C3u;
    v = (v | (v << 2)) & 0x09249249u;
    return v;
}

}  // namespace

ClusterMesh::ClusterMesh(const Mesh& mesh, int material, int clusterSize)
    : mesh_(mesh), material_(material) {
    if (clusterSize < 1) throw std::invalid_argument("cluster size must be at least 1");
    const size_t n = mesh.triangleCount();
    Bounds3f centroids;
    for (size_t t = 0; t < n; ++t) {
        for (int k = 0; k < 3; ++k) bounds_.extend(mesh.vertex(t, k));
        centroids.extend((mesh.vertex(t, 0) + mesh.vertex(t, 1) + mesh.vertex(t, 2)) / 3.0f);
    }
    std::vector<uint32_t> code(n);
    Vec3 extent = glm::max(centroids.diagonal(), Vec3(1e-30f));
    for (size_t t = 0; t < n; ++t) {
        Vec3 c = (mesh.vertex(t, 0) + mesh.vertex(t, 1) + mesh.vertex(t, 2)) / 3.0f;
        glm::uvec3 q =
            glm::uvec3(glm::clamp((c - centroids.min) / extent * 1023.0f, 0.0f, 1023.0f));
        code[t] = spreadBits(q.x) << 2 | spreadBits(q.y) << 1 | spreadBits(q.z);
    }
    order_.resize(n);
    std::iota(order_.begin(), order_.end(), 0u);
    std::stable_sort(order_.begin(), order_.end(),
                     [&](uint32_t a, uint32_t b) { return code[a] < code[b]; });
    for (uint32_t t : order_) {
        TriangleVertices v{mesh.vertex(t, 0), mesh.vertex(t, 1), mesh.vertex(t, 2)};
        vertices_.push_back(v);
        precomputed_.push_back(precomputeTriangle(v));
    }
    for (size_t begin = 0; begin < n; begin += size_t(clusterSize)) {
        Cluster c;
        c.begin = uint32_t(begin);
        c.end = uint32_t(std::min(n, begin + size_t(clusterSize)));
        for (uint32_t i = c.begin; i < c.end; ++i) {
            c.box.extend(vertices_[i].a);
            c.box.extend(vertices_[i].b);
            c.box.extend(vertices_[i].c);
        }
        clusters_.push_back(c);
    }
}

std::optional<float> ClusterMesh::boxTest(const Ray& ray, const PrecomputedRay& pre,
                                          const Bounds3f& box) const {
    return options_.reciprocal ? slabReciprocal(pre, box) : slabDivision(ray, box);
}

std::optional<TriangleHitT> ClusterMesh::triangleTest(const Ray& ray, uint32_t i) const {
    return options_.precomputedTriangles ? intersectPrecomputed(ray, precomputed_[i])
                                         : intersectFromVertices(ray, vertices_[i]);
}

long ClusterMesh::nearest(const Ray& rayIn, TriangleHitT& best) const {
    Ray ray = rayIn;
    PrecomputedRay pre = options_.reciprocal ? precomputeRay(ray) : PrecomputedRay{};
    uint64_t boxes = 0, tris = 0;
    long found = -1;
    for (const Cluster& c : clusters_) {
        ++boxes;
        // With early out the box is tested against [tmin, nearest t so far]: a box entered
        // beyond the nearest hit cannot hold a nearer one. Without, against the full ray.
        if (options_.skipFarClusters) pre.tmax = ray.tmax;
        Ray boxRay = options_.skipFarClusters ? ray : rayIn;
        if (!boxTest(boxRay, pre, c.box)) continue;
        for (uint32_t i = c.begin; i < c.end; ++i) {
            ++tris;
            if (auto h = triangleTest(ray, i)) {
                best = *h;
                ray.tmax = h->t;
                found = long(i);
            }
        }
    }
    boxTests_.fetch_add(boxes, std::memory_order_relaxed);
    triangleTests_.fetch_add(tris, std::memory_order_relaxed);
    return found;
}

bool ClusterMesh::intersect(const Ray& ray, SurfaceHit& hit) const {
    TriangleHitT best{};
    long i = nearest(ray, best);
    if (i < 0) return false;
    uint32_t t = order_[size_t(i)];
    hit.t = best.t;
    hit.point = ray.at(best.t);
    hit.geometricNormal = glm::normalize(precomputed_[size_t(i)].normal);
    const auto& idx = mesh_.triangles[t];
    if (mesh_.normals.size() == mesh_.positions.size()) {
        Vec3 n = (1.0f - best.u - best.v) * mesh_.normals[idx[0]] + best.u * mesh_.normals[idx[1]] +
                 best.v * mesh_.normals[idx[2]];
        float len = glm::length(n);
        hit.shadingNormal = len > 0.0f && std::isfinite(len) ? n / len : hit.geometricNormal;
    } else {
        hit.shadingNormal = hit.geometricNormal;
    }
    hit.u = best.u;
    hit.v = best.v;
    hit.material = material_;
    hit.primitive = t;
    hit.kind = SurfaceHit::Kind::Triangle;
    return true;
}

bool ClusterMesh::occluded(const Ray& ray) const {
    if (!options_.anyHitShadows) {
        TriangleHitT best{};
        return nearest(ray, best) >= 0;
    }
    PrecomputedRay pre = options_.reciprocal ? precomputeRay(ray) : PrecomputedRay{};
    uint64_t boxes = 0, tris = 0;
    bool blocked = anyHit(
        clusters_.size(),
        [&](size_t k) {
            const Cluster& c = clusters_[k];  // anyHit counts the box tests
            if (!boxTest(ray, pre, c.box)) return false;
            return anyHit(
                c.end - c.begin,
                [&](size_t j) { return triangleTest(ray, c.begin + uint32_t(j)).has_value(); },
                tris);
        },
        boxes);
    boxTests_.fetch_add(boxes, std::memory_order_relaxed);
    triangleTests_.fetch_add(tris, std::memory_order_relaxed);
    return blocked;
}

}  // namespace boxes
