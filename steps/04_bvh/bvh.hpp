// Step 04: a bounding volume hierarchy over triangles (or any primitives with bounds).
//
// Layout (after Bikker's tinybvh and pbrt's LinearBVHNode): one array of 32-byte nodes,
// two per cache line; the children of an interior node are adjacent (left, left + 1), so
// a node needs one index; a leaf names a range of "slots" in primitiveIndices, which the
// builder reorders so every leaf's primitives are contiguous. For meshes the triangles'
// vertices are also copied in slot order (leafTriangles): the leaf test reads them
// sequentially instead of chasing two indices per triangle.
//
// Builders share one recursive framework (buildBvh, bvh_build.cpp); what differs is how a
// node's primitives are split, and that is the exercises: 4.1 midpoint, 4.2 object median,
// 4.3 binned SAH. The traversal (4.4 nearest hit, 4.5 any hit) is in traverse.hpp.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory_resource>
#include <span>
#include <string>
#include <vector>

#include "core/bounds.hpp"
#include "core/exercise.hpp"
#include "core/mesh.hpp"

namespace boxes {

// 32 bytes: bounds, then leftFirst (interior: index of the left child, the right child is
// leftFirst + 1; leaf: first slot) and count (0 for an interior node, else the leaf's size).
struct alignas(32) BvhNode {
    Vec3 boundsMin{kInfinity<float>};
    uint32_t leftFirst = 0;
    Vec3 boundsMax{-kInfinity<float>};
    uint32_t count = 0;

    bool isLeaf() const { return count != 0; }
    Bounds3f bounds() const { return {boundsMin, boundsMax}; }
};
static_assert(sizeof(BvhNode) == 32, "two nodes per 64-byte cache line");

// A triangle's vertices, stored in leaf-slot order for the leaf test.
struct LeafTriangle {
    Vec3 a, b, c;
};

// The leaf-test copy of a mesh's triangle. A triangle without area (the cross product of
// its edge vectors exactly zero in double: a repeated vertex, or three on one line) is
// stored as its first vertex three times, which the watertight test misses for every ray
// (its edge functions and det are exactly 0), at no cost in the hot loop. pbrt-v4's
// IntersectTriangle rejects such triangles too: their edge functions are rounding noise,
// and so would be a t computed from them.
LeafTriangle leafTriangleOf(const Mesh& mesh, size_t triangle);

// The tree. Its arrays are std::pmr vectors: a build takes the memory they live in
// (BvhBuildOptions::memory), as pbrt-v4's builders take an allocator. The chapter's trees
// live on the heap; the step's engine places its trees on huge pages (advanced/memory.hpp).
struct Bvh {
    Bvh() = default;
    explicit Bvh(std::pmr::memory_resource* memory)
        : nodes(memory), primitiveIndices(memory), leafTriangles(memory) {}

    std::pmr::vector<BvhNode> nodes;               // nodes[0] is the root (when not empty)
    std::pmr::vector<uint32_t> primitiveIndices;   // slot -> primitive (triangle in file order)
    std::pmr::vector<LeafTriangle> leafTriangles;  // meshes only: vertices per slot

    bool empty() const { return nodes.empty(); }
    Bounds3f bounds() const { return empty() ? Bounds3f() : nodes[0].bounds(); }
    const BvhNode& rootNode() const { return nodes[0]; }  // not when empty
};

// The builders. The first three are the exercises, built by buildBvh below; the full-sweep
// SAH (the quality reference) and the SAH with spatial splits are the step's engine's
// (advanced/build.hpp).
enum class BvhBuilder { Midpoint, Median, BinnedSah, SweepSah, SpatialSah };
constexpr BvhBuilder kExerciseBuilders[] = {BvhBuilder::Midpoint, BvhBuilder::Median,
                                            BvhBuilder::BinnedSah};
// "midpoint", "median", "sah", "sweep-sah", "sbvh"
const char* bvhBuilderName(BvhBuilder builder);
BvhBuilder parseBvhBuilder(const std::string& name);  // throws InputError

// The deepest a tree may be: the builders make a node a leaf there, whatever its size,
// so the traversal's stack (traverse.hpp) never overflows.
constexpr int kMaxBvhDepth = 64;

struct BvhBuildOptions {
    BvhBuilder builder = BvhBuilder::BinnedSah;
    int bins = 16;                // binned SAH: candidate planes per axis are bins - 1
    int leafSize = 4;             // midpoint / median: a node with at most this many is a leaf
    int maxLeafSize = 16;         // SAH: a node may become a leaf (when cheaper) up to this size
    int maxDepth = kMaxBvhDepth;  // below this a node becomes a leaf, whatever its size
    // SAH constants: cost of a node visit and of a primitive test (Goldsmith & Salmon 1987,
    // MacDonald & Booth 1990). Only their ratio matters for the tree. A node visit tests
    // two boxes and may wait for memory; one watertight triangle test from a leaf's
    // contiguous slots costs about half of that (advanced/README.md).
    float traversalCost = 1.0f;
    float intersectionCost = 0.5f;
    // Builder sbvh only (advanced/bvh_spatial.cpp): spatial splits are tried where the
    // best object split's children overlap by more than alpha times the root's area, until
    // the triangles cut in two reach this fraction of the triangle count. Stich et al.
    // 2009 use alpha 1e-5; 1e-3 traces as fast and builds faster (advanced/README.md).
    float spatialSplitAlpha = 1e-3f;
    float spatialSplitBudget = 1.0f;
    // Where the tree's arrays and the build's working array live; null: the heap.
    std::pmr::memory_resource* memory = nullptr;
};

// Per build: what the report prints for every hierarchy.
struct BvhBuildStats {
    double buildMs = 0.0;  // the build only (primitive bounds included, file reading not)
    size_t nodes = 0, leaves = 0;
    size_t minLeafSize = 0, maxLeafSize = 0;
    double meanLeafSize = 0.0;
    int depth = 0;         // the deepest leaf; the root is depth 0
    double sahCost = 0.0;  // see bvhSahCost
};

// A primitive during the build: its bounds, their centroid, its index.
struct BuildPrimitive {
    Bounds3f bounds;
    Vec3 centroid;
    uint32_t index;
};

// The split rules. Each reorders `prims` (one node's primitives) and returns how many go
// to the left child (the first ones). Returning 0 or prims.size() means "no useful split";
// the framework then makes a leaf when it may, else splits the range in the middle.

// Exercise 4.1: midpoint split: the middle of the centroid bounds' longest axis.
size_t partitionMidpoint(std::span<BuildPrimitive> prims, const Bounds3f& centroidBounds);

// Exercise 4.2: object median: half of the primitives (by centroid) on each side, along
// the centroid bounds' longest axis.
size_t partitionMedian(std::span<BuildPrimitive> prims, const Bounds3f& centroidBounds);

// Exercise 4.3: binned SAH (Wald 2007): centroids into `bins` equal bins per axis, the
// split between bins with the least SAH cost. Sets `cost` to that split's cost,
// traversalCost + intersectionCost * (A_L N_L + A_R N_R) / A_node, and returns 0 (cost
// infinity) when no axis can be split (all centroids equal).
size_t partitionBinnedSah(std::span<BuildPrimitive> prims, const Bounds3f& nodeBounds,
                          const Bounds3f& centroidBounds, const BvhBuildOptions& options,
                          float& cost);

// A split rule as the framework calls it: the exercises' rules wrapped (splitRuleOf), or
// one of the caller's (the engine's full-sweep SAH, a test's reference). With `sah` the
// rule prices its split in `cost`, and a node of up to maxLeafSize primitives becomes a
// leaf when that is cheaper; without it a node of up to leafSize is a leaf.
struct SplitRule {
    size_t (*partition)(std::span<BuildPrimitive> prims, const Bounds3f& nodeBounds,
                        const Bounds3f& centroidBounds, const BvhBuildOptions& options,
                        float& cost);
    bool sah;
};
// The rule of an exercise builder (std::invalid_argument for the engine's two).
SplitRule splitRuleOf(BvhBuilder builder);

// Builds the hierarchy over primitives with the given bounds (index = position), with
// options.builder's rule. Handles every input: empty lists, identical centroids, flat
// boxes, huge counts. Throws InputError for bins outside 2..256 or a depth cap outside
// 1..kMaxBvhDepth (checkBuildOptions).
Bvh buildBvh(std::span<const Bounds3f> primitiveBounds, const BvhBuildOptions& options,
             BvhBuildStats* stats = nullptr);
// The same over a mesh's triangles, also filling leafTriangles.
Bvh buildBvh(const Mesh& mesh, const BvhBuildOptions& options, BvhBuildStats* stats = nullptr);
// Both with the caller's rule instead of options.builder's.
Bvh buildBvh(std::span<const Bounds3f> primitiveBounds, const SplitRule& rule,
             const BvhBuildOptions& options, BvhBuildStats* stats = nullptr);
Bvh buildBvh(const Mesh& mesh, const SplitRule& rule, const BvhBuildOptions& options,
             BvhBuildStats* stats = nullptr);

void checkBuildOptions(const BvhBuildOptions& options);
// The mesh's primitives as the builders start from them: each triangle's bounds and
// centroid; throws InputError for more triangles than 32-bit slots can name.
std::pmr::vector<BuildPrimitive> trianglePrimitives(const Mesh& mesh,
                                                    std::pmr::memory_resource* memory);
// Copies the triangles' vertices in slot order into bvh.leafTriangles.
void fillLeafTriangles(Bvh& bvh, const Mesh& mesh);

// SAH cost of a built tree: sum over interior nodes of traversalCost * A(node) / A(root)
// plus over leaves of intersectionCost * count * A(leaf) / A(root).
double bvhSahCost(const Bvh& bvh, float traversalCost = 1.0f, float intersectionCost = 1.0f);
// Nodes, leaves, leaf sizes, depth and the SAH cost (buildMs left 0).
BvhBuildStats bvhStats(const Bvh& bvh, const BvhBuildOptions& options);

}  // namespace boxes
