// The grader's call protocol between the checker and the worker of one test case.
//
// The checker (the tests, their expected values and the verdict; no student code) and the
// worker (the student's exercise functions, sandboxed) are two processes joined by two
// pipes. Only the checker starts calls: "run exercise 1.4 on these arguments". While a call
// runs the worker may call back (a traversal's primitive intersector, a renderer's clock),
// and that callback may call an exercise again: the calls nest strictly, one at a time, like
// the calls of one thread in one process. The principle is that of IOI's contest system and
// DOMjudge: the contestant's code computes, the judge's code decides.
//
// A message is a frame: 4 bytes of payload length, 1 byte of kind, 3 bytes of padding, then
// the payload. Everything a peer sends is read with bounds checks; a frame that does not
// parse is the peer's fault (Malformed), never a crash of the reader.
#pragma once

#include <errno.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>

namespace boxes::judge {

enum class Kind : uint8_t {
    Call = 1,        // checker -> worker: exercise id, variant, arguments
    Return,          // worker -> checker: result, then the out-parameters
    Throw,           // worker -> checker: the exercise threw (ErrorKind, message)
    Callback,        // worker -> checker: callback id, arguments
    CallbackReturn,  // checker -> worker: result, then the out-parameters
    CallbackThrow,   // checker -> worker: the callback threw (its exception stays in the checker)
};

// What a Throw carries: the exception's kind, so that the checker throws the same type
// (a test's CHECK_THROWS_AS(f(x), std::invalid_argument) holds across the pipe).
enum class ErrorKind : uint8_t {
    NotImplemented = 1,  // a starter kit's stub: boxes::NotImplemented (payload: the exercise)
    InvalidArgument,
    DomainError,
    LengthError,
    OutOfRange,
    LogicError,
    RangeError,
    OverflowError,
    UnderflowError,
    InputError,  // boxes::InputError
    RuntimeError,
    BadAlloc,
    Exception,  // another std::exception
    Unknown,    // not a std::exception
    Judge,      // the worker could not serve the call (unknown exercise, unreadable arguments)
};

// The largest frame either side accepts (the biggest argument of a test, a mesh's vertices,
// is a few megabytes).
constexpr uint32_t kMaxFrame = 256u << 20;

// The peer sent what the protocol does not allow.
struct Malformed : std::runtime_error {
    using std::runtime_error::runtime_error;
};

class Writer {
public:
    std::string bytes;

    void raw(const void* data, size_t size) {
        bytes.append(static_cast<const char*>(data), size);
    }
    template <typename T>
    void pod(const T& value) {
        static_assert(std::is_arithmetic_v<T>, "only numbers travel as raw bytes");
        raw(&value, sizeof value);
    }
    void count(uint64_t n) { pod(n); }
    void text(std::string_view s) {
        count(s.size());
        raw(s.data(), s.size());
    }
};

class Reader {
public:
    explicit Reader(std::string_view bytes) : p_(bytes.data()), end_(bytes.data() + bytes.size()) {}

    void raw(void* out, size_t size) {
        if (size_t(end_ - p_) < size) throw Malformed("a message ends early");
        if (size) std::memcpy(out, p_, size);
        p_ += size;
    }
    template <typename T>
    T pod() {
        static_assert(std::is_arithmetic_v<T>, "only numbers travel as raw bytes");
        T value;
        raw(&value, sizeof value);
        return value;
    }
    // A count of elements that each take at least `minBytes` of the message: a count the
    // rest of the message cannot hold is refused before anything is allocated for it.
    size_t count(size_t minBytes) {
        uint64_t n = pod<uint64_t>();
        uint64_t limit = minBytes ? remaining() / minBytes : uint64_t(1) << 24;
        if (n > limit) throw Malformed("a count larger than its message");
        return size_t(n);
    }
    std::string text() {
        size_t n = count(1);
        std::string s(p_, n);
        p_ += n;
        return s;
    }
    size_t remaining() const { return size_t(end_ - p_); }
    void expectEnd() const {
        if (p_ != end_) throw Malformed("a message longer than its contents");
    }

private:
    const char* p_;
    const char* end_;
};

// One end of the two pipes. Reads and writes whole frames; a peer that is gone reads as
// end of file (receive returns false) and writes as false (SIGPIPE is ignored).
class Endpoint {
public:
    Endpoint(int in, int out) : in_(in), out_(out) { ::signal(SIGPIPE, SIG_IGN); }

    bool send(Kind kind, const std::string& payload) {
        if (payload.size() > kMaxFrame) throw Malformed("a message over the frame limit");
        char header[8] = {};
        uint32_t size = uint32_t(payload.size());
        std::memcpy(header, &size, 4);
        header[4] = char(kind);
        frame_.assign(header, 8);
        frame_ += payload;
        return writeAll(frame_.data(), frame_.size());
    }

    // false at end of file (the peer ended); Malformed for a frame that is not one.
    bool receive(Kind& kind, std::string& payload) {
        char header[8];
        size_t got = readAll(header, 8);
        if (got == 0) return false;
        if (got < 8) throw Malformed("a frame header cut short");
        uint32_t size;
        std::memcpy(&size, header, 4);
        uint8_t k = uint8_t(header[4]);
        if (k < uint8_t(Kind::Call) || k > uint8_t(Kind::CallbackThrow) || header[5] || header[6] ||
            header[7])
            throw Malformed("a frame of no known kind");
        if (size > kMaxFrame) throw Malformed("a frame over the frame limit");
        kind = Kind(k);
        payload.resize(size);
        if (readAll(payload.data(), size) != size) throw Malformed("a frame cut short");
        return true;
    }

private:
    bool writeAll(const char* p, size_t n) {
        while (n > 0) {
            ssize_t w = ::write(out_, p, n);
            if (w < 0 && errno == EINTR) continue;
            if (w <= 0) return false;
            p += w;
            n -= size_t(w);
        }
        return true;
    }
    // Reads n bytes (fewer only at end of file) through a buffer: a frame that arrived whole,
    // the usual case, costs one system call.
    size_t readAll(char* p, size_t n) {
        size_t done = 0;
        while (done < n) {
            if (start_ == end_) {
                if (n - done >= sizeof buffer_) {  // a large payload: straight into place
                    ssize_t r = ::read(in_, p + done, n - done);
                    if (r < 0 && errno == EINTR) continue;
                    if (r <= 0) break;
                    done += size_t(r);
                    continue;
                }
                ssize_t r = ::read(in_, buffer_, sizeof buffer_);
                if (r < 0 && errno == EINTR) continue;
                if (r <= 0) break;
                start_ = 0;
                end_ = size_t(r);
            }
            size_t take = std::min(n - done, end_ - start_);
            std::memcpy(p + done, buffer_ + start_, take);
            start_ += take;
            done += take;
        }
        return done;
    }

    char buffer_[1 << 16];
    size_t start_ = 0, end_ = 0;
    int in_, out_;
    std::string frame_;
};

// "3,4": the two file descriptors (read, write) the grader passed, from an environment
// variable. False when it is unset or not two numbers.
inline bool parseFds(const char* text, int& in, int& out) {
    if (!text) return false;
    char* end = nullptr;
    long a = std::strtol(text, &end, 10);
    if (end == text || *end != ',') return false;
    const char* second = end + 1;
    long b = std::strtol(second, &end, 10);
    if (end == second || *end != '\0' || a < 0 || b < 0 || a > 1 << 20 || b > 1 << 20) return false;
    in = int(a);
    out = int(b);
    return true;
}

}  // namespace boxes::judge
