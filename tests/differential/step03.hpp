// Step 03's exercises on generated inputs (harness.hpp says how).
#pragma once

#include "03_aabb/aabb.hpp"
#include "differential/step01.hpp"

namespace boxes::differential {

template <typename T>
std::string given(const Bounds3T<T>& b) {
    return "[" + vec(b.min) + ", " + vec(b.max) + "]";
}

template <typename T>
void perturb(Bounds3T<T>& b, Rng& rng) {
    b.min = nudge(b.min, rng);
    b.max = nudge(b.max, rng);
}

// A box as six exact values (min, max).
template <typename T>
Record boundsRecord(const Bounds3T<T>& b) {
    return Record().v3(b.min).v3(b.max);
}

template <typename T>
std::string showBounds(const Record& r) {
    if (r.size() != 6) return "the numbers " + serialize(r);
    return "the box [(" + num(T(r[0])) + ", " + num(T(r[1])) + ", " + num(T(r[2])) + "), (" +
           num(T(r[3])) + ", " + num(T(r[4])) + ", " + num(T(r[5])) + ")]";
}

// A point on the quarter grid (zeros of either sign) or at random at a scale.
template <typename T>
Vec3T<T> gridPoint(Rng& rng, int half = 4) {
    Vec3d p;
    for (int k = 0; k < 3; ++k) {
        p[k] = rng.grid(-half, half, 2);
        if (p[k] == 0.0) p[k] = signedZero(rng);
    }
    return Vec3T<T>(p);
}
template <typename T>
Vec3T<T> randomPoint(Rng& rng, double scale) {
    return Vec3T<T>(rng.inCube(4.0) * scale);
}
template <typename T>
double randomScale(Rng& rng) {
    if (rng.chance(10))
        return std::is_same_v<T, float> ? rng.logUniform(100, 120) : rng.logUniform(900, 1000);
    return rng.logUniform(-8, 8);
}

// ---- 3.1 to 3.4: bounds and unions ----------------------------------------------------------

template <typename T>
struct SphereBoundsSpec {
    static constexpr const char* name = std::is_same_v<T, float> ? "3.1-float" : "3.1-double";
    static constexpr const char* exercise = "3.1";
    static constexpr int count = std::is_same_v<T, float> ? 600 : 200;
    using Input = SphereT<T>;
    static Case<Input> make(Rng& rng, int index) {
        if (index % 2 == 0) {
            Input s{gridPoint<T>(rng), T(rng.chance(15) ? 0.0 : rng.grid(0, 4, 2))};
            return {s, s.radius == T(0) ? "a sphere of radius 0" : "a sphere on the quarter grid",
                    true};
        }
        double scale = randomScale<T>(rng);
        Input s{randomPoint<T>(rng, scale), T(rng.uniform(0.0, 2.0) * scale)};
        return {s, scale > 1e30 ? "a huge sphere (centre + r may overflow)" : "a random sphere",
                false};
    }
    static Record run(const Input& s) { return boundsRecord(sphereBounds(s)); }
    static std::string given(const Input& s) {
        return "sphere centre " + vec(s.centre) + ", radius " + num(s.radius) + " (" +
               kPrecision<T> + ")";
    }
    static std::string show(const Record& r) { return showBounds<T>(r); }
    static void perturb(Input& s, Rng& rng) {
        s.centre = nudge(s.centre, rng);
        s.radius = nudge(s.radius, rng);
    }
};

template <typename T>
struct TriangleBoundsSpec {
    static constexpr const char* name = std::is_same_v<T, float> ? "3.2-float" : "3.2-double";
    static constexpr const char* exercise = "3.2";
    static constexpr int count = std::is_same_v<T, float> ? 600 : 200;
    using Input = Triangle3<T>;
    static Case<Input> make(Rng& rng, int index) {
        if (index % 2 == 0) {
            Input t{gridPoint<T>(rng, 2), gridPoint<T>(rng, 2), gridPoint<T>(rng, 2)};
            if (rng.chance(20)) t.c = t.a;
            return {t, "a triangle on the quarter grid (ties, zeros of either sign)", true};
        }
        double scale = randomScale<T>(rng);
        return {
            {randomPoint<T>(rng, scale), randomPoint<T>(rng, scale), randomPoint<T>(rng, scale)},
            "a random triangle",
            false};
    }
    static Record run(const Input& t) {
        return boundsRecord(triangleBounds(TriangleT<T>{t.a, t.b, t.c}));
    }
    static std::string given(const Input& t) {
        return "triangle a = " + vec(t.a) + ", b = " + vec(t.b) + ", c = " + vec(t.c) + " (" +
               kPrecision<T> + ")";
    }
    static std::string show(const Record& r) { return showBounds<T>(r); }
    static void perturb(Input& t, Rng& rng) {
        t.a = nudge(t.a, rng);
        t.b = nudge(t.b, rng);
        t.c = nudge(t.c, rng);
    }
};

struct MeshBoundsSpec {
    static constexpr const char* name = "3.3";
    static constexpr const char* exercise = "3.3";
    static constexpr int count = 500;
    using Input = Mesh;
    static Case<Input> make(Rng& rng, int index) {
        Mesh m;
        bool exact = index % 2 == 0;
        double scale = exact ? 1.0 : randomScale<float>(rng);
        int vertices = rng.range(1, 12);
        for (int i = 0; i < vertices; ++i)
            m.positions.push_back(exact ? gridPoint<float>(rng) : randomPoint<float>(rng, scale));
        int triangles = rng.chance(10) ? 0 : rng.range(1, 6);
        for (int i = 0; i < triangles; ++i)
            m.triangles.push_back({uint32_t(rng.below(vertices)), uint32_t(rng.below(vertices)),
                                   uint32_t(rng.below(vertices))});
        // Vertices no triangle uses, far outside: they must not count.
        int unused = rng.range(0, 3);
        for (int i = 0; i < unused; ++i)
            m.positions.push_back(exact ? gridPoint<float>(rng, 40)
                                        : randomPoint<float>(rng, 100 * scale));
        const char* family = triangles == 0 ? "a mesh without triangles (the empty box)"
                             : unused       ? "a mesh with vertices no triangle uses"
                                            : "a mesh";
        return {m, family, exact};
    }
    static Record run(const Input& m) { return boundsRecord(meshBounds(m)); }
    static std::string given(const Input& m) {
        std::string s = "mesh positions";
        for (size_t i = 0; i < m.positions.size(); ++i)
            s += (i ? ", " : " ") + std::to_string(i) + ": " + vec(m.positions[i]);
        s += "; triangles";
        for (const auto& t : m.triangles)
            s += " (" + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " +
                 std::to_string(t[2]) + ")";
        return m.triangles.empty() ? s + " none" : s;
    }
    static std::string show(const Record& r) { return showBounds<float>(r); }
    static void perturb(Input& m, Rng& rng) {
        for (auto& p : m.positions) p = nudge(p, rng);
    }
};

template <typename T>
struct BoxPair {
    Bounds3T<T> a, b;
};

template <typename T>
Bounds3T<T> gridBox(Rng& rng, int half = 3) {
    Vec3T<T> lo = gridPoint<T>(rng, half), hi;
    for (int k = 0; k < 3; ++k) hi[k] = lo[k] + T(rng.grid(0, 3, 1));
    return {lo, hi};
}

template <typename T>
Bounds3T<T> randomBox(Rng& rng, double scale) {
    Vec3T<T> a = randomPoint<T>(rng, scale), b = randomPoint<T>(rng, scale);
    return {glm::min(a, b), glm::max(a, b)};
}

template <typename T>
struct UnionBoundsSpec {
    static constexpr const char* name = std::is_same_v<T, float> ? "3.4-float" : "3.4-double";
    static constexpr const char* exercise = "3.4";
    static constexpr int count = std::is_same_v<T, float> ? 600 : 200;
    using Input = BoxPair<T>;
    static Case<Input> make(Rng& rng, int index) {
        Input in;
        const char* family = "two boxes on the grid";
        bool exact = index % 2 == 0;
        double scale = randomScale<T>(rng);
        in.a = exact ? gridBox<T>(rng) : randomBox<T>(rng, scale);
        in.b = exact ? gridBox<T>(rng) : randomBox<T>(rng, scale);
        if (!exact) family = "two random boxes";
        int kind = rng.below(10);
        if (kind == 0) {
            in.a = Bounds3T<T>();
            family = "the empty box and a box";
        } else if (kind == 1) {
            in.b = Bounds3T<T>();
            family = "a box and the empty box";
        } else if (kind == 2) {
            // Each box beyond the other on a different axis: every axis its own.
            int axis = rng.below(3);
            in.b.min[axis] = in.a.min[axis] - T(rng.grid(1, 4, 1));
            family = "the second box below the first on one axis only";
        }
        return {in, family, exact};
    }
    static Record run(const Input& in) { return boundsRecord(unionBounds(in.a, in.b)); }
    static std::string given(const Input& in) {
        return "boxes " + differential::given(in.a) + " and " + differential::given(in.b) + " (" +
               kPrecision<T> + ")";
    }
    static std::string show(const Record& r) { return showBounds<T>(r); }
    static void perturb(Input& in, Rng& rng) {
        differential::perturb(in.a, rng);
        differential::perturb(in.b, rng);
    }
};

// ---- 3.5 overlap ----------------------------------------------------------------------------

template <typename T>
struct OverlapsSpec {
    static constexpr const char* name = std::is_same_v<T, float> ? "3.5-float" : "3.5-double";
    static constexpr const char* exercise = "3.5";
    static constexpr int count = std::is_same_v<T, float> ? 2000 : 600;
    using Input = BoxPair<T>;
    static Case<Input> make(Rng& rng, int index) {
        Input in;
        if (index % 2 == 0) {
            // On the grid, each axis on its own: overlapping, touching or apart, either order.
            for (int k = 0; k < 3; ++k) {
                T lo = T(rng.range(-3, 3)), len = T(rng.range(0, 3));
                in.a.min[k] = lo;
                in.a.max[k] = lo + len;
                int relation = rng.below(6);
                T otherLen = T(rng.range(0, 3));
                T start = relation == 0   ? in.a.max[k]                    // touching above
                          : relation == 1 ? in.a.min[k] - otherLen         // touching below
                          : relation == 2 ? in.a.max[k] + T(1)             // apart above
                          : relation == 3 ? in.a.min[k] - otherLen - T(1)  // apart below
                          : relation == 4 ? in.a.min[k] - T(1)             // straddling
                                          : in.a.min[k];                   // inside
                in.b.min[k] = start;
                in.b.max[k] = start + otherLen;
            }
            if (rng.chance(50)) std::swap(in.a, in.b);
            return {in, "boxes on the grid: touching, apart or overlapping per axis", true};
        }
        double scale = randomScale<T>(rng);
        in.a = randomBox<T>(rng, scale);
        in.b = randomBox<T>(rng, scale * rng.uniform(0.2, 1.0));
        return {in, "two random boxes", false};
    }
    static Record run(const Input& in) { return Record().i(overlaps(in.a, in.b)); }
    static std::string given(const Input& in) {
        return "boxes a = " + differential::given(in.a) + " and b = " + differential::given(in.b) +
               " (" + kPrecision<T> + ")";
    }
    static std::string show(const Record& r) {
        if (r.size() != 1) return "the numbers " + serialize(r);
        return r[0] ? "they overlap (true)" : "they do not overlap (false)";
    }
    static void perturb(Input& in, Rng& rng) {
        differential::perturb(in.a, rng);
        differential::perturb(in.b, rng);
    }
};

// ---- 3.6 and 3.7: the slab tests -------------------------------------------------------------

template <typename T, bool Conservative>
struct SlabIntervalSpec {
    static constexpr bool f = std::is_same_v<T, float>;
    static constexpr const char* name =
        Conservative ? (f ? "3.7-float" : "3.7-double") : (f ? "3.6-float" : "3.6-double");
    static constexpr const char* exercise = Conservative ? "3.7" : "3.6";
    static constexpr int count = f ? 2000 : 600;
    using Input = RayBox<T>;
    static Case<Input> make(Rng& rng, int index) {
        if (index % 2 == 1) return randomRayBox<T>(rng);
        auto c = exactRayBox<T>(rng);
        if (rng.chance(8)) {
            // "A NaN coordinate constrains nothing" (the README's hard cases).
            T& at = rng.chance(50) ? c.input.lo[rng.below(3)] : c.input.hi[rng.below(3)];
            at = std::numeric_limits<T>::quiet_NaN();
            c.family = "a NaN box coordinate";
        }
        return c;
    }
    static Record run(const Input& in) {
        SlabRayT<T> ray(in.ray.ray());
        Bounds3T<T> box(in.lo, in.hi);
        auto r = Conservative ? intersectSlabsConservative(ray, box) : intersectSlabs(ray, box);
        if (!r) return Record::absent();
        // About one rounding: a far t not widened, or widened twice, is off by three.
        constexpr double rel = f ? 0x1p-23 : 0x1p-52;
        return Record().real(r->tnear, rel).real(r->tfar, rel);
    }
    static std::string given(const Input& in) {
        return differential::given(in) + " (" + kPrecision<T> + ", as a SlabRayT: 1/D precomputed)";
    }
    static std::string show(const Record& r) {
        if (r.state == Record::Absent) return "a miss (nullopt)";
        if (r.size() != 2) return "the numbers " + serialize(r);
        return "the interval [" + num(T(r[0])) + ", " + num(T(r[1])) + "]";
    }
    static void perturb(Input& in, Rng& rng) { differential::perturb(in, rng); }
};

using SphereBoundsFloat = SphereBoundsSpec<float>;
using SphereBoundsDouble = SphereBoundsSpec<double>;
using TriangleBoundsFloat = TriangleBoundsSpec<float>;
using TriangleBoundsDouble = TriangleBoundsSpec<double>;
using UnionBoundsFloat = UnionBoundsSpec<float>;
using UnionBoundsDouble = UnionBoundsSpec<double>;
using OverlapsFloat = OverlapsSpec<float>;
using OverlapsDouble = OverlapsSpec<double>;
using SlabsFloat = SlabIntervalSpec<float, false>;
using SlabsDouble = SlabIntervalSpec<double, false>;
using SlabsConservativeFloat = SlabIntervalSpec<float, true>;
using SlabsConservativeDouble = SlabIntervalSpec<double, true>;
#define BOXES_DIFFERENTIAL_STEP03(X)                                                              \
    X(SphereBoundsFloat)                                                                          \
    X(SphereBoundsDouble)                                                                         \
    X(TriangleBoundsFloat)                                                                        \
    X(TriangleBoundsDouble)                                                                       \
    X(MeshBoundsSpec) X(UnionBoundsFloat) X(UnionBoundsDouble) X(OverlapsFloat) X(OverlapsDouble) \
        X(SlabsFloat) X(SlabsDouble) X(SlabsConservativeFloat) X(SlabsConservativeDouble)

}  // namespace boxes::differential
