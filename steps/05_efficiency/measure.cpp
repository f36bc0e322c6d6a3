#include "05_efficiency/measure.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <memory>
#include <random>

#include "05_efficiency/bvh_mesh.hpp"
#include "05_efficiency/lab.hpp"
#include "05_efficiency/progressive.hpp"
#include "core/parallel.hpp"
#include "core/timing.hpp"

namespace boxes {

namespace {

// Image sizes and sample counts, reduced for a quick run.
int sized(const LabOptions& o, int full) {
    return o.quick ? std::max(4, full / 4) : full;
}
int samples(const LabOptions& o, int full) {
    return o.quick ? std::max(100, full / 50) : full;
}
double batchSeconds(const LabOptions& o) {
    return o.quick ? 0.001 : 0.01;
}

double ns(double seconds) {
    return seconds * 1e9;
}
double ms(double seconds) {
    return seconds * 1e3;
}

// Largest difference of two images in 8-bit sRGB steps (what a PNG shows).
long long maxStep8(const Image& a, const Image& b) {
    auto x = a.toRgb8(), y = b.toRgb8();
    int worst = 0;
    for (size_t i = 0; i < x.size(); ++i) worst = std::max(worst, std::abs(int(x[i]) - int(y[i])));
    return worst;
}
bool identical(const Image& a, const Image& b) {
    return a.width() == b.width() && a.height() == b.height() &&
           std::memcmp(a.pixels().data(), b.pixels().data(), a.pixels().size() * sizeof(Vec3)) == 0;
}

RenderSettings oneThread(int w, int h) {
    RenderSettings s;
    s.width = w;
    s.height = h;
    s.threads = 1;
    return s;
}

// Moller-Trumbore in any precision (the lab's reference for float against double).
template <typename T>
std::optional<T> mtT(const RayT<T>& ray, const Vec3T<T>& a, const Vec3T<T>& b, const Vec3T<T>& c) {
    Vec3T<T> e1 = b - a, e2 = c - a;
    Vec3T<T> p = glm::cross(ray.direction, e2);
    T det = glm::dot(e1, p);
    if (det == T(0)) return std::nullopt;
    T inv = T(1) / det;
    Vec3T<T> s = ray.origin - a;
    T u = glm::dot(s, p) * inv;
    if (u < T(0) || u > T(1)) return std::nullopt;
    Vec3T<T> q = glm::cross(s, e1);
    T v = glm::dot(ray.direction, q) * inv;
    if (v < T(0) || u + v > T(1)) return std::nullopt;
    T t = glm::dot(e2, q) * inv;
    if (t < ray.tmin || t > ray.tmax) return std::nullopt;
    return t;
}

}  // namespace

std::vector<std::vector<double>> sampleInterleaved(int repeats,
                                                   const std::vector<std::function<void()>>& fns) {
    std::vector<std::vector<double>> samples(fns.size());
    for (int r = 0; r < repeats; ++r)
        for (size_t i = 0; i < fns.size(); ++i) {
            Stopwatch watch;
            fns[i]();
            samples[i].push_back(watch.seconds());
        }
    return samples;
}

std::vector<Timing> measureInterleaved(int repeats, const std::vector<std::function<void()>>& fns) {
    std::vector<Timing> out;
    for (auto& s : sampleInterleaved(repeats, fns)) out.push_back(summarize(s));
    return out;
}

Table measureMeasuring(const LabOptions& o) {
    Table t;
    t.id = "measuring";
    t.title =
        "Measuring itself: one call per stopwatch sample against batches of calls (median of "
        "repeats)";
    t.columns = {"operation", "method", "samples", "median ns", "min ns", "max ns", "max/min"};
    t.note =
        "ray/sphere test (core intersectSphere, float) on one thread; 'one call': a steady_clock "
        "stopwatch around each single call, 2001 samples; 'batch': calls repeated until a batch "
        "takes >= 20 ms, " +
        std::to_string(std::max(o.repeats, 5)) + " batches, time per call";
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

Table measureFloatDouble(const LabOptions& o) {
    Table t;
    t.id = "float_double";
    t.title =
        "Float or double: time per test and float's error against double, near and far from the "
        "origin";
    t.columns = {"variant",         "offset",     "ns/test",
                 "min ns",          "max ns",     "median rel t error",
                 "max rel t error", "flipped /1M"};
    t.note =
        "4096 rays per shape, half aimed at the shape, half just past it; scene and rays built in "
        "double and moved by offset*(1,-0.7,0.3); float holds them rounded to float; the reference "
        "is the same test in double on the double scene; flipped: hit in one precision, miss in "
        "the other; ray/sphere: core "
        "intersectSphere; ray/triangle: Moller-Trumbore; one thread, median of repeats";
    const size_t n = size_t(samples(o, 4096));
    for (double offset : {0.0, 1e3, 1e4, 1e5}) {
        // The scene is built in double; the float renderer holds it rounded to float.
        Vec3d shift(offset, -0.7 * offset, 0.3 * offset);
        std::mt19937_64 rng(o.seed);
        std::uniform_real_distribution<double> u(-1.0, 1.0);
        std::vector<Rayd> exact;
        std::vector<Ray> rays;
        for (size_t i = 0; i < n; ++i) {
            double reach = i % 2 ? 1.4 : 0.6;
            Vec3d target(u(rng) * reach, u(rng) * reach, 0.1 * u(rng));
            Vec3d origin = Vec3d(u(rng), u(rng), 6.0) + shift;
            exact.emplace_back(origin, target + shift - origin);
            rays.emplace_back(Vec3(exact.back().origin), Vec3(exact.back().direction));
        }
        SphereT<double> sd{shift, 1.0};
        SphereT<float> sf{Vec3(shift), 1.0f};
        Vec3d ad = Vec3d(-1, -1, -0.3) + shift, bd = Vec3d(1, -1, 0.2) + shift,
              cd = Vec3d(0, 1.2, 0.1) + shift;
        Vec3 a(ad), b(bd), c(cd);
        for (int shape = 0; shape < 2; ++shape) {
            std::vector<double> relErr;
            long long flipped = 0;
            for (size_t i = 0; i < n; ++i) {
                const Ray& r = rays[i];
                const Rayd& rd = exact[i];
                std::optional<double> tf, td;
                if (shape == 0) {
                    if (auto h = intersectSphere(r, sf)) tf = *h;
                    td = intersectSphere(rd, sd);
                } else {
                    if (auto h = mtT<float>(r, a, b, c)) tf = *h;
                    td = mtT<double>(rd, ad, bd, cd);
                }
                if (tf.has_value() != td.has_value())
                    ++flipped;
                else if (tf)
                    relErr.push_back(std::abs(*tf - *td) / std::abs(*td));
            }
            std::sort(relErr.begin(), relErr.end());
            double medErr = relErr.empty() ? 0.0 : relErr[relErr.size() / 2];
            double maxErr = relErr.empty() ? 0.0 : relErr.back();
            const std::vector<Rayd>& raysD = exact;
            auto timeIt = [&](auto precision) {
                using T = decltype(precision);
                const auto& rs = [&]() -> const auto& {
                    if constexpr (sizeof(T) == 4)
                        return rays;
                    else
                        return raysD;
                }
                ();
                SphereT<T> s{Vec3T<T>(sd.centre), T(1)};
                Vec3T<T> A(ad), B(bd), C(cd);
                return measureBatched(
                    o.repeats,
                    [&] {
                        int hits = 0;
                        for (size_t i = 0; i < n; ++i)
                            hits += shape == 0 ? intersectSphere(rs[i], s).has_value()
                                               : mtT<T>(rs[i], A, B, C).has_value();
                        keepValue(hits);
                    },
                    0.01);
            };
            const char* shapeName = shape == 0 ? "ray/sphere" : "ray/triangle";
            Timing tF = timeIt(0.0f), tD = timeIt(0.0);
            double per = 1e9 / double(n);
            t.row({std::string(shapeName) + " float", offset, tF.median * per, tF.min * per,
                   tF.max * per, medErr, maxErr, double(flipped) * 1e6 / double(n)});
            t.row({std::string(shapeName) + " double", offset, tD.median * per, tD.min * per,
                   tD.max * per, 0.0, 0.0, 0.0});
        }
    }
    return t;
}

Table measureAcne(const LabOptions& o) {
    Table t;
    t.id = "acne";
    t.title = "Self-intersection acne: lit pixels whose shadow ray hits the surface it starts on";
    t.columns = {"offset", "lit pixels", "acne, origin on the hit point", "acne, robust offset"};
    t.note =
        "the 'diffuse' spheres scene moved by offset*(1,-0.7,0.3) (float), 160x120 primary hits "
        "facing a light; a convex surface cannot shadow itself, so any hit of the shadow ray on "
        "its own object in (0, distance to light) is acne; robust offset: core offsetOrigin "
        "(1e-4 * (1 + max |p|) along the normal)";
    for (double offset : {0.0, 1e3, 1e4, 1e5}) {
        Scene scene = makeScene("diffuse", {});
        Vec3 shift(float(offset), float(-0.7 * offset), float(0.3 * offset));
        for (auto& s : scene.spheres) s.shape.centre += shift;
        for (auto& p : scene.planes) p.shape.d = -glm::dot(p.shape.normal, shift) + p.shape.d;
        for (auto& l : scene.lights) l.position += shift;
        scene.camera.eye += shift;
        const int w = sized(o, 160), h = sized(o, 120);
        CameraBasisT<float> basis = scene.camera.basis();
        long long lit = 0, acneRaw = 0, acneOffset = 0;
        auto selfHit = [&](const Ray& r, const SurfaceHit& hit) {
            if (hit.kind == SurfaceHit::Kind::Sphere)
                return intersectSphere(r, scene.spheres[hit.primitive].shape).has_value();
            return intersectPlane(r, scene.planes[hit.primitive].shape).has_value();
        };
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                Ray ray(scene.camera.eye,
                        scene.camera.directionThrough(basis, x + 0.5f, y + 0.5f, w, h));
                SurfaceHit hit;
                if (!scene.intersect(ray, hit)) continue;
                const Vec3 toLight = scene.lights[0].position - hit.point;
                Vec3 n = glm::dot(hit.geometricNormal, ray.direction) < 0 ? hit.geometricNormal
                                                                          : -hit.geometricNormal;
                if (glm::dot(n, toLight) <= 0.0f) continue;
                ++lit;
                acneRaw += selfHit(Ray(hit.point, toLight, 0.0f, 1.0f), hit);
                Ray off(offsetOrigin(hit.point, hit.geometricNormal, toLight), toLight, 0.0f, 1.0f);
                acneOffset += selfHit(off, hit);
            }
        t.row({offset, lit, acneRaw, acneOffset});
    }
    return t;
}

Table measureSinCos(const LabOptions& o) {
    Table t;
    t.id = "sincos";
    t.title = "Sine from a table: time per call against the largest error over the full circle";
    t.columns = {"variant", "ns/call", "min ns", "max ns", "max abs error", "stated bound"};
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
    return t;
}

Table measureEarlyOut(LabBvhMesh& mesh, const LabOptions& o) {
    Table t;
    t.id = "early_out";
    t.title = "Early out: box and triangle tests per ray and time, with and without";
    t.columns = {"rays",   "method", "count",  "box tests/ray", "triangle tests/ray",
                 "us/ray", "min us", "max us", "speed-up"};
    t.note =
        "the mesh in step 04's hierarchy (full-sweep SAH, leaves of at most 8 triangles), the "
        "lab's own traversal; primary rays of an 80x60 view, shadow rays from their hits to the "
        "light; one thread, median of repeats interleaved round-robin; speed-up: the first row of "
        "each pair over the second";
    const Bounds3f b(mesh.boundsMin(), mesh.boundsMax());
    Camera cam = fitCamera(b.min, b.max, 4.0f / 3.0f);
    CameraBasisT<float> basis = cam.basis();
    Vec3 light = b.centroid() + glm::length(b.diagonal()) * Vec3(0.6f, 1.2f, 0.9f);
    std::vector<Ray> primary, shadow;
    const int w = sized(o, 80), h = sized(o, 60);
    mesh.setOptions({});
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            Ray r(cam.eye, cam.directionThrough(basis, x + 0.5f, y + 0.5f, w, h));
            primary.push_back(r);
            SurfaceHit hit;
            if (mesh.intersect(r, hit)) {
                Vec3 d = light - hit.point;
                shadow.emplace_back(offsetOrigin(hit.point, hit.geometricNormal, d), d, 0.0f, 1.0f);
            }
        }
    LabMeshOptions on, anyOff, skipOff;
    anyOff.anyHitShadows = false;
    skipOff.skipBeyondNearest = false;
    struct Variant {
        const char* kind;
        const char* method;
        const std::vector<Ray>* rays;
        LabMeshOptions opt;
        bool shadows;
    };
    const Variant variants[] = {
        {"shadow", "any hit (stop at the first occluder)", &shadow, on, true},
        {"shadow", "nearest hit, then 'is there one'", &shadow, anyOff, true},
        {"primary", "nearer child first, skip nodes beyond the nearest t", &primary, on, false},
        {"primary", "every node the ray meets, storage order", &primary, skipOff, false}};
    std::vector<std::function<void()>> passes;
    std::vector<double> boxes, tris;
    for (const Variant& v : variants) {
        auto pass = [&mesh, &v] {
            mesh.setOptions(v.opt);
            int n = 0;
            SurfaceHit hit;
            for (const Ray& r : *v.rays) n += v.shadows ? mesh.occluded(r) : mesh.intersect(r, hit);
            keepValue(n);
        };
        mesh.resetCounters();
        pass();
        const double count = double(std::max<size_t>(1, v.rays->size()));
        boxes.push_back(double(mesh.boxTests()) / count);
        tris.push_back(double(mesh.triangleTests()) / count);
        passes.push_back(pass);
    }
    std::vector<Timing> times = measureInterleaved(o.repeats, passes);
    mesh.setOptions({});
    for (size_t i = 0; i < std::size(variants); ++i) {
        const Variant& v = variants[i];
        double per = 1e6 / double(std::max<size_t>(1, v.rays->size()));
        size_t first = i - i % 2;
        t.row({std::string(v.kind), std::string(v.method), (long long)v.rays->size(), boxes[i],
               tris[i], times[i].median * per, times[i].min * per, times[i].max * per,
               times[first + 1].median / times[i].median});
    }
    return t;
}

Table measureLightRadius(const LabOptions& o) {
    Table t;
    t.id = "light_radius";
    t.title = "Lights with a finite radius: time saved and the largest pixel difference";
    t.columns = {"scene",
                 "radius rule",
                 "largest radius",
                 "ms/frame",
                 "min ms",
                 "max ms",
                 "speed-up",
                 "light evaluations skipped/pixel",
                 "shadow rays/pixel",
                 "max diff (8-bit sRGB)",
                 "max diff (linear, 1/255 units)"};
    t.note =
        "160x120, one thread, median of repeats interleaved round-robin; radius = sqrt(I_max / "
        "threshold) (exercise 5.5); differences against the same scene with infinite radii, in "
        "steps of the 8-bit sRGB image (the PNG) and in linear light; 'linear half step': the "
        "threshold 0.5/255 in linear light, 12.92x too coarse near black; 'sRGB half step': "
        "0.5/255/12.92 per light (n lights may add up to n half steps); 'sRGB half step / n' (the "
        "scenes' default, PointLight::cutoffThreshold): guaranteed within one step";
    struct Rule {
        const char* name;
        float threshold;  // 0: infinite radius
    };
    for (const char* name : {"small-lights", "spheres"}) {
        Scene base = makeScene(name, {});
        const size_t n = base.lights.size();
        const Rule rules[] = {{"infinite (reference)", 0.0f},
                              {"linear half step 0.5/255", 0.5f / 255.0f},
                              {"sRGB half step per light", PointLight::kHalfStep8},
                              {"sRGB half step / n (default)", PointLight::cutoffThreshold(n)}};
        std::vector<Scene> scenes;
        for (const Rule& rule : rules) {
            Scene s = base;
            for (auto& l : s.lights)
                l.radius = rule.threshold > 0.0f
                               ? PointLight::radiusFor(l.intensity, rule.threshold)
                               : kInfinity<float>;
            scenes.push_back(std::move(s));
        }
        const int w = sized(o, 160), h = sized(o, 120);
        std::vector<std::unique_ptr<Renderer>> renderers;
        std::vector<std::function<void()>> frames;
        for (const Scene& s : scenes) {
            renderers.push_back(std::make_unique<Renderer>(s, s.camera, oneThread(w, h)));
            frames.push_back([r = renderers.back().get()] { keepValue(r->render()); });
        }
        std::vector<Timing> times = measureInterleaved(o.repeats, frames);
        Image ref;
        for (size_t i = 0; i < scenes.size(); ++i) {
            RayCounts c;
            Image img = renderers[i]->render(&c);
            if (i == 0) ref = img;
            float largest = 0.0f;
            for (const auto& l : scenes[i].lights) largest = std::max(largest, l.radius);
            ImageDifference d = compareImages(img, ref);
            const double px = double(w * h);
            t.row({std::string(name), std::string(rules[i].name), double(largest),
                   ms(times[i].median), ms(times[i].min), ms(times[i].max),
                   times[0].median / times[i].median, double(c.lightsOutOfRange) / px,
                   double(c.shadow) / px, maxStep8(img, ref), d.maxError * 255.0});
        }
    }
    return t;
}

Table measureEffects(const LabOptions& o) {
    Table t;
    t.id = "effects";
    t.title = "Effects on demand: rays traced per kind with the scene analysis on and forced off";
    t.columns = {"scene",      "analysis",   "primary",  "shadow",       "shadow skipped",
                 "reflection", "refraction", "ms/frame", "bit-identical"};
    t.note =
        "160x120, max depth 5, one thread, median of repeats; 'forced': "
        "RenderSettings::forceAllEffects "
        "traces every shadow, reflection and refraction ray; bit-identical: the float images equal";
    for (const char* name :
         {"single-sphere", "diffuse", "mirrors", "glass", "spheres", "small-lights"}) {
        Scene scene = makeScene(name, {});
        Image on;
        for (bool force : {false, true}) {
            RenderSettings s = oneThread(sized(o, 160), sized(o, 120));
            s.forceAllEffects = force;
            Renderer r(scene, scene.camera, s);
            RayCounts c;
            Image img = r.render(&c);
            if (!force) on = img;
            Timing tm = measure(o.repeats, [&] { keepValue(r.render()); });
            t.row({std::string(name), std::string(force ? "forced" : "on"), (long long)c.primary,
                   (long long)c.shadow, (long long)c.shadowSkipped, (long long)c.reflection,
                   (long long)c.refraction, ms(tm.median),
                   std::string(identical(img, on) ? "yes" : "NO")});
        }
    }
    return t;
}

Table measurePrecalculation(LabBvhMesh& mesh, const LabOptions& o) {
    Table t;
    t.id = "precalc";
    t.title =
        "Precalculation and early out: time per frame of a mesh, each optimization added in turn";
    t.columns = {"variant",
                 "ms/frame",
                 "min ms",
                 "max ms",
                 "speed-up",
                 "box tests/pixel",
                 "triangle tests/pixel",
                 "pixels differing"};
    t.note =
        "the mesh alone (no floor) in step 04's hierarchy, the lab's traversal with each switch "
        "(Moller-Trumbore and the lab's slab tests, not step 04's robust ones), "
        "96x72, primary and shadow rays, one thread, median of repeats interleaved "
        "(one frame of each variant per round); pixels "
        "differing: "
        "against the first row, any float difference";
    // The scene refers to the caller's mesh (no ownership: it outlives the scene).
    std::shared_ptr<LabBvhMesh> cm(&mesh, [](LabBvhMesh*) {});
    Scene scene;
    scene.name = "mesh";
    scene.geometries.push_back(cm);
    Bounds3f b(cm->boundsMin(), cm->boundsMax());
    float diag = glm::length(b.diagonal());
    scene.lights.push_back(
        {b.centroid() + diag * Vec3(0.6f, 1.2f, 0.9f), Vec3(1.6f * diag * diag)});
    scene.setLightRadii();
    scene.camera = fitCamera(b.min, b.max, 4.0f / 3.0f);
    struct Variant {
        const char* name;
        LabMeshOptions opt;
    };
    std::vector<Variant> variants = {
        {"naive: divisions, edges per test, every node, nearest for shadows",
         {false, false, false, false, false}},
        {"+ reciprocal direction and signs per ray", {true, false, false, false, false}},
        {"+ precomputed triangle edges", {true, true, false, false, false}},
        {"+ early out (skip far nodes, any-hit shadows)", {true, true, true, true, false}}};
    Renderer r(scene, scene.camera, oneThread(sized(o, 96), sized(o, 72)));
    const double px = double(sized(o, 96) * sized(o, 72));
    std::vector<Image> images;
    std::vector<double> boxes, tris;
    for (const Variant& v : variants) {
        cm->setOptions(v.opt);
        cm->resetCounters();
        images.push_back(r.render());
        boxes.push_back(double(cm->boxTests()) / px);
        tris.push_back(double(cm->triangleTests()) / px);
    }
    // Interleaved: one frame of each variant per round, so a change in the machine's load
    // (other processes) affects every variant alike instead of one.
    std::vector<std::function<void()>> frames;
    for (const Variant& v : variants)
        frames.push_back([&, opt = v.opt] {
            cm->setOptions(opt);
            keepValue(r.render());
        });
    std::vector<Timing> times = measureInterleaved(o.repeats, frames);
    cm->setOptions({});
    for (size_t i = 0; i < variants.size(); ++i) {
        size_t differ = compareImages(images[i], images[0]).pixelsDiffering;
        t.row({std::string(variants[i].name), ms(times[i].median), ms(times[i].min),
               ms(times[i].max), times[0].median / times[i].median, boxes[i], tris[i],
               (long long)differ});
    }
    return t;
}

namespace {

struct OpCounts {
    uint64_t sqrt = 0, div = 0;
};

// A field of spheres lit by one light: the kernel of a ray tracer written twice, once the
// way it is first written and once with the expensive operations taken out.
struct SphereField {
    std::vector<Sphere> spheres;
    std::vector<float> invRadius;  // precomputed for the optimized normal
    Vec3 light{0.0f, 8.0f, 6.0f};
    Camera camera;
};

SphereField makeField(uint64_t seed) {
    SphereField f;
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (int i = 0; i < 48; ++i) {
        Sphere s{Vec3(4.0f * u(rng), 3.0f * u(rng), -3.0f * std::abs(u(rng))),
                 0.3f + 0.25f * std::abs(u(rng))};
        f.spheres.push_back(s);
        f.invRadius.push_back(1.0f / s.radius);
    }
    f.camera.eye = Vec3(0, 0, 8);
    f.camera.view = Vec3(0, 0, -1);
    f.camera.fovYDegrees = 50.0f;
    return f;
}

template <bool Count>
struct Ops {
    OpCounts* c;
    float sqrt(float x) const {
        if constexpr (Count) ++c->sqrt;
        return std::sqrt(x);
    }
    float div(float a, float b) const {
        if constexpr (Count) ++c->div;
        return a / b;
    }
};

// The first version: an unnormalized direction, the quadratic with 2a divisions, nearest
// by Euclidean distance, a normal divided by the radius, the light direction normalized
// by three divisions and the falloff by a division.
template <bool Count>
float shadeNaive(const SphereField& f, Vec3 origin, Vec3 dir, Ops<Count> ops) {
    float bestDist = kInfinity<float>;
    int best = -1;
    Vec3 bestPoint(0.0f);
    for (size_t i = 0; i < f.spheres.size(); ++i) {
        const Sphere& s = f.spheres[i];
        Vec3 oc = origin - s.centre;
        float a = glm::dot(dir, dir), b = 2.0f * glm::dot(oc, dir),
              c = glm::dot(oc, oc) - s.radius * s.radius;
        float disc = b * b - 4.0f * a * c;
        float root = ops.sqrt(std::max(disc, 0.0f));  // computed before the test, as first written
        if (disc < 0.0f) continue;
        float t = ops.div(-b - root, 2.0f * a);
        if (t <= 0.0f) t = ops.div(-b + root, 2.0f * a);
        if (t <= 0.0f) continue;
        Vec3 p = origin + t * dir;
        Vec3 d = p - origin;
        float dist = ops.sqrt(glm::dot(d, d));
        if (dist < bestDist) bestDist = dist, best = int(i), bestPoint = p;
    }
    if (best < 0) return 0.0f;
    const Sphere& s = f.spheres[size_t(best)];
    Vec3 n = Vec3(ops.div(bestPoint.x - s.centre.x, s.radius),
                  ops.div(bestPoint.y - s.centre.y, s.radius),
                  ops.div(bestPoint.z - s.centre.z, s.radius));
    Vec3 toLight = f.light - bestPoint;
    float len = ops.sqrt(glm::dot(toLight, toLight));
    Vec3 l(ops.div(toLight.x, len), ops.div(toLight.y, len), ops.div(toLight.z, len));
    float cosine = glm::dot(n, l);
    if (cosine <= 0.0f) return 0.0f;
    return ops.div(60.0f * cosine, len * len);
}

// The same with the direction normalized once (a = 1, so t = -b' -+ sqrt(b'^2 - c) with
// no division), the square root taken only for a hit, t compared instead of distances, a
// precomputed 1 / radius, and one reciprocal of the light distance reused.
template <bool Count>
float shadeOptimized(const SphereField& f, Vec3 origin, Vec3 dir, Ops<Count> ops) {
    float invLen = ops.div(1.0f, ops.sqrt(glm::dot(dir, dir)));
    Vec3 d = dir * invLen;
    float bestT = kInfinity<float>;
    int best = -1;
    for (size_t i = 0; i < f.spheres.size(); ++i) {
        const Sphere& s = f.spheres[i];
        Vec3 oc = origin - s.centre;
        float b = glm::dot(oc, d), c = glm::dot(oc, oc) - s.radius * s.radius;
        float disc = b * b - c;
        if (disc < 0.0f) continue;
        float root = ops.sqrt(disc);
        float t = -b - root;
        if (t <= 0.0f) t = -b + root;
        if (t > 0.0f && t < bestT) bestT = t, best = int(i);
    }
    if (best < 0) return 0.0f;
    const Sphere& s = f.spheres[size_t(best)];
    Vec3 p = origin + bestT * d;
    Vec3 n = (p - s.centre) * f.invRadius[size_t(best)];
    Vec3 toLight = f.light - p;
    float dist2 = glm::dot(toLight, toLight);
    float invDist = ops.div(1.0f, ops.sqrt(dist2));
    float cosine = glm::dot(n, toLight) * invDist;
    if (cosine <= 0.0f) return 0.0f;
    return 60.0f * cosine * invDist * invDist;
}

}  // namespace

Table measureExpensiveOps(const LabOptions& o) {
    Table t;
    t.id = "expensive_ops";
    t.title = "Expensive operations: square roots and divisions per ray, and time per frame";
    t.columns = {"variant", "sqrt/ray", "div/ray",        "ms/frame",
                 "min ms",  "max ms",   "max difference", "pixels > 0.1%"};
    t.note =
        "48 spheres, one light, 160x120 primary rays with diffuse shading, one thread, median of "
        "repeats; counts from the same code with counting compiled in; differences against the "
        "first version relative to its brightest pixel (silhouette pixels where the two "
        "discriminants round apart)";
    SphereField f = makeField(o.seed);
    const int w = sized(o, 160), h = sized(o, 120);
    CameraBasisT<float> basis = f.camera.basis();
    std::vector<Vec3> dirs;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            // The unnormalized direction through the pixel (the naive version keeps it so).
            float hh = f.camera.halfHeight();
            float sx = (2.0f * (x + 0.5f) / w - 1.0f) * f.camera.aspect * hh;
            float sy = (1.0f - 2.0f * (y + 0.5f) / h) * hh;
            dirs.push_back(basis.forward + sx * basis.right + sy * basis.up);
        }
    std::vector<float> naive(dirs.size()), fast(dirs.size());
    OpCounts cn, cf;
    for (size_t i = 0; i < dirs.size(); ++i) {
        naive[i] = shadeNaive<true>(f, f.camera.eye, dirs[i], {&cn});
        fast[i] = shadeOptimized<true>(f, f.camera.eye, dirs[i], {&cf});
    }
    double worst = 0.0, brightest = 0.0;
    long long differing = 0;
    for (size_t i = 0; i < dirs.size(); ++i) brightest = std::max(brightest, double(naive[i]));
    for (size_t i = 0; i < dirs.size(); ++i) {
        double d = std::abs(double(naive[i]) - fast[i]) / brightest;
        worst = std::max(worst, d);
        differing += d > 1e-3;
    }
    Timing tn = measure(o.repeats, [&] {
        float s = 0;
        for (const Vec3& d : dirs) s += shadeNaive<false>(f, f.camera.eye, d, {nullptr});
        keepValue(s);
    });
    Timing tf = measure(o.repeats, [&] {
        float s = 0;
        for (const Vec3& d : dirs) s += shadeOptimized<false>(f, f.camera.eye, d, {nullptr});
        keepValue(s);
    });
    double n = double(dirs.size());
    t.row({std::string("first version"), double(cn.sqrt) / n, double(cn.div) / n, ms(tn.median),
           ms(tn.min), ms(tn.max), 0.0, 0LL});
    t.row({std::string("fewer sqrt and div"), double(cf.sqrt) / n, double(cf.div) / n,
           ms(tf.median), ms(tf.min), ms(tf.max), worst, differing});
    return t;
}

Table measureInverseSqrt(const LabOptions& o) {
    Table t;
    t.id = "rsqrt";
    t.title = "Reciprocal square root: exact against the bit trick, with and without a Newton step";
    t.columns = {"variant", "ns/call", "min ns", "max ns", "max relative error"};
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
    return t;
}

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
    Table t;
    t.id = "threads";
    t.title = "Threads: speed-up over one thread, and how the work is handed out";
    t.columns = {"threads",  "schedule",     "ms/frame",     "min ms",   "max ms",
                 "speed-up", "speed-up min", "speed-up max", "identical"};
    int all = resolveThreads(0);
    const int repeats = std::max(o.repeats, 7);
    t.note = "scene '" + scene.name + "', " + std::to_string(sized(o, 320)) + "x" +
             std::to_string(sized(o, 240)) + ", " + std::to_string(repeats) +
             " rounds; each round renders one frame of every row in turn (round-robin), and the "
             "speed-up is per round (one thread's frame over this row's frame in the same round), "
             "then its median, min and max: a change of the machine's load hits both frames of a "
             "ratio alike; this machine has " +
             std::to_string(all) + " hardware threads" + (all <= 2 ? " (so 'all' is 2)" : "") +
             ", shared with other work";
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
               std::string(identical(variants[i].image, ref) ? "yes" : "NO")});
    }
    return t;
}

Table measureAntiAliasing(const Scene& scene, const LabOptions& o) {
    Table t;
    t.id = "antialiasing";
    t.title = "Anti-aliasing: error against a 256 samples per pixel reference, and time";
    t.columns = {"samples/pixel", "ms/frame", "RMSE", "max error"};
    t.note = "scene '" + scene.name +
             "', 96x72, stratified jittered samples, all threads, one frame each; "
             "RMSE over all channels in linear units against 256 samples per pixel (another seed)";
    RenderSettings s;
    s.width = sized(o, 96);
    s.height = sized(o, 72);
    s.threads = o.threads;
    s.samplesPerPixel = 256;
    s.seed = o.seed + 1000;
    Image ref = renderImage(scene, scene.camera, s);
    for (int spp : {1, 4, 16, 64}) {
        s.samplesPerPixel = spp;
        s.seed = o.seed;
        Stopwatch watch;
        Image img = renderImage(scene, scene.camera, s);
        double sec = watch.seconds();
        ImageDifference d = compareImages(img, ref);
        t.row({(long long)spp, ms(sec), d.rmse, d.maxError});
    }
    return t;
}

Table measurePreviews(const Scene& scene, const LabOptions& o) {
    Table t;
    t.id = "previews";
    t.title = "Preview modes: time per frame while the camera moves, against the full render";
    t.columns = {"mode", "ms/frame", "min ms", "max ms", "rays/frame", "RMSE against full"};
    t.note = "scene '" + scene.name +
             "', 320x240, all threads, median of repeats; adaptive at the scale it "
             "settles on for a 1/30 s target";
    RenderSettings s;
    s.width = sized(o, 320);
    s.height = sized(o, 240);
    s.threads = o.threads;
    Image full = renderImage(scene, scene.camera, s);
    AdaptiveResolution adaptive(1.0 / 30.0);
    for (int i = 0; i < 6; ++i) {
        Stopwatch w;
        renderPreview(scene, scene.camera, PreviewMode::Adaptive, s, adaptive.scale());
        adaptive.update(w.seconds());
    }
    for (PreviewMode m : kAllPreviewModes) {
        RayCounts c;
        Image img = renderPreview(scene, scene.camera, m, s, adaptive.scale(), &c);
        Timing tm = measure(o.repeats, [&] {
            keepValue(renderPreview(scene, scene.camera, m, s, adaptive.scale()));
        });
        std::string name = previewModeName(m);
        if (m == PreviewMode::Adaptive)
            name += " (scale " + std::to_string(adaptive.scale()).substr(0, 4) + ")";
        t.row({name, ms(tm.median), ms(tm.min), ms(tm.max), (long long)c.total(),
               compareImages(img, full).rmse});
    }
    return t;
}

}  // namespace boxes
