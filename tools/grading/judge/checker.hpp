// The checker's end of the call protocol: what the checker's copy of each exercise function
// calls instead of a solution (judge::remote), and the exceptions a worker's Throw becomes.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <new>
#include <stdexcept>
#include <string>

#include "core/exercise.hpp"
#include "core/mesh.hpp"
#include "judge/codec.hpp"

namespace boxes::judge {

// The worker could not serve a call (no such exercise, arguments it cannot read).
struct WorkerError : std::logic_error {
    using std::logic_error::logic_error;
};
// What the student's code threw when it was not a std::exception.
struct UnknownException {};

template <typename T>
constexpr const char* variantOf() {
    if constexpr (std::is_same_v<T, float>)
        return "float";
    else if constexpr (std::is_same_v<T, double>)
        return "double";
    else if constexpr (std::is_same_v<T, long double>)
        return "long double";
    else
        static_assert(sizeof(T) == 0, "the grader's calls know float, double and long double");
}

// A message from the worker as the checker may report it: printable ASCII, every other byte
// written \xNN (a control character or a byte that is no UTF-8 would make the checker's XML
// result unreadable, and the case's reason "no test result"), at most kMaxMessage bytes.
inline std::string printableMessage(const std::string& text) {
    constexpr size_t kMaxMessage = 2000;
    std::string out;
    for (unsigned char c : text) {
        if (out.size() >= kMaxMessage) {
            out += "...";
            break;
        }
        if (c >= 0x20 && c < 0x7f) {
            out += char(c);
        } else {
            char escaped[8];
            std::snprintf(escaped, sizeof escaped, "\\x%02x", c);
            out += escaped;
        }
    }
    return out;
}

[[noreturn]] inline void rethrowRemote(Reader& r) {
    auto kind = ErrorKind(r.pod<uint8_t>());
    std::string what = printableMessage(r.text());
    switch (kind) {
        case ErrorKind::NotImplemented:
            throw NotImplemented(printableMessage(r.text()));
        case ErrorKind::InvalidArgument:
            throw std::invalid_argument(what);
        case ErrorKind::DomainError:
            throw std::domain_error(what);
        case ErrorKind::LengthError:
            throw std::length_error(what);
        case ErrorKind::OutOfRange:
            throw std::out_of_range(what);
        case ErrorKind::LogicError:
            throw std::logic_error(what);
        case ErrorKind::RangeError:
            throw std::range_error(what);
        case ErrorKind::OverflowError:
            throw std::overflow_error(what);
        case ErrorKind::UnderflowError:
            throw std::underflow_error(what);
        case ErrorKind::InputError:
            throw InputError(what);
        case ErrorKind::RuntimeError:
            throw std::runtime_error(what);
        case ErrorKind::BadAlloc:
            throw std::bad_alloc();
        case ErrorKind::Exception:
            throw std::runtime_error(what);
        case ErrorKind::Unknown:
            throw UnknownException();
        case ErrorKind::Judge:
            throw WorkerError("the grader's worker: " + what);
    }
    throw Malformed("an exception of no known kind");
}

inline Session& checkerSession(const char* id) {
    Session& s = Session::get();
    if (!s.connected()) {
        if (!s.connect(std::getenv("BOXES_JUDGE_FDS")))
            throw WorkerError(std::string("exercise ") + id +
                              ": this test program is the grader's checker; its exercises run "
                              "in a worker it was not given (BOXES_JUDGE_FDS)");
        s.serve = [&s](Kind, const std::string& payload) {
            // A callback: the worker names one the calls in progress registered.
            Reader r(payload);
            uint32_t id = 0;
            try {
                id = r.pod<uint32_t>();
            } catch (const Malformed& e) {
                s.peerMalformed(e.what());
            }
            if (id >= s.callbacks.size()) s.peerMalformed("a callback that was not passed");
            Writer w;
            bool ok = true;
            try {
                auto callback = s.callbacks[id];  // it may register more (a nested call)
                callback(r, w);
            } catch (const Malformed& e) {
                s.peerMalformed(e.what());
            } catch (...) {
                // The test's exception (a failed REQUIRE, say) is thrown again when the
                // call that led here returns; the student's code sees CallbackFailed.
                if (!s.frames.empty() && !s.frames.back().callbackError)
                    s.frames.back().callbackError = std::current_exception();
                ok = false;
            }
            if (!s.endpoint().send(ok ? Kind::CallbackReturn : Kind::CallbackThrow,
                                   ok ? w.bytes : std::string()))
                s.peerGone();
        };
    }
    return s;
}

// One call of exercise `id` (`variant`: its template argument, or "") in the worker, with
// the arguments of the declared parameter types D: the result, the out-parameters written
// back, or the worker's exception thrown here.
template <typename R, typename... D>
R remote(const char* id, const char* variant, D... args) {
    Session& s = checkerSession(id);
    std::lock_guard<std::recursive_mutex> guard(s.lock);
    struct Current {
        const char* outer = currentCall;
        ~Current() { currentCall = outer; }
    } current;
    currentCall = id;
    s.frames.push_back({s.callbacks.size(), nullptr});
    auto popFrame = [&s] {
        Session::Frame f = s.frames.back();
        s.frames.pop_back();
        s.callbacks.resize(f.callbacksMark);
        return f;
    };
    Writer w;
    w.text(id);
    w.text(variant);
    try {
        (Param<D>::put(w, args), ...);
    } catch (...) {
        popFrame();
        throw;
    }
    std::string reply;
    Kind kind = s.request(Kind::Call, w.bytes, reply, Kind::Return, Kind::Throw);
    Session::Frame frame = popFrame();
    if (frame.callbackError) std::rethrow_exception(frame.callbackError);
    Reader r(reply);
    try {
        if (kind == Kind::Throw) rethrowRemote(r);
        if constexpr (std::is_void_v<R>) {
            (Param<D>::back(r, args), ...);
            r.expectEnd();
        } else {
            R result = make<R>();
            get(r, result);
            (Param<D>::back(r, args), ...);
            r.expectEnd();
            return result;
        }
    } catch (const Malformed& e) {
        s.peerMalformed(e.what());
    }
}

}  // namespace boxes::judge
