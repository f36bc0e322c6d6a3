// Expensive operations: a small ray tracer with and without its square roots and divisions.
#include <algorithm>
#include <cmath>
#include <random>

#include "05_efficiency/experiments/lab_helpers.hpp"
#include "05_efficiency/measure.hpp"
#include "core/timing.hpp"

namespace boxes {

using namespace lab;

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
    Table t("expensive_ops",
            "Expensive operations: square roots and divisions per ray, and time per frame",
            {"variant", "sqrt/ray", "div/ray", "ms/frame", "min ms", "max ms", "max difference",
             "pixels > 0.1%"});
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
    t.timeAndError("ms/frame", "min ms", "max ms", "max difference");
    return t;
}

}  // namespace boxes
