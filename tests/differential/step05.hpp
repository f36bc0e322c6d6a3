// Step 05's exercises on generated inputs (harness.hpp says how).
#pragma once

#include "05_efficiency/lab.hpp"
#include "05_efficiency/progressive.hpp"
#include "differential/step03.hpp"

namespace boxes::differential {

// ---- 5.1 to 5.3: the sine table -------------------------------------------------------------

struct FillSinTableSpec {
    static constexpr const char* name = "5.1";
    static constexpr const char* exercise = "5.1";
    static constexpr int count = 100;
    using Input = int;
    static Case<Input> make(Rng& rng, int index) {
        if (index < 36)
            return {index - 4, index < 6 ? "fewer than 2 entries (refused)" : "n from 2 to 31",
                    true};
        return {rng.range(32, 5000), "a large table (a sample of its entries)", true};
    }
    // Every entry of small tables; of large ones the first, the quarters, the last two and
    // a few between.
    static Record run(const Input& n) {
        auto table = fillSinTable(n);
        Record r;
        r.i(int64_t(table.size()));
        std::vector<size_t> at;
        if (table.size() <= 32) {
            for (size_t i = 0; i < table.size(); ++i) at.push_back(i);
        } else {
            size_t m = table.size() - 1;
            at = {0, 1, m / 4, m / 3, m / 2, 3 * m / 4, m - 1, m, 7 * m / 11};
        }
        // Each entry the float nearest to the sine (in double, then rounded once).
        for (size_t i : at) r.f(i < table.size() ? table[i] : kInfinity<float>, 0.0, 0x1p-30);
        return r;
    }
    static std::string given(const Input& n) { return "n = " + std::to_string(n); }
    static std::string show(const Record& r) {
        if (r.size() < 1) return "the numbers " + serialize(r);
        std::string s = num(int64_t(r[0])) + " entries:";
        for (size_t i = 1; i < r.size() && i < 12; ++i) s += " " + num(float(r[i]));
        return r.size() > 12 ? s + " ..." : s;
    }
    static void perturb(Input&, Rng&) {}
};

struct SinLookup {
    std::vector<float> entries;  // n + 1, the last equal to the first
    float radians = 0.0f;
};

// A table of n arbitrary entries (not sines: an entry read from the wrong index shows), and
// angles anywhere: in [0, 2 pi), negative, far beyond 2 pi, at entries and between them.
inline Case<SinLookup> sinLookupCase(Rng& rng, int) {
    SinLookup in;
    int n = rng.chance(30) ? rng.range(2, 8) : rng.range(9, 720);
    for (int i = 0; i < n; ++i) in.entries.push_back(float(rng.grid(-1024, 1024)) / 1024.0f);
    in.entries.push_back(in.entries[0]);
    double step = 2.0 * M_PI / n;
    const char* family = "an angle in [0, 2 pi)";
    switch (rng.below(8)) {
        case 0:
            in.radians = float(-rng.uniform(0.0, 4.0 * M_PI));
            family = "a negative angle";
            break;
        case 1:
            in.radians = float(rng.uniform(-1e4, 1e4));
            family = "an angle far beyond one turn";
            break;
        case 2:
            in.radians = float(rng.range(-2 * n, 2 * n) * step);
            family = "an angle at an entry";
            break;
        case 3:
            in.radians = float((rng.range(-2 * n, 2 * n) + 0.5) * step);
            family = "an angle halfway between entries";
            break;
        case 4:
            in.radians = float(rng.pick({0.0, -0.0, 2.0 * M_PI, -2.0 * M_PI, 2.0 * M_PI - 1e-6}));
            family = "0, -0 and one turn";
            break;
        default:
            in.radians = float(rng.uniform(0.0, 2.0 * M_PI));
    }
    return {in, family, false};
}

inline std::string givenLookup(const SinLookup& in) {
    std::string s = "a table of n = " + std::to_string(in.entries.size() - 1) + " entries (";
    for (size_t i = 0; i < in.entries.size() && i < 10; ++i)
        s += (i ? ", " : "") + num(in.entries[i]);
    if (in.entries.size() > 10) s += ", ...";
    return s + "), radians = " + num(in.radians);
}

template <bool Interpolated>
struct SinTableSpec {
    static constexpr const char* name = Interpolated ? "5.3" : "5.2";
    static constexpr const char* exercise = Interpolated ? "5.3" : "5.2";
    static constexpr int count = 2000;
    using Input = SinLookup;
    static Case<Input> make(Rng& rng, int index) { return sinLookupCase(rng, index); }
    static Record run(const Input& in) {
        SinTable table(in.entries);
        if (Interpolated) return Record().f(table.sinInterpolated(in.radians), 0x1p-20, 0x1p-20);
        return Record().f(table.sinNearest(in.radians));
    }
    static std::string given(const Input& in) { return givenLookup(in); }
    static std::string show(const Record& r) {
        if (r.size() != 1) return "the numbers " + serialize(r);
        return num(float(r[0]));
    }
    static void perturb(Input& in, Rng& rng) { in.radians = nudge(in.radians, rng); }
};

// ---- 5.4 early out ---------------------------------------------------------------------------

struct AnyHitInput {
    int count = 0;
    std::vector<int> blockers;  // the primitives that block
    uint64_t testsBefore = 0;   // the counter as the caller hands it in
};

struct EarlyOutSpec {
    static constexpr const char* name = "5.4";
    static constexpr const char* exercise = "5.4";
    static constexpr int count = 1500;
    using Input = AnyHitInput;
    static Case<Input> make(Rng& rng, int) {
        Input in;
        in.count = rng.chance(10) ? rng.range(0, 1) : rng.range(2, 60);
        int blockers = rng.chance(25) ? 0 : rng.range(1, 4);
        for (int i = 0; i < blockers && in.count > 0; ++i)
            in.blockers.push_back(rng.below(in.count));
        if (rng.chance(20) && in.count > 0) in.blockers = {in.count - 1};
        in.testsBefore = rng.chance(20) ? 0 : uint64_t(rng.range(1, 100000));
        const char* family = in.blockers.empty() ? "nothing blocks" : "some primitives block";
        return {in, in.testsBefore ? family : "the counter handed in at 0", true};
    }
    // The answer, the counter after the call, the calls made and the last primitive tested.
    static Record run(const Input& in) {
        int64_t calls = 0, last = -1;
        uint64_t tests = in.testsBefore;
        bool hit = anyHit(
            size_t(in.count),
            [&](size_t i) {
                ++calls;
                last = int64_t(i);
                return std::find(in.blockers.begin(), in.blockers.end(), int(i)) !=
                       in.blockers.end();
            },
            tests);
        return Record().i(hit).i(int64_t(tests)).i(calls).i(last);
    }
    static std::string given(const Input& in) {
        std::string s = std::to_string(in.count) + " primitives, blocking:";
        for (int b : in.blockers) s += " " + std::to_string(b);
        if (in.blockers.empty()) s += " none";
        return s + "; the counter handed in at " + std::to_string(in.testsBefore);
    }
    static std::string show(const Record& r) {
        if (r.size() != 4) return "the numbers " + serialize(r);
        return std::string(r[0] ? "blocked (true)" : "not blocked (false)") + ", the counter at " +
               num(int64_t(r[1])) + ", " + num(int64_t(r[2])) + " primitives tested, the last " +
               num(int64_t(r[3]));
    }
    static void perturb(Input&, Rng&) {}
};

// ---- 5.5 the light's radius -------------------------------------------------------------------

struct LightRadiusInput {
    Vec3 intensity{1.0f};
    float threshold = PointLight::kHalfStep8;
};

struct LightRadiusSpec {
    static constexpr const char* name = "5.5";
    static constexpr const char* exercise = "5.5";
    static constexpr int count = 1500;
    using Input = LightRadiusInput;
    static Case<Input> make(Rng& rng, int index) {
        Input in;
        const char* family = "a random light";
        if (index % 2 == 0) {
            in.intensity = Vec3(float(rng.grid(0, 64, 2)), float(rng.grid(0, 64, 2)),
                                float(rng.grid(0, 64, 2)));
            in.threshold = float(rng.power(-12, 0));
            family = "intensities and thresholds on a grid";
        } else {
            in.intensity = Vec3(float(rng.logUniform(-8, 8)), float(rng.logUniform(-8, 8)),
                                float(rng.logUniform(-8, 8)));
            if (rng.chance(20)) in.intensity[rng.below(3)] = 0.0f;
            in.threshold = rng.chance(30) ? PointLight::kHalfStep8 : float(rng.logUniform(-20, 2));
        }
        int kind = rng.below(12);
        if (kind == 0) {
            in.threshold = float(rng.pick({0.0, -0.0, -1.0, -1e-30}));
            family = "a threshold that is not positive (refused)";
        } else if (kind == 1) {
            in.threshold = std::numeric_limits<float>::quiet_NaN();
            family = "a NaN threshold (refused)";
        } else if (kind == 2) {
            in.intensity = Vec3(0.0f);
            family = "a black light (radius 0)";
        }
        return {in, family, index % 2 == 0};
    }
    static Record run(const Input& in) {
        return Record().f(finiteLightRadius(in.intensity, in.threshold), 0x1p-20);
    }
    static std::string given(const Input& in) {
        return "intensity " + vec(in.intensity) + ", threshold " + num(in.threshold);
    }
    static std::string show(const Record& r) {
        if (r.size() != 1) return "the numbers " + serialize(r);
        return "radius " + num(float(r[0]));
    }
    static void perturb(Input& in, Rng& rng) {
        in.intensity = nudge(in.intensity, rng);
        in.threshold = nudge(in.threshold, rng);
    }
};

// ---- 5.6 the reciprocal slab test, 5.7 precomputed triangles --------------------------------------

struct ReciprocalSlabSpec {
    static constexpr const char* name = "5.6";
    static constexpr const char* exercise = "5.6";
    static constexpr int count = 2000;
    using Input = RayBox<float>;
    static Case<Input> make(Rng& rng, int index) {
        return index % 2 == 0 ? exactRayBox<float>(rng) : randomRayBox<float>(rng);
    }
    static Record run(const Input& in) {
        auto t = slabReciprocal(precomputeRay(in.ray.ray()), Bounds3f(in.lo, in.hi));
        if (!t) return Record::absent();
        return Record().f(*t, 0x1p-23);
    }
    static std::string given(const Input& in) {
        return differential::given(in) + " (the ray prepared by precomputeRay: 1/D and the signs)";
    }
    static std::string show(const Record& r) {
        if (r.state == Record::Absent) return "a miss (nullopt)";
        if (r.size() != 1) return "the numbers " + serialize(r);
        return "the entry t = " + num(float(r[0]));
    }
    static void perturb(Input& in, Rng& rng) { differential::perturb(in, rng); }
};

struct PrecomputedTriangleSpec {
    static constexpr const char* name = "5.7";
    static constexpr const char* exercise = "5.7";
    static constexpr int count = 2000;
    using Input = RayTriangle<float>;
    static Case<Input> make(Rng& rng, int index) { return rayTriangleCase<float>(rng, index); }
    // Bit for bit the test from the vertices: compared exactly.
    static Record run(const Input& in) {
        auto h = intersectPrecomputed(in.ray.ray(), precomputeTriangle({in.a, in.b, in.c}));
        if (!h) return Record::absent();
        return Record().f(h->t).f(h->u).f(h->v);
    }
    static std::string given(const Input& in) {
        return differential::given(in) + " (prepared by precomputeTriangle)";
    }
    static std::string show(const Record& r) { return showHit<float>(r); }
    static void perturb(Input& in, Rng& rng) { differential::perturb(in, rng); }
};

// ---- 5.8 the inverse square root ---------------------------------------------------------------

struct InverseSqrtSpec {
    static constexpr const char* name = "5.8";
    static constexpr const char* exercise = "5.8";
    static constexpr int count = 1500;
    using Input = float;
    // Positive normal floats (the contract): every exponent, powers of two and of four,
    // mantissas at their ends.
    static Case<Input> make(Rng& rng, int index) {
        if (index % 3 == 0) {
            float x = float(std::ldexp(1.0, rng.range(-126, 127)));
            if (rng.chance(30)) x = std::nextafter(x, rng.chance(50) ? 0.0f : kInfinity<float>);
            if (!(x >= std::numeric_limits<float>::min())) x = std::numeric_limits<float>::min();
            return {x, "powers of two and their neighbours", true};
        }
        float x = float(std::ldexp(1.0 + rng.unit(), rng.range(-126, 127)));
        if (!std::isfinite(x)) x = std::numeric_limits<float>::max();
        return {x, "a positive normal float", true};
    }
    static Record run(const Input& x) { return Record().f(approxInverseSqrt(x), 0x1p-20); }
    static std::string given(const Input& x) { return "x = " + num(x); }
    static std::string show(const Record& r) {
        if (r.size() != 1) return "the numbers " + serialize(r);
        return num(float(r[0]));
    }
    static void perturb(Input& x, Rng& rng) { x = nudge(x, rng); }
};

// ---- 5.9 line by line within a budget, 5.10 the adaptive resolution ------------------------------

struct RefineInput {
    int height = 4;
    std::vector<double> lineCost;  // seconds per row (dyadic: every sum is exact)
    std::vector<double> budgets;   // one advance() each
};

struct RefineSpec {
    static constexpr const char* name = "5.9";
    static constexpr const char* exercise = "5.9";
    static constexpr int count = 1500;
    using Input = RefineInput;
    static Case<Input> make(Rng& rng, int) {
        Input in;
        in.height = rng.range(1, 24);
        bool even = rng.chance(40);
        double common = rng.grid(1, 16) / 64.0;
        for (int y = 0; y < in.height; ++y)
            in.lineCost.push_back(even ? common : rng.grid(0, 16) / 64.0);
        int calls = rng.range(1, 8);
        for (int i = 0; i < calls; ++i)
            in.budgets.push_back(rng.chance(15) ? 0.0 : rng.grid(0, 64) / 64.0);
        return {
            in,
            even ? "every line costs the same (budgets met exactly)" : "lines of different cost",
            true};
    }
    // Per call the lines it returned; then the rows in the order they were rendered (each
    // once, top to bottom: 1) and whether the image is complete.
    static Record run(const Input& in) {
        double now = 0.0;
        std::vector<int> rows;
        IncrementalRenderer r(
            2, in.height,
            [&](Image&, int row) {
                rows.push_back(row);
                now += row >= 0 && row < in.height ? in.lineCost[size_t(row)] : 1.0;
            },
            [&] { return now; });
        Record out;
        for (double b : in.budgets) out.i(r.advance(b));
        bool inOrder = true;
        for (size_t i = 0; i < rows.size(); ++i) inOrder = inOrder && rows[i] == int(i);
        return out.i(inOrder).i(r.complete());
    }
    static std::string given(const Input& in) {
        std::string s = std::to_string(in.height) + " rows costing";
        for (double c : in.lineCost) s += " " + num(c);
        s += " s; advance() called with budgets";
        for (double b : in.budgets) s += " " + num(b);
        return s + " s (a clock that moves only while a line renders)";
    }
    static std::string show(const Record& r) {
        if (r.size() < 2) return "the numbers " + serialize(r);
        std::string s = "lines per call:";
        for (size_t i = 0; i + 2 < r.size(); ++i) s += " " + num(int64_t(r[i]));
        s += r[r.size() - 2] ? ", rows in order" : ", rows out of order or repeated";
        return s + (r[r.size() - 1] ? ", complete" : ", not complete");
    }
    static void perturb(Input&, Rng&) {}
};

struct AdaptiveInput {
    double target = 1.0 / 60.0;
    float minScale = 0.125f, maxScale = 1.0f;
    std::vector<double> frames;
};

struct AdaptiveSpec {
    static constexpr const char* name = "5.10";
    static constexpr const char* exercise = "5.10";
    static constexpr int count = 1000;
    using Input = AdaptiveInput;
    static Case<Input> make(Rng& rng, int) {
        Input in;
        in.target = rng.logUniform(-8, 0);
        in.minScale = float(rng.pick({0.125, 0.25, 0.05}));
        in.maxScale = float(rng.pick({1.0, 0.5, 2.0}));
        int frames = rng.range(1, 8);
        const char* family = "frame times around the target";
        for (int i = 0; i < frames; ++i) {
            double f = in.target * rng.logUniform(-4, 3);
            int kind = rng.below(14);
            if (kind == 0)
                f = rng.pick({0.0, -0.0, -in.target});
            else if (kind == 1)
                f = std::numeric_limits<double>::quiet_NaN();
            else if (kind == 2)
                f = kInfinity<double>;
            else if (kind == 3)
                f = in.target;
            if (kind <= 2) family = "frame times that are not positive, NaN or infinite (ignored)";
            in.frames.push_back(f);
        }
        return {in, family, false};
    }
    static Record run(const Input& in) {
        AdaptiveResolution a(in.target, in.minScale, in.maxScale);
        Record r;
        for (double f : in.frames) {
            a.update(f);
            r.f(a.scale(), 0x1p-20);
        }
        return r;
    }
    static std::string given(const Input& in) {
        std::string s = "target " + num(in.target) + " s, scales " + num(in.minScale) + " to " +
                        num(in.maxScale) + "; frames of";
        for (double f : in.frames) s += " " + num(f);
        return s + " s";
    }
    static std::string show(const Record& r) {
        std::string s = "scales after each frame:";
        for (size_t i = 0; i < r.size(); ++i) s += " " + num(float(r[i]));
        return s;
    }
    static void perturb(Input& in, Rng& rng) {
        for (double& f : in.frames) f = nudge(f, rng);
    }
};

using SinNearestSpec = SinTableSpec<false>;
using SinInterpolatedSpec = SinTableSpec<true>;
#define BOXES_DIFFERENTIAL_STEP05(X)                                                    \
    X(FillSinTableSpec)                                                                 \
    X(SinNearestSpec)                                                                   \
    X(SinInterpolatedSpec)                                                              \
    X(EarlyOutSpec) X(LightRadiusSpec) X(ReciprocalSlabSpec) X(PrecomputedTriangleSpec) \
        X(InverseSqrtSpec) X(RefineSpec) X(AdaptiveSpec)

}  // namespace boxes::differential
