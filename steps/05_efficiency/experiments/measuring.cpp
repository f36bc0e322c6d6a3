// Measuring itself: one call per stopwatch sample against batches of calls, and one frame.
#include <algorithm>
#include <random>

#include "05_efficiency/experiments/lab_helpers.hpp"
#include "05_efficiency/measure.hpp"
#include "core/timing.hpp"

namespace boxes {

using namespace lab;

Table measureMeasuring(const LabOptions& o) {
    Table t(
        "measuring",
        "Measuring itself: one call per stopwatch sample against batches of calls (median of "
        "repeats)",
        {"operation", "method", "samples", "median ns", "min ns", "max ns", "max/min"},
        "ray/sphere test (core intersectSphere, float) on one thread; 'one call': a steady_clock "
        "stopwatch around each single call, 2001 samples; 'batch': calls repeated until a batch "
        "takes >= 20 ms, " +
            std::to_string(std::max(o.repeats, 5)) + " batches, time per call");
    std::mt19937_64 rng(o.seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::vector<Ray> rays;
    for (int i = 0; i < 256; ++i)
        rays.emplace_back(Vec3(u(rng), u(rng), 5.0f), Vec3(0.2f * u(rng), 0.2f * u(rng), -1.0f));
    Sphere sphere{Vec3(0.0f), 1.0f};
    size_t k = 0;
    auto once = [&] {
        auto h = intersectSphere(rays[k++ & 255], sphere);
        keepValue(h);
    };
    Timing single = measure(samples(o, 2001), once);
    Timing batch = measureBatched(std::max(o.repeats, 5), once, o.quick ? 0.002 : 0.02);
    for (auto [name, tm] :
         {std::pair{"one call per sample", single}, std::pair{"batch, median of repeats", batch}})
        t.row({std::string("ray/sphere"), std::string(name), (long long)tm.repeats, ns(tm.median),
               ns(tm.min), ns(tm.max), tm.min > 0 ? tm.max / tm.min : 0.0});
    // A whole small frame is long enough to time one at a time.
    Scene scene = makeScene("spheres", {});
    Renderer r(scene, scene.camera, oneThread(64, 48));
    Timing frame = measure(std::max(o.repeats, 5), [&] { keepValue(r.render()); });
    t.row({std::string("frame 64x48"), std::string("one frame per sample"),
           (long long)frame.repeats, ns(frame.median), ns(frame.min), ns(frame.max),
           frame.max / frame.min});
    return t;
}

}  // namespace boxes
