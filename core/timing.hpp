// Measuring time the way step 05 teaches it: a stopwatch around a batch of work long
// enough to time reliably, repeated, and reported as the median with min and max.
#pragma once

#include <algorithm>
#include <chrono>
#include <functional>
#include <vector>

namespace boxes {

class Stopwatch {
public:
    Stopwatch() : start_(Clock::now()) {}
    void restart() { start_ = Clock::now(); }
    double seconds() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }
    double milliseconds() const { return seconds() * 1e3; }

private:
    using Clock = std::chrono::steady_clock;
    Clock::time_point start_;
};

struct Timing {
    double median = 0.0;  // seconds per call
    double min = 0.0;
    double max = 0.0;
    int repeats = 0;
    long long callsPerRepeat = 1;
};

// Median/min/max of samples (seconds).
Timing summarize(std::vector<double> samples, long long callsPerRepeat = 1);

// Times fn() `repeats` times, each sample one call.
Timing measure(int repeats, const std::function<void()>& fn);

// Times batches of calls: the batch size grows until one batch takes at least
// minBatchSeconds, then `repeats` batches are timed. Reports seconds per call.
Timing measureBatched(int repeats, const std::function<void()>& fn, double minBatchSeconds = 0.02);

}  // namespace boxes
