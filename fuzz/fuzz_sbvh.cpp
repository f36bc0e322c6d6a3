// Step 04's builder with spatial splits (steps/04_bvh/advanced/bvh_spatial.cpp) on fuzzed
// geometry. Input: a byte of options, a byte of scale, then up to 48 triangles of 9 int16
// each, coordinates int16 * 2^(scale - 128) (clamped to 2^-120 .. 2^110): meshes from tiny
// to near the float limit, each with 16 bits of resolution. (Raw float triples mixed
// magnitudes 1e-125 to 1e37 in one mesh, where the float leaf test itself breaks down: see
// steps/04_bvh/advanced/README.md, "Known limits".) Promises: the build ends, with a depth
// within the cap and every triangle referenced; every vertex, edge midpoint and centroid
// of every triangle lies in a leaf box that references it (the conservative clipping);
// rays aimed at those points from three origins hit what brute force hits, in the binary
// tree and its 8-wide collapse (where brute force's own hit is within the leaf test's
// error bound, see trustworthy()); occlusion agrees.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "04_bvh/advanced/build.hpp"
#include "04_bvh/advanced/bvh4.hpp"
#include "04_bvh/advanced/rays.hpp"
#include "core/exercise.hpp"
#include "fuzz/fuzz_common.hpp"

namespace {

using namespace boxes;

// Every leaf box that references each triangle; fails on a structural break.
std::vector<std::vector<Bounds3f>> leafBoxes(const Bvh& bvh, size_t triangles) {
    std::vector<std::vector<Bounds3f>> boxes(triangles);
    struct Item {
        uint32_t node;
        int depth;
    };
    std::vector<Item> stack = {{0, 0}};
    while (!stack.empty()) {
        Item item = stack.back();
        stack.pop_back();
        if (item.node >= bvh.nodes.size()) fuzz::fail("node index out of range");
        if (item.depth >= 64) fuzz::fail("deeper than the depth cap");
        const BvhNode& node = bvh.nodes[item.node];
        if (node.isLeaf()) {
            for (uint32_t s = node.leftFirst; s < node.leftFirst + node.count; ++s) {
                if (s >= bvh.primitiveIndices.size()) fuzz::fail("slot out of range");
                uint32_t t = bvh.primitiveIndices[s];
                if (t >= triangles) fuzz::fail("triangle index out of range");
                boxes[t].push_back(node.bounds());
            }
        } else {
            if (node.leftFirst <= item.node) fuzz::fail("a child before its parent");
            stack.push_back({node.leftFirst, item.depth + 1});
            stack.push_back({node.leftFirst + 1, item.depth + 1});
        }
    }
    return boxes;
}

bool inside(const Vec3d& p, const Bounds3f& box) {
    Vec3d lo(box.min), hi(box.max), slack = 1e-12 * (glm::abs(lo) + glm::abs(hi));
    return glm::all(glm::greaterThanEqual(p, lo - slack)) &&
           glm::all(glm::lessThanEqual(p, hi + slack));
}

// The hierarchy promises brute force's hit when the leaf test's hit point lies within the
// triangle's box widened by the traversal margin (the leaf test's error bound for a
// triangle with area). For a needle below the float resolution at the ray origin the leaf
// test's t can be noise far beyond that (step 04's README, "What is left"); then no box
// test can promise the same answer, and the ray is skipped. (Zero-area triangles are
// never hit: leafTriangleOf.)
bool trustworthy(const Mesh& mesh, const Ray& ray, const TraceHit& hit, float margin) {
    if (hit.triangle == kNoPrimitive) return true;
    Vec3d o(ray.origin), d(ray.direction);
    Vec3d p = o + double(hit.t) * d;
    double slack = double(margin) + 4.0 * 0x1p-24 * std::fabs(double(hit.t)) *
                                        (std::fabs(d.x) + std::fabs(d.y) + std::fabs(d.z));
    Bounds3d box;
    for (int k = 0; k < 3; ++k) box.extend(Vec3d(mesh.vertex(hit.triangle, k)));
    return glm::all(glm::greaterThanEqual(p, box.min - Vec3d(slack))) &&
           glm::all(glm::lessThanEqual(p, box.max + Vec3d(slack)));
}

// Only coordinates a float holds (converting a larger double is undefined behaviour).
bool fitsFloat(const Vec3d& v) {
    return glm::all(glm::lessThanEqual(glm::abs(v), Vec3d(3.0e38)));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 2) return 0;
    BvhBuildOptions options;
    options.builder = BvhBuilder::SpatialSah;
    // Small leaves, expensive triangle tests and no overlap threshold: the few triangles
    // of an input are then split, spatially too, as a large mesh's would be.
    options.maxLeafSize = 1 + (data[0] & 3);
    options.intersectionCost = float(1 + ((data[0] >> 2) & 7));
    options.spatialSplitAlpha = 0.0f;
    options.bins = 2 + ((data[0] >> 5) & 7) * 2;
    const float scale = std::ldexp(1.0f, std::clamp(int(data[1]) - 128, -120, 110));
    Mesh mesh;
    for (size_t at = 2; at + 18 <= size && mesh.triangles.size() < 48; at += 18) {
        int16_t q[9];
        std::memcpy(q, data + at, sizeof q);
        uint32_t n = uint32_t(mesh.positions.size());
        for (int k = 0; k < 3; ++k)
            mesh.positions.push_back(scale * Vec3(q[3 * k], q[3 * k + 1], q[3 * k + 2]));
        mesh.triangles.push_back({n, n + 1, n + 2});
    }
    if (mesh.triangles.empty()) return 0;
    Bvh bvh;
    try {
        bvh = buildEngineBvh(mesh, options);
    } catch (const NotImplemented&) {
        return 0;  // a starter kit: exercise 4.3 not solved yet
    }
    size_t triangles = mesh.triangleCount();
    auto boxes = leafBoxes(bvh, triangles);
    if (bvh.leafTriangles.size() != bvh.primitiveIndices.size())
        fuzz::fail("leaf triangles and slots differ in number");

    // The points that matter for cracks, in double; the rays aim at their float roundings.
    std::vector<Vec3d> points;
    Bounds3d all;
    for (size_t t = 0; t < triangles; ++t) {
        if (boxes[t].empty()) fuzz::fail("a triangle in no leaf");
        Vec3d a(mesh.vertex(t, 0)), b(mesh.vertex(t, 1)), c(mesh.vertex(t, 2));
        for (const Vec3d& p :
             {a, b, c, 0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + a), (a + b + c) / 3.0}) {
            bool covered = false;
            for (const Bounds3f& box : boxes[t]) covered = covered || inside(p, box);
            if (!covered) fuzz::fail("a point of a triangle outside every leaf box of it");
            points.push_back(p);
            all.extend(p);
        }
    }
    Bvh8 wide = collapseToBvh8(bvh);
    Vec3d centre = all.centroid(), reach = all.diagonal() + Vec3d(1.0);
    const Vec3d origins[3] = {centre + Vec3d(reach.x, 0.37 * reach.y, 0.21 * reach.z),
                              centre - Vec3d(0.29 * reach.x, reach.y, 0.43 * reach.z),
                              centre + Vec3d(0.11 * reach.x, 0.53 * reach.y, -reach.z)};
    for (const Vec3d& target : points)
        for (const Vec3d& from : origins) {
            if (!fitsFloat(from)) continue;
            Vec3 o(from), d = Vec3(target) - o;
            if (!isFinite(d) || maxComponent(glm::abs(d)) < kMinRayDirection) continue;
            Ray ray(o, d, 0.0f, 2.0f);
            TraceHit want = traceBruteForce(mesh, ray);
            if (!trustworthy(mesh, ray, want, TraversalRay::marginFor(ray, bvh.bounds()))) {
                continue;
            }
            if (!hitsAgree(traceNearest(bvh, ray), want))
                fuzz::fail("the spatial-split tree disagrees with brute force");
            if (!hitsAgree(traceNearest(wide, ray), want))
                fuzz::fail("its 8-wide collapse disagrees with brute force");
            if (traceOccluded(bvh, ray) != (want.triangle != kNoPrimitive))
                fuzz::fail("occlusion disagrees with the nearest hit");
        }
    return 0;
}
