#include "03_aabb/slab_reference.hpp"

#include <random>
#include <stdexcept>

namespace boxes {

namespace {

int64_t onGrid(float v, int bits) {
    double scaled = std::ldexp(double(v), bits);
    if (!(std::abs(scaled) < 0x1p40) || scaled != std::trunc(scaled))
        throw std::invalid_argument("exact slab reference: value is not on the dyadic grid");
    return int64_t(scaled);
}

// A fraction num / den with den > 0.
struct Fraction {
    int64_t num, den;
};
bool lessEqual(Fraction a, Fraction b) {
    return __int128(a.num) * b.den <= __int128(b.num) * a.den;
}

}  // namespace

bool exactRayMeetsBox(const Ray& ray, const Bounds3f& box) {
    std::vector<Fraction> lower, upper;
    // t is measured in the same units on every axis, so the grid scale cancels.
    if (ray.tmin > 0.0f || ray.tmin == kInfinity<float>)
        lower.push_back({onGrid(ray.tmin, 10), int64_t(1) << 10});
    if (ray.tmax != kInfinity<float>) upper.push_back({onGrid(ray.tmax, 10), int64_t(1) << 10});
    if (ray.tmax < 0.0f || ray.tmax < ray.tmin) return false;
    for (int k = 0; k < 3; ++k) {
        int64_t lo = onGrid(box.min[k], kGridBits), hi = onGrid(box.max[k], kGridBits);
        int64_t o = onGrid(ray.origin[k], kGridBits), d = onGrid(ray.direction[k], kGridBits);
        if (lo > hi) return false;
        if (d == 0) {
            if (o < lo || o > hi) return false;
            continue;
        }
        if (d > 0) {
            lower.push_back({lo - o, d});
            upper.push_back({hi - o, d});
        } else {
            lower.push_back({o - hi, -d});
            upper.push_back({o - lo, -d});
        }
    }
    // tmin is 0 unless set; an empty lower list means t >= tmin = 0 is all that holds.
    if (ray.tmin <= 0.0f) lower.push_back({0, 1});
    for (const Fraction& a : lower)
        for (const Fraction& b : upper)
            if (!lessEqual(a, b)) return false;
    return true;
}

const std::vector<std::string>& hardSlabCategories() {
    static const std::vector<std::string> names = {
        "grazing an edge",   "grazing a corner",
        "just past an edge", "along a face plane",
        "+-0 components",    "origin on a plane, D_k = +-0",
        "flat box",          "origin inside",
        "box behind",        "ends at or before the box"};
    return names;
}

std::vector<HardSlabRay> makeHardSlabRays(size_t perCategory, uint64_t seed) {
    std::mt19937_64 rng(seed);
    const float step = std::ldexp(1.0f, -kGridBits);
    // A grid value in [-range, range].
    auto grid = [&](float range) {
        int64_t n = int64_t(std::ldexp(double(range), kGridBits));
        return float(int64_t(rng() % uint64_t(2 * n + 1)) - n) * step;
    };
    auto coin = [&] { return (rng() & 1) != 0; };
    std::vector<HardSlabRay> rays;
    const int categories = int(hardSlabCategories().size());
    for (int c = 0; c < categories; ++c) {
        for (size_t i = 0; i < perCategory; ++i) {
            // A box inside [-4, 4]^3 of size at least 1/4 (flat boxes: one axis of size 0).
            Bounds3f box;
            for (int k = 0; k < 3; ++k) {
                float a = grid(3.5f), size = 0.25f + std::abs(grid(0.25f)) * 2.0f;
                box.min[k] = a;
                box.max[k] = a + size;
            }
            if (c == 6) {
                int k = int(rng() % 3);
                box.max[k] = box.min[k];
            }
            auto inside = [&](int k) {  // a grid point within the slab k
                int64_t lo = int64_t(std::ldexp(double(box.min[k]), kGridBits));
                int64_t hi = int64_t(std::ldexp(double(box.max[k]), kGridBits));
                return float(lo + int64_t(rng() % uint64_t(hi - lo + 1))) * step;
            };
            auto plane = [&](int k) { return coin() ? box.min[k] : box.max[k]; };
            Vec3 target(inside(0), inside(1), inside(2));
            Vec3 origin(grid(7.5f), grid(7.5f), grid(7.5f));
            float tmax = kInfinity<float>;
            int k = int(rng() % 3), m = (k + 1) % 3;
            switch (c) {
                case 0:
                    target[k] = plane(k), target[m] = plane(m);
                    break;
                case 1:
                    target = Vec3(plane(0), plane(1), plane(2));
                    break;
                case 2:  // an edge point moved 1 to 3 grid steps outwards
                    target[k] = plane(k), target[m] = plane(m);
                    target[k] +=
                        (target[k] == box.max[k] ? 1.0f : -1.0f) * step * float(1 + rng() % 3);
                    break;
                case 3:
                    origin[k] = target[k] = plane(k);
                    break;  // the ray lies in the face plane
                case 4:
                    origin[k] = target[k] = coin() ? inside(k) : grid(7.5f);
                    break;
                case 5:
                    origin[k] = target[k] = plane(k);
                    break;
                case 6:
                    break;  // target inside the flat box
                case 7:
                    origin = Vec3(inside(0), inside(1), inside(2));
                    target[k] = grid(7.5f);
                    break;
                case 8:
                    break;  // looking away from the box: D reversed below
                case 9:
                    tmax = float(rng() % 1025) / 1024.0f;
                    break;  // t = 1 at the target
            }
            // Exact: both ends on the grid and every difference below 16 in magnitude.
            Vec3 direction = target - origin;
            if (c == 8) direction = -direction;  // looking away: the box lies behind
            if (c <= 1)  // grazing: D off by up to 2 grid steps per axis (t = 1 is no longer exact)
                for (int a = 0; a < 3; ++a) direction[a] += float(int(rng() % 5) - 2) * step;
            if (c == 4 || c == 5) direction[k] = coin() ? 0.0f : -0.0f;
            if (c == 4 && coin()) direction[m] = coin() ? 0.0f : -0.0f;
            if (isZero(direction)) continue;
            Ray ray(origin, direction, 0.0f, tmax);
            rays.push_back({ray, box, c, exactRayMeetsBox(ray, box)});
        }
    }
    return rays;
}

}  // namespace boxes
