// Float or double: time per ray/sphere and ray/triangle test against float's error in t.
#include <algorithm>
#include <cmath>
#include <optional>
#include <random>

#include "05_efficiency/experiments/lab_helpers.hpp"
#include "05_efficiency/measure.hpp"
#include "core/timing.hpp"

namespace boxes {

using namespace lab;

namespace {

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

Table measureFloatDouble(const LabOptions& o) {
    Table t(
        "float_double",
        "Float or double: time per test and float's error against double, near and far from the "
        "origin",
        {"variant", "offset", "ns/test", "min ns", "max ns", "median rel t error",
         "max rel t error", "flipped /1M"},
        "4096 rays per shape, half aimed at the shape, half just past it; scene and rays built in "
        "double and moved by offset*(1,-0.7,0.3); float holds them rounded to float; the reference "
        "is the same test in double on the double scene; flipped: hit in one precision, miss in "
        "the other; ray/sphere: core "
        "intersectSphere; ray/triangle: Moller-Trumbore; one thread, median of repeats");
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
    t.timeAndError("ns/test", "min ns", "max ns", "max rel t error");
    return t;
}

}  // namespace boxes
