// What every question generator shares: seeded numbers that repeat on every platform, how
// numbers and vectors are printed, and the answer parts. Internal to exam/.
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "core/bounds.hpp"
#include "core/math.hpp"
#include "exam/questions.hpp"

namespace boxes::exam::gen {

// Seeded integers that come out the same on every platform (std:: distributions do not).
struct Rng {
    std::mt19937_64 engine;
    explicit Rng(uint64_t seed) : engine(seed * 0x9E3779B97F4A7C15ull + 12345) {}
    int pick(int lo, int hi) { return lo + int(engine() % uint64_t(hi - lo + 1)); }
    bool chance(int percent) { return pick(1, 100) <= percent; }
    Vec3d vec(int lo, int hi) { return Vec3d(pick(lo, hi), pick(lo, hi), pick(lo, hi)); }
    Vec3d nonZero(int lo, int hi) {
        for (;;) {
            Vec3d v = vec(lo, hi);
            if (!isZero(v)) return v;
        }
    }
    template <typename T>
    const T& oneOf(const std::vector<T>& items) {
        return items[size_t(pick(0, int(items.size()) - 1))];
    }
    // Fisher-Yates with the engine above: the same order on every platform.
    template <typename T>
    void shuffle(std::vector<T>& items) {
        for (size_t i = items.size(); i > 1; --i)
            std::swap(items[i - 1], items[size_t(pick(0, int(i) - 1))]);
    }
};

// "2.5", "-0.333333": six significant digits, never "-0".
std::string num(double v);
// " + 3", " - 3": a number after another in a sum.
std::string plus(double v);
// "(1, 2.5, -3)"
std::string vec(const Vec3d& v);
std::vector<double> values(const Vec3d& v);
// "[(0, 0, 0), (1, 1, 1)]"
std::string box(const Bounds3d& b);

Part numbersPart(const std::string& prompt, std::vector<double> expected, size_t count,
                 bool noneAllowed = false);
Part yesNoPart(const std::string& prompt, bool yes);
Part wordsPart(const std::string& prompt, std::vector<std::vector<std::string>> keywords,
               const std::string& shown);

// A box with integer corners in [lo, hi], each side 1 to 4 long.
Bounds3d randomBox(Rng& rng, int lo, int hi);
// A unit normal with a short exact form, (1, 2, 2)/3 and the like, either sign.
Vec3d niceNormal(Rng& rng);

}  // namespace boxes::exam::gen
