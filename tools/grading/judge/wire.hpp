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
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <memory>
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

// The fast path, where the two ends have a core each: a slot per direction in memory both
// map (a sealed memfd the grader passes). A message that fits is copied into the sender's
// slot and published by bumping its sequence number; the receiver spins for it a few
// microseconds (adaptively: less when spinning did not pay), then sleeps on the pipe, into
// which the sender writes a doorbell byte 'b' only when the receiver said it sleeps. A
// message too large for the slot goes through the pipe, announced in the slot, after an 'F'.
// The protocol alternates strictly (every message answers the peer's last one), so a slot
// is never rewritten before its reader copied it out; what the peer writes into shared
// memory is copied once and then read with the usual bounds checks.
constexpr uint32_t kSlotBytes = 1u << 20;
constexpr uint8_t kInPipe = 0xFF;  // the slot's kind when the message follows in the pipe

struct SharedSlot {
    alignas(64) std::atomic<uint32_t> seq;       // the sender's count of published messages
    alignas(64) std::atomic<uint32_t> sleeping;  // the receiver sleeps on the pipe: ring it
    alignas(64) uint32_t size;
    uint8_t kind;
    alignas(64) char data[kSlotBytes];
};
struct SharedChannel {
    SharedSlot slots[2];  // [0]: checker to worker, [1]: worker to checker
};

// One end of the two pipes (and, on the fast path, of the shared slots). Reads and writes
// whole frames; a peer that is gone reads as end of file (receive returns false) and writes
// as false (SIGPIPE is ignored).
class Endpoint {
public:
    Endpoint(int in, int out) : in_(in), out_(out) { ::signal(SIGPIPE, SIG_IGN); }
    // The fast path: `shared` maps a SharedChannel; `checker` says which slot is whose.
    Endpoint(int in, int out, SharedChannel* shared, bool checker)
        : in_(in), out_(out),
          inSlot_(&shared->slots[checker ? 1 : 0]), outSlot_(&shared->slots[checker ? 0 : 1]) {
        ::signal(SIGPIPE, SIG_IGN);  // both sequences start at 0: the grader's memfd is zeros
    }

    bool send(Kind kind, const std::string& payload) {
        if (payload.size() > kMaxFrame) throw Malformed("a message over the frame limit");
        if (outSlot_ && payload.size() <= kSlotBytes) {
            std::memcpy(outSlot_->data, payload.data(), payload.size());
            outSlot_->size = uint32_t(payload.size());
            outSlot_->kind = uint8_t(kind);
            outSlot_->seq.store(++sent_, std::memory_order_seq_cst);
            if (outSlot_->sleeping.load(std::memory_order_seq_cst)) return writeAll("b", 1);
            return true;
        }
        char header[8] = {};
        uint32_t size = uint32_t(payload.size());
        std::memcpy(header, &size, 4);
        header[4] = char(kind);
        frame_.clear();
        if (outSlot_) {  // announced in the slot, the frame itself after an 'F' in the pipe
            outSlot_->kind = kInPipe;
            outSlot_->seq.store(++sent_, std::memory_order_seq_cst);
            frame_ = "F";
        }
        frame_.append(header, 8);
        frame_ += payload;
        return writeAll(frame_.data(), frame_.size());
    }

    // false at end of file (the peer ended); Malformed for a frame that is not one.
    bool receive(Kind& kind, std::string& payload) {
        if (inSlot_) {
            if (!awaitSlot()) return false;
            uint8_t k = inSlot_->kind;
            if (k != kInPipe) {
                uint32_t size = inSlot_->size;
                if (size > kSlotBytes) throw Malformed("a message over its slot");
                if (k < uint8_t(Kind::Call) || k > uint8_t(Kind::CallbackThrow))
                    throw Malformed("a message of no known kind");
                kind = Kind(k);
                payload.assign(inSlot_->data, size);
                return true;
            }
            if (!frameStarted_) {  // doorbells may come first
                char b = 'b';
                while (b == 'b')
                    if (readAll(&b, 1) != 1) throw Malformed("a frame announced but not sent");
                if (b != 'F') throw Malformed("a byte in the pipe that is no doorbell");
            }
            frameStarted_ = false;
            if (!receiveFrame(kind, payload)) throw Malformed("a frame announced but not sent");
            return true;
        }
        return receiveFrame(kind, payload);
    }

private:
    // Waits until the peer published a message in its slot: true, or false at end of file.
    bool awaitSlot() {
        using Clock = std::chrono::steady_clock;
        // First spin: the peer may be answering on another core right now.
        Clock::time_point start = Clock::now();
        for (uint32_t i = 1;; ++i) {
            if (published()) {
                spin_ = std::min(kMaxSpin, spin_ * 2);
                return true;
            }
            if ((i & 63) == 0 && Clock::now() - start >= spin_) break;
#if defined(__x86_64__) || defined(__i386__)
            __builtin_ia32_pause();
#endif
        }
        spin_ = std::max(kMinSpin, spin_ / 2);  // it did not pay: spin less next time
        // Then sleep on the pipe: a doorbell, the 'F' of a frame, or the end.
        for (;;) {
            inSlot_->sleeping.store(1, std::memory_order_seq_cst);
            if (published()) {
                inSlot_->sleeping.store(0, std::memory_order_seq_cst);
                return true;
            }
            char b;
            ssize_t r;
            do {
                r = ::read(in_, &b, 1);
            } while (r < 0 && errno == EINTR);
            inSlot_->sleeping.store(0, std::memory_order_seq_cst);
            if (r <= 0) return false;
            if (b == 'F')
                frameStarted_ = true;
            else if (b != 'b')
                throw Malformed("a byte in the pipe that is no doorbell");
            if (published()) return true;
            if (frameStarted_) throw Malformed("a frame sent but not announced");
        }
    }

    bool published() {
        uint32_t s = inSlot_->seq.load(std::memory_order_acquire);
        if (s == seen_) return false;
        seen_ = s;
        return true;
    }

    bool receiveFrame(Kind& kind, std::string& payload) {
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
    static constexpr std::chrono::nanoseconds kMinSpin{1000}, kMaxSpin{50000};
    int in_, out_;
    SharedSlot* inSlot_ = nullptr;
    SharedSlot* outSlot_ = nullptr;
    uint32_t seen_ = 0, sent_ = 0;
    bool frameStarted_ = false;
    std::chrono::nanoseconds spin_{20000};
    std::string frame_;
};

// The descriptors the grader passed, from an environment variable: "3,4" (the pipes: read,
// write) or "3,4,5" (and the memfd of the shared slots: the fast path). False when it is
// unset or not such numbers.
inline bool parseFds(const char* text, int fds[3]) {
    if (!text) return false;
    fds[2] = -1;
    const char* p = text;
    for (int k = 0; k < 3; ++k) {
        char* end = nullptr;
        long v = std::strtol(p, &end, 10);
        if (end == p || v < 0 || v > 1 << 20) return false;
        fds[k] = int(v);
        if (*end == '\0') return k >= 1;
        if (*end != ',') return false;
        p = end + 1;
    }
    return false;
}

// This end of the protocol from the variable's descriptors (nullptr when they are not
// usable). `checker` picks this end's slots on the fast path.
inline std::unique_ptr<Endpoint> connectEndpoint(const char* text, bool checker) {
    int fds[3];
    if (!parseFds(text, fds)) return nullptr;
    if (fds[2] < 0) return std::make_unique<Endpoint>(fds[0], fds[1]);
    struct stat info;
    if (::fstat(fds[2], &info) != 0 || size_t(info.st_size) < sizeof(SharedChannel)) return nullptr;
    void* shared = ::mmap(nullptr, sizeof(SharedChannel), PROT_READ | PROT_WRITE, MAP_SHARED, fds[2], 0);
    if (shared == MAP_FAILED) return nullptr;
    return std::make_unique<Endpoint>(fds[0], fds[1], static_cast<SharedChannel*>(shared), checker);
}

}  // namespace boxes::judge
