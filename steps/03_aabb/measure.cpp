#include "03_aabb/measure.hpp"

#include <algorithm>
#include <cstdio>
#include <iostream>

#include "core/heatmap.hpp"
#include "core/render.hpp"
#include "core/timing.hpp"

namespace boxes {

// One case per value and no default: -Wswitch names a value added without its name.
const char* slabVariantName(SlabVariant v) {
    switch (v) {
        case SlabVariant::Naive:
            return "naive (the slide's)";
        case SlabVariant::NaiveSwapped:
            return "naive, min/max arguments swapped";
        case SlabVariant::StandIn:
            return "1e30 stand-in for 1/0";
        case SlabVariant::Robust:
            return "robust (3.6)";
        case SlabVariant::Conservative:
            return "conservative (3.7)";
    }
    return "?";
}

bool slabHit(SlabVariant v, const Ray& ray, const SlabRay& slabRay, const Bounds3f& box) {
    switch (v) {
        case SlabVariant::Naive:
            return intersectSlabsNaive(ray, box).has_value();
        case SlabVariant::NaiveSwapped:
            return intersectSlabsNaive(ray, box, true).has_value();
        case SlabVariant::StandIn:
            return intersectSlabsStandIn(ray, box).has_value();
        case SlabVariant::Robust:
            return intersectSlabs(slabRay, box).has_value();
        default:
            return intersectSlabsConservative(slabRay, box).has_value();
    }
}

std::vector<Table> measureSlabTests(const std::vector<HardSlabRay>& rays, int repeats) {
    Table accuracy(
        "slab_accuracy", "Accuracy against time: slab tests on hard rays against the exact answer",
        {"variant", "ns/test", "min ns", "max ns", "false misses", "false hits", "wrong /1M"});
    accuracy.note =
        std::to_string(rays.size()) +
        " hard rays (see slab_hard_rays); exact answers in 64-bit integers on a dyadic grid; "
        "a false miss loses geometry behind a box, a false hit only costs time; "
        "the naive tests divide, the others use 1/D precomputed per ray as a BVH does; median "
        "of " +
        std::to_string(repeats) + " repeats with the variants taking turns in each, one thread";
    accuracy.timeAndError("ns/test", "min ns", "max ns", "wrong /1M");
    Table byCategory("slab_hard_rays",
                     "Wrong answers per kind of hard ray (false misses + false hits)",
                     {"rays", "count", "exact hits"});
    for (SlabVariant v : kAllSlabVariants) byCategory.columns.push_back(slabVariantName(v));
    byCategory.note = "each ray is tested against the one box it was made for";

    std::vector<Ray> plain;
    std::vector<SlabRay> prepared;
    std::vector<Bounds3f> boxes;
    for (const HardSlabRay& r : rays) {
        plain.push_back(r.ray);
        prepared.emplace_back(r.ray);
        boxes.push_back(r.box);
    }
    const auto& categories = hardSlabCategories();
    std::vector<std::vector<long long>> wrong(categories.size(), std::vector<long long>(5, 0));
    // Timing: the variants take turns within every repeat, so a busy machine slows them
    // alike; each sample is one pass over all the rays with the variant's own loop.
    std::vector<std::vector<double>> samples(std::size(kAllSlabVariants));
    auto pass = [&](SlabVariant v) {
        auto loop = [&](auto test) {
            Stopwatch watch;
            long long h = 0;
            for (size_t i = 0; i < rays.size(); ++i) h += test(i);
            keepValue(h);
            return watch.seconds();
        };
        switch (v) {
            case SlabVariant::Naive:
                return loop(
                    [&](size_t i) { return intersectSlabsNaive(plain[i], boxes[i]).has_value(); });
            case SlabVariant::NaiveSwapped:
                return loop([&](size_t i) {
                    return intersectSlabsNaive(plain[i], boxes[i], true).has_value();
                });
            case SlabVariant::StandIn:
                return loop([&](size_t i) {
                    return intersectSlabsStandIn(plain[i], boxes[i]).has_value();
                });
            case SlabVariant::Robust:
                return loop(
                    [&](size_t i) { return intersectSlabs(prepared[i], boxes[i]).has_value(); });
            default:
                return loop([&](size_t i) {
                    return intersectSlabsConservative(prepared[i], boxes[i]).has_value();
                });
        }
    };
    for (int r = 0; r < repeats; ++r)
        for (SlabVariant v : kAllSlabVariants) samples[size_t(v)].push_back(pass(v));
    for (SlabVariant v : kAllSlabVariants) {
        Timing timing = summarize(samples[size_t(v)]);
        long long falseMiss = 0, falseHit = 0;
        for (size_t i = 0; i < rays.size(); ++i) {
            bool got = slabHit(v, plain[i], prepared[i], boxes[i]);
            if (got == rays[i].exact) continue;
            (got ? falseHit : falseMiss) += 1;
            ++wrong[size_t(rays[i].category)][size_t(v)];
        }
        double scale = 1e9 / double(rays.size());
        accuracy.row(
            {std::string(slabVariantName(v)), timing.median * scale, timing.min * scale,
             timing.max * scale, falseMiss, falseHit,
             double(falseMiss + falseHit) * 1e6 / double(std::max<size_t>(1, rays.size()))});
    }
    for (size_t c = 0; c < categories.size(); ++c) {
        long long count = 0, exactHits = 0;
        for (const HardSlabRay& r : rays)
            if (size_t(r.category) == c) ++count, exactHits += r.exact;
        std::vector<Cell> row = {categories[c], count, exactHits};
        for (long long w : wrong[c]) row.push_back(w);
        byCategory.row(row);
    }
    return {accuracy, byCategory};
}

PretestResult measurePretest(ManyObjects& objects, const Camera& camera,
                             const RenderSettings& settings) {
    PretestResult result;
    Table& t = result.table;
    t.id = "pretest";
    t.title = "Why we care: the scene rendered with and without a bounding-box pre-test";
    t.columns = {
        "pre-test",      "ms/frame",        "min ms", "max ms", "rays", "primitive tests/ray",
        "box tests/ray", "pixels differing"};
    t.note = std::to_string(settings.width) + "x" + std::to_string(settings.height) +
             " pixels, one frame each (primary and shadow rays); boxes per sphere, per group of 8 "
             "triangles and per mesh, conservative slab test (3.7); images compared exactly, the "
             "frame without the pre-test the reference; ms/frame: the frame rendered once as "
             "three interleaved sets of rows, each timed, three times the median set (min, max: "
             "the fastest and slowest set)";
    t.timeAndError("ms/frame", "min ms", "max ms", "pixels differing");
    for (bool pretest : {false, true}) {
        objects.setPretest(pretest);
        objects.counts->reset();
        RenderSettings s = settings;
        s.progressLabel = pretest ? "03_aabb: with the pre-test" : "03_aabb: without the pre-test";
        // Rows y mod 3 see alike content, so the sets' spread is the machine's, and the slow
        // frame without the pre-test is still rendered only once.
        constexpr int kSets = 3;
        Renderer renderer(objects.scene, camera, s);
        Image image(s.width, s.height);
        std::vector<RayCounts> perThread(size_t(resolveThreads(s.threads)));
        std::vector<double> setMs;
        // Each pixel's tests counted as it is rendered: the heat maps show these very rays.
        PixelCosts& costs = pretest ? result.withCosts : result.withoutCosts;
        for (int set = 0; set < kSets && set < s.height; ++set) {
            std::vector<int> rows;
            for (int y = set; y < s.height; y += kSets) rows.push_back(y);
            Stopwatch watch;
            renderCountingPixels(renderer, image, costs, perThread, rows,
                                 s.progressLabel + ", row set " + std::to_string(set + 1) + " of " +
                                     std::to_string(kSets));
            setMs.push_back(watch.milliseconds() * double(s.height) / double(rows.size()));
        }
        Timing ms = summarize(setMs);
        RayCounts rays;
        for (const RayCounts& c : perThread) rays += c;
        double n = double(std::max<uint64_t>(1, rays.total()));
        (pretest ? result.with : result.without) = std::move(image);
        if (pretest)
            result.pixelsDiffering = compareImages(result.with, result.without).pixelsDiffering;
        t.row({std::string(pretest ? "per sphere, group, mesh" : "none"), ms.median, ms.min, ms.max,
               (long long)rays.total(), double(objects.counts->primitiveTests.load()) / n,
               double(objects.counts->boxTests.load()) / n,
               (long long)(pretest ? result.pixelsDiffering : 0)});
    }
    return result;
}

void addHeatMaps(const StepRun& run, const PretestResult& p, Report& report) {
    // Small frames drawn large: each pixel a block, so a room sees it.
    const int block = std::max(1, 384 / std::max(1, p.withCosts.width));
    auto upscale = [&](const std::vector<double>& v) {
        const int w = p.withCosts.width, h = p.withCosts.height;
        std::vector<double> out(size_t(w * block) * size_t(h * block));
        for (int y = 0; y < h * block; ++y)
            for (int x = 0; x < w * block; ++x)
                out[size_t(y) * size_t(w * block) + size_t(x)] =
                    v[size_t(y / block) * size_t(w) + size_t(x / block)];
        return out;
    };
    // Primitive tests with and without the pre-test on one scale, so they compare.
    double largest = 0.0;
    for (const PixelCosts* c : {&p.withoutCosts, &p.withCosts})
        for (double v : c->primitiveTests) largest = std::max(largest, v);
    const double top = scaleTop(largest);
    struct Map {
        const char *suffix, *fact, *what;
        const PixelCosts* costs;
        bool boxes;
    };
    for (const Map& m : {Map{"-heat-without", "heat_primitive_tests_per_ray_without",
                             "primitive tests per pixel, no pre-test", &p.withoutCosts, false},
                         Map{"-heat-with", "heat_primitive_tests_per_ray_with",
                             "primitive tests per pixel, pre-test on", &p.withCosts, false},
                         Map{"-heat-boxes", "heat_box_tests_per_ray_with",
                             "box tests per pixel, pre-test on", &p.withCosts, true}}) {
        const std::vector<double>& v = m.boxes ? m.costs->boxTests : m.costs->primitiveTests;
        double perRay = m.boxes ? m.costs->boxTestsPerRay() : m.costs->primitiveTestsPerRay();
        double mapTop = m.boxes ? scaleTop(*std::max_element(v.begin(), v.end())) : top;
        char title[160];
        std::snprintf(title, sizeof title, "%s (mean %.1f per ray)", m.what, perRay);
        std::string png = pngWithSuffix(run.png, m.suffix);
        heatMapImage(upscale(v), m.costs->width * block, m.costs->height * block, mapTop, title)
            .writePng(png);
        report.images.push_back({png, std::string(title) + ", log scale 0 to " +
                                          std::to_string(int(mapTop)) +
                                          ": the pretest table's frame, ray for ray"});
        report.facts[m.fact] = perRay;
    }
}

void measureBoundingBoxes(const StepRun& run, ManyObjects& objects, size_t hardRays, int frameWidth,
                          int frameHeight, Report& report) {
    std::cerr << "03_aabb: slab tests on hard rays...\n";
    for (Table& t : measureSlabTests(makeHardSlabRays(hardRays, run.options.seed), 15)) {
        if (t.id == "slab_accuracy") {
            // The decks quote these numbers (slides/build.mjs's fact placeholders).
            const char* names[] = {"naive", "naive_swapped", "stand_in", "robust", "conservative"};
            for (size_t v = 0; v < t.rows.size() && v < std::size(names); ++v)
                report.facts[std::string(names[v]) + "_ns_per_test"] =
                    std::get<double>(t.rows[v][1]);
        }
        report.add(std::move(t));
    }
    RenderSettings small = run.settings;
    small.width = frameWidth;
    small.height = frameHeight;
    Camera camera = run.scene.camera;
    camera.aspect = float(frameWidth) / float(frameHeight);
    PretestResult p = measurePretest(objects, camera, small);
    report.add(p.table);
    addHeatMaps(run, p, report);
    report.facts["pretest_pixels_differing"] = p.pixelsDiffering;
    const auto& off = p.table.rows.at(0);
    const auto& on = p.table.rows.at(1);
    report.facts["pretest_primitive_test_ratio"] =
        std::get<double>(off[5]) / std::max(1e-30, std::get<double>(on[5]));
    report.facts["pretest_frame_time_ratio"] =
        std::get<double>(off[1]) / std::max(1e-30, std::get<double>(on[1]));
    report.plots.push_back({{"table", "slab_accuracy"},
                            {"x", "ns/test"},
                            {"y", "wrong /1M"},
                            {"series", "variant"},
                            {"logy", true},
                            {"pareto", true},
                            {"title",
                             "Slab tests: wrong answers on hard rays against time per test, "
                             "with the Pareto front"}});
    report.plots.push_back(
        {{"table", "pretest"},
         {"x", "ms/frame"},
         {"y", "primitive tests/ray"},
         {"series", "pre-test"},
         {"logx", true},
         {"logy", true},
         {"title", "A box pre-test: time per frame and primitive tests per ray"}});
}

}  // namespace boxes
