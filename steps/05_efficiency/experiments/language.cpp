// The choice of language, measured: one ray/sphere kernel compiled with different flags
// (language.hpp), side by side in float and double, against the double -O2 result.
#include "05_efficiency/language.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "05_efficiency/experiments/lab_helpers.hpp"
#include "05_efficiency/measure.hpp"
#include "core/timing.hpp"

namespace boxes::language {

namespace o0 {
BOXES_LANGUAGE_KERNEL_DECLARATIONS
}
namespace o1 {
BOXES_LANGUAGE_KERNEL_DECLARATIONS
}
namespace o2 {
BOXES_LANGUAGE_KERNEL_DECLARATIONS
}
namespace o3 {
BOXES_LANGUAGE_KERNEL_DECLARATIONS
}
#if BOXES_LANGUAGE_NATIVE
namespace native {
BOXES_LANGUAGE_KERNEL_DECLARATIONS
}
namespace native_fma {
BOXES_LANGUAGE_KERNEL_DECLARATIONS
}
#endif

const std::vector<KernelVariant>& kernelVariants() {
    static const std::vector<KernelVariant> variants = {
        {"O0", o0::flags(), o0::nearestFloat, o0::nearestDouble},
        {"O1", o1::flags(), o1::nearestFloat, o1::nearestDouble},
        {"O2", o2::flags(), o2::nearestFloat, o2::nearestDouble},
        {"O3", o3::flags(), o3::nearestFloat, o3::nearestDouble},
#if BOXES_LANGUAGE_NATIVE
        {"native", native::flags(), native::nearestFloat, native::nearestDouble},
        {"native+fma", native_fma::flags(), native_fma::nearestFloat, native_fma::nearestDouble},
#endif
    };
    return variants;
}

const KernelVariant& referenceVariant() {
    for (const KernelVariant& v : kernelVariants())
        if (v.name == "O2") return v;
    throw std::logic_error("no O2 kernel variant");
}

}  // namespace boxes::language

namespace boxes {

using namespace lab;
using language::KernelVariant;

Table measureLanguage(const LabOptions& o) {
    Table t(
        "language",
        "The choice of language, within one: the same ray/sphere kernel under different compiler "
        "flags, in float and double",
        {"variant", "flags", "type", "ns/ray", "min ns", "max ns", "x O2 same type",
         "max rel t error", "flipped"},
        "4096 rays (quick: 100) from (0,0,8) towards random points of a field of 32 spheres, every "
        "ray against every sphere, nearest t; built in double and rounded for float; the kernel "
        "compiled once per row's flags, never -ffast-math; error: "
        "the largest |t - t_ref| / t_ref over the rays both hit, against the double O2 result; "
        "flipped: hit in one, miss in the other; one thread, variants interleaved round by "
        "round, median of repeats");
    std::mt19937_64 rng(o.seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<double> spheres, rays;
    for (int i = 0; i < 32; ++i)
        for (double v : {4.0 * u(rng), 3.0 * u(rng), -2.0 + u(rng), 0.3 + 0.2 * std::abs(u(rng))})
            spheres.push_back(v);
    const size_t n = size_t(samples(o, 4096));
    for (size_t i = 0; i < n; ++i) {
        // Towards a point of the plane z = -2, through the middle of the field.
        double x = 5.0 * u(rng), y = 3.5 * u(rng), z = -2.0 - 8.0;
        double len = std::sqrt(x * x + y * y + z * z);
        for (double v : {0.0, 0.0, 8.0, x / len, y / len, z / len}) rays.push_back(v);
    }
    std::vector<float> spheresF(spheres.begin(), spheres.end()), raysF(rays.begin(), rays.end());
    std::vector<double> ref(n);
    language::referenceVariant().nearestDouble(spheres.data(), 32, rays.data(), n, ref.data());

    const auto& variants = language::kernelVariants();
    std::vector<std::vector<float>> outF(variants.size(), std::vector<float>(n));
    std::vector<std::vector<double>> outD(variants.size(), std::vector<double>(n));
    std::vector<std::function<void()>> fns;
    for (size_t v = 0; v < variants.size(); ++v) {
        fns.push_back([&, v] {
            variants[v].nearestFloat(spheresF.data(), 32, raysF.data(), n, outF[v].data());
            keepValue(outF[v][0]);
        });
        fns.push_back([&, v] {
            variants[v].nearestDouble(spheres.data(), 32, rays.data(), n, outD[v].data());
            keepValue(outD[v][0]);
        });
    }
    std::vector<Timing> times = measureInterleaved(o.repeats, fns);
    size_t o2 = 0;
    for (size_t v = 0; v < variants.size(); ++v)
        if (variants[v].name == "O2") o2 = v;
    auto errors = [&](auto& out) {
        double worst = 0.0;
        long long flipped = 0;
        for (size_t i = 0; i < n; ++i) {
            bool hit = std::isfinite(double(out[i])), hitRef = std::isfinite(ref[i]);
            if (hit != hitRef)
                ++flipped;
            else if (hit)
                worst = std::max(worst, std::abs(double(out[i]) - ref[i]) / ref[i]);
        }
        return std::pair{worst, flipped};
    };
    double per = 1e9 / double(n);
    for (int type = 0; type < 2; ++type)
        for (size_t v = 0; v < variants.size(); ++v) {
            const Timing& tm = times[2 * v + size_t(type)];
            const Timing& base = times[2 * o2 + size_t(type)];
            auto [worst, flipped] = type == 0 ? errors(outF[v]) : errors(outD[v]);
            t.row({variants[v].name, variants[v].flags, std::string(type == 0 ? "float" : "double"),
                   tm.median * per, tm.min * per, tm.max * per, tm.median / base.median, worst,
                   flipped});
        }
    t.timeAndError("ns/ray", "min ns", "max ns", "max rel t error");
    return t;
}

}  // namespace boxes
