#include "core/timing.hpp"

namespace boxes {

Timing summarize(std::vector<double> samples, long long callsPerRepeat) {
    Timing t;
    if (samples.empty()) return t;
    std::sort(samples.begin(), samples.end());
    size_t n = samples.size();
    double median = n % 2 ? samples[n / 2] : 0.5 * (samples[n / 2 - 1] + samples[n / 2]);
    double scale = 1.0 / double(callsPerRepeat);
    t.median = median * scale;
    t.min = samples.front() * scale;
    t.max = samples.back() * scale;
    t.repeats = int(n);
    t.callsPerRepeat = callsPerRepeat;
    return t;
}

Timing measure(int repeats, const std::function<void()>& fn) {
    std::vector<double> samples;
    for (int r = 0; r < repeats; ++r) {
        Stopwatch watch;
        fn();
        samples.push_back(watch.seconds());
    }
    return summarize(samples);
}

Timing measureBatched(int repeats, const std::function<void()>& fn, double minBatchSeconds) {
    long long batch = 1;
    for (;;) {
        Stopwatch watch;
        for (long long i = 0; i < batch; ++i) fn();
        if (watch.seconds() >= minBatchSeconds || batch >= (1LL << 40)) break;
        batch *= 2;
    }
    std::vector<double> samples;
    for (int r = 0; r < repeats; ++r) {
        Stopwatch watch;
        for (long long i = 0; i < batch; ++i) fn();
        samples.push_back(watch.seconds());
    }
    return summarize(samples, batch);
}

}  // namespace boxes
