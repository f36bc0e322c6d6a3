// A callable passed by reference: what the checker's copy of an exercise that takes a
// callback (a traversal's primitive intersector, an any-hit loop's blocker) hands to the
// call protocol. It does not own or copy the callable: a lambda's state stays the test's.
#pragma once

#include <memory>
#include <type_traits>
#include <utility>

namespace boxes::judge {

template <typename Signature>
class Callback;

template <typename R, typename... A>
class Callback<R(A...)> {
public:
    template <typename F, typename = std::enable_if_t<!std::is_same_v<std::decay_t<F>, Callback>>>
    Callback(F&& f)  // NOLINT: converts implicitly, as std::function does
        : object_(const_cast<void*>(static_cast<const void*>(std::addressof(f)))),
          call_([](void* o, A... a) -> R {
              return (*static_cast<std::remove_reference_t<F>*>(o))(std::forward<A>(a)...);
          }) {}

    R operator()(A... a) const { return call_(object_, std::forward<A>(a)...); }

private:
    void* object_;
    R (*call_)(void*, A...);
};

}  // namespace boxes::judge
