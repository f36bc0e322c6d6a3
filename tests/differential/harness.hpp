// Each exercise against its reference on many generated inputs (differential tests).
//
// An exercise's spec (tests/differential/stepNN.hpp) makes its inputs from a seed, calls the
// exercise on one input and writes what came back as a Record: a few numbers, each compared
// exactly (a decision, a count, an index, a value every correct formula computes exactly) or
// within a stated bound (a distance, a weight). The reference's records for one seed are
// data (tests/differential/data/NAME.txt, written from the reference tree by
// `./workbook differential --write`), so a starter kit, which has no reference code, runs
// the same comparison: its tests regenerate the inputs from the seed in the data and
// compare the student's records with the shipped ones. An instructor's hidden sets are the
// same data for another seed, compiled into a doctest file (`--hidden DIR --seed S`).
//
// Each line of the data is one input's record, with flags the generator found:
//   @n   the reference made a NaN on this input (0 * inf on a slab plane, a NaN input):
//        floating-point traps are off while the student's code runs on it;
//   @?   the decision sits within rounding of its boundary (a few ulps of the inputs
//        change it): either answer is accepted;
//   @~K  the values' bounds are 2^K times the stated ones (an ill-conditioned input: a
//        few ulps of the inputs move the value by that much).
// Inputs built on purpose for exact arithmetic (small dyadic coordinates, power-of-two
// determinants) get no flags: every correct formula gives the same decision there.
#pragma once

#include <doctest/doctest.h>

#include <array>
#include <cfenv>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "core/math.hpp"
#include "support.hpp"

namespace boxes::differential {

// ---- Random numbers ------------------------------------------------------------------------

// splitmix64 (Steele, Lea, Flood 2014): the same sequence on every machine, compiler and
// standard library (std::uniform_real_distribution is not), and only exact or correctly
// rounded arithmetic turns its bits into numbers.
class Rng {
public:
    explicit Rng(uint64_t seed) : state_(seed) {}
    uint64_t bits() {
        uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
    int below(int n) { return int(bits() % uint64_t(n)); }
    int range(int lo, int hi) { return lo + below(hi - lo + 1); }  // inclusive
    bool chance(int percent) { return below(100) < percent; }
    double unit() { return double(bits() >> 11) * 0x1p-53; }  // [0, 1)
    double uniform(double lo, double hi) { return lo + (hi - lo) * unit(); }
    // A multiple of 2^-fractionBits in [lo, hi]: exact in float for small ranges.
    double grid(int lo, int hi, int fractionBits = 0) {
        return std::ldexp(double(range(lo * (1 << fractionBits), hi * (1 << fractionBits))),
                          -fractionBits);
    }
    // 2^e with e in [lo, hi], with a random sign when `signed`.
    double power(int lo, int hi, bool withSign = false) {
        double p = std::ldexp(1.0, range(lo, hi));
        return withSign && chance(50) ? -p : p;
    }
    // A magnitude spread evenly over the exponents: m * 2^e, m in [1, 2).
    double logUniform(int lo, int hi) { return std::ldexp(1.0 + unit(), range(lo, hi)); }
    template <typename T>
    T pick(std::initializer_list<T> options) {
        return *(options.begin() + below(int(options.size())));
    }
    Vec3d inCube(double half) {
        return {uniform(-half, half), uniform(-half, half), uniform(-half, half)};
    }
    // A direction of length 1 (rejection from the cube: sqrt is correctly rounded, so
    // the same on every machine).
    Vec3d direction() {
        for (;;) {
            Vec3d v = inCube(1.0);
            double l2 = glm::dot(v, v);
            if (l2 > 1e-4 && l2 <= 1.0) return v / std::sqrt(l2);
        }
    }

private:
    uint64_t state_;
};

// The stream of one data set: the seed mixed with its name, so that adding a data set or
// changing one's inputs leaves the others' inputs alone.
inline uint64_t streamSeed(uint64_t seed, std::string_view name) {
    uint64_t h = 1469598103934665603ull;  // FNV-1a
    for (char c : name) h = (h ^ uint8_t(c)) * 1099511628211ull;
    return seed * 0x9e3779b97f4a7c15ull ^ h;
}

// A few ulps away: the perturbations that tell a decision on a knife's edge (or a value
// that rounding moves a lot) from a stable one. Zero stays zero (axis-parallel rays).
template <typename T>
T nudge(T x, Rng& rng, int maxUlps = 4) {
    if (x == T(0) || !std::isfinite(x)) return x;
    int steps = rng.range(-maxUlps, maxUlps);
    for (int i = 0; i < std::abs(steps); ++i)
        x = std::nextafter(x, steps > 0 ? std::numeric_limits<T>::infinity()
                                        : -std::numeric_limits<T>::infinity());
    return x;
}
template <typename T>
Vec3T<T> nudge(const Vec3T<T>& v, Rng& rng, int maxUlps = 4) {
    return {nudge(v.x, rng, maxUlps), nudge(v.y, rng, maxUlps), nudge(v.z, rng, maxUlps)};
}

// ---- Numbers in words ----------------------------------------------------------------------

// The shortest text that reads back as the same number (std::to_chars): what a student
// sees is the exact value.
template <typename T>
std::string num(T x) {
    if constexpr (std::is_integral_v<T>) {
        return std::to_string(x);
    } else {
        char buf[64];
        auto r = std::to_chars(buf, buf + sizeof buf, x);
        return std::string(buf, r.ptr);
    }
}
template <typename T>
std::string vec(const Vec3T<T>& v) {
    return "(" + num(v.x) + ", " + num(v.y) + ", " + num(v.z) + ")";
}
template <typename T>
std::string vec(const glm::vec<2, T>& v) {
    return "(" + num(v.x) + ", " + num(v.y) + ")";
}
template <typename T>
std::string vec(const glm::vec<4, T>& v) {
    return "(" + num(v.x) + ", " + num(v.y) + ", " + num(v.z) + ", " + num(v.w) + ")";
}

// ---- Records -------------------------------------------------------------------------------

// One number of a result: its value (floats and integers are exact in a double), how it is
// written ('f' float, 'd' double, 'i' integer or flag) and its bound: |got - expected| <=
// abs + rel |expected|; both 0: compared exactly (NaN equals NaN, +0 equals -0).
struct Value {
    double v = 0.0;
    char kind = 'd';
    double rel = 0.0, abs = 0.0;
    bool exact() const { return rel == 0.0 && abs == 0.0; }
};

// What one call gave: values, nothing (a miss, nullopt) or an exception.
struct Record {
    enum State { Values, Absent, Threw } state = Values;
    std::vector<Value> values;
    std::string what;  // the exception's message (not in the data)

    static Record absent() {
        Record r;
        r.state = Absent;
        return r;
    }
    static Record threw(const std::string& what = "") {
        Record r;
        r.state = Threw;
        r.what = what;
        return r;
    }
    Record& f(float x, double rel = 0.0, double abs = 0.0) {
        values.push_back({double(x), 'f', rel, abs});
        return *this;
    }
    Record& d(double x, double rel = 0.0, double abs = 0.0) {
        values.push_back({x, 'd', rel, abs});
        return *this;
    }
    Record& i(int64_t x) {
        values.push_back({double(x), 'i'});
        return *this;
    }
    template <typename T>
    Record& real(T x, double rel = 0.0, double abs = 0.0) {
        return std::is_same_v<T, float> ? f(float(x), rel, abs) : d(double(x), rel, abs);
    }
    template <typename T>
    Record& v3(const Vec3T<T>& v, double rel = 0.0, double abs = 0.0) {
        return real(v.x, rel, abs).real(v.y, rel, abs).real(v.z, rel, abs);
    }
    size_t size() const { return values.size(); }
    double operator[](size_t k) const { return values[k].v; }
};

// A value as text: exact ones in full (the shortest text that reads back the same), others
// with as few digits as keep them within 1/64 of their bound (the data stays small).
inline std::string token(const Value& x) {
    if (x.kind == 'i') return num(int64_t(x.v));
    if (std::isnan(x.v)) return "nan";
    if (std::isinf(x.v)) return x.v > 0 ? "inf" : "-inf";
    std::string full = x.kind == 'f' ? num(float(x.v)) + "f" : num(x.v);
    if (x.exact()) return full;
    double allowed = (x.abs + x.rel * std::fabs(x.v)) / 64.0;
    for (int digits = 1; digits < 17; ++digits) {
        char buf[64];
        auto r = std::to_chars(buf, buf + sizeof buf, x.v, std::chars_format::general, digits);
        double back = 0.0;
        std::from_chars(buf, r.ptr, back);
        if (std::fabs(back - x.v) <= allowed && size_t(r.ptr - buf) < full.size())
            return std::string(buf, r.ptr);
    }
    return full;
}

inline std::string serialize(const Record& r) {
    if (r.state == Record::Absent) return "-";
    if (r.state == Record::Threw) return "!";
    if (r.values.empty()) return "=";
    std::string s;
    for (const Value& x : r.values) s += (s.empty() ? "" : " ") + token(x);
    return s;
}

// Reads one record's tokens (no flags); nullopt when malformed.
inline std::optional<Record> parseRecord(std::string_view text) {
    Record r;
    if (text == "-") return Record::absent();
    if (text == "!") return Record::threw();
    if (text == "=") return r;
    size_t at = 0;
    while (at < text.size()) {
        size_t end = text.find(' ', at);
        if (end == std::string_view::npos) end = text.size();
        std::string_view t = text.substr(at, end - at);
        at = end + 1;
        if (t.empty()) continue;
        Value x;
        if (t == "nan" || t == "-nan") {
            x.v = std::numeric_limits<double>::quiet_NaN();
        } else if (t == "inf" || t == "-inf") {
            x.v = t[0] == '-' ? -kInfinity<double> : kInfinity<double>;
        } else if (t.back() == 'f') {
            float value;
            auto res = std::from_chars(t.data(), t.data() + t.size() - 1, value);
            if (res.ec != std::errc() || res.ptr != t.data() + t.size() - 1) return std::nullopt;
            x.v = value;
            x.kind = 'f';
        } else {
            auto res = std::from_chars(t.data(), t.data() + t.size(), x.v);
            if (res.ec != std::errc() || res.ptr != t.data() + t.size()) return std::nullopt;
        }
        r.values.push_back(x);
    }
    return r;
}

// The flags of one data line (see the top of this file).
struct Flags {
    bool nan = false, ambiguous = false;
    int scale = 0;  // bounds times 2^scale
};

inline std::string serialize(const Flags& f) {
    if (!f.nan && !f.ambiguous && f.scale == 0) return "";
    std::string s = "@";
    if (f.nan) s += "n";
    if (f.ambiguous) s += "?";
    if (f.scale) s += "~" + std::to_string(f.scale);
    return s + " ";
}

// Within the bound (`scale`: the record's ~K); the first value that is not, or -1.
inline bool valueMatches(const Value& got, double expected, int scale) {
    double a = got.v, b = expected;
    if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
    if (a == b) return true;
    if (got.exact() || std::isinf(a) || std::isinf(b)) return false;
    return std::fabs(a - b) <= std::ldexp(got.abs + got.rel * std::fabs(b), scale);
}

// Same state, same count, every value within its bound: "" or what differs, in words.
inline std::string compareRecords(const Record& got, const Record& expected, int scale,
                                  const std::vector<std::string>& names = {}) {
    if (got.state != expected.state) return "a different kind of answer";
    if (got.size() != expected.size())
        return std::to_string(got.size()) + " numbers instead of " +
               std::to_string(expected.size());
    for (size_t k = 0; k < got.size(); ++k)
        if (!valueMatches(got.values[k], expected[k], scale)) {
            std::string name = k < names.size() ? names[k] : "number " + std::to_string(k + 1);
            const Value& g = got.values[k];
            if (g.exact()) return name + " differs (compared exactly)";
            return name + " is off by " + num(std::fabs(g.v - expected[k])) +
                   ", beyond the bound " +
                   num(std::ldexp(g.abs + g.rel * std::fabs(expected[k]), scale)) + " (" +
                   (g.rel ? num(g.rel) + " relative" : std::string()) +
                   (g.rel && g.abs ? " + " : "") + (g.abs ? num(g.abs) + " absolute" : "") +
                   (scale ? " times 2^" + std::to_string(scale) + " for this input" : "") + ")";
        }
    return "";
}

// The decisions of a record: its state, its count of numbers and its integers (flags,
// counts, indices). A real value moves with its inputs even when it is compared exactly.
inline bool sameDecisions(const Record& a, const Record& b) {
    if (a.state != b.state || a.size() != b.size()) return false;
    for (size_t k = 0; k < a.size(); ++k)
        if (a.values[k].kind == 'i' && !valueMatches(a.values[k], b[k], 0)) return false;
    return true;
}

// The smallest K with every toleranced value of `moved` within 2^K / 4 of its bound
// around `base` (a margin of 4 over what a few ulps of the inputs did).
inline int scaleFor(const Record& base, const Record& moved) {
    int k = 0;
    for (size_t i = 0; i < base.size() && i < moved.size(); ++i) {
        const Value& b = base.values[i];
        if (b.exact() || !std::isfinite(b.v) || !std::isfinite(moved[i])) continue;
        double bound = b.abs + b.rel * std::fabs(b.v);
        double off = std::fabs(moved[i] - b.v);
        while (k < 60 && off * 4.0 > std::ldexp(bound, k)) ++k;
    }
    return k;
}

// ---- Specs ---------------------------------------------------------------------------------

// One generated input and what family it comes from; exact inputs are built for exact
// arithmetic (no perturbation: their decisions are compared as they are).
template <typename Input>
struct Case {
    Input input;
    const char* family;
    bool exact = false;
};

// A spec (see step01.hpp):
//   static constexpr const char* name;      // the data set: "1.4-float"
//   static constexpr const char* exercise;  // "1.4"
//   static constexpr int count;             // inputs
//   using Input = ...;
//   static Case<Input> make(Rng&, int index);
//   static Record run(const Input&);        // calls the exercise
//   static std::string given(const Input&); // the input in words
//   static std::string show(const Record&); // a record in words
//   static void perturb(Input&, Rng&);      // a few ulps (inputs that are not exact)
// and optionally
//   static std::string compare(const Input&, const Record& got, const Record& expected,
//                              int scale);  // "" when they agree (else compareRecords)

template <typename Spec>
Record runGuarded(const typename Spec::Input& input) {
    try {
        return Spec::run(input);
    } catch (const std::exception& e) {
        // A starter kit's stub goes on to the test case: "exercise N.M is not implemented".
        if (std::strstr(e.what(), " is not implemented yet")) throw;
        return Record::threw(e.what());
    }
}

template <typename Spec>
std::string compareCase(const typename Spec::Input& input, const Record& got,
                        const Record& expected, int scale) {
    if constexpr (requires { Spec::compare(input, got, expected, scale); })
        return Spec::compare(input, got, expected, scale);
    else
        return compareRecords(got, expected, scale);
}

template <typename Spec>
std::string showRecord(const Record& r) {
    if (r.state == Record::Threw)
        return "an exception" + (r.what.empty() ? std::string() : " (" + r.what + ")");
    return Spec::show(r);
}

template <typename Spec>
std::vector<Case<typename Spec::Input>> inputs(uint64_t seed) {
    Rng rng(streamSeed(seed, Spec::name));
    std::vector<Case<typename Spec::Input>> cases;
    cases.reserve(size_t(Spec::count));
    for (int i = 0; i < Spec::count; ++i) cases.push_back(Spec::make(rng, i));
    return cases;
}

// One input's line of data: the reference's record with its flags.
template <typename Spec>
std::string evaluate(const Case<typename Spec::Input>& c, Rng& perturbations) {
    Flags flags;
    std::feclearexcept(FE_ALL_EXCEPT);
    Record r = runGuarded<Spec>(c.input);
    flags.nan = std::fetestexcept(FE_INVALID) != 0;
    if (!c.exact) {
        for (int p = 0; p < 6 && !flags.ambiguous; ++p) {
            auto moved = c.input;
            Spec::perturb(moved, perturbations);
            Record m = runGuarded<Spec>(moved);
            if (!sameDecisions(r, m))
                flags.ambiguous = true;
            else
                flags.scale = std::max(flags.scale, scaleFor(r, m));
        }
        if (flags.scale > 40) flags.ambiguous = true;  // the value means nothing
    }
    if (flags.ambiguous) flags.scale = 0;
    std::feclearexcept(FE_ALL_EXCEPT);
    return serialize(flags) + serialize(r);
}

// The data set for `seed`: a header line, then one line per input (the reference's
// records when this runs in the reference tree).
template <typename Spec>
std::string generate(uint64_t seed) {
    std::string out = "#! " + std::string(Spec::name) + " " + std::to_string(seed) + " " +
                      std::to_string(Spec::count) + "\n";
    Rng perturbations(streamSeed(seed + 1, Spec::name));
    for (const auto& c : inputs<Spec>(seed)) out += evaluate<Spec>(c, perturbations) + "\n";
    return out;
}

// Every input with its family and the reference's line, for a reader (differential_data
// --show NAME).
template <typename Spec>
std::string explain(uint64_t seed) {
    std::string out;
    Rng perturbations(streamSeed(seed + 1, Spec::name));
    int i = 0;
    for (const auto& c : inputs<Spec>(seed))
        out += std::to_string(++i) + " [" + c.family + (c.exact ? ", exact" : "") + "] " +
               evaluate<Spec>(c, perturbations) + "\n    " + Spec::given(c.input) + "\n";
    return out;
}

// Checks the exercise against a data set; the first differing input in words.
template <typename Spec>
void check(std::string_view data) {
    // The header: "#! NAME SEED COUNT".
    std::vector<std::string_view> lines;
    for (size_t at = 0; at < data.size();) {
        size_t end = data.find('\n', at);
        if (end == std::string_view::npos) end = data.size();
        std::string_view line = data.substr(at, end - at);
        at = end + 1;
        if (!line.empty() && line[0] != '#') lines.push_back(line);
        if (line.rfind("#! ", 0) == 0) lines.insert(lines.begin(), line);
    }
    REQUIRE_MESSAGE(!lines.empty(), "no data for " << Spec::name);
    std::istringstream header(std::string(lines[0].substr(3)));
    std::string name;
    uint64_t seed = 0;
    int count = 0;
    header >> name >> seed >> count;
    REQUIRE_MESSAGE(name == Spec::name, "the data is " << name << "'s, not " << Spec::name << "'s");
    REQUIRE_MESSAGE((count == Spec::count && int(lines.size()) == count + 1),
                    "the data of " << Spec::name << " has " << lines.size() - 1 << " records for "
                                   << Spec::count
                                   << " inputs (stale: ./workbook differential --write)");
    auto cases = inputs<Spec>(seed);
    int differing = 0, ambiguousAccepted = 0;
    std::string first;
    bool firstExact = false;  // an input built for exact arithmetic reads best: shown first
    for (size_t i = 0; i < cases.size(); ++i) {
        std::string_view line = lines[i + 1];
        Flags flags;
        if (!line.empty() && line[0] == '@') {
            size_t end = line.find(' ');
            std::string_view f = line.substr(1, end - 1);
            flags.nan = f.find('n') != std::string_view::npos;
            flags.ambiguous = f.find('?') != std::string_view::npos;
            size_t tilde = f.find('~');
            if (tilde != std::string_view::npos)
                std::from_chars(f.data() + tilde + 1, f.data() + f.size(), flags.scale);
            line = end == std::string_view::npos ? std::string_view() : line.substr(end + 1);
        }
        auto expected = parseRecord(line);
        if (!expected) FAIL("the data of " << Spec::name << " has a malformed line " << i + 2);
        Record got;
        if (flags.nan) {
            // The reference itself makes a NaN here (a documented robust path, or a NaN
            // input): no traps for this input.
            test::FpTrapsOff off;
            got = runGuarded<Spec>(cases[i].input);
        } else {
            got = runGuarded<Spec>(cases[i].input);
        }
        std::string why = compareCase<Spec>(cases[i].input, got, *expected, flags.scale);
        if (why.empty()) continue;
        if (flags.ambiguous && !sameDecisions(got, *expected)) {
            ++ambiguousAccepted;  // within rounding of the boundary: either answer
            continue;
        }
        ++differing;
        if (first.empty() || (cases[i].exact && !firstExact)) {
            firstExact = cases[i].exact;
            first = "input " + std::to_string(i + 1) + " of " + std::to_string(cases.size()) +
                    " (" + cases[i].family + (cases[i].exact ? ", exact arithmetic" : "") +
                    ")\n  given: " + Spec::given(cases[i].input) +
                    "\n  came back: " + showRecord<Spec>(got) +
                    "\n  expected: " + showRecord<Spec>(*expected) + "\n  (" + why + ")";
        }
    }
    INFO("exercise " << std::string(Spec::exercise) << " (" << std::string(Spec::name)
                     << ") against the reference's answers on " << cases.size()
                     << " generated inputs: " << differing << " differ; the first"
                     << std::string(firstExact ? " built for exact arithmetic" : "") << ": "
                     << first);
    CHECK(differing == 0);
    (void)ambiguousAccepted;
}

// The data sets shipped with the tree (tests/differential/data/NAME.txt); the folder's path
// is in a file tests/differential/CMakeLists.txt generates, not in the test files.
std::string dataFolder();
inline std::string readData(const std::string& name) {
    return test::readText(dataFolder() + "/" + name + ".txt");
}
// The check on the shipped data set of SPEC.
template <typename Spec>
void checkShipped() {
    check<Spec>(readData(Spec::name));
}

}  // namespace boxes::differential
