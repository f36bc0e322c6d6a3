#include "exam/generate.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace boxes::exam::gen {

std::string num(double v) {
    if (std::abs(v) < 1e-12) v = 0.0;  // no "-0", no rounding noise like 1.1e-16
    std::ostringstream s;
    s.precision(6);
    s << v;
    return s.str();
}

std::string plus(double v) {
    return v < 0.0 && num(v) != "0" ? " - " + num(-v) : " + " + num(v);
}

std::string vec(const Vec3d& v) {
    return "(" + num(v.x) + ", " + num(v.y) + ", " + num(v.z) + ")";
}

std::vector<double> values(const Vec3d& v) {
    return {v.x, v.y, v.z};
}

std::string box(const Bounds3d& b) {
    return "[" + vec(b.min) + ", " + vec(b.max) + "]";
}

Part numbersPart(const std::string& prompt, std::vector<double> expected, size_t count,
                 bool noneAllowed) {
    Part p;
    p.prompt = prompt;
    p.expected = std::move(expected);
    p.count = count;
    p.noneAllowed = noneAllowed;
    p.shown = p.expected.empty() ? "none"
              : count == 1       ? num(p.expected[0])
                                 : formatNumbers(p.expected);
    return p;
}

Part yesNoPart(const std::string& prompt, bool yes) {
    Part p;
    p.prompt = prompt + " (yes or no)";
    p.type = AnswerType::YesNo;
    p.yes = yes;
    p.shown = yes ? "yes" : "no";
    return p;
}

Part wordsPart(const std::string& prompt, std::vector<std::vector<std::string>> keywords,
               const std::string& shown) {
    Part p;
    p.prompt = prompt;
    p.type = AnswerType::Words;
    p.keywords = std::move(keywords);
    p.shown = shown;
    return p;
}

Bounds3d randomBox(Rng& rng, int lo, int hi) {
    Bounds3d b;
    for (int axis = 0; axis < 3; ++axis) {
        int a = rng.pick(lo, hi - 1);
        b.min[axis] = a;
        b.max[axis] = rng.pick(a + 1, std::min(hi, a + 4));
    }
    return b;
}

Vec3d niceNormal(Rng& rng) {
    static const std::vector<Vec3d> normals = {{0, 1, 0}, {1, 0, 0}, {0, 0, 1}, {1, 2, 2},
                                               {2, 3, 6}, {0, 3, 4}, {3, 4, 0}, {1, 1, 0}};
    Vec3d n = glm::normalize(rng.oneOf(normals));
    if (rng.chance(50)) n = -n;
    return n;
}

}  // namespace boxes::exam::gen
