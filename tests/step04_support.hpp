// Step 04's tests: what several of the topic files share. Builds and traces only through
// the chapter (steps/04_bvh, not advanced/), so the exercises' tests need nothing else.
#pragma once

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <vector>

#include "04_bvh/frustum.hpp"
#include "04_bvh/trace.hpp"
#include "core/mesh.hpp"
#include "support.hpp"

namespace boxes::test04 {

inline Bounds3f unitBoxAt(Vec3 lo) {
    return {lo, lo + Vec3(1.0f)};
}

inline std::vector<BuildPrimitive> primitivesOf(const std::vector<Bounds3f>& boxes) {
    std::vector<BuildPrimitive> prims;
    for (size_t i = 0; i < boxes.size(); ++i)
        prims.push_back({boxes[i], boxes[i].centroid(), uint32_t(i)});
    return prims;
}

inline Bounds3f centroidBounds(const std::vector<BuildPrimitive>& prims) {
    Bounds3f b;
    for (const auto& p : prims) b.extend(p.centroid);
    return b;
}

inline Bounds3f boundsOf(const std::vector<BuildPrimitive>& prims) {
    Bounds3f b;
    for (const auto& p : prims) {
        b.extend(p.bounds.min);
        b.extend(p.bounds.max);
    }
    return b;
}

// Random small triangles in the unit cube (a soup: the hard, overlapping case).
inline Mesh triangleSoup(size_t count, uint64_t seed, float size = 0.08f) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    Mesh m;
    for (size_t i = 0; i < count; ++i) {
        Vec3 c(u(rng), u(rng), u(rng));
        for (int k = 0; k < 3; ++k)
            m.positions.push_back(c + size * (Vec3(u(rng), u(rng), u(rng)) - 0.5f));
        m.triangles.push_back({uint32_t(3 * i), uint32_t(3 * i + 1), uint32_t(3 * i + 2)});
    }
    return m;
}

// Checks what every builder must give: each primitive in exactly one leaf, node bounds
// equal to the union of their children (leaves: of their primitives), children adjacent
// after the parent, depth within the cap.
inline void checkStructure(const Bvh& bvh, const std::vector<Bounds3f>& boxes, int maxDepth = 64) {
    REQUIRE_FALSE(bvh.empty());
    REQUIRE(bvh.primitiveIndices.size() == boxes.size());
    std::vector<int> seen(boxes.size(), 0);
    std::vector<std::pair<uint32_t, int>> stack = {{0, 0}};
    size_t reached = 0;
    while (!stack.empty()) {
        auto [index, depth] = stack.back();
        stack.pop_back();
        ++reached;
        REQUIRE(index < bvh.nodes.size());
        const BvhNode& node = bvh.nodes[index];
        CHECK(depth < maxDepth);
        Bounds3f expected;
        if (node.isLeaf()) {
            REQUIRE(size_t(node.leftFirst) + node.count <= boxes.size());
            for (uint32_t s = node.leftFirst; s < node.leftFirst + node.count; ++s) {
                uint32_t p = bvh.primitiveIndices[s];
                REQUIRE(p < boxes.size());
                ++seen[p];
                expected.extend(boxes[p].min);
                expected.extend(boxes[p].max);
            }
        } else {
            REQUIRE(node.leftFirst > index);
            REQUIRE(node.leftFirst + 1 < bvh.nodes.size());
            for (uint32_t c : {node.leftFirst, node.leftFirst + 1}) {
                expected.extend(bvh.nodes[c].boundsMin);
                expected.extend(bvh.nodes[c].boundsMax);
                stack.push_back({c, depth + 1});
            }
        }
        CHECK(node.bounds() == expected);
    }
    CHECK(reached == bvh.nodes.size());
    for (int n : seen) REQUIRE(n == 1);
}

inline std::vector<Bounds3f> triangleBounds(const Mesh& m) {
    std::vector<Bounds3f> boxes;
    for (size_t i = 0; i < m.triangleCount(); ++i) {
        Bounds3f b;
        for (int k = 0; k < 3; ++k) b.extend(m.vertex(i, k));
        boxes.push_back(b);
    }
    return boxes;
}

inline BvhBuildOptions optionsFor(BvhBuilder builder) {
    BvhBuildOptions o;
    o.builder = builder;
    o.intersectionCost = 1.0f;  // the hand-worked SAH costs below take both costs as 1
    return o;
}

// Test-local reference triangle test: Moller-Trumbore in double (not step 01's exercise).
inline bool referenceTriangle(const Ray& ray, const LeafTriangle& tri, double& t) {
    Vec3d o(ray.origin), d(ray.direction), a(tri.a), b(tri.b), c(tri.c);
    Vec3d e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
    double det = glm::dot(e1, p);
    if (det == 0.0) return false;
    Vec3d s = o - a;
    double u = glm::dot(s, p) / det;
    Vec3d q = glm::cross(s, e1);
    double v = glm::dot(d, q) / det;
    if (u < 0.0 || v < 0.0 || u + v > 1.0) return false;
    t = glm::dot(e2, q) / det;
    return t >= ray.tmin && t <= ray.tmax;
}

// The reference test as a traversal's leaf test over `tree`'s leaf triangles: a hit in
// [ray.tmin, tmax] nearer than tBest (double) lowers both.
template <typename Tree>
inline auto referenceLeafTest(const Tree& tree, const Ray& ray, double& tBest) {
    return [&tree, &ray, &tBest](uint32_t s, float& tmax) {
        double t;
        if (!referenceTriangle(ray, tree.leafTriangles[s], t) || !(t <= double(tmax)) ||
            !(t < tBest))
            return false;
        tBest = t;
        tmax = float(t);
        return true;
    };
}

// Nearest through the hierarchy with the reference test; the slot's primitive or miss.
inline uint32_t nearestWithReference(const Bvh& bvh, const Ray& ray, double& tBest) {
    tBest = kInfinity<double>;
    float tClosest = ray.tmax;
    uint32_t slot =
        traverseNearest(bvh, TraversalRay(ray), tClosest, referenceLeafTest(bvh, ray, tBest));
    return slot == kTraversalMiss ? kNoPrimitive : bvh.primitiveIndices[slot];
}

inline uint32_t bruteWithReference(const Mesh& m, const Ray& ray, double& tBest) {
    tBest = kInfinity<double>;
    uint32_t best = kNoPrimitive;
    for (size_t i = 0; i < m.triangleCount(); ++i) {
        double t;
        LeafTriangle tri{m.vertex(i, 0), m.vertex(i, 1), m.vertex(i, 2)};
        if (referenceTriangle(ray, tri, t) && t < tBest) {
            tBest = t;
            best = uint32_t(i);
        }
    }
    return best;
}

inline std::vector<Ray> randomRays(size_t count, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> u(-0.2f, 1.2f), d(-1.0f, 1.0f);
    std::vector<Ray> rays;
    while (rays.size() < count) {
        Vec3 dir(d(rng), d(rng), d(rng));
        if (glm::length(dir) < 0.1f) continue;
        rays.emplace_back(Vec3(u(rng), u(rng), u(rng)), dir);
    }
    return rays;
}

// Rays from `distance` away towards triangles' centres (the camera of makeRays needs
// squared lengths, which overflow for meshes near 1e20).
inline std::vector<Ray> raysAtTriangles(const Mesh& m, size_t count, float distance,
                                        uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    std::vector<Ray> rays;
    for (size_t i = 0; i < count; ++i) {
        size_t tri = size_t(rng() % m.triangleCount());
        Vec3 target = (m.vertex(tri, 0) + m.vertex(tri, 1) + m.vertex(tri, 2)) / 3.0f;
        Vec3 offset(unit(rng), unit(rng), unit(rng));
        if (glm::length(offset) < 0.1f) offset = Vec3(0.0f, 0.0f, 1.0f);
        Vec3 origin = target + glm::normalize(offset) * distance;
        rays.emplace_back(origin, target - origin);
    }
    return rays;
}

// A camera at the origin looking down -z, 90 degree field of view, square.
inline Camera frustumCamera() {
    Camera c;
    c.eye = Vec3(0.0f);
    c.view = Vec3(0, 0, -1);
    c.up = Vec3(0, 1, 0);
    c.fovYDegrees = 90.0f;
    c.aspect = 1.0f;
    return c;
}

// Hand-made frustum of that camera (near 1, far 100), so the culling tests do not depend
// on exercise 4.6.
inline Frustum handFrustum() {
    Frustum f;
    float s = std::sqrt(0.5f);
    f.planes[kLeftPlane] = {Vec3(s, 0, -s), 0.0f};    // x >= z
    f.planes[kRightPlane] = {Vec3(-s, 0, -s), 0.0f};  // x <= -z
    f.planes[kBottomPlane] = {Vec3(0, s, -s), 0.0f};  // y >= z
    f.planes[kTopPlane] = {Vec3(0, -s, -s), 0.0f};    // y <= -z
    f.planes[kNearPlane] = {Vec3(0, 0, -1), -1.0f};   // z <= -1
    f.planes[kFarPlane] = {Vec3(0, 0, 1), 100.0f};    // z >= -100
    f.corners = {Vec3(-1, 1, -1),        Vec3(1, 1, -1),        Vec3(-1, -1, -1),
                 Vec3(1, -1, -1),        Vec3(-100, 100, -100), Vec3(100, 100, -100),
                 Vec3(-100, -100, -100), Vec3(100, -100, -100)};
    return f;
}

// Every triangle of m whose box meets the frustum exactly is among `kept` (culling is
// conservative); returns how many there are.
inline size_t checkKeptInsideFrustum(const Mesh& m, const Frustum& f,
                                     const std::set<uint32_t>& kept) {
    size_t inside = 0;
    for (size_t i = 0; i < m.triangleCount(); ++i) {
        Bounds3f b;
        for (int k = 0; k < 3; ++k) b.extend(m.vertex(i, k));
        if (!boxIntersectsFrustumExact(f, b)) continue;
        ++inside;
        CHECK(kept.count(uint32_t(i)) == 1);
    }
    return inside;
}

// The tests' own reference builder: the full-sweep SAH (every primitive boundary on every
// axis), not an exercise, so the traversal and culling tests pass with only their own
// exercise solved. The engine has the same rule (advanced/build.hpp); this is a copy, not a
// call, because the grader takes everything under steps/ from the student's tree (a
// reference there would be the student's to change) and the exercises' tests must not
// need the engine.
inline size_t referenceSweepSah(std::span<BuildPrimitive> prims, const Bounds3f& nodeBounds,
                                const Bounds3f&, const BvhBuildOptions& options, float& cost) {
    cost = kInfinity<float>;
    size_t n = prims.size();
    float nodeArea = nodeBounds.surfaceArea();
    if (n < 2 || !(nodeArea > 0.0f)) return 0;
    auto byCentroid = [](int axis) {
        return [axis](const BuildPrimitive& a, const BuildPrimitive& b) {
            return a.centroid[axis] < b.centroid[axis] ||
                   (a.centroid[axis] == b.centroid[axis] && a.index < b.index);
        };
    };
    int bestAxis = -1;
    size_t bestLeft = 0;
    std::vector<float> rightArea(n);
    for (int axis = 0; axis < 3; ++axis) {
        std::sort(prims.begin(), prims.end(), byCentroid(axis));
        Bounds3f right, left;
        for (size_t i = n; i-- > 1;) {
            right.extend(prims[i].bounds.min);
            right.extend(prims[i].bounds.max);
            rightArea[i] = right.surfaceArea();
        }
        for (size_t i = 1; i < n; ++i) {
            left.extend(prims[i - 1].bounds.min);
            left.extend(prims[i - 1].bounds.max);
            if (prims[i - 1].centroid[axis] == prims[i].centroid[axis]) continue;
            float c = options.traversalCost +
                      options.intersectionCost *
                          (left.surfaceArea() * float(i) + rightArea[i] * float(n - i)) / nodeArea;
            if (c < cost) cost = c, bestAxis = axis, bestLeft = i;
        }
    }
    if (bestAxis < 0) return 0;
    std::sort(prims.begin(), prims.end(), byCentroid(bestAxis));
    return bestLeft;
}

// A tree of the reference builder over a mesh (both SAH costs 1, as optionsFor).
inline Bvh referenceTree(const Mesh& m, BvhBuildStats* stats = nullptr) {
    return buildBvh(m, SplitRule{referenceSweepSah, true}, optionsFor(BvhBuilder::SweepSah), stats);
}

}  // namespace boxes::test04
