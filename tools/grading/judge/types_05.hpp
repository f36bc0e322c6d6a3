// Step 05's types as they cross the call protocol (judge/codec.hpp). The classes whose
// exercises are member functions travel with their private state.
#pragma once

#include "05_efficiency/lab.hpp"
#include "05_efficiency/progressive.hpp"
#include "judge/types_04.hpp"

namespace boxes {
namespace judge {
BOXES_JUDGE_PRIVATE(SinTable, std::vector<float>, table_);
BOXES_JUDGE_PRIVATE(SinTable, int, n_);
BOXES_JUDGE_PRIVATE(SinTable, float, step_);
BOXES_JUDGE_PRIVATE(SinTable, float, perStep_);
BOXES_JUDGE_PRIVATE(IncrementalRenderer, Image, image_);
BOXES_JUDGE_PRIVATE(IncrementalRenderer, LineRenderer, renderLine_);
BOXES_JUDGE_PRIVATE(IncrementalRenderer, Clock, clock_);
BOXES_JUDGE_PRIVATE(IncrementalRenderer, int, nextRow_);
BOXES_JUDGE_PRIVATE(IncrementalRenderer, double, lastLineSeconds_);
BOXES_JUDGE_PRIVATE(AdaptiveResolution, double, target_);
BOXES_JUDGE_PRIVATE(AdaptiveResolution, float, minScale_);
BOXES_JUDGE_PRIVATE(AdaptiveResolution, float, maxScale_);
BOXES_JUDGE_PRIVATE(AdaptiveResolution, float, scale_);

template <>
struct Make<SinTable> {
    static SinTable make() { return SinTable(std::vector<float>(3, 0.0f)); }
};
template <>
struct Fields<SinTable> {
    static auto of(SinTable& x) {
        return std::tie(BOXES_JUDGE_MEMBER(x, SinTable, table_), BOXES_JUDGE_MEMBER(x, SinTable, n_),
                        BOXES_JUDGE_MEMBER(x, SinTable, step_),
                        BOXES_JUDGE_MEMBER(x, SinTable, perStep_));
    }
};
template <>
struct Make<IncrementalRenderer> {
    static IncrementalRenderer make() { return IncrementalRenderer(1, 1, LineRenderer(), Clock()); }
};
template <>
struct Fields<IncrementalRenderer> {
    static auto of(IncrementalRenderer& x) {
        return std::tie(BOXES_JUDGE_MEMBER(x, IncrementalRenderer, image_),
                        BOXES_JUDGE_MEMBER(x, IncrementalRenderer, renderLine_),
                        BOXES_JUDGE_MEMBER(x, IncrementalRenderer, clock_),
                        BOXES_JUDGE_MEMBER(x, IncrementalRenderer, nextRow_),
                        BOXES_JUDGE_MEMBER(x, IncrementalRenderer, lastLineSeconds_));
    }
};
template <>
struct Make<AdaptiveResolution> {
    static AdaptiveResolution make() { return AdaptiveResolution(1.0); }
};
template <>
struct Fields<AdaptiveResolution> {
    static auto of(AdaptiveResolution& x) {
        return std::tie(BOXES_JUDGE_MEMBER(x, AdaptiveResolution, target_),
                        BOXES_JUDGE_MEMBER(x, AdaptiveResolution, minScale_),
                        BOXES_JUDGE_MEMBER(x, AdaptiveResolution, maxScale_),
                        BOXES_JUDGE_MEMBER(x, AdaptiveResolution, scale_));
    }
};
template <>
struct Fields<PrecomputedRay> {
    static auto of(PrecomputedRay& x) {
        return std::tie(x.origin, x.invDirection, x.negative, x.tmin, x.tmax);
    }
};
template <>
struct Fields<PrecomputedTriangle> {
    static auto of(PrecomputedTriangle& x) { return std::tie(x.a, x.e1, x.e2, x.normal); }
};
template <>
struct Fields<TriangleHitT> {
    static auto of(TriangleHitT& x) { return std::tie(x.t, x.u, x.v); }
};
template <>
struct Fields<TriangleVertices> {
    static auto of(TriangleVertices& x) { return std::tie(x.a, x.b, x.c); }
};

}  // namespace judge
}  // namespace boxes
