// The worker's end of the call protocol: a loop that reads a call, runs the student's
// exercise function on its arguments and answers with the result and the out-parameters,
// or with what it threw. It keeps nothing between test cases: the grader starts a fresh
// worker for each.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <new>
#include <span>
#include <string>
#include <string_view>

#include "core/exercise.hpp"
#include "core/mesh.hpp"
#include "judge/codec.hpp"

namespace boxes::judge {

using Handler = void (*)(Reader&, Writer&);
struct Entry {
    const char* id;       // "1.4"
    const char* variant;  // "float", "double", or "" for a function that is no template
    Handler handler;
};

inline void answerThrow(ErrorKind kind, std::string_view what, std::string_view exercise = {}) {
    Writer w;
    w.pod(uint8_t(kind));
    w.text(what);
    if (kind == ErrorKind::NotImplemented) w.text(exercise);
    if (!Session::get().endpoint().send(Kind::Throw, w.bytes)) Session::get().peerGone();
}

inline void serveCall(std::span<const Entry> table, const std::string& payload) {
    Reader r(payload);
    std::string id, variant;
    try {
        id = r.text();
        variant = r.text();
    } catch (const Malformed&) {
        answerThrow(ErrorKind::Judge, "a call it cannot read");
        return;
    }
    if (id == "judge.ping" && variant.empty()) {  // the grader's probe: the worker has started
        if (!Session::get().endpoint().send(Kind::Return, std::string())) Session::get().peerGone();
        return;
    }
    Handler handler = nullptr;
    for (const Entry& e : table)
        if (id == e.id && variant == e.variant) handler = e.handler;
    if (!handler) {
        answerThrow(ErrorKind::Judge, "no exercise " + id + (variant.empty() ? "" : " for ") +
                                          variant + " in this step's worker");
        return;
    }
    Writer w;
    // Each standard exception its own kind, most derived first: the checker throws the same
    // type again (checker.hpp), so a test's CHECK_THROWS_AS sees what the student's code threw.
    try {
        handler(r, w);
    } catch (const Malformed& e) {
        answerThrow(ErrorKind::Judge, std::string("the arguments of exercise ") + id +
                                          " do not fit this tree's types (" + e.what() +
                                          "): keep the starter kit's types");
        return;
    } catch (const NotImplemented& e) {
        answerThrow(ErrorKind::NotImplemented, e.what(), e.exercise);
        return;
    } catch (const std::invalid_argument& e) {
        answerThrow(ErrorKind::InvalidArgument, e.what());
        return;
    } catch (const std::domain_error& e) {
        answerThrow(ErrorKind::DomainError, e.what());
        return;
    } catch (const std::length_error& e) {
        answerThrow(ErrorKind::LengthError, e.what());
        return;
    } catch (const std::out_of_range& e) {
        answerThrow(ErrorKind::OutOfRange, e.what());
        return;
    } catch (const std::logic_error& e) {
        answerThrow(ErrorKind::LogicError, e.what());
        return;
    } catch (const std::range_error& e) {
        answerThrow(ErrorKind::RangeError, e.what());
        return;
    } catch (const std::overflow_error& e) {
        answerThrow(ErrorKind::OverflowError, e.what());
        return;
    } catch (const std::underflow_error& e) {
        answerThrow(ErrorKind::UnderflowError, e.what());
        return;
    } catch (const InputError& e) {
        answerThrow(ErrorKind::InputError, e.what());
        return;
    } catch (const std::runtime_error& e) {
        answerThrow(ErrorKind::RuntimeError, e.what());
        return;
    } catch (const std::bad_alloc&) {
        answerThrow(ErrorKind::BadAlloc, "std::bad_alloc");
        return;
    } catch (const std::exception& e) {
        answerThrow(ErrorKind::Exception, e.what());
        return;
    } catch (...) {
        answerThrow(ErrorKind::Unknown, "an exception that is no std::exception");
        return;
    }
    if (!Session::get().endpoint().send(Kind::Return, w.bytes)) Session::get().peerGone();
}

// The worker's main: serves calls until the checker closes its end, then ends at once
// (std::_Exit: no static destructor or atexit handler of the student's runs after the last
// answer).
inline int serve(std::span<const Entry> table) {
    Session& s = Session::get();
    s.worker = true;
    if (!s.connect(std::getenv("BOXES_JUDGE_FDS"))) {
        std::fprintf(stderr, "judge worker: run by the grader only (BOXES_JUDGE_FDS)\n");
        return 2;
    }
    s.serve = [table](Kind, const std::string& payload) { serveCall(table, payload); };
    for (;;) {
        Kind kind;
        std::string payload;
        bool open;
        try {
            open = s.endpoint().receive(kind, payload);
        } catch (const Malformed&) {
            std::_Exit(3);
        }
        if (!open) std::_Exit(0);
        if (kind != Kind::Call) std::_Exit(3);
        serveCall(table, payload);
    }
}

}  // namespace boxes::judge
