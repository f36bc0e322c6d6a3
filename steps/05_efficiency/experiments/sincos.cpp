// Sine from a table (exercises 5.1-5.3) or a polynomial: time per call against its error.
#include <algorithm>
#include <cmath>
#include <random>

#include "05_efficiency/experiments/lab_helpers.hpp"
#include "05_efficiency/lab.hpp"
#include "05_efficiency/measure.hpp"
#include "core/timing.hpp"

namespace boxes {

using namespace lab;

Table measureSinCos(const LabOptions& o) {
    Table t("sincos",
            "Sine from a table: time per call against the largest error over the full circle",
            {"variant", "ns/call", "min ns", "max ns", "max abs error", "stated bound"});
    t.note =
        "error: max |f(x) - sin(x)| (sin in double of the float angle x) over 1,000,000 angles "
        "evenly spaced in [0, 2 pi); time: 4096 angles, 3 in 4 in [0, 2 pi), 1 in 4 in [-20, 20] "
        "(wrapped), one thread, median of repeats; "
        "lecture: sin(i / 10) table read at (int)(a * 10) for a in degrees [0, 360)";
    std::mt19937_64 rng(o.seed);
    std::uniform_real_distribution<float> u(-20.0f, 20.0f), circle(0.0f, 2.0f * kPi);
    std::vector<float> angles(4096);
    for (size_t i = 0; i < angles.size(); ++i) angles[i] = i % 4 == 3 ? u(rng) : circle(rng);
    auto row = [&](const std::string& name, auto f, double bound) {
        double worst = 0.0;
        const int count = samples(o, 1000000);
        for (int i = 0; i < count; ++i) {
            float x = float(2.0 * M_PI * i / count);
            // Against the sine of the angle as the function receives it (a float).
            worst = std::max(worst, std::abs(double(f(x)) - std::sin(double(x))));
        }
        Timing tm = measureBatched(
            o.repeats,
            [&] {
                float sum = 0.0f;
                for (float a : angles) sum += f(a);
                keepValue(sum);
            },
            0.01);
        double per = 1e9 / double(angles.size());
        t.row({name, tm.median * per, tm.min * per, tm.max * per, worst, bound});
    };
    row(
        "std::sin double", [](float a) { return float(std::sin(double(a))); }, 0.0);
    row(
        "std::sin float", [](float a) { return std::sin(a); }, 6e-8);
    for (int n : {360, 3600, 36000}) {
        SinTable table = SinTable::make(n);
        row(
            "table nearest " + std::to_string(n), [&](float a) { return table.sinNearest(a); },
            table.nearestErrorBound());
    }
    for (int n : {360, 3600}) {
        SinTable table = SinTable::make(n);
        row(
            "table interpolated " + std::to_string(n),
            [&](float a) { return table.sinInterpolated(a); }, table.interpolatedErrorBound());
    }
    row(
        "polynomial degree 7", [](float a) { return sinPolynomial(a); }, 1.6e-4);
    // The lecture's table, read in degrees over [0, 360): its error against the true sine.
    LectureSinTable lecture;
    double worst = 0.0;
    for (int i = 0, count = samples(o, 360000); i < count; ++i) {
        double deg = 360.0 * i / count;
        worst = std::max(worst, std::abs(double(lecture.sin(float(deg)).value_or(0.0f)) -
                                         std::sin(deg * M_PI / 180.0)));
    }
    std::vector<float> degrees(4096);
    for (size_t i = 0; i < degrees.size(); ++i) degrees[i] = float(i % 3600) / 10.0f;
    Timing tm = measureBatched(
        o.repeats,
        [&] {
            float sum = 0.0f;
            for (float d : degrees) sum += lecture.sin(d).value_or(0.0f);
            keepValue(sum);
        },
        batchSeconds(o));
    double per = 1e9 / double(degrees.size());
    t.row({std::string("lecture's table (3600, buggy)"), tm.median * per, tm.min * per,
           tm.max * per, worst, std::string("-")});
    t.timeAndError("ns/call", "min ns", "max ns", "max abs error");
    return t;
}

}  // namespace boxes
