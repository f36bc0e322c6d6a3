// How values cross the pipe, and the session both ends share.
//
// Codec<T>::put writes a value, Codec<T>::get reads one into an existing object (so that a
// type without a default constructor, or an out-parameter the caller owns, can be filled).
// The workbook's own types are listed field by field in the types_*.hpp files
// (Fields<T>::of); the standard containers, glm's vectors and matrices and numbers are here.
// Directions follow the declared parameter types: `const X&` and `X` go in, `X&` and
// std::span<X> go in and come back, a Callback is called back.
#pragma once

#include <array>
#include <cstdint>
#include <exception>
#include <functional>
#include <glm/glm.hpp>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "judge/callback.hpp"
#include "judge/wire.hpp"

namespace boxes::judge {

// Exit status of a checker whose worker ended, or broke the protocol, in the middle of a
// call: the test case has no verdict but "failed" (the grader adds the worker's reason).
constexpr int kExitWorkerGone = 75;
constexpr int kExitWorkerMalformed = 76;

// A value the protocol cannot carry (a scene's polymorphic geometries, say): the test case
// fails with this message.
struct Unsupported : std::logic_error {
    using std::logic_error::logic_error;
};

// Thrown into the student's code when a callback of the checker threw (a failed REQUIRE in
// the test's lambda, say). The checker keeps the real exception and throws it once the call
// returns, whatever the student's code did with this one.
struct CallbackFailed : std::runtime_error {
    CallbackFailed() : std::runtime_error("the test's callback failed") {}
};

// What an object of a type without a default constructor starts as before get() fills it.
template <typename T, typename = void>
struct Make {
    static T make() { return T{}; }
};
template <typename T>
T make() {
    return Make<T>::make();
}

template <typename T, typename = void>
struct Codec;

// A struct listed field by field: Fields<T>::of(x) is std::tie(x.a, x.b, ...).
template <typename T>
struct Fields;

template <typename T, typename = void>
struct HasFields : std::false_type {};
template <typename T>
struct HasFields<T, std::void_t<decltype(Fields<T>::of(std::declval<T&>()))>> : std::true_type {};

template <typename T>
void put(Writer& w, const T& v) {
    Codec<std::remove_cv_t<T>>::put(w, v);
}
template <typename T>
void get(Reader& r, T& v) {
    Codec<std::remove_cv_t<T>>::get(r, v);
}

// The fewest bytes a value of T takes: counts are checked against it (Reader::count).
template <typename T>
constexpr size_t minBytes() {
    return Codec<std::remove_cv_t<T>>::kMin;
}

template <typename T>
struct Codec<T, std::enable_if_t<std::is_arithmetic_v<T>>> {
    static constexpr size_t kMin = std::is_same_v<T, bool> ? 1 : sizeof(T);
    static void put(Writer& w, const T& v) {
        if constexpr (std::is_same_v<T, bool>)
            w.pod(uint8_t(v ? 1 : 0));
        else
            w.pod(v);
    }
    static void get(Reader& r, T& v) {
        if constexpr (std::is_same_v<T, bool>)
            v = r.pod<uint8_t>() != 0;  // any other byte would not be a bool
        else
            v = r.pod<T>();
    }
};

template <typename T>
struct Codec<T, std::enable_if_t<std::is_enum_v<T>>> {
    using U = std::underlying_type_t<T>;
    static constexpr size_t kMin = sizeof(U);
    static void put(Writer& w, const T& v) { w.pod(U(v)); }
    static void get(Reader& r, T& v) { v = T(r.pod<U>()); }
};

template <glm::length_t L, typename T, glm::qualifier Q>
struct Codec<glm::vec<L, T, Q>> {
    static constexpr size_t kMin = size_t(L) * sizeof(T);
    static void put(Writer& w, const glm::vec<L, T, Q>& v) {
        for (glm::length_t i = 0; i < L; ++i) w.pod(v[i]);
    }
    static void get(Reader& r, glm::vec<L, T, Q>& v) {
        for (glm::length_t i = 0; i < L; ++i) v[i] = r.pod<T>();
    }
};

template <glm::length_t C, glm::length_t R, typename T, glm::qualifier Q>
struct Codec<glm::mat<C, R, T, Q>> {
    static constexpr size_t kMin = size_t(C) * size_t(R) * sizeof(T);
    static void put(Writer& w, const glm::mat<C, R, T, Q>& m) {
        for (glm::length_t c = 0; c < C; ++c) judge::put(w, m[c]);
    }
    static void get(Reader& r, glm::mat<C, R, T, Q>& m) {
        for (glm::length_t c = 0; c < C; ++c) judge::get(r, m[c]);
    }
};

template <typename T>
struct Codec<std::optional<T>> {
    static constexpr size_t kMin = 1;
    static void put(Writer& w, const std::optional<T>& v) {
        w.pod(uint8_t(v ? 1 : 0));
        if (v) judge::put(w, *v);
    }
    static void get(Reader& r, std::optional<T>& v) {
        uint8_t has = r.pod<uint8_t>();
        if (has > 1) throw Malformed("an optional that is neither empty nor full");
        if (!has) {
            v.reset();
            return;
        }
        if (!v) v.emplace(make<T>());
        judge::get(r, *v);
    }
};

template <typename T, typename A>
struct Codec<std::vector<T, A>> {
    static constexpr size_t kMin = 8;
    static void put(Writer& w, const std::vector<T, A>& v) {
        w.count(v.size());
        if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>)
            w.raw(v.data(), v.size() * sizeof(T));
        else
            for (const T& x : v) judge::put(w, x);
    }
    static void get(Reader& r, std::vector<T, A>& v) {
        size_t n = r.count(minBytes<T>());
        v.clear();
        if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
            v.resize(n);
            r.raw(v.data(), n * sizeof(T));
        } else {
            v.reserve(n);
            for (size_t i = 0; i < n; ++i) {
                v.push_back(make<T>());
                judge::get(r, v.back());
            }
        }
    }
};

template <typename T, size_t N>
struct Codec<std::array<T, N>> {
    static constexpr size_t kMin = N * minBytes<T>();
    static void put(Writer& w, const std::array<T, N>& a) {
        for (const T& x : a) judge::put(w, x);
    }
    static void get(Reader& r, std::array<T, N>& a) {
        for (T& x : a) judge::get(r, x);
    }
};

template <typename T, size_t N>
struct Codec<T[N]> {
    static constexpr size_t kMin = N * minBytes<T>();
    static void put(Writer& w, const T (&a)[N]) {
        for (const T& x : a) judge::put(w, x);
    }
    static void get(Reader& r, T (&a)[N]) {
        for (T& x : a) judge::get(r, x);
    }
};

template <>
struct Codec<std::string> {
    static constexpr size_t kMin = 8;
    static void put(Writer& w, const std::string& s) { w.text(s); }
    static void get(Reader& r, std::string& s) { s = r.text(); }
};

template <typename A, typename B>
struct Codec<std::pair<A, B>> {
    static constexpr size_t kMin = minBytes<A>() + minBytes<B>();
    static void put(Writer& w, const std::pair<A, B>& p) {
        judge::put(w, p.first);
        judge::put(w, p.second);
    }
    static void get(Reader& r, std::pair<A, B>& p) {
        judge::get(r, p.first);
        judge::get(r, p.second);
    }
};

// The elements of a span: sent, and read back into the caller's elements when they are not
// const (std::span<BuildPrimitive> is partitioned in place). Its size cannot change.
template <typename T, size_t E>
struct Codec<std::span<T, E>> {
    static constexpr size_t kMin = 8;
    static void put(Writer& w, const std::span<T, E>& s) {
        w.count(s.size());
        for (const T& x : s) judge::put(w, x);
    }
    static void get(Reader& r, std::span<T, E>& s) {
        if (r.count(minBytes<T>()) != s.size()) throw Malformed("a span came back with another size");
        if constexpr (!std::is_const_v<T>)
            for (T& x : s) judge::get(r, x);
        else
            throw Malformed("a const span cannot come back");
    }
};

template <typename... F>
constexpr size_t sumMinBytes(std::tuple<F&...>*) {
    return (size_t(0) + ... + minBytes<F>());
}

template <typename T>
struct Codec<T, std::enable_if_t<HasFields<T>::value>> {
    using Tuple = decltype(Fields<T>::of(std::declval<T&>()));
    static constexpr size_t kMin = sumMinBytes(static_cast<Tuple*>(nullptr));
    static void put(Writer& w, const T& v) {
        std::apply([&](auto&... f) { (judge::put(w, f), ...); }, Fields<T>::of(const_cast<T&>(v)));
    }
    static void get(Reader& r, T& v) {
        std::apply([&](auto&... f) { (judge::get(r, f), ...); }, Fields<T>::of(v));
    }
};

// Private members, for the classes whose exercise is a member function (the worker's copy of
// the object must hold what the checker's held). An explicit instantiation may name a
// private member (C++20 [temp.spec.general]/6), so Member<Tag>::pointer reaches it without
// changing the class.
template <typename Tag, typename Tag::type M>
struct PrivateMember {
    friend typename Tag::type memberPointer(Tag) { return M; }
};
#define BOXES_JUDGE_PRIVATE(Class, Type, name)                                 \
    struct Class##_##name {                                                    \
        using type = Type Class::*;                                            \
        friend type memberPointer(Class##_##name);                             \
    };                                                                         \
    template struct ::boxes::judge::PrivateMember<Class##_##name, &Class::name>
#define BOXES_JUDGE_MEMBER(object, Class, name) ((object).*memberPointer(Class##_##name{}))

// The two ends' shared state. A checker's session starts at its first call, from the
// pipes the grader passed in BOXES_JUDGE_FDS ("read,write").
class Session {
public:
    // Whether this process is the worker (it serves calls) or the checker (it makes them).
    bool worker = false;

    // What the checker's arguments registered for the calls in progress (Codec<Callback>):
    // the worker names them by index.
    std::vector<std::function<void(Reader&, Writer&)>> callbacks;
    // The checker's calls in progress, innermost last: where its callbacks registered from,
    // and the first exception a callback threw while it ran.
    struct Frame {
        size_t callbacksMark;
        std::exception_ptr callbackError;
    };
    std::vector<Frame> frames;

    // Serves one request of the peer (a callback on the checker, a call on the worker).
    std::function<void(Kind, const std::string&)> serve;

    std::recursive_mutex lock;  // one call at a time (a test may call from several threads)

    Endpoint& endpoint() { return *endpoint_; }
    bool connected() const { return endpoint_ != nullptr; }
    // From the descriptors the grader passed (BOXES_JUDGE_FDS); false when unusable.
    bool connect(const char* fds) {
        endpoint_ = connectEndpoint(fds, !worker);
        return endpoint_ != nullptr;
    }

    // Sends `kind` and returns the reply's kind (its bytes in `reply`), serving the peer's
    // requests that arrive before it. `replies` are the two kinds that answer `kind`.
    Kind request(Kind kind, const std::string& payload, std::string& reply, Kind ok, Kind failed) {
        if (!endpoint_->send(kind, payload)) peerGone();
        for (;;) {
            Kind got;
            bool open;
            try {
                open = endpoint_->receive(got, reply);
            } catch (const Malformed& e) {
                peerMalformed(e.what());
            }
            if (!open) peerGone();
            if (got == ok || got == failed) return got;
            if (got != (worker ? Kind::Call : Kind::Callback))
                peerMalformed("a message out of turn");
            serve(got, reply);
        }
    }

    [[noreturn]] void peerGone();
    [[noreturn]] void peerMalformed(const char* what);

    static Session& get() {
        static Session s;
        return s;
    }

private:
    std::unique_ptr<Endpoint> endpoint_;
};

inline const char* currentCall = "";  // the checker's exercise in progress, for its messages

inline void Session::peerGone() {
    if (worker) std::_Exit(0);  // the checker ended: nothing more to serve
    std::string text = std::string("[judge] the worker ended while exercise ") + currentCall +
                       " ran: no result\n";
    (void)!::write(2, text.data(), text.size());
    std::_Exit(kExitWorkerGone);
}

inline void Session::peerMalformed(const char* what) {
    if (worker) std::_Exit(3);
    std::string text = std::string("[judge] the worker's answer to exercise ") + currentCall +
                       " breaks the protocol: " + what + "\n";
    (void)!::write(2, text.data(), text.size());
    std::_Exit(kExitWorkerMalformed);
}

// Parameter directions, by the declared type D of the parameter. The caller uses put() before
// the call and back() on the reply; the callee's Slot<D> holds the value it calls with and
// sends back what may have changed.
template <typename D>
struct Param {  // by value: in
    static void put(Writer& w, const D& v) { judge::put(w, v); }
    static void back(Reader&, const D&) {}
};
template <typename X>
struct Param<const X&> {
    static void put(Writer& w, const X& v) { judge::put(w, v); }
    static void back(Reader&, const X&) {}
};
template <typename X>
struct Param<X&> {  // in and out
    static void put(Writer& w, const X& v) { judge::put(w, v); }
    static void back(Reader& r, X& v) { judge::get(r, v); }
};
template <typename X, size_t E>
struct Param<std::span<X, E>> {
    static void put(Writer& w, const std::span<X, E>& s) { judge::put(w, s); }
    static void back(Reader& r, std::span<X, E> s) {
        if constexpr (!std::is_const_v<X>) judge::get(r, s);
    }
};

template <typename D>
struct Slot {  // by value or const reference
    using X = std::remove_cvref_t<D>;
    explicit Slot(Reader& r) : value(make<X>()) { judge::get(r, value); }
    X& arg() { return value; }
    void back(Writer&) {}
    X value;
};
template <typename X>
struct Slot<const X&> : Slot<X> {
    using Slot<X>::Slot;
};
template <typename X>
struct Slot<X&> {
    explicit Slot(Reader& r) : value(make<X>()) { judge::get(r, value); }
    X& arg() { return value; }
    void back(Writer& w) { judge::put(w, value); }
    X value;
};
template <typename X, size_t E>
struct Slot<std::span<X, E>> {
    explicit Slot(Reader& r) {
        size_t n = r.count(minBytes<X>());
        values.reserve(n);
        for (size_t i = 0; i < n; ++i) {
            values.push_back(make<std::remove_const_t<X>>());
            judge::get(r, values.back());
        }
    }
    std::span<X, E> arg() { return std::span<X, E>(values); }
    void back(Writer& w) {
        if constexpr (!std::is_const_v<X>) judge::put(w, std::span<X, E>(values));
    }
    std::vector<std::remove_const_t<X>> values;
};

// The worker's stand-in for a callback of the checker: calling it is a Callback request.
template <typename Signature>
class RemoteFunction;
template <typename R, typename... A>
class RemoteFunction<R(A...)> {
public:
    explicit RemoteFunction(uint32_t id) : id_(id) {}
    R operator()(A... a) const {
        Session& s = Session::get();
        Writer w;
        w.pod(id_);
        (Param<A>::put(w, a), ...);
        std::string reply;
        if (s.request(Kind::Callback, w.bytes, reply, Kind::CallbackReturn, Kind::CallbackThrow) ==
            Kind::CallbackThrow)
            throw CallbackFailed();
        Reader r(reply);
        try {
            if constexpr (std::is_void_v<R>) {
                (Param<A>::back(r, a), ...);
                r.expectEnd();
            } else {
                R result = make<R>();
                judge::get(r, result);
                (Param<A>::back(r, a), ...);
                r.expectEnd();
                return result;
            }
        } catch (const Malformed& e) {
            s.peerMalformed(e.what());
        }
    }

private:
    uint32_t id_;
};

// Runs a callable on a callback request's arguments; the result and out-parameters go to w.
template <typename R, typename... A, typename F>
void runCallback(F& f, Reader& r, Writer& w) {
    std::tuple<Slot<A>...> slots{Slot<A>(r)...};
    r.expectEnd();
    std::apply(
        [&](auto&... slot) {
            if constexpr (std::is_void_v<R>) {
                f(slot.arg()...);
            } else {
                R result = f(slot.arg()...);
                judge::put(w, result);
            }
            (slot.back(w), ...);
        },
        slots);
}

// The checker registers a callable for the call in progress (an lvalue by reference, a
// temporary by value); the worker gets its index.
template <typename R, typename... A, typename F>
uint32_t registerCallback(F&& f) {
    Session& s = Session::get();
    if constexpr (std::is_lvalue_reference_v<F>) {
        auto* p = &f;
        s.callbacks.push_back([p](Reader& r, Writer& w) { runCallback<R, A...>(*p, r, w); });
    } else {
        s.callbacks.push_back(
            [g = std::move(f)](Reader& r, Writer& w) mutable { runCallback<R, A...>(g, r, w); });
    }
    return uint32_t(s.callbacks.size() - 1);
}

template <typename R, typename... A>
struct Param<Callback<R(A...)>> {
    static void put(Writer& w, const Callback<R(A...)>& f) { w.pod(registerCallback<R, A...>(f)); }
    static void back(Reader&, const Callback<R(A...)>&) {}
};
template <typename R, typename... A>
struct Slot<Callback<R(A...)>> {
    explicit Slot(Reader& r) : f(r.pod<uint32_t>()) {}
    RemoteFunction<R(A...)>& arg() { return f; }
    void back(Writer&) {}
    RemoteFunction<R(A...)> f;
};

// A std::function member of an object (a renderer's line renderer and clock): the checker
// registers its own; the worker's copy calls back; on the way back the checker keeps its own.
template <typename R, typename... A>
struct Codec<std::function<R(A...)>> {
    static constexpr size_t kMin = 1;
    static void put(Writer& w, const std::function<R(A...)>& f) {
        Session& s = Session::get();
        if (s.worker) {  // the worker sends its copy back: the checker keeps its own
            w.pod(uint8_t(0));
            return;
        }
        w.pod(uint8_t(f ? 1 : 0));
        if (f) w.pod(registerCallback<R, A...>(f));
    }
    static void get(Reader& r, std::function<R(A...)>& f) {
        uint8_t has = r.pod<uint8_t>();
        if (has > 1) throw Malformed("a function that is neither empty nor set");
        if (!Session::get().worker) return;
        if (has)
            f = RemoteFunction<R(A...)>(r.pod<uint32_t>());
        else
            f = nullptr;
    }
};

}  // namespace boxes::judge
