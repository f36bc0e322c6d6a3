// Reciprocal square root: 1 / std::sqrt against the bit trick and its Newton step (5.8).
#include <algorithm>
#include <bit>
#include <cmath>
#include <random>

#include "05_efficiency/experiments/lab_helpers.hpp"
#include "05_efficiency/lab.hpp"
#include "05_efficiency/measure.hpp"
#include "core/timing.hpp"

namespace boxes {

using namespace lab;

Table measureInverseSqrt(const LabOptions& o) {
    Table t("rsqrt",
            "Reciprocal square root: exact against the bit trick, with and without a Newton step",
            {"variant", "ns/call", "min ns", "max ns", "max relative error"});
    t.note =
        "error: over 1,000,000 values log-spaced in [1e-6, 1e6] against 1/sqrt in double; time: "
        "4096 "
        "values, one thread, median of repeats";
    std::mt19937_64 rng(o.seed);
    std::uniform_real_distribution<float> u(-6.0f, 6.0f);
    std::vector<float> xs(4096);
    for (float& x : xs) x = std::pow(10.0f, u(rng));
    auto row = [&](const std::string& name, auto f) {
        double worst = 0.0;
        for (int i = 0, count = samples(o, 1000000); i < count; ++i) {
            double x = std::pow(10.0, -6.0 + 12.0 * i / count);
            double exact = 1.0 / std::sqrt(double(float(x)));
            worst = std::max(worst, std::abs(double(f(float(x))) - exact) / exact);
        }
        Timing tm = measureBatched(
            o.repeats,
            [&] {
                float s = 0.0f;
                for (float x : xs) s += f(x);
                keepValue(s);
            },
            0.01);
        double per = 1e9 / double(xs.size());
        t.row({name, tm.median * per, tm.min * per, tm.max * per, worst});
    };
    row("1 / std::sqrt", [](float x) { return 1.0f / std::sqrt(x); });
    row("bit trick, no Newton step", [](float x) {
        return std::bit_cast<float>(0x5f3759dfu - (std::bit_cast<uint32_t>(x) >> 1));
    });
    row("bit trick + one Newton step (5.8)", [](float x) { return approxInverseSqrt(x); });
    t.timeAndError("ns/call", "min ns", "max ns", "max relative error");
    return t;
}

}  // namespace boxes
