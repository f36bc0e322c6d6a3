// Exam practice: every generated answer re-derived here by another formula in double for
// many seeds, the answer parser, and the program run with answers from a file and stdin.
#include <algorithm>
#include <cmath>
#include <optional>
#include <set>

#include "exam/answer.hpp"
#include "exam/questions.hpp"
#include "support.hpp"

using namespace boxes;
using namespace boxes::exam;

namespace {

constexpr int kSeeds = 300;

Vec3d given3(const Question& q, const std::string& name) {
    const std::vector<double>& v = q.given.at(name);
    return {v.at(0), v.at(1), v.at(2)};
}
double given1(const Question& q, const std::string& name) {
    return q.given.at(name).at(0);
}

void checkValues(const Part& part, const std::vector<double>& expected, double tolerance = 1e-9) {
    INFO(part.prompt << ": generated " << formatNumbers(part.expected) << ", re-derived "
                     << formatNumbers(expected));
    REQUIRE(part.expected.size() == expected.size());
    for (size_t i = 0; i < expected.size(); ++i)
        CHECK(std::abs(part.expected[i] - expected[i]) <=
              tolerance * std::max(1.0, std::abs(expected[i])));
    // The answer as the program prints it is accepted.
    if (!expected.empty())
        CHECK(checkAnswer(part, formatNumbers(part.expected)).verdict == Verdict::Correct);
}

std::vector<double> v3(const Vec3d& v) {
    return {v.x, v.y, v.z};
}

// Screen corners by Gram-Schmidt: the screen's up is U made orthogonal to the view.
struct Corners {
    Vec3d topLeft, topRight, bottomLeft, bottomRight;
};
Corners cornersByGramSchmidt(const Question& q) {
    Vec3d eye = given3(q, "eye"), view = given3(q, "view"), up = given3(q, "up");
    double fov = given1(q, "fov"), aspect = given1(q, "aspect");
    Vec3d w = view / std::sqrt(glm::dot(view, view));
    Vec3d v = up - glm::dot(up, w) * w;
    v /= std::sqrt(glm::dot(v, v));
    Vec3d u = glm::cross(w, v);
    double h = std::tan(fov * std::acos(-1.0) / 360.0), half = aspect * h;
    Vec3d m = eye + w;
    return {m - half * u + h * v, m + half * u + h * v, m - half * u - h * v, m + half * u - h * v};
}

}  // namespace

TEST_SUITE("exam practice") {
    TEST_CASE("answer parser: numbers and vectors in forgiving formats") {
        CHECK(evaluateExpression("sqrt(10)-1") == doctest::Approx(std::sqrt(10.0) - 1));
        CHECK(evaluateExpression("2sqrt(3)") == doctest::Approx(2 * std::sqrt(3.0)));
        CHECK(evaluateExpression("-(1 + 2) * 3 / 4") == doctest::Approx(-2.25));
        CHECK(evaluateExpression("2^3 - 1e-1") == doctest::Approx(7.9));
        CHECK(evaluateExpression("1/sqrt 2") == doctest::Approx(std::sqrt(0.5)));
        CHECK(evaluateExpression("pi / 2") == doctest::Approx(std::acos(0.0)));
        using V = std::vector<double>;
        CHECK(parseNumberList("(1, 2, 3)") == V{1, 2, 3});
        CHECK(parseNumberList("1 2 3") == V{1, 2, 3});
        CHECK(parseNumberList("[1; 2; 3]") == V{1, 2, 3});
        CHECK(parseNumberList("1 -2 3") == V{1, -2, 3});  // a sign before a number starts one
        CHECK(parseNumberList("1 - 2 3") == V{-1, 3});    // a spaced minus subtracts
        CHECK(parseNumberList("  -1,-2 ,  -3 ") == V{-1, -2, -3});
        V exact = parseNumberList("sqrt(10)-1, 1, sqrt(10) - 1");
        REQUIRE(exact.size() == 3);
        CHECK(exact[0] == doctest::Approx(std::sqrt(10.0) - 1));
        CHECK(exact[2] == doctest::Approx(std::sqrt(10.0) - 1));
        V scaled = parseNumberList("(-1, 0, -1)/sqrt(2)");
        REQUIRE(scaled.size() == 3);
        CHECK(scaled[0] == doctest::Approx(-std::sqrt(0.5)));
        CHECK(scaled[1] == 0.0);
        CHECK(parseNumberList("2 * (1 2 3)") == V{2, 4, 6});
        CHECK(parseNumberList("(sqrt(4)-1)/2") == V{0.5});
        CHECK(parseNumberList("0.5") == V{0.5});
    }
    TEST_CASE("answer parser: what it cannot read is named") {
        for (const char* bad : {"1 +", "sqrt(-1)", "(1, 2", "1 ) 2", "foo", "1 # 2", "1/0", "1,"}) {
            INFO(std::string(bad));
            CHECK_THROWS_AS(parseNumberList(bad), std::invalid_argument);
        }
        CHECK_THROWS_AS(evaluateExpression("1 2"), std::invalid_argument);
        CHECK_THROWS_WITH_AS(evaluateExpression("x + 1"), doctest::Contains("unknown word 'x'"),
                             std::invalid_argument);
    }
    TEST_CASE("answer parser: long and deeply nested answers are refused not overflowed") {
        // Issue 10's fuzzing: 10^6 parentheses made the reader quadratic (a hang).
        std::string deep = std::string(200000, '(') + "1" + std::string(200000, ')');
        CHECK_THROWS_WITH_AS(parseNumberList(deep), doctest::Contains("longer than 1000"),
                             std::invalid_argument);
        std::string nested = "1+" + std::string(300, '(') + "1" + std::string(300, ')');
        CHECK_THROWS_WITH_AS(evaluateExpression(nested), doctest::Contains("nested too deeply"),
                             std::invalid_argument);
        CHECK_THROWS_WITH_AS(evaluateExpression(std::string(500, '-') + "1"),
                             doctest::Contains("nested too deeply"), std::invalid_argument);
        // Ordinary nesting still reads.
        CHECK(evaluateExpression("1+((((2))))*-(-3)") == 7.0);
        CHECK(parseNumberList(std::string(400, '(') + "1, 2" + std::string(400, ')')) ==
              std::vector<double>{1.0, 2.0});
    }
    TEST_CASE("checking answers: the stated tolerance and none and yes/no and letters") {
        CHECK(withinTolerance(1.0009, 1.0));
        CHECK_FALSE(withinTolerance(1.0011, 1.0));
        CHECK(withinTolerance(1000.9, 1000.0));  // 0.1% of a large number
        CHECK_FALSE(withinTolerance(1002.0, 1000.0));
        Question q = makeQuestion("worked-example", 1);
        REQUIRE(q.parts.size() == 4);
        CHECK(checkAnswer(q.parts[0], "(2.162, 1, 2.162)").verdict == Verdict::Correct);
        CHECK(checkAnswer(q.parts[0], "(2.17, 1, 2.17)").verdict == Verdict::Wrong);
        CHECK(checkAnswer(q.parts[0], "2.162 1").verdict == Verdict::Unreadable);
        CHECK(checkAnswer(q.parts[0], "none").verdict == Verdict::Unreadable);  // not allowed here
        Checked unnormalized = checkAnswer(q.parts[1], "-1 0 -1");
        CHECK(unnormalized.verdict == Verdict::Wrong);
        CHECK(unnormalized.note.find("not of unit length") != std::string::npos);
        CHECK(checkAnswer(q.parts[3], "None").verdict == Verdict::Correct);
        CHECK(checkAnswer(q.parts[3], "no hit").verdict == Verdict::Correct);
        CHECK(checkAnswer(q.parts[2], "none").verdict == Verdict::Wrong);
        Part yes;
        yes.type = AnswerType::YesNo;
        yes.yes = true;
        CHECK(checkAnswer(yes, " Yes ").verdict == Verdict::Correct);
        CHECK(checkAnswer(yes, "no").verdict == Verdict::Wrong);
        CHECK(checkAnswer(yes, "maybe").verdict == Verdict::Unreadable);
    }
    TEST_CASE("generated questions: the same seed gives the same question") {
        for (const QuestionKind& k : questionKinds()) {
            Question a = makeQuestion(k.name, 42), b = makeQuestion(k.name, 42);
            CHECK(a.statement == b.statement);
            CHECK(a.given == b.given);
            CHECK_FALSE(a.parts.empty());
            CHECK_FALSE(a.solution.empty());
        }
        CHECK(makeQuestion("ray-plane", 1).statement != makeQuestion("ray-plane", 2).statement);
        CHECK_THROWS_AS(makeQuestion("no-such-kind", 1), std::invalid_argument);
    }
    TEST_CASE("generated questions: vectors re-derived by components") {
        for (int seed = 0; seed < kSeeds; ++seed) {
            Question q = makeQuestion("vectors", uint64_t(seed));
            const auto& a = q.given.at("a");
            const auto& b = q.given.at("b");
            double dot = 0, len = 0;
            for (int i = 0; i < 3; ++i)
                dot += a[size_t(i)] * b[size_t(i)], len += a[size_t(i)] * a[size_t(i)];
            checkValues(q.parts[0], {dot});
            checkValues(q.parts[1], {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                                     a[0] * b[1] - a[1] * b[0]});
            checkValues(q.parts[2],
                        {a[0] / std::sqrt(len), a[1] / std::sqrt(len), a[2] / std::sqrt(len)});
            double k = given1(q, "k"), m = given1(q, "m");
            checkValues(q.parts[3],
                        {k * a[0] + m * b[0], k * a[1] + m * b[1], k * a[2] + m * b[2]});
        }
    }
    TEST_CASE("generated questions: screen corners and primary rays re-derived by Gram-Schmidt") {
        for (int seed = 0; seed < kSeeds; ++seed) {
            Question q = makeQuestion("screen-corners", uint64_t(seed));
            Corners c = cornersByGramSchmidt(q);
            checkValues(q.parts[0], v3(c.topLeft));
            checkValues(q.parts[1], v3(c.bottomRight));
            // A primary ray through a pixel centre: bilinear between the corners.
            Question r = makeQuestion("primary-ray", uint64_t(seed));
            Corners s = cornersByGramSchmidt(r);
            double w = r.given.at("image")[0], h = r.given.at("image")[1];
            double fx = (r.given.at("pixel")[0] + 0.5) / w, fy = (r.given.at("pixel")[1] + 0.5) / h;
            CHECK(given1(r, "aspect") == doctest::Approx(w / h));
            Vec3d p = s.topLeft + fx * (s.topRight - s.topLeft) + fy * (s.bottomLeft - s.topLeft);
            Vec3d d = p - given3(r, "eye");
            checkValues(r.parts[0], v3(d / std::sqrt(glm::dot(d, d))));
        }
    }
    TEST_CASE("generated questions: ray/plane re-derived through a point on the plane") {
        int hits = 0;
        for (int seed = 0; seed < kSeeds; ++seed) {
            Question q = makeQuestion("ray-plane", uint64_t(seed));
            Vec3d o = given3(q, "origin"), d = given3(q, "direction"), n = given3(q, "normal");
            Vec3d onPlane = -given1(q, "d") * n / glm::dot(n, n);
            double dn = glm::dot(d, n);
            std::optional<double> t;
            if (dn != 0.0 && glm::dot(onPlane - o, n) / dn >= 0.0)
                t = glm::dot(onPlane - o, n) / dn;
            hits += t.has_value();
            checkValues(q.parts[0], t ? v3(o + *t * d) : std::vector<double>{});
        }
        CHECK(hits > kSeeds / 2);  // both outcomes are asked
        CHECK(hits < kSeeds);
    }
    TEST_CASE("generated questions: ray/sphere re-derived by the textbook quadratic") {
        int hits = 0;
        for (int seed = 0; seed < kSeeds; ++seed) {
            Question q = makeQuestion("ray-sphere", uint64_t(seed));
            Vec3d o = given3(q, "origin"), d = given3(q, "direction"), c = given3(q, "centre");
            double r2 = given1(q, "radius2");
            double a = glm::dot(d, d), b = 2 * glm::dot(o - c, d), cc = glm::dot(o - c, o - c) - r2;
            double disc = b * b - 4 * a * cc;
            std::optional<double> t;
            if (disc >= 0) {
                double t0 = (-b - std::sqrt(disc)) / (2 * a), t1 = (-b + std::sqrt(disc)) / (2 * a);
                if (t0 >= 0)
                    t = t0;
                else if (t1 >= 0)
                    t = t1;
            }
            hits += t.has_value();
            checkValues(q.parts[0], t ? v3(o + *t * d) : std::vector<double>{});
            if (t) {
                REQUIRE(q.parts.size() == 2);
                checkValues(q.parts[1], v3((o + *t * d - c) / std::sqrt(r2)));
            }
        }
        CHECK(hits > kSeeds / 2);
        CHECK(hits < kSeeds);
    }
    TEST_CASE("generated questions: ray/triangle re-derived through the plane and area ratios") {
        int hits = 0;
        for (int seed = 0; seed < kSeeds; ++seed) {
            Question q = makeQuestion("ray-triangle", uint64_t(seed));
            Vec3d o = given3(q, "origin"), d = given3(q, "direction");
            Vec3d a = given3(q, "a"), b = given3(q, "b"), c = given3(q, "c");
            Vec3d n = glm::cross(b - a, c - a);
            double dn = glm::dot(d, n);
            std::vector<double> expected;
            if (dn != 0.0) {
                double t = glm::dot(a - o, n) / dn;
                Vec3d p = o + t * d;
                double u = glm::dot(glm::cross(p - a, c - a), n) / glm::dot(n, n);
                double v = glm::dot(glm::cross(b - a, p - a), n) / glm::dot(n, n);
                if (t >= 0 && u >= 0 && v >= 0 && u + v <= 1) expected = {t, u, v};
            }
            hits += !expected.empty();
            checkValues(q.parts[0], expected, 1e-8);
        }
        CHECK(hits > kSeeds / 2);
        CHECK(hits < kSeeds);
    }
    TEST_CASE(
        "generated questions: ray/box slabs re-derived from the six faces and clipped as in 3.6") {
        int hits = 0;
        for (int seed = 0; seed < kSeeds; ++seed) {
            Question q = makeQuestion("ray-box", uint64_t(seed));
            Vec3d o = given3(q, "origin"), d = given3(q, "direction"), lo = given3(q, "min"),
                  hi = given3(q, "max");
            // Every face plane the line crosses inside the face: the line's entry and exit.
            std::vector<double> ts;
            for (int axis = 0; axis < 3; ++axis) {
                if (d[axis] == 0.0) continue;
                for (double plane : {lo[axis], hi[axis]}) {
                    double t = (plane - o[axis]) / d[axis];
                    Vec3d p = o + t * d;
                    bool inside = true;
                    for (int k = 0; k < 3; ++k)
                        if (k != axis)
                            inside = inside && p[k] >= lo[k] - 1e-9 && p[k] <= hi[k] + 1e-9;
                    if (inside) ts.push_back(t);
                }
            }
            // The ray's part inside, clipped to its [0, +inf) as exercise 3.6 returns it.
            std::vector<double> expected;
            if (!ts.empty()) {
                auto [enter, exit] = std::minmax_element(ts.begin(), ts.end());
                if (*exit >= 0) expected = {std::max(0.0, *enter), *exit};
            }
            hits += !expected.empty();
            checkValues(q.parts[0], expected);
        }
        CHECK(hits > kSeeds / 2);
        CHECK(hits < kSeeds);
    }
    TEST_CASE("generated questions: reflection and refraction and Fresnel re-derived by angles") {
        int tir = 0;
        for (int seed = 0; seed < kSeeds; ++seed) {
            Question q = makeQuestion("reflect", uint64_t(seed));
            Vec3d d = given3(q, "d"), n = given3(q, "n");
            Vec3d normalPart = glm::dot(d, n) * n, tangent = d - normalPart;
            checkValues(q.parts[0], v3(tangent - normalPart));

            Question r = makeQuestion("refract", uint64_t(seed));
            Vec3d di = given3(r, "d"), ni = given3(r, "n");
            double n1 = given1(r, "n1"), n2 = given1(r, "n2");
            double cosI = -glm::dot(di, ni), sinI = std::sqrt(std::max(0.0, 1 - cosI * cosI));
            double sinT = n1 / n2 * sinI;
            std::vector<double> expected;
            if (sinT <= 1.0) {
                Vec3d along = di + cosI * ni;  // the tangential part of d
                Vec3d tangentUnit = sinI > 0 ? along / sinI : Vec3d(0);
                expected = v3(sinT * tangentUnit - std::sqrt(1 - sinT * sinT) * ni);
            }
            tir += expected.empty();
            checkValues(r.parts[0], expected);

            Question f = makeQuestion("fresnel", uint64_t(seed));
            double c = std::cos(given1(f, "angle") * std::acos(-1.0) / 180.0);
            double r0 = std::pow(
                (given1(f, "n1") - given1(f, "n2")) / (given1(f, "n1") + given1(f, "n2")), 2);
            checkValues(f.parts[0], {r0 + (1 - r0) * std::pow(1 - c, 5)});
        }
        CHECK(tir > 0);  // total internal reflection is asked too
    }
    TEST_CASE("generated questions: boxes and culling re-derived from corners and intersections") {
        int overlaps = 0, culled = 0;
        for (int seed = 0; seed < kSeeds; ++seed) {
            Question q = makeQuestion("aabb-points", uint64_t(seed));
            const auto& pts = q.given.at("points");
            Vec3d lo(1e300), hi(-1e300);
            for (size_t i = 0; i < pts.size(); i += 3)
                for (int k = 0; k < 3; ++k)
                    lo[k] = std::min(lo[k], pts[i + size_t(k)]),
                    hi[k] = std::max(hi[k], pts[i + size_t(k)]);
            checkValues(q.parts[0], v3(lo));
            checkValues(q.parts[1], v3(hi));

            Question u = makeQuestion("aabb-union", uint64_t(seed));
            Vec3d umin, umax;
            for (int k = 0; k < 3; ++k) {
                umin[k] = std::min(given3(u, "amin")[k], given3(u, "bmin")[k]);
                umax[k] = std::max(given3(u, "amax")[k], given3(u, "bmax")[k]);
            }
            checkValues(u.parts[0], v3(umin));
            checkValues(u.parts[1], v3(umax));

            // Overlap: the intersection box is not empty.
            Question o = makeQuestion("aabb-overlap", uint64_t(seed));
            Vec3d imin = glm::max(given3(o, "amin"), given3(o, "bmin")),
                  imax = glm::min(given3(o, "amax"), given3(o, "bmax"));
            bool overlap = imin.x <= imax.x && imin.y <= imax.y && imin.z <= imax.z;
            overlaps += overlap;
            CHECK(o.parts[0].yes == overlap);

            // Culled by one plane exactly when all eight corners are outside; the p-vertex is
            // the corner farthest along N.
            Question c = makeQuestion("frustum-cull", uint64_t(seed));
            Vec3d n = given3(c, "n"), bmin = given3(c, "min"), bmax = given3(c, "max");
            double d = given1(c, "d"), best = -1e300;
            bool allOutside = true;
            for (int i = 0; i < 8; ++i) {
                Vec3d corner(i & 1 ? bmax.x : bmin.x, i & 2 ? bmax.y : bmin.y,
                             i & 4 ? bmax.z : bmin.z);
                allOutside = allOutside && glm::dot(n, corner) + d < 0;
                best = std::max(best, glm::dot(n, corner));
            }
            Vec3d p(c.parts[0].expected[0], c.parts[0].expected[1], c.parts[0].expected[2]);
            CHECK(glm::dot(n, p) == best);
            CHECK(((p.x == bmin.x || p.x == bmax.x) && (p.y == bmin.y || p.y == bmax.y) &&
                   (p.z == bmin.z || p.z == bmax.z)));
            CHECK(c.parts[1].yes == allOutside);
            culled += allOutside;
        }
        CHECK(overlaps > kSeeds / 4);
        CHECK(overlaps < kSeeds * 3 / 4);
        CHECK(culled > 0);
        CHECK(culled < kSeeds);
    }
    TEST_CASE("generated questions: terminology") {
        // Every term of the lecture is asked within 400 seeds; its own name is a right
        // answer, a neighbouring term's is not.
        std::vector<std::string> names = terminologyTerms();
        REQUIRE(names.size() >= 10);
        std::set<std::string> seen;
        bool sawGlass = false, sawCulling = false;
        for (int seed = 0; seed < 400; ++seed) {
            Question q = makeQuestion("terminology", uint64_t(seed));
            const Part& p = q.parts.at(0);
            if (p.type == AnswerType::Words && p.shown == "reflection and refraction") {
                sawGlass = true;
                CHECK(checkAnswer(p, "Reflection and refraction").verdict == Verdict::Correct);
                CHECK(checkAnswer(p, "it reflects and transmits").verdict == Verdict::Correct);
                CHECK(checkAnswer(p, "reflection").verdict == Verdict::Wrong);
            } else if (p.type == AnswerType::Words) {
                INFO(p.shown);
                REQUIRE(std::find(names.begin(), names.end(), p.shown) != names.end());
                seen.insert(p.shown);
                CHECK(checkAnswer(p, p.shown).verdict == Verdict::Correct);
                CHECK(checkAnswer(p, "I do not know").verdict == Verdict::Wrong);
                CHECK(q.solution.size() == 1);
            } else {
                sawCulling = true;
                REQUIRE(p.type == AnswerType::Choice);
                std::string line = std::string("\n  ") + p.choice + ") ";
                size_t at = q.statement.find(line);
                REQUIRE(at != std::string::npos);
                CHECK(q.statement.compare(at + line.size(), 20, "it never removes an ") == 0);
                CHECK(checkAnswer(p, std::string(1, p.choice)).verdict == Verdict::Correct);
                CHECK(checkAnswer(p, std::string(1, p.choice == 'a' ? 'b' : 'a')).verdict ==
                      Verdict::Wrong);
            }
        }
        CHECK(sawGlass);
        CHECK(sawCulling);
        CHECK(seen.size() == names.size());
        // Terms of the lecture that must be among them (its cursive ones included).
        for (const char* term :
             {"AABB", "slab test", "view frustum", "false negatives", "conservative", "global data",
              "vertex shader", "z-buffer", "tangent space", "hierarchical grouping"})
            CHECK(std::find(names.begin(), names.end(), std::string(term)) != names.end());
    }
    TEST_CASE("generated questions: culling terminology uses the lecture's false negative") {
        // The lecture: the conservative test produces false negatives, no false positives.
        // The term question accepts that answer, and the choice question's solution names
        // the lecture's word for the box kept although it is outside.
        bool sawTerm = false, sawChoice = false;
        for (int seed = 0; seed < 400; ++seed) {
            Question q = makeQuestion("terminology", uint64_t(seed));
            const Part& p = q.parts.at(0);
            if (p.shown == "false negatives") {
                sawTerm = true;
                CHECK(checkAnswer(p, "False negatives, but no false positives").verdict ==
                      Verdict::Correct);
                CHECK(checkAnswer(p, "false positives").verdict == Verdict::Wrong);
            } else if (p.type == AnswerType::Choice) {
                sawChoice = true;
                REQUIRE(q.solution.size() >= 2);
                CHECK(q.solution[1].find("The lecture calls that a false negative") !=
                      std::string::npos);
                CHECK(q.solution[1].find("kept although it is outside") != std::string::npos);
            }
        }
        CHECK(sawTerm);
        CHECK(sawChoice);
    }
    TEST_CASE("exam: the worked example notes where the lecture's question is ambiguous") {
        Question q = makeQuestion("worked-example", 3);
        for (const char* note :
             {"first question of the lecture's example exam", "the ray r runs from E along V",
              "up vector", "E lies inside the sphere", "'-X - Z = 10' lies behind"}) {
            INFO(note);
            CHECK(q.statement.find(note) != std::string::npos);
        }
        // What the notes decide is what the parts ask: the exit point, the inward normal,
        // no hit with -x - z = 10.
        REQUIRE(q.parts.size() == 4);
        CHECK(q.parts[0].prompt.find("leaves") != std::string::npos);
        CHECK(q.parts[1].prompt.find("inside") != std::string::npos);
        CHECK(q.parts[3].expected.empty());
    }
    TEST_CASE("the worked example: the exact numbers of the lecture's example exam") {
        Question q = makeQuestion("worked-example", 7);
        REQUIRE(q.parts.size() == 4);
        double r10 = std::sqrt(10.0), s = std::sqrt(0.5);
        checkValues(q.parts[0], {r10 - 1, 1, r10 - 1}, 1e-14);
        checkValues(q.parts[1], {-s, 0, -s}, 1e-14);
        checkValues(q.parts[2], {5, 1, 5}, 1e-14);
        CHECK(q.parts[3].expected.empty());  // -x - z = 10 lies behind the eye
        CHECK(checkAnswer(q.parts[0], "sqrt(10)-1, 1, sqrt(10)-1").verdict == Verdict::Correct);
        CHECK(checkAnswer(q.parts[1], "(-1, 0, -1)/sqrt(2)").verdict == Verdict::Correct);
        CHECK(makeQuestion("worked-example", 99).statement == q.statement);  // fixed numbers
    }
}

TEST_SUITE("exam practice") {
    const std::string program = BOXES_EXAM_PROGRAM;

    TEST_CASE("program: --list shows every question kind") {
        test::TempDir dir;
        auto run = test::runProgram(program, "--list --width 0", dir);
        REQUIRE(run.exitCode == 0);
        CHECK(test::lineCount(run.out) == questionKinds().size());
        for (const QuestionKind& k : questionKinds())
            CHECK(run.out.find(k.name) != std::string::npos);
    }
    TEST_CASE("program: answers from a file are checked and the solution is shown") {
        test::TempDir dir;
        std::ofstream(dir.file("answers.txt"))
            << "# the worked example\nsqrt(10)-1, 1, sqrt(10)-1\n"
               "(-1 0 -1)/sqrt(2)\n\n(5 1 5)\n2 2 2\n";
        auto run = test::runProgram(
            program, "--kind worked-example --count 1 --answers answers.txt --width 0", dir);
        INFO(run.out << run.err);
        REQUIRE(run.exitCode == 0);
        CHECK(run.out.find("Score: 3 of 4 answers correct") != std::string::npos);
        CHECK(run.out.find("wrong") != std::string::npos);
        CHECK(run.out.find("Worked solution") != std::string::npos);
        CHECK(run.out.find("t = -6 < 0") != std::string::npos);
        CHECK(run.out.find("within 0.001") != std::string::npos);  // the tolerance is stated
    }
    TEST_CASE("program: answers from stdin for seeded questions") {
        // The answers of the seeded questions, as --show prints them, fed back on stdin.
        test::TempDir dir;
        std::string answers;
        for (int i = 0; i < 3; ++i)
            for (const Part& p : makeQuestion("ray-box", uint64_t(5 + i)).parts)
                answers += p.shown + "\n";
        std::ofstream(dir.file("in.txt")) << answers;
        auto run = test::runProgram(
            "/bin/sh",
            "-c \"cat in.txt | '" + program + "' --kind ray-box --seed 5 --count 3 --answers -\"",
            dir);
        INFO(run.out << run.err);
        REQUIRE(run.exitCode == 0);
        CHECK(run.out.find("Score: 3 of 3 answers correct") != std::string::npos);
        auto show =
            test::runProgram(program, "--kind ray-box --seed 5 --count 3 --show --width 0", dir);
        CHECK(show.out.find(makeQuestion("ray-box", 6).statement) != std::string::npos);
    }
    TEST_CASE("program: --count and --seed that overflow or have a fraction or junk are refused") {
        // CLI11 alone read --seed -1 as 2^64 - 1 and an overflowing seed as 2^64 - 1.
        test::TempDir dir;
        for (auto [args, expect] : std::vector<std::pair<std::string, std::string>>{
                 {"--count 99999999999999999999",
                  "--count: '99999999999999999999' is out of range"},
                 {"--count 2.5", "--count: '2.5' is not a decimal integer"},
                 {"--count 3x", "--count: '3x' is not a decimal integer"},
                 {"--seed 18446744073709551616", "--seed: '18446744073709551616' is out of range"},
                 {"--seed 1.5", "--seed: '1.5' is not a decimal integer"},
                 {"--seed 7abc", "--seed: '7abc' is not a decimal integer"},
                 {"--seed -1", "--seed: '-1' is negative"}}) {
            INFO(args);
            auto run = test::runProgram(program, "--show " + args, dir);
            CHECK(run.exitCode == 2);
            CHECK(test::lineCount(run.err) == 1);
            CHECK(run.err.find("exam_practice: error: " + expect) == 0);
        }
        // The largest seed is read as itself: question 1 shows it.
        auto run = test::runProgram(
            program, "--kind ray-box --seed 18446744073709551615 --count 1 --show --width 0", dir);
        CHECK(run.exitCode == 0);
        CHECK(run.out.find("--seed 18446744073709551615") != std::string::npos);
    }
    TEST_CASE("answer parser: numbers that overflow or have junk are refused") {
        // std::stod read "0x10" as 16; from_chars reads decimals only.
        for (const char* bad : {"1e999", "-1e999", "0x10", "3abc", "2.5x", "1.5.2"}) {
            INFO(bad);
            CHECK_THROWS_AS(evaluateExpression(bad), std::invalid_argument);
        }
        CHECK_THROWS_AS(parseNumberList("(1, 2, 3x)"), std::invalid_argument);
        CHECK_THROWS_WITH_AS(evaluateExpression("1e999"),
                             doctest::Contains("could not read a number at '1e999'"),
                             std::invalid_argument);
        // A fraction is a number like any other: read exactly (to the nearest double).
        CHECK(evaluateExpression("2.5") == 2.5);
        CHECK(evaluateExpression(".125") == 0.125);
        CHECK(parseNumberList("(0.1, 2e-3, 1e308)") == std::vector<double>{0.1, 2e-3, 1e308});
    }
    TEST_CASE("program: bad input gives one line and a non-zero exit") {
        test::TempDir dir;
        for (auto [args, expect] : std::vector<std::pair<std::string, std::string>>{
                 {"--kind nosuch", "unknown question kind"},
                 {"--answers missing.txt", "cannot read"},
                 {"--count 0", "count"}}) {
            INFO(args);
            auto run = test::runProgram(program, args, dir);
            CHECK(run.exitCode != 0);
            CHECK(test::lineCount(run.err) == 1);
            CHECK(run.err.find(expect) != std::string::npos);
        }
    }
}
