// "What does this slide code return?": the lecture's union lines and its slab test (the
// formulas and the pseudo-code), printed as the slides print them, typos included, run by
// hand on seeded boxes and rays. docs/errata.md says what each gets wrong.
#include <algorithm>
#include <cmath>
#include <limits>

#include "exam/kinds.hpp"
#include "exam/reference.hpp"

namespace boxes::exam::gen {

namespace {

// The union slide's six lines as printed (its runs of tabs shown as one space).
const char* kUnionCode =
    "box.bmin.x = min(A.bmin.x, B.bmin.x);\n"
    "box.bmax.x = max(A.bmax.x, B.bmax.x);\n"
    "box.bmin.y = min(A.bmin.y, B.bmin.x);\n"
    "box.bmax.y = max(A.bmax.y, B.bmax.y);\n"
    "box.bmin.z = min(A.bmin.z, B.bmin.z);\n"
    "box.bmax.z = max(A.bmax.z, B.bmax.z);";

// The slab slide's formulas as its text has them (LaTeX).
const char* kSlabFormulas =
    "$t_{min} = +\\infty, t_{max} = -\\infty$\n"
    "$t_{min} = \\max(t_{min}, \\min(t1, t2))$\n"
    "$t_{max} = \\min(t_{max}, \\max(t1, t2))$\n"
    "intersection if: $t_{min} < t_{max}$";

// The pseudo-code slide as printed (its blank lines left out).
const char* kSlabPseudoCode =
    "bool intersection(box b, ray r)\n"
    "float tx1 = (b.min.x - r.0.x) / r.D.x;\n"
    "float tx2 = (b.max.x - r.0.x) / r.D.x;\n"
    "float tmin = min(tx1, tx2);\n"
    "float tmax = max(tx1, tx2);\n"
    "float ty1 = (b.min.y - r.0.y) / r.D.y;\n"
    "float ty2 = (b.max.y - r.0.y) / r.D.y;\n"
    "tmin = max(tmin, min(ty1, ty2)); tmax = min(tmax, max(ty1, ty2));\n"
    "return tmax >= tmin;";

std::string indented(const char* code) {
    std::string s = "    ";
    for (const char* c = code; *c; ++c)
        s += *c == '\n' ? std::string("\n    ") : std::string(1, *c);
    return s;
}

std::string boxText(const char* name, const Bounds3d& b) {
    return std::string(name) + ".bmin = " + vec(b.min) + ", " + name + ".bmax = " + vec(b.max);
}

// The true answer: does the ray (t >= 0) meet the closed box? And where (for the solution).
std::optional<Interval> rayMeetsBox(const Vec3d& o, const Vec3d& d, const Bounds3d& b) {
    return raySlabs(Rayd(o, d), b);
}

}  // namespace

Question slideUnion(Rng& rng, Question q) {
    // In about half the questions the typo changes the answer.
    bool typoShows = rng.chance(60);
    Bounds3d a, b;
    for (int attempt = 0;; ++attempt) {
        a = randomBox(rng, -5, 5);
        b = randomBox(rng, -5, 5);
        double right = std::min(a.min.y, b.min.y), slide = std::min(a.min.y, b.min.x);
        if ((right != slide) == typoShows || attempt > 500) break;
    }
    q.given["amin"] = values(a.min);
    q.given["amax"] = values(a.max);
    q.given["bmin"] = values(b.min);
    q.given["bmax"] = values(b.max);
    q.statement = "The lecture's union of two boxes, as the slide prints it:\n" +
                  indented(kUnionCode) + "\nRun it for " + boxText("A", a) + " and " +
                  boxText("B", b) + ".";
    Vec3d lo(std::min(a.min.x, b.min.x), std::min(a.min.y, b.min.x), std::min(a.min.z, b.min.z));
    Vec3d hi = glm::max(a.max, b.max);
    Vec3d rightLo = glm::min(a.min, b.min);
    q.parts.push_back(numbersPart("box.bmin as the code computes it", values(lo), 3));
    q.parts.push_back(numbersPart("box.bmax as the code computes it", values(hi), 3));
    q.solution = {"line by line: bmin.x = min(" + num(a.min.x) + ", " + num(b.min.x) +
                      ") = " + num(lo.x) + "; bmin.y = min(A.bmin.y, B.bmin.x) = min(" +
                      num(a.min.y) + ", " + num(b.min.x) + ") = " + num(lo.y) +
                      " (the typo: B.bmin.x, not B.bmin.y); bmin.z = " + num(lo.z),
                  "the bmax lines are right: bmax = " + vec(hi)};
    if (lo.y == rightLo.y)
        q.solution.push_back("here the typo changes nothing: min(A.bmin.y, B.bmin.y) = " +
                             num(rightLo.y) + " as well");
    else if (lo.y > rightLo.y)
        q.solution.push_back("the union's bmin.y is " + num(rightLo.y) +
                             ": the code's box loses "
                             "the bottom of B (y from " +
                             num(rightLo.y) + " to " + num(lo.y) +
                             "), and a ray through it misses what B holds");
    else
        q.solution.push_back("the union's bmin.y is " + num(rightLo.y) +
                             ": the code's box is "
                             "too big (still right, only slower)");
    return q;
}

Question slideSlab(Rng& rng, Question q) {
    bool formulas = rng.chance(30);
    bool formulasHit = rng.chance(75);
    // The pseudo-code: true and right, true for a ray beside the box in z, true for a box
    // behind the ray, or false.
    int wanted = rng.pick(0, 3);
    for (int attempt = 0;; ++attempt) {
        Bounds3d b = randomBox(rng, -3, 3);
        Vec3d o = rng.vec(-5, 5), d = rng.vec(-2, 2);
        if (d.x == 0.0 || d.y == 0.0) continue;  // the slide divides by both
        double tx1 = (b.min.x - o.x) / d.x, tx2 = (b.max.x - o.x) / d.x;
        double ty1 = (b.min.y - o.y) / d.y, ty2 = (b.max.y - o.y) / d.y;
        double tmin = std::max(std::min(tx1, tx2), std::min(ty1, ty2));
        double tmax = std::min(std::max(tx1, tx2), std::max(ty1, ty2));
        bool returns = tmax >= tmin;
        if (std::abs(tmax - tmin) < 0.1) continue;  // no grazing: nothing hangs on rounding
        auto hit = rayMeetsBox(o, d, b);
        if (hit && hit->exit - std::max(0.0, hit->enter) < 0.1) continue;
        int got = !returns ? 3 : hit ? 0 : tmax < 0.0 ? 2 : 1;
        if (formulas ? hit.has_value() != formulasHit && attempt < 2000
                     : got != wanted && attempt < 4000)
            continue;
        q.given["origin"] = values(o);
        q.given["direction"] = values(d);
        q.given["min"] = values(b.min);
        q.given["max"] = values(b.max);
        q.given["formulas"] = {formulas ? 1.0 : 0.0};
        std::string setting =
            "The ray r has the origin r.O = " + vec(o) + " and the direction r.D = " + vec(d) +
            " (its points r.O + t r.D, t >= 0); the box b has b.min = " + vec(b.min) +
            " and b.max = " + vec(b.max) + ".";
        if (formulas) {
            q.statement =
                "The lecture's slab test, as the slide's formulas print it (t1 and t2 "
                "are the t of a pair of planes, taken for x, y and z in turn):\n" +
                indented(kSlabFormulas) + "\n" + setting;
            q.parts.push_back(yesNoPart("does the slide's test report an intersection?", false));
            q.parts.push_back(yesNoPart("does the ray really meet the box?", hit.has_value()));
            q.solution = {
                "start: t_min = +inf, t_max = -inf; max(+inf, anything) stays +inf and "
                "min(-inf, anything) stays -inf",
                "so after x, y and z: t_min = +inf, t_max = -inf, and t_min < t_max is false: "
                "the formulas report no intersection, for every ray",
                hit ? "the ray meets the box for t in [" + num(std::max(0.0, hit->enter)) + ", " +
                          num(hit->exit) +
                          "]: start with t_min = -inf, t_max = +inf (or the "
                          "ray's [0, +inf)) and it is found"
                    : "the ray misses the box, so here the answer is right, by accident"};
            return q;
        }
        q.statement =
            "The lecture's slab test, as the slide's pseudo-code prints it (r.0 is "
            "the slide's typo for the origin r.O; min and max are the usual ones):\n" +
            indented(kSlabPseudoCode) + "\n" + setting;
        q.parts.push_back(numbersPart("tmin and tmax when it returns", {tmin, tmax}, 2));
        q.parts.push_back(
            yesNoPart("does it return true? (the truth of the ray and the box aside)", returns));
        q.solution = {"x: tx1 = (" + num(b.min.x) + " - " + num(o.x) + ") / " + num(d.x) + " = " +
                          num(tx1) + ", tx2 = " + num(tx2) + ": tmin = " + num(std::min(tx1, tx2)) +
                          ", tmax = " + num(std::max(tx1, tx2)),
                      "y: ty1 = " + num(ty1) + ", ty2 = " + num(ty2) + ": tmin = max(tmin, " +
                          num(std::min(ty1, ty2)) + ") = " + num(tmin) + ", tmax = min(tmax, " +
                          num(std::max(ty1, ty2)) + ") = " + num(tmax),
                      "return tmax >= tmin: " + std::string(returns ? "true" : "false")};
        if (got == 1)
            q.solution.push_back(
                "but the ray misses the box: the code never looks at z, and the line passes "
                "beside the box in z (the same lines for tz1, tz2 find it)");
        else if (got == 2)
            q.solution.push_back(
                "but the box is behind the ray: tmax = " + num(tmax) +
                " < 0, and the code never compares with t = 0 (start with tmin = 0)");
        else if (got == 0)
            q.solution.push_back("and the ray does meet the box, for t in [" +
                                 num(std::max(0.0, hit->enter)) + ", " + num(hit->exit) + "]");
        else
            q.solution.push_back(
                "and the ray misses the box: the x and y intervals of t do "
                "not overlap");
        return q;
    }
}

}  // namespace boxes::exam::gen
