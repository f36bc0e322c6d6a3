// Step 06's types as they cross the call protocol (judge/codec.hpp).
#pragma once

#include "06_raster/pipeline.hpp"
#include "06_raster/raster.hpp"
#include "judge/types_core.hpp"

namespace boxes::judge {

template <>
struct Fields<SpaceMatrices> {
    static auto of(SpaceMatrices& x) { return std::tie(x.view, x.projection); }
};
template <>
struct Fields<ClipVertex> {
    static auto of(ClipVertex& x) { return std::tie(x.position, x.weights); }
};
template <>
struct Fields<ClipPolygon> {
    static auto of(ClipPolygon& x) { return std::tie(x.vertices, x.count); }
};
template <>
struct Fields<FixedPoint2> {
    static auto of(FixedPoint2& x) { return std::tie(x.x, x.y); }
};
template <>
struct Fields<ShadowMap> {
    static auto of(ShadowMap& x) { return std::tie(x.lightCamera, x.viewProjection, x.size, x.depth); }
};

}  // namespace boxes::judge
