// The question kinds that ask light transport, the example exam's questions 1a and 1b, what
// the slides' code returns and the measured cost of operations: every answer re-derived
// here by another route, for many seeds; and the text wrapping of the exam's output.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>

#include "exam/answer.hpp"
#include "exam/questions.hpp"
#include "exam/terminal.hpp"
#include "support.hpp"

using namespace boxes;
using namespace boxes::exam;

namespace {

constexpr int kSeeds = 400;

Vec3d given3(const Question& q, const std::string& name, size_t at = 0) {
    const std::vector<double>& v = q.given.at(name);
    return {v.at(at), v.at(at + 1), v.at(at + 2)};
}
double given1(const Question& q, const std::string& name, size_t at = 0) {
    return q.given.at(name).at(at);
}
std::vector<double> v3(const Vec3d& v) {
    return {v.x, v.y, v.z};
}

void checkValues(const Part& part, const std::vector<double>& expected, double tolerance = 1e-9) {
    INFO(part.prompt << ": generated " << formatNumbers(part.expected) << ", re-derived "
                     << formatNumbers(expected));
    REQUIRE(part.expected.size() == expected.size());
    for (size_t i = 0; i < expected.size(); ++i)
        CHECK(std::abs(part.expected[i] - expected[i]) <=
              tolerance * std::max(1.0, std::abs(expected[i])));
    // The answer as the program shows it is accepted.
    CHECK(checkAnswer(part, part.shown).verdict == Verdict::Correct);
}

// The line meets the closed box for t >= 0: the faces it crosses inside the face (a route
// apart from the slab test the generators use).
std::optional<std::pair<double, double>> rayThroughFaces(const Vec3d& o, const Vec3d& d,
                                                         const Vec3d& lo, const Vec3d& hi) {
    std::vector<double> ts;
    for (int axis = 0; axis < 3; ++axis) {
        if (d[axis] == 0.0) continue;
        for (double plane : {lo[axis], hi[axis]}) {
            double t = (plane - o[axis]) / d[axis];
            Vec3d p = o + t * d;
            bool inside = true;
            for (int k = 0; k < 3; ++k)
                if (k != axis) inside = inside && p[k] >= lo[k] - 1e-9 && p[k] <= hi[k] + 1e-9;
            if (inside) ts.push_back(t);
        }
    }
    if (ts.empty()) return std::nullopt;
    auto [enter, exit] = std::minmax_element(ts.begin(), ts.end());
    if (*exit < 0) return std::nullopt;
    return std::pair{std::max(0.0, *enter), *exit};
}

}  // namespace

TEST_SUITE("exam practice") {
    TEST_CASE("light shading: re-derived from the offset to the light for many seeds") {
        int dark = 0, lit = 0;
        for (int seed = 0; seed < kSeeds; ++seed) {
            Question q = makeQuestion("light-shading", uint64_t(seed));
            Vec3d p = given3(q, "p"), n = given3(q, "n"), s = given3(q, "light");
            double a = given1(q, "albedo"), intensity = given1(q, "intensity");
            Vec3d toLight = s - p;
            double d = std::sqrt(glm::dot(toLight, toLight));
            CHECK(d == std::round(d));  // the distance is a whole number: exact by hand
            // N.L by the law of cosines: |N - L|^2 = |N|^2 + |L|^2 - 2 N.L.
            Vec3d l = toLight / d;
            double cosine = (glm::dot(n, n) + glm::dot(l, l) - glm::dot(n - l, n - l)) / 2.0;
            REQUIRE(q.parts.size() == 3);
            checkValues(q.parts[0], v3(l));
            checkValues(q.parts[1], {cosine});
            checkValues(q.parts[2],
                        {a * intensity * std::max(0.0, glm::dot(n, toLight)) / (d * d * d)});
            (cosine < 0.0 ? dark : lit)++;
        }
        CHECK(dark > kSeeds / 20);  // the light behind the surface is asked too
        CHECK(lit > kSeeds / 2);
    }
    TEST_CASE("shadow ray: re-derived from the closest point of the segment for many seeds") {
        int shadow = 0, beyond = 0, behind = 0, beside = 0;
        for (int seed = 0; seed < kSeeds; ++seed) {
            Question q = makeQuestion("shadow-ray", uint64_t(seed));
            Vec3d p = given3(q, "p"), s = given3(q, "light"), c = given3(q, "centre");
            double r2 = given1(q, "radius2");
            Vec3d d = s - p;
            // P and the light lie outside the sphere.
            REQUIRE(glm::dot(p - c, p - c) > r2);
            REQUIRE(glm::dot(s - c, s - c) > r2);
            // The line's closest approach to C at t_c, half a chord of h around it.
            double tc = glm::dot(c - p, d) / glm::dot(d, d);
            Vec3d closest = p + tc * d;
            double h2 = r2 - glm::dot(closest - c, closest - c);
            std::vector<double> t;
            if (h2 > 0) {
                double half = std::sqrt(h2 / glm::dot(d, d));
                if (tc - half > 0)
                    t = {tc - half};
                else if (tc + half > 0)
                    t = {tc + half};
            }
            REQUIRE(q.parts.size() == 2);
            checkValues(q.parts[0], t);
            // In shadow: the segment's closest point lies inside the sphere.
            double onSegment = std::clamp(tc, 0.0, 1.0);
            Vec3d nearest = p + onSegment * d;
            bool inShadow = glm::dot(nearest - c, nearest - c) < r2;
            CHECK(q.parts[1].yes == inShadow);
            if (inShadow)
                ++shadow;
            else if (h2 <= 0)
                ++beside;
            else if (tc > 1)
                ++beyond;
            else
                ++behind;
        }
        // Each way of being lit is asked: beyond the light, behind the point, beside the ray.
        CHECK(shadow > kSeeds / 4);
        CHECK(beyond > kSeeds / 20);
        CHECK(behind > kSeeds / 20);
        CHECK(beside > kSeeds / 20);
    }
    TEST_CASE("ray depth: the slab's rays re-derived by Snell's angles for many seeds") {
        int totalInternal = 0;
        for (int seed = 0; seed < kSeeds; ++seed) {
            Question q = makeQuestion("ray-depth", uint64_t(seed));
            Vec3d o = given3(q, "origin"), d = given3(q, "direction");
            double h = given1(q, "thickness"), n1 = given1(q, "n1"), n2 = given1(q, "n2"),
                   n3 = given1(q, "n3");
            REQUIRE(q.parts.size() == 5);
            // The horizontal unit direction and the angle from the normal.
            Vec3d across(d.x, 0, d.z);
            double sin1 = glm::length(across);
            across /= sin1;
            Vec3d p1 = o + (o.y / -d.y) * d;
            checkValues(q.parts[0], v3(p1));
            checkValues(q.parts[1], {d.x, -d.y, d.z});  // the mirror flips the normal part
            double sin2 = n1 / n2 * sin1, cos2 = std::sqrt(1 - sin2 * sin2);
            checkValues(q.parts[2], v3(sin2 * across - cos2 * Vec3d(0, 1, 0)));
            // Down h through the slab, across h tan(theta2).
            checkValues(q.parts[3], v3(p1 + h * (sin2 / cos2) * across - Vec3d(0, h, 0)));
            double sin3 = n1 / n3 * sin1;
            if (sin3 > 1.0) {
                checkValues(q.parts[4], {});
                ++totalInternal;
            } else {
                checkValues(q.parts[4],
                            v3(sin3 * across - std::sqrt(1 - sin3 * sin3) * Vec3d(0, 1, 0)));
            }
        }
        CHECK(totalInternal > 0);  // total internal reflection at the bottom is asked too
    }
    TEST_CASE("example 1a and 1b: corners and the ray by Gram-Schmidt for many seeds") {
        for (int seed = 0; seed < kSeeds; ++seed) {
            Question a = makeQuestion("example-1a", uint64_t(seed));
            Question b = makeQuestion("example-1b", uint64_t(seed));
            CHECK(a.given == b.given);  // one set of givens, as on the exam
            Vec3d e = given3(a, "eye"), view = given3(a, "view"), up = given3(a, "up");
            double distance = given1(a, "screen", 0), width = given1(a, "screen", 1),
                   height = given1(a, "screen", 2);
            Vec3d w = view / std::sqrt(glm::dot(view, view));
            Vec3d v = up - glm::dot(up, w) * w;
            v /= std::sqrt(glm::dot(v, v));
            Vec3d u = glm::cross(w, v), m = e + distance * w;
            Vec3d tl = m - width / 2 * u + height / 2 * v, tr = m + width / 2 * u + height / 2 * v,
                  bl = m - width / 2 * u - height / 2 * v, br = m + width / 2 * u - height / 2 * v;
            REQUIRE(a.parts.size() == 4);
            checkValues(a.parts[0], v3(tl));
            checkValues(a.parts[1], v3(tr));
            checkValues(a.parts[2], v3(bl));
            checkValues(a.parts[3], v3(br));
            // The ray through a point of the screen: bilinear between the corners.
            double sx = given1(b, "through", 0), sy = given1(b, "through", 1);
            Vec3d point =
                tl + (sx + width / 2) / width * (tr - tl) + (height / 2 - sy) / height * (bl - tl);
            Vec3d r = point - e;
            REQUIRE(b.parts.size() == 1);
            checkValues(b.parts[0], v3(r / std::sqrt(glm::dot(r, r))));
        }
        // Seed 0: the example exam's own numbers, E = (1,1,1), V = (1,0,1): the ray through
        // the screen's centre is (1,0,1)/sqrt(2), the top-left corner (1 + sqrt 2, 2, 1).
        Question a = makeQuestion("example-1a", 0), b = makeQuestion("example-1b", 0);
        CHECK(given3(a, "eye") == Vec3d(1, 1, 1));
        CHECK(given3(a, "view") == Vec3d(1, 0, 1));
        checkValues(a.parts[0], {1 + std::sqrt(2.0), 2, 1}, 1e-14);
        checkValues(b.parts[0], {std::sqrt(0.5), 0, std::sqrt(0.5)}, 1e-14);
        CHECK(checkAnswer(b.parts[0], "(1, 0, 1)/sqrt(2)").verdict == Verdict::Correct);
        CHECK(a.statement.find("its up vector is printed equal to V") != std::string::npos);
        CHECK(makeQuestion("example-1a", 1).given.at("eye") != a.given.at("eye"));
    }
    TEST_CASE("slide union: the printed lines re-run with the typo B.bmin.x for many seeds") {
        int typoShows = 0;
        for (int seed = 0; seed < kSeeds; ++seed) {
            Question q = makeQuestion("slide-union", uint64_t(seed));
            Vec3d amin = given3(q, "amin"), amax = given3(q, "amax"), bmin = given3(q, "bmin"),
                  bmax = given3(q, "bmax");
            // The slide's third line reads B.bmin.x; every other line is right.
            Vec3d lo = glm::min(amin, bmin);
            lo.y = std::min(amin.y, bmin.x);
            REQUIRE(q.parts.size() == 2);
            checkValues(q.parts[0], v3(lo));
            checkValues(q.parts[1], v3(glm::max(amax, bmax)));
            typoShows += lo.y != std::min(amin.y, bmin.y);
            // The code is printed as on the slide, typo included.
            CHECK(q.statement.find("box.bmin.y = min(A.bmin.y, B.bmin.x);") != std::string::npos);
        }
        CHECK(typoShows > kSeeds / 3);  // the typo changes the answer often, not always
        CHECK(typoShows < kSeeds * 9 / 10);
    }
    TEST_CASE("slide slab: tmin and tmax from the sorted ends and the truth from the faces") {
        int formulas = 0, wrongTrue = 0, right = 0, misses = 0;
        for (int seed = 0; seed < kSeeds; ++seed) {
            Question q = makeQuestion("slide-slab", uint64_t(seed));
            Vec3d o = given3(q, "origin"), d = given3(q, "direction"), lo = given3(q, "min"),
                  hi = given3(q, "max");
            auto truth = rayThroughFaces(o, d, lo, hi);
            REQUIRE(q.parts.size() == 2);
            if (given1(q, "formulas") == 1.0) {
                // t_min starts at +inf and never comes down: the formulas never report a hit.
                ++formulas;
                CHECK_FALSE(q.parts[0].yes);
                CHECK(q.parts[1].yes == truth.has_value());
                CHECK(q.statement.find("$t_{min} = +\\infty, t_{max} = -\\infty$") !=
                      std::string::npos);
                continue;
            }
            // Two intervals: where they overlap, the overlap is [2nd, 3rd] of the four ends
            // sorted; where they do not, max of the starts is the 3rd and min of the ends the
            // 2nd.
            double tx1 = (lo.x - o.x) / d.x, tx2 = (hi.x - o.x) / d.x;
            double ty1 = (lo.y - o.y) / d.y, ty2 = (hi.y - o.y) / d.y;
            std::vector<double> ends = {tx1, tx2, ty1, ty2};
            std::sort(ends.begin(), ends.end());
            bool overlap = !(std::max(tx1, tx2) < std::min(ty1, ty2) ||
                             std::max(ty1, ty2) < std::min(tx1, tx2));
            checkValues(q.parts[0], overlap ? std::vector<double>{ends[1], ends[2]}
                                            : std::vector<double>{ends[2], ends[1]});
            CHECK(q.parts[1].yes == overlap);
            if (overlap && !truth) ++wrongTrue;  // beside the box in z, or behind the ray
            if (overlap == truth.has_value()) ++right;
            misses += !overlap;
            CHECK(q.statement.find("float tx1 = (b.min.x - r.0.x) / r.D.x;") != std::string::npos);
            CHECK(q.statement.find("bool intersection(box b, ray r)") != std::string::npos);
        }
        CHECK(formulas > kSeeds / 10);
        CHECK(wrongTrue > kSeeds / 10);  // the code's errors are what is asked most
        CHECK(right > kSeeds / 10);
        CHECK(misses > 0);
    }
    TEST_CASE("cost order: the letters sorted by the measured times for many seeds and runs") {
        // Runs of many kinds: the reference run, and made-up runs with the times shuffled.
        std::vector<MeasuredCosts> runs = {referenceCosts()};
        uint64_t state = 7;
        auto next = [&] {
            state = state * 6364136223846793005ull + 1442695040888963407ull;
            return double((state >> 33) % 1000) / 100.0 + 0.3;
        };
        for (int r = 0; r < 6; ++r) {
            MeasuredCosts m;
            m.source = "a made-up run";
            for (const char* op : {"sin", "cos", "sqrt", "/", "*", "+", "-"})
                for (const char* type : {"float", "double"}) m.ops.push_back({op, type, next()});
            m.tableNs = next();
            m.stdSinNs = next();
            runs.push_back(m);
        }
        int withFour = 0;
        for (const MeasuredCosts& run : runs)
            for (int seed = 0; seed < 60; ++seed) {
                Question q = makeQuestion("cost-order", uint64_t(seed), run);
                REQUIRE(q.parts.size() == 2);
                const Part& order = q.parts[0];
                REQUIRE(order.type == AnswerType::Order);
                // The letters given, sorted by the time each was given.
                std::vector<std::pair<double, char>> byTime;
                for (char c = 'a'; q.given.count(std::string(1, c)); ++c)
                    byTime.push_back({given1(q, std::string(1, c)), c});
                std::sort(byTime.begin(), byTime.end());
                std::string expected;
                for (auto [ns, c] : byTime) expected += c;
                CHECK(order.order == expected);
                withFour += expected.size() == 4;
                // Clearly apart, so the noise of a run does not decide the order.
                for (size_t i = 1; i < byTime.size() && byTime.size() > 2; ++i)
                    CHECK(byTime[i].first >= 1.25 * byTime[i - 1].first);
                CHECK(checkAnswer(order, order.shown).verdict == Verdict::Correct);
                std::string reversed(expected.rbegin(), expected.rend());
                CHECK(checkAnswer(order, reversed).verdict == Verdict::Wrong);
                CHECK(q.parts[1].yes == (2.0 * run.tableNs <= run.stdSinNs));
                CHECK(q.statement.find(run.source) != std::string::npos);
            }
        CHECK(withFour > 0);
    }
    TEST_CASE("cost order: read from a step 05 report and its faults named") {
        test::TempDir dir;
        std::ofstream(dir.file("report.json")) << R"({"tables": [
            {"id": "op_cost", "columns": ["operation", "type", "ns/op", "min ns"],
             "rows": [["sqrt", "float", 5.0, 4.0], ["+", "float", 0.5, 0.4],
                      ["sin", "double", 9.0, 8.0], ["*", "double", 1.0, 0.9]]},
            {"id": "sincos", "columns": ["variant", "ns/call", "min ns"],
             "rows": [["std::sin float", 9.0, 7.0], ["table nearest 3600", 5.0, 3.0],
                      ["table nearest 360", 1.0, 1.0]]}]})";
        MeasuredCosts m = readMeasuredCosts(dir.file("report.json"));
        REQUIRE(m.ops.size() == 4);
        CHECK(m.ops[0].op == "sqrt");
        CHECK(m.ops[0].ns == 5.0);
        CHECK(m.tableNs == 3.0);
        CHECK(m.stdSinNs == 7.0);
        CHECK(m.source.find("report.json") != std::string::npos);
        std::ofstream(dir.file("no_sincos.json")) << R"({"tables": [{"id": "op_cost",
            "columns": ["operation", "type", "ns/op"], "rows": []}]})";
        CHECK_THROWS_WITH_AS(readMeasuredCosts(dir.file("no_sincos.json")),
                             doctest::Contains("no table 'sincos'"), std::runtime_error);
        std::ofstream(dir.file("bad.json")) << "{ not json";
        CHECK_THROWS_WITH_AS(readMeasuredCosts(dir.file("bad.json")),
                             doctest::Contains("is not JSON"), std::runtime_error);
        CHECK_THROWS_WITH_AS(readMeasuredCosts(dir.file("missing.json")),
                             doctest::Contains("cannot read"), std::runtime_error);
    }
    TEST_CASE("answers in order: letters with or without separators") {
        Part p;
        p.type = AnswerType::Order;
        p.order = "cab";
        for (const char* right : {"c a b", "c, a, b", "cab", "C < A < B", " c a  b "})
            CHECK(checkAnswer(p, right).verdict == Verdict::Correct);
        CHECK(checkAnswer(p, "a b c").verdict == Verdict::Wrong);
        Checked missing = checkAnswer(p, "c a");
        CHECK(missing.verdict == Verdict::Unreadable);
        CHECK(missing.note == "give each of the letters a, b and c once, in order");
        CHECK(checkAnswer(p, "c a b b").verdict == Verdict::Unreadable);
    }
    TEST_CASE("the exam's text wraps at spaces and never inside a word") {
        uint64_t state = 11;
        auto next = [&](int n) {
            state = state * 6364136223846793005ull + 1442695040888963407ull;
            return int((state >> 33) % uint64_t(n));
        };
        for (int round = 0; round < 300; ++round) {
            // Words of 1 to 30 letters, vectors in parentheses, and now and then a line break.
            std::string text;
            for (int w = next(60); w >= 0; --w) {
                if (next(10) == 0)
                    text += "(" + std::to_string(next(100)) + ", -" + std::to_string(next(9)) +
                            ".5, 3)";
                else
                    text += std::string(size_t(1 + next(30)), char('a' + next(26)));
                text += next(15) == 0 ? "\n" : " ";
            }
            int width = 20 + next(80);
            std::string wrapped = wrapText(text, width, 2);
            auto words = [](const std::string& s) {
                std::vector<std::string> v;
                std::istringstream in(s);
                for (std::string w; in >> w;) v.push_back(w);
                return v;
            };
            INFO("width " << width << ":\n" << wrapped);
            CHECK(words(wrapped) == words(text));  // no word split, none lost
            std::istringstream lines(wrapped);
            for (std::string line; std::getline(lines, line);) {
                bool oneWord = words(line).size() == 1;
                CHECK((int(line.size()) <= width || oneWord));
            }
        }
        // A vector is kept on one line when it fits; the indent of the next lines is 2.
        CHECK(wrapText("the answer is (1.5, -2, 3)", 20, 2) == "the answer is\n  (1.5, -2, 3)");
        CHECK(wrapText("short  spacing kept", 40, 2) == "short  spacing kept");
        CHECK(wrapText("no wrapping", 0, 2) == "no wrapping");
    }
}
