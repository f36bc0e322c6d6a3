#include "05_efficiency/bvh_mesh.hpp"

#include <algorithm>

#include "04_bvh/advanced/build.hpp"
#include "core/mesh.hpp"

namespace boxes {

namespace {

BvhBuildOptions labBuildOptions() {
    BvhBuildOptions o;
    o.builder = BvhBuilder::SweepSah;  // not an exercise of step 04
    o.maxLeafSize = 8;
    return o;
}

}  // namespace

LabBvhMesh::LabBvhMesh(const Mesh& mesh, int material)
    : mesh_(mesh), material_(material), bvh_(buildEngineBvh(mesh, labBuildOptions(), &stats_)) {
    for (const LeafTriangle& t : bvh_.leafTriangles) {
        TriangleVertices v{t.a, t.b, t.c};
        vertices_.push_back(v);
        precomputed_.push_back(precomputeTriangle(v));
    }
}

LabBvhMesh::RayData LabBvhMesh::prepare(const Ray& ray) const {
    // Only what the chosen tests use is computed (the others are left default).
    const bool robust = options_.robust;
    return {ray, !robust && options_.reciprocal ? precomputeRay(ray) : PrecomputedRay{},
            robust ? TraversalRay(ray, bvh_) : TraversalRay(Ray(Vec3(0.0f), Vec3(1.0f))),
            robust ? WatertightRay(ray) : WatertightRay(Ray(Vec3(0.0f), Vec3(1.0f)))};
}

bool LabBvhMesh::boxTest(RayData& r, const BvhNode& node, float tmax, float& tEntry) const {
    if (options_.robust) return intersectNodeBounds(node, r.traversal, tmax, tEntry);
    std::optional<float> t;
    if (options_.reciprocal) {
        r.pre.tmax = tmax;
        t = slabReciprocal(r.pre, node.bounds());
    } else {
        Ray clipped = r.ray;
        clipped.tmax = tmax;
        t = slabDivision(clipped, node.bounds());
    }
    if (t) tEntry = *t;
    return t.has_value();
}

std::optional<TriangleHitT> LabBvhMesh::triangleTest(const RayData& r, const Ray& ray,
                                                     uint32_t slot) const {
    if (options_.robust) {
        float t = ray.tmax, u = 0.0f, v = 0.0f;
        if (!intersectLeafTriangle(r.watertight, bvh_.leafTriangles[slot], t, &u, &v))
            return std::nullopt;
        return TriangleHitT{t, u, v};
    }
    return options_.precomputedTriangles ? intersectPrecomputed(ray, precomputed_[slot])
                                         : intersectFromVertices(ray, vertices_[slot]);
}

long LabBvhMesh::nearest(const Ray& rayIn, TriangleHitT& best) const {
    if (bvh_.empty()) return -1;
    Ray ray = rayIn;  // ray.tmax falls to the nearest hit found so far
    RayData data = prepare(rayIn);
    uint64_t boxes = 0, tris = 0;
    long found = -1;
    const bool skip = options_.skipBeyondNearest;
    struct Entry {
        uint32_t node;
        float tEntry;
    } stack[kTraversalStackSize];
    int size = 0;
    float tRoot = 0.0f;
    ++boxes;
    if (boxTest(data, bvh_.nodes[0], rayIn.tmax, tRoot)) stack[size++] = {0, tRoot};
    while (size > 0) {
        Entry e = stack[--size];
        // Early out: a node entered beyond the nearest hit so far cannot hold a nearer one.
        if (skip && e.tEntry > ray.tmax) continue;
        const BvhNode& node = bvh_.nodes[e.node];
        if (node.isLeaf()) {
            for (uint32_t s = node.leftFirst; s < node.leftFirst + node.count; ++s) {
                ++tris;
                if (auto h = triangleTest(data, ray, s)) {
                    best = *h;
                    ray.tmax = h->t;
                    found = long(s);
                }
            }
            continue;
        }
        // With the early out the boxes are tested against the nearest t so far and the
        // nearer child is visited first; without it, against the ray's whole extent, left
        // child first (storage order).
        float boxTmax = skip ? ray.tmax : rayIn.tmax;
        uint32_t a = node.leftFirst, b = node.leftFirst + 1;
        float ta = 0.0f, tb = 0.0f;
        boxes += 2;
        bool hitA = boxTest(data, bvh_.nodes[a], boxTmax, ta);
        bool hitB = boxTest(data, bvh_.nodes[b], boxTmax, tb);
        if (skip && hitA && hitB && tb < ta) {
            std::swap(a, b);
            std::swap(ta, tb);
        }
        // The stack is last in, first out: push the one to visit second first.
        if (hitB) stack[size++] = {b, tb};
        if (hitA) stack[size++] = {a, ta};
    }
    boxTests_.fetch_add(boxes, std::memory_order_relaxed);
    triangleTests_.fetch_add(tris, std::memory_order_relaxed);
    return found;
}

bool LabBvhMesh::intersect(const Ray& ray, SurfaceHit& hit) const {
    TriangleHitT best{};
    long slot = nearest(ray, best);
    if (slot < 0) return false;
    uint32_t t = bvh_.primitiveIndices[size_t(slot)];
    hit = triangleHit(mesh_, t, ray, best.t, best.u, best.v, material_);
    return true;
}

bool LabBvhMesh::occluded(const Ray& ray) const {
    if (!options_.anyHitShadows) {
        TriangleHitT best{};
        return nearest(ray, best) >= 0;
    }
    if (bvh_.empty()) return false;
    // Any hit: no order, no nearest t; the first triangle that blocks ends the traversal.
    RayData data = prepare(ray);
    uint64_t boxes = 0, tris = 0;
    uint32_t stack[kTraversalStackSize];
    int size = 0;
    stack[size++] = 0;
    bool blocked = false;
    while (size > 0 && !blocked) {
        const BvhNode& node = bvh_.nodes[stack[--size]];
        float tEntry;
        ++boxes;
        if (!boxTest(data, node, ray.tmax, tEntry)) continue;
        if (node.isLeaf()) {
            blocked = anyHit(  // exercise 5.4 over the leaf's triangles
                node.count,
                [&](size_t j) {
                    return triangleTest(data, ray, node.leftFirst + uint32_t(j)).has_value();
                },
                tris);
        } else {
            stack[size++] = node.leftFirst + 1;
            stack[size++] = node.leftFirst;
        }
    }
    boxTests_.fetch_add(boxes, std::memory_order_relaxed);
    triangleTests_.fetch_add(tris, std::memory_order_relaxed);
    return blocked;
}

}  // namespace boxes
