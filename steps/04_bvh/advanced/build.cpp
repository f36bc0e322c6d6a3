#include "04_bvh/advanced/build.hpp"

#include <algorithm>

#include "04_bvh/advanced/memory.hpp"
#include "core/timing.hpp"

namespace boxes {

size_t partitionSweepSah(std::span<BuildPrimitive> prims, const Bounds3f& nodeBounds,
                         const Bounds3f&, const BvhBuildOptions& options, float& cost) {
    cost = kInfinity<float>;
    size_t n = prims.size();
    float nodeArea = nodeBounds.surfaceArea();
    if (n < 2 || !(nodeArea > 0.0f)) return 0;
    int bestAxis = -1;
    size_t bestLeft = 0;
    std::vector<float> rightArea(n);
    for (int axis = 0; axis < 3; ++axis) {
        std::sort(prims.begin(), prims.end(),
                  [&](const BuildPrimitive& a, const BuildPrimitive& b) {
                      return a.centroid[axis] < b.centroid[axis] ||
                             (a.centroid[axis] == b.centroid[axis] && a.index < b.index);
                  });
        Bounds3f right;
        for (size_t i = n; i-- > 1;) {
            right.extend(prims[i].bounds.min);
            right.extend(prims[i].bounds.max);
            rightArea[i] = right.surfaceArea();
        }
        Bounds3f left;
        for (size_t i = 1; i < n; ++i) {
            left.extend(prims[i - 1].bounds.min);
            left.extend(prims[i - 1].bounds.max);
            // Only between different centroids: a plane must separate them.
            if (prims[i - 1].centroid[axis] == prims[i].centroid[axis]) continue;
            float c = options.traversalCost +
                      options.intersectionCost *
                          (left.surfaceArea() * float(i) + rightArea[i] * float(n - i)) / nodeArea;
            if (c < cost) {
                cost = c;
                bestAxis = axis;
                bestLeft = i;
            }
        }
    }
    if (bestAxis < 0) return 0;
    std::sort(prims.begin(), prims.end(), [&](const BuildPrimitive& a, const BuildPrimitive& b) {
        return a.centroid[bestAxis] < b.centroid[bestAxis] ||
               (a.centroid[bestAxis] == b.centroid[bestAxis] && a.index < b.index);
    });
    return bestLeft;
}

namespace {

BvhBuildOptions onLargeArrays(BvhBuildOptions options) {
    if (!options.memory) options.memory = largeArrayMemory();
    return options;
}

SplitRule ruleOf(BvhBuilder builder) {
    if (builder == BvhBuilder::SweepSah) return kSweepSahRule;
    // Bare bounds have no triangles for spatial splits to cut.
    if (builder == BvhBuilder::SpatialSah) return splitRuleOf(BvhBuilder::BinnedSah);
    return splitRuleOf(builder);
}

}  // namespace

Bvh buildEngineBvh(const Mesh& mesh, const BvhBuildOptions& requested, BvhBuildStats* stats) {
    BvhBuildOptions options = onLargeArrays(requested);
    if (options.builder != BvhBuilder::SpatialSah)
        return buildBvh(mesh, ruleOf(options.builder), options, stats);
    checkBuildOptions(options);
    Stopwatch watch;
    std::pmr::vector<BuildPrimitive> prims = trianglePrimitives(mesh, options.memory);
    Bvh bvh = buildSpatialSplitBvh(mesh, {prims.begin(), prims.end()}, options);
    fillLeafTriangles(bvh, mesh);
    if (stats) {
        double ms = watch.milliseconds();
        *stats = bvhStats(bvh, options);
        stats->buildMs = ms;
    }
    return bvh;
}

Bvh buildEngineBvh(std::span<const Bounds3f> primitiveBounds, const BvhBuildOptions& requested,
                   BvhBuildStats* stats) {
    BvhBuildOptions options = onLargeArrays(requested);
    return buildBvh(primitiveBounds, ruleOf(options.builder), options, stats);
}

}  // namespace boxes
