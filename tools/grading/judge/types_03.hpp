// Step 03's types as they cross the call protocol (judge/codec.hpp).
#pragma once

#include "03_aabb/aabb.hpp"
#include "judge/types_01.hpp"

namespace boxes::judge {

template <typename T>
struct Make<SlabRayT<T>> {
    static SlabRayT<T> make() { return SlabRayT<T>(Make<RayT<T>>::make()); }
};
template <typename T>
struct Fields<SlabRayT<T>> {
    static auto of(SlabRayT<T>& x) { return std::tie(x.origin, x.invDirection, x.tmin, x.tmax); }
};
template <typename T>
struct Fields<RayInterval<T>> {
    static auto of(RayInterval<T>& x) { return std::tie(x.tnear, x.tfar); }
};

}  // namespace boxes::judge
