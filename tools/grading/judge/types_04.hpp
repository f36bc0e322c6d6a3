// Step 04's types as they cross the call protocol (judge/codec.hpp).
#pragma once

#include "04_bvh/bvh.hpp"
#include "04_bvh/frustum.hpp"
#include "04_bvh/traverse.hpp"
#include "judge/types_core.hpp"

namespace boxes::judge {

template <>
struct Fields<BvhNode> {
    static auto of(BvhNode& x) { return std::tie(x.boundsMin, x.leftFirst, x.boundsMax, x.count); }
};
template <>
struct Fields<LeafTriangle> {
    static auto of(LeafTriangle& x) { return std::tie(x.a, x.b, x.c); }
};
template <>
struct Fields<Bvh> {
    static auto of(Bvh& x) { return std::tie(x.nodes, x.primitiveIndices, x.leafTriangles); }
};
template <>
struct Fields<BuildPrimitive> {
    static auto of(BuildPrimitive& x) { return std::tie(x.bounds, x.centroid, x.index); }
};
// The options' memory resource is the caller's allocator: the worker uses its own (nullptr).
template <>
struct Codec<BvhBuildOptions> {
    static constexpr size_t kMin = 4 * 4 + 4 * 4;
    static auto fields(BvhBuildOptions& x) {
        return std::tie(x.builder, x.bins, x.leafSize, x.maxLeafSize, x.maxDepth, x.traversalCost,
                        x.intersectionCost, x.spatialSplitAlpha, x.spatialSplitBudget);
    }
    static void put(Writer& w, const BvhBuildOptions& o) {
        std::apply([&](auto&... f) { (judge::put(w, f), ...); },
                   fields(const_cast<BvhBuildOptions&>(o)));
    }
    static void get(Reader& r, BvhBuildOptions& o) {
        std::apply([&](auto&... f) { (judge::get(r, f), ...); }, fields(o));
        o.memory = nullptr;
    }
};
template <>
struct Make<TraversalRay> {
    static TraversalRay make() { return TraversalRay(Make<Ray>::make()); }
};
template <>
struct Fields<TraversalRay> {
    static auto of(TraversalRay& x) {
        return std::tie(x.originForMin, x.originForMax, x.direction, x.inverseDirection,
                        x.farInverseDirection, x.tmin, x.tmax, x.nearOffset, x.farOffset,
                        x.nearOrigin, x.farOrigin);
    }
};
template <>
struct Fields<Frustum> {
    static auto of(Frustum& x) { return std::tie(x.planes, x.corners); }
};

}  // namespace boxes::judge
