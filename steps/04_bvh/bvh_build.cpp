// The builders: the recursive framework and the split rules (exercises 4.1 to 4.3).
#include <algorithm>
#include <cstdint>
#include <stdexcept>
#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "04_bvh/bvh.hpp"
#include "core/timing.hpp"

namespace boxes {

// One case per value and no default: -Wswitch names a value added without its name.
const char* bvhBuilderName(BvhBuilder builder) {
    switch (builder) {
        case BvhBuilder::Midpoint:
            return "midpoint";
        case BvhBuilder::Median:
            return "median";
        case BvhBuilder::BinnedSah:
            return "sah";
        case BvhBuilder::SweepSah:
            return "sweep-sah";
        case BvhBuilder::SpatialSah:
            return "sbvh";
    }
    return "?";
}

BvhBuilder parseBvhBuilder(const std::string& name) {
    for (BvhBuilder b : {BvhBuilder::Midpoint, BvhBuilder::Median, BvhBuilder::BinnedSah,
                         BvhBuilder::SweepSah, BvhBuilder::SpatialSah})
        if (name == bvhBuilderName(b)) return b;
    throw UsageError("unknown builder '" + name +
                     "' (use midpoint, median, sah, sweep-sah or sbvh)");
}

// EXERCISE 4.1: midpoint split along the longest axis of the centroid bounds (2 points)
size_t partitionMidpoint(std::span<BuildPrimitive> prims, const Bounds3f& centroidBounds) {
    // BEGIN SOLUTION
    int axis = centroidBounds.maxExtentAxis();
    float middle = centroidBounds.centroid()[axis];
    // Every centroid equal along the axis: all land on one side and the framework decides.
    auto right = std::partition(prims.begin(), prims.end(),
                                [&](const BuildPrimitive& p) { return p.centroid[axis] < middle; });
    return size_t(right - prims.begin());
    // END SOLUTION
}

// EXERCISE 4.2: object median split along the longest axis of the centroid bounds (2 points)
size_t partitionMedian(std::span<BuildPrimitive> prims, const Bounds3f& centroidBounds) {
    // BEGIN SOLUTION
    int axis = centroidBounds.maxExtentAxis();
    size_t half = prims.size() / 2;
    // nth_element: the median in place, smaller before, larger after, in O(n).
    std::nth_element(prims.begin(), prims.begin() + std::ptrdiff_t(half), prims.end(),
                     [&](const BuildPrimitive& a, const BuildPrimitive& b) {
                         return a.centroid[axis] < b.centroid[axis];
                     });
    return half;
    // END SOLUTION
}

namespace {

constexpr int kMaxBins = 256;

// glm's operator[] is a switch; the hot loops read components through a pointer.
inline float component(const Vec3& v, int axis) {
    return (&v.x)[axis];
}

inline float area(const Vec3& lo, const Vec3& hi) {
    Vec3 d = hi - lo;
    return 2.0f * (d.x * d.y + d.y * d.z + d.z * d.x);
}

// Bounds that a build loop extends once per primitive: the framework's pass over a node
// and the binned SAH's bins. With SSE each of min and max is one 4-wide register (x, y,
// z and a 4th lane that is never read), so extending by a primitive's box is one min and
// one max instead of six scalar operations; elsewhere three floats, the same results.
// Trivial on purpose: an array of 768 bins costs nothing until a bin is set to empty().
struct PackedBounds {
#if defined(__SSE2__)
    __m128 lo, hi;

    static PackedBounds empty() {
        return {_mm_set1_ps(kInfinity<float>), _mm_set1_ps(-kInfinity<float>)};
    }
    // By the primitive's box: bounds.min and bounds.max read as 4 floats each (the 4th is
    // the next member's, inside the same BuildPrimitive, and ends in the unused lane).
    void extend(const BuildPrimitive& p) {
        lo = _mm_min_ps(lo, _mm_loadu_ps(&p.bounds.min.x));
        hi = _mm_max_ps(hi, _mm_loadu_ps(&p.bounds.max.x));
    }
    // By the primitive's centroid (the 4th lane a copy of z, not the index's bits).
    void extendByCentroid(const BuildPrimitive& p) {
        __m128 c = _mm_loadu_ps(&p.centroid.x);
        c = _mm_shuffle_ps(c, c, _MM_SHUFFLE(2, 2, 1, 0));
        lo = _mm_min_ps(lo, c);
        hi = _mm_max_ps(hi, c);
    }
    void extend(const PackedBounds& b) {
        lo = _mm_min_ps(lo, b.lo);
        hi = _mm_max_ps(hi, b.hi);
    }
    Bounds3f bounds() const {
        alignas(16) float l[4], h[4];
        _mm_store_ps(l, lo);
        _mm_store_ps(h, hi);
        return {Vec3(l[0], l[1], l[2]), Vec3(h[0], h[1], h[2])};
    }
#else
    Vec3 lo, hi;

    static PackedBounds empty() {
        return {Vec3(kInfinity<float>), Vec3(-kInfinity<float>)};
    }
    void extend(const BuildPrimitive& p) {
        lo = glm::min(lo, p.bounds.min);
        hi = glm::max(hi, p.bounds.max);
    }
    void extendByCentroid(const BuildPrimitive& p) {
        lo = glm::min(lo, p.centroid);
        hi = glm::max(hi, p.centroid);
    }
    void extend(const PackedBounds& b) {
        lo = glm::min(lo, b.lo);
        hi = glm::max(hi, b.hi);
    }
    Bounds3f bounds() const {
        return {lo, hi};
    }
#endif
    // Only for bounds that contain something (an empty box has no meaningful area).
    float surfaceArea() const {
        Bounds3f b = bounds();
        return area(b.min, b.max);
    }
};

struct SahBin {
    PackedBounds bounds;  // of the primitives in the bin
    uint32_t count;
};

}  // namespace

// EXERCISE 4.3: binned SAH split (5 points)
size_t partitionBinnedSah(std::span<BuildPrimitive> prims, const Bounds3f& nodeBounds,
                          const Bounds3f& centroidBounds, const BvhBuildOptions& options,
                          float& cost) {
    // BEGIN SOLUTION
    cost = kInfinity<float>;
    int bins = std::clamp(options.bins, 2, kMaxBins);
    float nodeArea = nodeBounds.surfaceArea();
    // A node without area (all primitives on one line) gives no guidance: no split.
    if (!(nodeArea > 0.0f)) return 0;
    // Two primitives (a third of the calls): the only split puts one on each side; it is
    // the plane the bins would find on the first axis where the centroids differ.
    if (prims.size() == 2) {
        for (int axis = 0; axis < 3; ++axis) {
            float a = component(prims[0].centroid, axis), b = component(prims[1].centroid, axis);
            if (a == b) continue;
            if (b < a) std::swap(prims[0], prims[1]);
            cost = options.traversalCost +
                   options.intersectionCost *
                       (prims[0].bounds.surfaceArea() + prims[1].bounds.surfaceArea()) / nodeArea;
            return 1;
        }
        return 0;
    }
    int bestAxis = -1, bestPlane = 0;
    // Per axis: the bin scale (0 for an axis with zero extent: nothing to split there, and
    // a division by zero otherwise). All three axes are binned in one pass over the
    // primitives: the build reads each primitive once per level, not three times.
    Vec3 extent = centroidBounds.diagonal();
    float scale[3], lowest[3];
    for (int axis = 0; axis < 3; ++axis) {
        float axisExtent = component(extent, axis);
        float s = axisExtent > 0.0f ? float(bins) / axisExtent : 0.0f;
        scale[axis] = std::isfinite(s) ? s : 0.0f;
        lowest[axis] = component(centroidBounds.min, axis);
    }
    if (scale[0] == 0.0f && scale[1] == 0.0f && scale[2] == 0.0f) return 0;
    SahBin bin[3][kMaxBins];
    for (int axis = 0; axis < 3; ++axis)
        for (int b = 0; b < bins; ++b) bin[axis][b] = {PackedBounds::empty(), 0};
    for (const BuildPrimitive& p : prims) {
        for (int axis = 0; axis < 3; ++axis) {
            int b =
                std::min(bins - 1, int((component(p.centroid, axis) - lowest[axis]) * scale[axis]));
            SahBin& into = bin[axis][b];
            into.count++;
            into.bounds.extend(p);
        }
    }
    for (int axis = 0; axis < 3; ++axis) {
        if (scale[axis] == 0.0f) continue;
        const SahBin* axisBins = bin[axis];
        // Only the occupied bins matter: a plane between empty bins repeats its neighbour's
        // split, and a small node fills few of its bins. List them (without a branch).
        int occupied[kMaxBins], used = 0;
        for (int b = 0; b < bins; ++b) {
            occupied[used] = b;
            used += axisBins[b].count > 0 ? 1 : 0;
        }
        // Sweep from the right: area and count of the occupied bins j.. (the primitives
        // right of the plane before bin occupied[j]); then from the left, pricing each plane.
        float rightArea[kMaxBins];
        uint32_t rightCount[kMaxBins];
        PackedBounds side = PackedBounds::empty();
        uint32_t count = 0;
        for (int j = used - 1; j > 0; --j) {
            count += axisBins[occupied[j]].count;
            side.extend(axisBins[occupied[j]].bounds);
            rightArea[j] = side.surfaceArea();
            rightCount[j] = count;
        }
        side = PackedBounds::empty();
        count = 0;
        for (int j = 1; j < used; ++j) {
            count += axisBins[occupied[j - 1]].count;
            side.extend(axisBins[occupied[j - 1]].bounds);
            float c = options.traversalCost + options.intersectionCost *
                                                  (side.surfaceArea() * float(count) +
                                                   rightArea[j] * float(rightCount[j])) /
                                                  nodeArea;
            if (c < cost) {
                cost = c;
                bestAxis = axis;
                bestPlane = occupied[j];  // bins below this one go left
            }
        }
    }
    if (bestAxis < 0) return 0;
    // Partition with the same bin arithmetic, so every primitive lands where it was counted.
    // Lomuto's scheme without a branch: each primitive is swapped to the end of the left
    // part, which grows only when it goes left. (std::partition branches on every
    // primitive, and the branch mispredicts often.)
    float axisLowest = lowest[bestAxis], axisScale = scale[bestAxis];
    size_t left = 0;
    for (BuildPrimitive& p : prims) {
        int b = std::min(bins - 1, int((component(p.centroid, bestAxis) - axisLowest) * axisScale));
        bool goesLeft = b < bestPlane;
        std::swap(p, prims[left]);
        left += goesLeft ? 1 : 0;
    }
    return left;
    // END SOLUTION
}

namespace {

// The exercises' rules in the framework's shape.
size_t midpointRule(std::span<BuildPrimitive> prims, const Bounds3f&, const Bounds3f& centroids,
                    const BvhBuildOptions&, float&) {
    return partitionMidpoint(prims, centroids);
}
size_t medianRule(std::span<BuildPrimitive> prims, const Bounds3f&, const Bounds3f& centroids,
                  const BvhBuildOptions&, float&) {
    return partitionMedian(prims, centroids);
}

using BuildPrimitives = std::pmr::vector<BuildPrimitive>;

class BvhBuildJob {
public:
    BvhBuildJob(BuildPrimitives& prims, const SplitRule& rule, const BvhBuildOptions& options,
                Bvh& bvh)
        : prims_(prims), rule_(rule), options_(options), bvh_(bvh) {}

    void build() {
        bvh_.nodes.clear();
        if (prims_.empty()) return;
        bvh_.nodes.reserve(2 * prims_.size());
        bvh_.nodes.emplace_back();
        buildNode(0, 0, prims_.size(), 0);
    }

private:
    void buildNode(uint32_t nodeIndex, size_t begin, size_t end, int depth) {
        PackedBounds packedBounds = PackedBounds::empty(), packedCentroids = PackedBounds::empty();
        for (size_t i = begin; i < end; ++i) {
            packedBounds.extend(prims_[i]);
            packedCentroids.extendByCentroid(prims_[i]);
        }
        Bounds3f bounds = packedBounds.bounds(), centroids = packedCentroids.bounds();
        size_t n = end - begin;
        BvhNode& node = bvh_.nodes[nodeIndex];
        node.boundsMin = bounds.min;
        node.boundsMax = bounds.max;
        size_t leafLimit =
            size_t(std::max(1, rule_.sah ? options_.maxLeafSize : options_.leafSize));
        auto makeLeaf = [&] {
            BvhNode& leaf = bvh_.nodes[nodeIndex];
            leaf.leftFirst = uint32_t(begin);
            leaf.count = uint32_t(n);
        };
        // The depth cap ends any recursion, whatever the split rule does.
        if (n == 1 || depth >= options_.maxDepth - 1) return makeLeaf();
        if (!rule_.sah && n <= leafLimit) return makeLeaf();

        std::span<BuildPrimitive> range(prims_.data() + begin, n);
        float splitCost = kInfinity<float>;
        size_t left = rule_.partition(range, bounds, centroids, options_, splitCost);
        bool split = left > 0 && left < n;
        if (rule_.sah && n <= leafLimit && !(splitCost < options_.intersectionCost * float(n)))
            return makeLeaf();
        if (!split) {
            // No rule separates them (identical centroids, a line of primitives): a leaf if
            // small enough, else halves in array order, which always terminates.
            if (n <= leafLimit) return makeLeaf();
            left = n / 2;
        }
        uint32_t leftChild = uint32_t(bvh_.nodes.size());
        bvh_.nodes.emplace_back();
        bvh_.nodes.emplace_back();
        bvh_.nodes[nodeIndex].leftFirst = leftChild;
        bvh_.nodes[nodeIndex].count = 0;
        buildNode(leftChild, begin, begin + left, depth + 1);
        buildNode(leftChild + 1, begin + left, end, depth + 1);
    }

    BuildPrimitives& prims_;
    const SplitRule& rule_;
    const BvhBuildOptions& options_;
    Bvh& bvh_;
};

std::pmr::memory_resource* memoryOf(const BvhBuildOptions& options) {
    return options.memory ? options.memory : std::pmr::get_default_resource();
}

Bvh buildFromPrimitives(BuildPrimitives& prims, const SplitRule& rule,
                        const BvhBuildOptions& options) {
    checkBuildOptions(options);
    Bvh bvh(memoryOf(options));
    BvhBuildJob(prims, rule, options, bvh).build();
    bvh.primitiveIndices.reserve(prims.size());
    for (const BuildPrimitive& p : prims) bvh.primitiveIndices.push_back(p.index);
    return bvh;
}

void finishStats(const Bvh& bvh, const BvhBuildOptions& options, double ms, BvhBuildStats* stats) {
    if (!stats) return;
    *stats = bvhStats(bvh, options);
    stats->buildMs = ms;
}

}  // namespace

SplitRule splitRuleOf(BvhBuilder builder) {
    switch (builder) {
        case BvhBuilder::Midpoint:
            return {midpointRule, false};
        case BvhBuilder::Median:
            return {medianRule, false};
        case BvhBuilder::BinnedSah:
            return {partitionBinnedSah, true};
        default:
            throw std::invalid_argument(std::string("builder '") + bvhBuilderName(builder) +
                                        "' is the engine's (advanced/build.hpp)");
    }
}

void checkBuildOptions(const BvhBuildOptions& options) {
    if (options.bins < 2 || options.bins > kMaxBins)
        throw InputError("SAH bins must be between 2 and 256");
    if (options.maxDepth < 1 || options.maxDepth > kMaxBvhDepth)
        throw InputError("BVH depth limit must be between 1 and 64");
}

Bvh buildBvh(std::span<const Bounds3f> primitiveBounds, const BvhBuildOptions& options,
             BvhBuildStats* stats) {
    return buildBvh(primitiveBounds, splitRuleOf(options.builder), options, stats);
}

Bvh buildBvh(const Mesh& mesh, const BvhBuildOptions& options, BvhBuildStats* stats) {
    return buildBvh(mesh, splitRuleOf(options.builder), options, stats);
}

Bvh buildBvh(std::span<const Bounds3f> primitiveBounds, const SplitRule& rule,
             const BvhBuildOptions& options, BvhBuildStats* stats) {
    Stopwatch watch;
    BuildPrimitives prims(memoryOf(options));
    prims.reserve(primitiveBounds.size());
    for (size_t i = 0; i < primitiveBounds.size(); ++i)
        prims.push_back({primitiveBounds[i], primitiveBounds[i].centroid(), uint32_t(i)});
    Bvh bvh = buildFromPrimitives(prims, rule, options);
    finishStats(bvh, options, watch.milliseconds(), stats);
    return bvh;
}

Bvh buildBvh(const Mesh& mesh, const SplitRule& rule, const BvhBuildOptions& options,
             BvhBuildStats* stats) {
    Stopwatch watch;
    BuildPrimitives prims = trianglePrimitives(mesh, memoryOf(options));
    Bvh bvh = buildFromPrimitives(prims, rule, options);
    fillLeafTriangles(bvh, mesh);
    finishStats(bvh, options, watch.milliseconds(), stats);
    return bvh;
}

std::pmr::vector<BuildPrimitive> trianglePrimitives(const Mesh& mesh,
                                                    std::pmr::memory_resource* memory) {
    if (mesh.triangles.size() >= size_t(0xFFFFFFF0u))
        throw InputError("mesh has too many triangles for 32-bit indices");
    std::pmr::vector<BuildPrimitive> prims(memory);
    prims.reserve(mesh.triangles.size());
    for (size_t i = 0; i < mesh.triangles.size(); ++i) {
        Bounds3f b;
        for (int k = 0; k < 3; ++k) b.extend(mesh.vertex(i, k));
        prims.push_back({b, b.centroid(), uint32_t(i)});
    }
    return prims;
}

void fillLeafTriangles(Bvh& bvh, const Mesh& mesh) {
    bvh.leafTriangles.clear();
    bvh.leafTriangles.reserve(bvh.primitiveIndices.size());
    for (uint32_t t : bvh.primitiveIndices) bvh.leafTriangles.push_back(leafTriangleOf(mesh, t));
}

LeafTriangle leafTriangleOf(const Mesh& mesh, size_t triangle) {
    Vec3 a = mesh.vertex(triangle, 0), b = mesh.vertex(triangle, 1), c = mesh.vertex(triangle, 2);
    Vec3d normal = glm::cross(Vec3d(b) - Vec3d(a), Vec3d(c) - Vec3d(a));
    if (normal == Vec3d(0.0)) return {a, a, a};
    return {a, b, c};
}

double bvhSahCost(const Bvh& bvh, float traversalCost, float intersectionCost) {
    if (bvh.empty()) return 0.0;
    double rootArea = double(bvh.nodes[0].bounds().surfaceArea());
    double cost = 0.0;
    for (const BvhNode& node : bvh.nodes) {
        // A tree without area (everything on a line) counts every node with weight 1.
        double ratio = rootArea > 0.0 ? double(node.bounds().surfaceArea()) / rootArea : 1.0;
        cost += node.isLeaf() ? double(intersectionCost) * node.count * ratio
                              : double(traversalCost) * ratio;
    }
    return cost;
}

BvhBuildStats bvhStats(const Bvh& bvh, const BvhBuildOptions& options) {
    BvhBuildStats s;
    if (bvh.empty()) return s;
    s.nodes = bvh.nodes.size();
    s.minLeafSize = size_t(-1);
    size_t leafPrims = 0;
    std::vector<std::pair<uint32_t, int>> stack = {{0, 0}};
    while (!stack.empty()) {
        auto [index, depth] = stack.back();
        stack.pop_back();
        const BvhNode& node = bvh.nodes[index];
        if (node.isLeaf()) {
            ++s.leaves;
            leafPrims += node.count;
            s.minLeafSize = std::min(s.minLeafSize, size_t(node.count));
            s.maxLeafSize = std::max(s.maxLeafSize, size_t(node.count));
            s.depth = std::max(s.depth, depth);
        } else {
            stack.push_back({node.leftFirst, depth + 1});
            stack.push_back({node.leftFirst + 1, depth + 1});
        }
    }
    s.meanLeafSize = s.leaves ? double(leafPrims) / double(s.leaves) : 0.0;
    s.sahCost = bvhSahCost(bvh, options.traversalCost, options.intersectionCost);
    return s;
}

}  // namespace boxes
