// Step 02's types as they cross the call protocol (judge/codec.hpp).
#pragma once

#include "02_box/box.hpp"
#include "judge/types_core.hpp"

namespace boxes::judge {

template <typename T>
struct Fields<OrientedBoxT<T>> {
    static auto of(OrientedBoxT<T>& x) { return std::tie(x.centre, x.axes, x.halfExtents); }
};
template <typename T>
struct Fields<BoxHit<T>> {
    static auto of(BoxHit<T>& x) { return std::tie(x.t, x.normal, x.face, x.entering); }
};

}  // namespace boxes::judge
