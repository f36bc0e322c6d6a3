#include "02_box/measure.hpp"

#include <algorithm>
#include <iostream>
#include <random>
#include <stdexcept>

#include "core/render.hpp"
#include "core/timing.hpp"

namespace boxes {

BoxRaySet makeBoxRays(size_t boxCount, size_t raysPerBox, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    auto sym = [&] { return 2.0f * u01(rng) - 1.0f; };
    auto unit = [&] {
        for (;;) {
            Vec3 v(sym(), sym(), sym());
            float l = glm::length(v);
            if (l > 0.1f && l <= 1.0f) return v / l;
        }
    };
    BoxRaySet set;
    for (size_t b = 0; b < boxCount; ++b) {
        Vec3 centre(10.0f * sym(), 10.0f * sym(), 10.0f * sym());
        Vec3 half(0.1f + 1.9f * u01(rng), 0.1f + 1.9f * u01(rng), 0.1f + 1.9f * u01(rng));
        OrientedBox box = b % 4 == 0
                              ? OrientedBox::axisAligned(Bounds3f(centre - half, centre + half))
                              : OrientedBox::rotated(centre, half, unit(), 6.2831853f * u01(rng));
        set.boxes.push_back(box);
        auto local = [&](Vec3 p) {
            return box.centre + p.x * box.axes[0] + p.y * box.axes[1] + p.z * box.axes[2];
        };
        for (size_t i = 0; i < raysPerBox; ++i) {
            int kind = int(i % 10);
            Vec3 p(sym() * half.x, sym() * half.y, sym() * half.z);
            if (kind < 6) {  // a point on a face
                int k = int(rng() % 3);
                p[k] = (rng() & 1 ? 1.0f : -1.0f) * half[k];
            } else if (kind < 8) {  // a point on an edge
                int k = int(rng() % 3), m = (k + 1) % 3;
                p[k] = (rng() & 1 ? 1.0f : -1.0f) * half[k];
                p[m] = (rng() & 1 ? 1.0f : -1.0f) * half[m];
            } else if (kind == 8) {  // near the box: hits and misses
                p *= 1.5f;
            }
            Vec3 target = local(p);
            Vec3 origin;
            if (kind == 9) {  // from inside the box
                origin = local(0.9f * Vec3(sym() * half.x, sym() * half.y, sym() * half.z));
                target = origin + unit();
            } else {
                origin = target + (2.0f + 6.0f * u01(rng)) * maxComponent(half) * unit();
            }
            set.rays.push_back({Ray(origin, target - origin), uint32_t(b)});
        }
    }
    return set;
}

namespace {

template <typename T>
OrientedBoxT<T> castBox(const OrientedBox& b) {
    return {Vec3T<T>(b.centre),
            {Vec3T<T>(b.axes[0]), Vec3T<T>(b.axes[1]), Vec3T<T>(b.axes[2])},
            Vec3T<T>(b.halfExtents)};
}

using Real = long double;  // the reference: the slab method in x87 extended precision

}  // namespace

namespace {

// One method in one precision: its rays, boxes and planes, and a timed pass over them.
template <typename T>
struct BoxVariant {
    BoxMethod method;
    std::vector<RayT<T>> rays;
    std::vector<OrientedBoxT<T>> boxes;
    std::vector<std::array<PlaneT<T>, 6>> planes;
    const BoxRaySet* set;

    BoxVariant(BoxMethod m, const BoxRaySet& s) : method(m), set(&s) {
        for (const BoxRay& r : s.rays) rays.push_back(r.ray.as<T>());
        for (const OrientedBox& b : s.boxes) {
            boxes.push_back(castBox<T>(b));
            planes.push_back(boxFacePlanes(boxes.back()));
        }
    }
    std::optional<BoxHit<T>> test(size_t i) const {
        uint32_t b = set->rays[i].box;
        return method == BoxMethod::SixPlanes ? intersectSixPlanes(rays[i], planes[b])
                                              : intersectBoxSlabs(rays[i], boxes[b]);
    }
    double pass(long long& hits) const {
        Stopwatch watch;
        long long h = 0;
        for (size_t i = 0; i < rays.size(); ++i) h += test(i).has_value();
        keepValue(h);
        hits = h;
        return watch.seconds();
    }
};

}  // namespace

std::vector<Table> measureBoxMethods(const BoxRaySet& set, int repeats) {
    Table speed(
        "box_speed", "Time per ray/box test: the six-plane method against the slab method",
        {"method", "precision", "ns/test", "min ns", "max ns", "hits", "wrong hit/miss"},
        "median of repeats over " + std::to_string(set.rays.size()) +
            " rays at random oriented boxes (faces, edges, near misses, from inside); the "
            "variants take turns in every repeat; one thread; six planes use precomputed "
            "planes (exercise 2.1); wrong hit/miss: against the slab method in long double");
    speed.timeAndError("ns/test", "min ns", "max ns", "wrong hit/miss");
    Table accuracy(
        "box_accuracy",
        "Accuracy against time: wrong answers of each method against a long double reference",
        {"variant", "ns/test", "min ns", "max ns", "wrong hit/miss", "wrong face",
         "max rel t error"},
        "reference: the slab method in long double (64-bit mantissa) on the same "
        "float rays and boxes; a face counts as wrong only when the reference puts "
        "that face's plane at another t (on an edge both faces are right); time as in box_speed");
    accuracy.timeAndError("ns/test", "min ns", "max ns", "wrong hit/miss");

    std::vector<std::optional<BoxHit<Real>>> reference;
    std::vector<std::array<PlaneT<Real>, 6>> refPlanes;
    for (const OrientedBox& b : set.boxes) refPlanes.push_back(boxFacePlanes(castBox<Real>(b)));
    for (const BoxRay& r : set.rays)
        reference.push_back(intersectBoxSlabs(r.ray.as<Real>(), castBox<Real>(set.boxes[r.box])));

    BoxVariant<float> planesF(BoxMethod::SixPlanes, set), slabsF(BoxMethod::Slabs, set);
    BoxVariant<double> planesD(BoxMethod::SixPlanes, set), slabsD(BoxMethod::Slabs, set);
    std::vector<double> samples[4];
    long long hits[4] = {0, 0, 0, 0};
    for (int r = 0; r < repeats; ++r) {
        samples[0].push_back(planesF.pass(hits[0]));
        samples[1].push_back(planesD.pass(hits[1]));
        samples[2].push_back(slabsF.pass(hits[2]));
        samples[3].push_back(slabsD.pass(hits[3]));
    }
    auto grade = [&](const auto& variant, int index) {
        long long wrongHit = 0, wrongFace = 0;
        double maxT = 0.0;
        for (size_t i = 0; i < variant.rays.size(); ++i) {
            const auto& ref = reference[i];
            const auto got = variant.test(i);
            if (ref.has_value() != got.has_value()) {
                ++wrongHit;
                continue;
            }
            if (!ref) continue;
            Real tRef = ref->t;
            if (got->face != ref->face) {
                RayT<Real> ray = set.rays[i].ray.as<Real>();
                const PlaneT<Real>& p = refPlanes[set.rays[i].box][size_t(got->face)];
                Real denom = glm::dot(ray.direction, p.normal);
                Real tFace =
                    denom == 0 ? kInfinity<Real> : -(glm::dot(ray.origin, p.normal) + p.d) / denom;
                if (!(std::abs(tFace - tRef) <= Real(1e-6) * std::max(Real(1), std::abs(tRef))))
                    ++wrongFace;
            }
            maxT = std::max(maxT, double(std::abs(Real(got->t) - tRef) /
                                         std::max(std::abs(tRef), Real(1e-30))));
        }
        Timing timing = summarize(samples[index]);
        double scale = 1e9 / double(variant.rays.size());
        std::string name = boxMethodName(variant.method);
        std::string prec = index % 2 ? "double" : "float";
        speed.row({name, prec, timing.median * scale, timing.min * scale, timing.max * scale,
                   hits[index], wrongHit});
        accuracy.row({name + " " + prec, timing.median * scale, timing.min * scale,
                      timing.max * scale, wrongHit, wrongFace, maxT});
    };
    grade(planesF, 0);
    grade(planesD, 1);
    grade(slabsF, 2);
    grade(slabsD, 3);
    return {speed, accuracy};
}

Disagreement compareMethods(const BoxRaySet& set) {
    Disagreement d;
    std::vector<std::array<Plane, 6>> planes;
    for (const OrientedBox& b : set.boxes) planes.push_back(boxFacePlanes(b));
    for (const BoxRay& r : set.rays) {
        auto a = intersectSixPlanes(r.ray, planes[r.box]);
        auto b = intersectBoxSlabs(r.ray, set.boxes[r.box]);
        ++d.rays;
        if (a.has_value() != b.has_value()) {
            ++d.hitMiss;
            continue;
        }
        if (!a) continue;
        if (a->face != b->face && std::abs(a->t - b->t) > 1e-5f * std::max(1.0f, std::abs(a->t)))
            ++d.face;
        d.maxRelativeT = std::max(d.maxRelativeT, double(std::abs(a->t - b->t)) /
                                                      std::max(double(std::abs(b->t)), 1e-30));
    }
    return d;
}

PixelComparison markDisagreements(const BoxSet& set, const Camera& camera, Image& image,
                                  int threads) {
    std::vector<uint8_t> differ(size_t(image.width()) * size_t(image.height()), 0);
    std::vector<double> maxT(size_t(image.height()), 0.0);
    CameraBasisT<float> basis = camera.basis();
    parallelRows(image.height(), threads, [&](int y, int) {
        for (int x = 0; x < image.width(); ++x) {
            Ray ray(camera.eye, camera.directionThrough(basis, x + 0.5f, y + 0.5f, image.width(),
                                                        image.height()));
            BoxSet::Nearest a = set.nearest(ray, BoxMethod::SixPlanes);
            BoxSet::Nearest b = set.nearest(ray, BoxMethod::Slabs);
            bool tie = a.box >= 0 && b.box >= 0 &&
                       std::abs(a.hit.t - b.hit.t) <= 1e-5f * std::max(1.0f, std::abs(b.hit.t));
            if (a.box != b.box || (a.box >= 0 && a.hit.face != b.hit.face && !tie)) {
                differ[size_t(y) * size_t(image.width()) + size_t(x)] = 1;
            } else if (a.box >= 0) {
                double rel = std::abs(double(a.hit.t) - double(b.hit.t)) /
                             std::max(1e-30, double(std::abs(b.hit.t)));
                maxT[size_t(y)] = std::max(maxT[size_t(y)], rel);
            }
        }
    });
    PixelComparison c;
    c.pixels = (long long)image.width() * image.height();
    for (double t : maxT) c.maxRelativeT = std::max(c.maxRelativeT, t);
    // Ringed: a single magenta pixel is lost on a projector.
    c.differ = (long long)markPixels(image, differ, Vec3(1.0f, 0.0f, 1.0f));
    return c;
}

void measureBoxTests(const StepRun& run, BoxSet& set, size_t raysPerBox, Report& report) {
    BoxMethod method = set.method();
    set.setMethod(BoxMethod::SixPlanes);  // both methods' data ready
    set.setMethod(method);
    Image marked = run.image;
    PixelComparison pixels = markDisagreements(set, run.scene.camera, marked, run.options.threads);
    std::string disagreePath = pngWithSuffix(run.png, "-disagree");
    marked.writePng(disagreePath);
    report.images.push_back(
        {disagreePath,
         pixels.differ == 0
             ? std::string("no pixel where six planes and slabs see another box or face")
             : "ringed in magenta: the " + std::to_string(pixels.differ) + " of " +
                   std::to_string(pixels.pixels) +
                   " pixels where six planes and slabs see another box or face"});
    std::cerr << "02_box: measuring both methods...\n";
    BoxRaySet rays = makeBoxRays(64, raysPerBox, run.options.seed);
    for (Table& t : measureBoxMethods(rays, 11)) {
        if (t.id == "box_speed") {
            // Rows: six planes float, double; slabs float, double (the decks quote the ratio).
            double planes = std::get<double>(t.rows.at(0)[2]),
                   slabs = std::get<double>(t.rows.at(2)[2]);
            report.facts["slab_speedup_float"] = planes / std::max(1e-30, slabs);
        }
        report.add(std::move(t));
    }
    Disagreement d = compareMethods(rays);
    Table dis("method_disagreement", "Where six planes and slabs disagree (both in float)",
              {"rays", "count", "hit/miss differ", "face differs", "max rel t difference"});
    dis.note =
        "a face counts only when the t differ too (on an edge both faces are right); "
        "t compared where both hit";
    dis.row(
        {std::string("random rays at oriented boxes"), d.rays, d.hitMiss, d.face, d.maxRelativeT});
    dis.row({std::string("primary rays of the image"), pixels.pixels, pixels.differ, 0LL,
             pixels.maxRelativeT});
    report.add(dis);
    report.facts["pixels_disagreeing"] = pixels.differ;
    report.facts["random_rays"] = d.rays;
    report.facts["random_rays_hit_miss_differ"] = d.hitMiss;
    report.facts["random_rays_face_differs"] = d.face;
    report.plots.push_back(
        {{"table", "box_accuracy"},
         {"x", "ns/test"},
         {"y", "wrong hit/miss"},
         {"series", "variant"},
         {"logy", true},
         {"pareto", true},
         {"title",
          "Six planes against slabs: wrong hit/miss answers against time per test, with the "
          "Pareto front"}});
    report.plots.push_back(
        {{"table", "box_accuracy"},
         {"x", "ns/test"},
         {"y", "max rel t error"},
         {"series", "variant"},
         {"logy", true},
         {"title", "Six planes against slabs: time per test and the error of t"}});
}

}  // namespace boxes
