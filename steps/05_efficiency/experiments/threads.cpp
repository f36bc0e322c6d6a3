// Threads: the speed-up over one thread for three ways of handing out the work.
#include <algorithm>
#include <functional>

#include "05_efficiency/experiments/lab_helpers.hpp"
#include "05_efficiency/measure.hpp"
#include "core/render.hpp"
#include "core/timing.hpp"

namespace boxes {

using namespace lab;

const char* scheduleName(Schedule s) {
    switch (s) {
        case Schedule::StaticRows:
            return "static blocks of rows";
        case Schedule::DynamicRows:
            return "dynamic, one row at a time";
        default:
            return "dynamic 16x16 tiles";
    }
}

Image renderScheduled(const Renderer& renderer, int threads, Schedule schedule) {
    const int w = renderer.settings().width, h = renderer.settings().height;
    Image image(w, h);
    threads = resolveThreads(threads);
    if (schedule == Schedule::DynamicRows) {
        parallelRows(h, threads, [&](int row, int) {
            RayCounts c;
            renderer.renderRows(image, row, row + 1, c);
        });
        return image;
    }
    if (schedule == Schedule::StaticRows) {
        // Thread k gets rows [k h / n, (k+1) h / n): no coordination, but a thread with
        // the expensive rows (mirrors, glass) finishes last while the others wait.
        parallelRows(threads, threads, [&](int k, int) {
            RayCounts c;
            renderer.renderRows(image, k * h / threads, (k + 1) * h / threads, c);
        });
        return image;
    }
    const int tile = 16, tx = (w + tile - 1) / tile, ty = (h + tile - 1) / tile;
    parallelRows(tx * ty, threads, [&](int index, int) {
        RayCounts c;
        int x0 = (index % tx) * tile, y0 = (index / tx) * tile;
        for (int y = y0; y < std::min(h, y0 + tile); ++y)
            for (int x = x0; x < std::min(w, x0 + tile); ++x)
                image.at(x, y) = renderer.pixel(x, y, c);
    });
    return image;
}

Table measureThreads(const Scene& scene, const LabOptions& o) {
    Table t("threads", "Threads: speed-up over one thread, and how the work is handed out",
            {"threads", "schedule", "ms/frame", "min ms", "max ms", "speed-up", "speed-up min",
             "speed-up max", "pixels differing"});
    int all = resolveThreads(0);
    const int repeats = std::max(o.repeats, 7);
    t.note = "scene '" + scene.name + "', " + std::to_string(sized(o, 320)) + "x" +
             std::to_string(sized(o, 240)) + ", " + std::to_string(repeats) +
             " rounds; each round renders one frame of every row in turn (round-robin), and the "
             "speed-up is per round (one thread's frame over this row's frame in the same round), "
             "then its median, min and max: a change of the machine's load hits both frames of a "
             "ratio alike; this machine has " +
             std::to_string(all) + " hardware threads" + (all <= 2 ? " (so 'all' is 2)" : "") +
             ", shared with other work; pixels differing: against one thread's frame (the "
             "reference), any float difference";
    Renderer r(scene, scene.camera, oneThread(sized(o, 320), sized(o, 240)));
    Image ref = r.render();
    std::vector<int> counts = {1, 2};
    if (all > 2) counts.push_back(all);
    struct Variant {
        Schedule schedule;
        int threads;
        Image image;
    };
    std::vector<Variant> variants;
    for (Schedule s : {Schedule::StaticRows, Schedule::DynamicRows, Schedule::DynamicTiles})
        for (int n : counts) variants.push_back({s, n, Image()});
    std::vector<std::function<void()>> frames;
    for (Variant& v : variants)
        frames.push_back([&r, &v] { v.image = renderScheduled(r, v.threads, v.schedule); });
    std::vector<std::vector<double>> samples = sampleInterleaved(repeats, frames);
    for (size_t i = 0; i < variants.size(); ++i) {
        // The one-thread row of the same schedule comes first in its group.
        size_t one = i - i % counts.size();
        std::vector<double> ratios;
        for (int k = 0; k < repeats; ++k)
            ratios.push_back(samples[one][size_t(k)] / samples[i][size_t(k)]);
        Timing tm = summarize(samples[i]), speedup = summarize(ratios);
        t.row({(long long)variants[i].threads, std::string(scheduleName(variants[i].schedule)),
               ms(tm.median), ms(tm.min), ms(tm.max), speedup.median, speedup.min, speedup.max,
               (long long)compareImages(variants[i].image, ref).pixelsDiffering});
    }
    t.timeAndError("ms/frame", "min ms", "max ms", "pixels differing");
    return t;
}

}  // namespace boxes
