// Step 01's types as they cross the call protocol (judge/codec.hpp).
#pragma once

#include "01_triangle/triangle.hpp"
#include "judge/types_core.hpp"

namespace boxes::judge {

template <typename T>
struct Fields<TriangleT<T>> {
    static auto of(TriangleT<T>& x) { return std::tie(x.a, x.b, x.c); }
};
template <typename T>
struct Fields<TriangleHit<T>> {
    static auto of(TriangleHit<T>& x) { return std::tie(x.t, x.u, x.v); }
};

}  // namespace boxes::judge
