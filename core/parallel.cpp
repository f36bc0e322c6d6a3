#include "core/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <cfenv>
#include <chrono>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace boxes {

int resolveThreads(int threads) {
    return threads > 0 ? threads : int(std::max(1u, std::thread::hardware_concurrency()));
}

namespace {

// One call of runOnThreads: the task, the caller's floating-point environment, and the
// first exception.
struct Call {
    const std::function<void(int)>* task = nullptr;
    std::fenv_t fpEnvironment;
    std::mutex failureMutex;
    std::exception_ptr failure;

    void run(int thread) {
        try {
            (*task)(thread);
        } catch (...) {
            std::lock_guard lock(failureMutex);
            if (!failure) failure = std::current_exception();
        }
    }
};

// Spins for about a millisecond, then sleeps, until `value` is no longer `old`: a repeated
// trace or the next frame starts within microseconds, and waking a sleeping thread costs a
// noticeable share of a short parallel pass.
template <typename T>
T awaitChange(const std::atomic<T>& value, T old) {
    auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(1);
    for (int spin = 0;; ++spin) {
        T now = value.load(std::memory_order_acquire);
        if (now != old) return now;
        if ((spin & 63) == 0 && std::chrono::steady_clock::now() > until) break;
#if defined(__SSE2__)
        _mm_pause();
#endif
    }
    value.wait(old, std::memory_order_acquire);
    return value.load(std::memory_order_acquire);
}

class WorkerPool {
public:
    ~WorkerPool() { resize(0); }

    // false when the pool is busy: the caller then starts threads of its own.
    bool run(Call& call, int threads) {
        if (busy_.exchange(true, std::memory_order_acquire)) return false;
        struct Release {
            std::atomic<bool>& busy;
            ~Release() { busy.store(false, std::memory_order_release); }
        } release{busy_};
        resize(size_t(threads - 1));
        call_ = &call;
        pending_.store(int(workers_.size()), std::memory_order_relaxed);
        generation_.fetch_add(1, std::memory_order_release);
        generation_.notify_all();
        call.run(0);
        for (int left = pending_.load(std::memory_order_acquire); left != 0;)
            left = awaitChange(pending_, left);
        return true;
    }

private:
    void resize(size_t workers) {
        if (workers_.size() == workers) return;
        if (!workers_.empty()) {
            stop_.store(true, std::memory_order_relaxed);
            generation_.fetch_add(1, std::memory_order_release);
            generation_.notify_all();
            for (std::thread& t : workers_) t.join();
            workers_.clear();
            stop_.store(false, std::memory_order_relaxed);
        }
        uint64_t current = generation_.load(std::memory_order_relaxed);
        for (size_t i = 0; i < workers; ++i)
            workers_.emplace_back([this, current, i] { work(int(i) + 1, current); });
    }

    void work(int thread, uint64_t seen) {
        for (;;) {
            seen = awaitChange(generation_, seen);
            if (stop_.load(std::memory_order_relaxed)) return;
            std::fesetenv(&call_->fpEnvironment);
            call_->run(thread);
            if (pending_.fetch_sub(1, std::memory_order_acq_rel) == 1) pending_.notify_one();
        }
    }

    std::atomic<bool> busy_{false};
    std::vector<std::thread> workers_;
    std::atomic<uint64_t> generation_{0};
    std::atomic<int> pending_{0};
    std::atomic<bool> stop_{false};
    Call* call_ = nullptr;
};

WorkerPool& workerPool() {
    static WorkerPool pool;
    return pool;
}

}  // namespace

void runOnThreads(int threads, const std::function<void(int)>& task) {
    threads = resolveThreads(threads);
    if (threads == 1) return task(0);
    Call call;
    call.task = &task;
    std::fegetenv(&call.fpEnvironment);
    if (!workerPool().run(call, threads)) {
        std::vector<std::thread> own;
        for (int t = 1; t < threads; ++t) own.emplace_back([&call, t] { call.run(t); });
        call.run(0);
        for (std::thread& t : own) t.join();
    }
    if (call.failure) std::rethrow_exception(call.failure);
}

}  // namespace boxes
