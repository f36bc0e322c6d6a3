// Step 01's exercises on generated inputs (harness.hpp says how).
#pragma once

#include "01_triangle/triangle.hpp"
#include "differential/inputs.hpp"

namespace boxes::differential {

// The stated bounds: about 64 ulps of the routine's own precision, relative to the value or
// (for t and d) to the scene's size; inputs where a few ulps move a value further get a
// wider bound in the data (@~K).
template <typename T>
constexpr double kRel = std::is_same_v<T, float> ? 0x1p-17 : 0x1p-42;
template <typename T>
constexpr const char* kPrecision = std::is_same_v<T, float> ? "float" : "double";

template <typename T>
double sceneSize(std::initializer_list<Vec3T<T>> points) {
    double s = 0.0;
    for (const auto& p : points)
        s = std::max({s, std::fabs(double(p.x)), std::fabs(double(p.y)), std::fabs(double(p.z))});
    return s;
}

template <typename T>
std::string showHit(const Record& r) {
    if (r.state == Record::Absent) return "a miss (nullopt)";
    if (r.size() != 3) return "the numbers " + serialize(r);
    return "a hit at t = " + num(T(r[0])) + ", u = " + num(T(r[1])) + ", v = " + num(T(r[2]));
}

template <typename T, typename Hit>
Record hitRecord(const std::optional<Hit>& h, const RayTriangle<T>& in) {
    if (!h) return Record::absent();
    double tScale = sceneSize<T>({in.ray.origin, in.a, in.b, in.c}) /
                    std::max(1e-300, double(glm::length(Vec3d(in.ray.direction))));
    return Record()
        .real(h->t, kRel<T>, kRel<T> * tScale)
        .real(h->u, 0.0, kRel<T>)
        .real(h->v, 0.0, kRel<T>);
}

// An edge function that float rounds to exactly 0 although it is not (its two products
// differ below float's rounding), with the other two of the other sign: the ray passes just
// outside the edge, which only the recomputation in double sees (Woop et al., section 3.3).
// A miss; a float recomputation calls it a hit on the edge.
template <typename T>
Case<RayTriangle<T>> edgeRoundsToZero(Rng& rng) {
    const double e = 0x1p-20;
    const double candidates[4][2] = {{2, -1}, {-2, 1}, {1, -3}, {-3, 2}};
    for (;;) {
        Vec3d b(1.0, 1.0 + rng.range(-3, 3) * e, 1.0);
        Vec3d c(-(1.0 + rng.range(-3, 3) * e), -(1.0 + rng.range(-3, 3) * e), 1.0);
        const double* pick = candidates[rng.below(4)];
        Vec3d a(pick[0], pick[1], 1.0);
        // The edge functions at the origin (products of floats: exact in double).
        double u = c.x * b.y - c.y * b.x, v = a.x * c.y - a.y * c.x, w = b.x * a.y - b.y * a.x;
        float uf = float(c.x) * float(b.y) - float(c.y) * float(b.x);
        bool outside = (u > 0 && v < 0 && w < 0) || (u < 0 && v > 0 && w > 0);
        if (u == 0.0 || uf != 0.0f || !outside) continue;
        AxisMap m = AxisMap::random(rng);
        RayTriangle<T> in;
        in.a = Vec3T<T>(m.apply(a));
        in.b = Vec3T<T>(m.apply(b));
        in.c = Vec3T<T>(m.apply(c));
        if (rng.chance(50)) std::swap(in.b, in.c);
        in.ray.origin = Vec3T<T>(0);
        in.ray.direction = Vec3T<T>(m.apply(Vec3d(signedZero(rng), signedZero(rng), 1.0)));
        return {in, "an edge function that float rounds to 0 (just outside the edge)", true};
    }
}

// Half exact families, half random. Scenes reach 2^40 and 2^-20 in float (2^300 and 2^-300
// in double), where every product stays within range; the watertight test's float scenes
// reach 2^66 (its products overflow float: the fallback in double) and 2^-60 (t underflows).
// One input in ten of Moller-Trumbore's and the watertight test's is a triangle so far out
// (2^70 in float, 2^540 in double) that the determinant overflows: no hit (the test's
// guard on a determinant that is not finite), or the watertight test's fallback in float.
template <typename T>
Case<RayTriangle<T>> rayTriangleCase(Rng& rng, int index, int exercise = 3) {
    constexpr bool isFloat = std::is_same_v<T, float>;
    if (index % 2 == 0) {
        if (exercise == 5 && isFloat && index % 10 == 4) return edgeRoundsToZero<T>(rng);
        return exactRayTriangle<T>(rng);
    }
    if (exercise >= 4 && index % 20 == 9) {
        auto c = isFloat ? randomRayTriangle<T>(rng, 74, -20, 8)
                         : randomRayTriangle<T>(rng, 548, -300, 8);
        c.family = "a triangle so far out that the determinant overflows";
        return c;
    }
    if (!isFloat) return randomRayTriangle<T>(rng, 300, -300);
    return exercise == 5 ? randomRayTriangle<T>(rng, 66, -60) : randomRayTriangle<T>(rng, 40, -20);
}

// ---- 1.1 the triangle's plane --------------------------------------------------------------

template <typename T>
struct Triangle3 {
    Vec3T<T> a{0}, b{0}, c{0};
};

template <typename T>
struct TrianglePlaneSpec {
    static constexpr const char* name = std::is_same_v<T, float> ? "1.1-float" : "1.1-double";
    static constexpr const char* exercise = "1.1";
    static constexpr int count = std::is_same_v<T, float> ? 800 : 300;
    using Input = Triangle3<T>;
    static Case<Input> make(Rng& rng, int index) {
        Input in;
        if (index % 2 == 0) {
            // On the integer grid: exact zero area for repeated and collinear vertices.
            Vec3d a(rng.range(-4, 4), rng.range(-4, 4), rng.range(-4, 4));
            Vec3d e1(rng.range(-3, 3), rng.range(-3, 3), rng.range(-3, 3));
            Vec3d e2(rng.range(-3, 3), rng.range(-3, 3), rng.range(-3, 3));
            const char* family = "a triangle on the integer grid";
            int kind = rng.below(8);
            if (kind == 0) {
                e2 = e1 * double(rng.range(-2, 2));
                family = "a degenerate triangle (collinear or repeated vertices)";
            } else if (kind == 1) {
                e1 = Vec3d(rng.range(1, 3), 0, 0);
                e2 = Vec3d(0, rng.range(-3, 3), 0);
                AxisMap m = AxisMap::random(rng);
                e1 = m.apply(e1);
                e2 = m.apply(e2);
                family = "an axis-aligned right triangle";
            }
            in = {Vec3T<T>(a), Vec3T<T>(a + e1), Vec3T<T>(a + e2)};
            return {in, family, true};
        }
        const char* family = "a random triangle";
        int kind = rng.below(8);
        double scale = rng.logUniform(-4, 4);
        if (kind == 0) {
            scale = std::is_same_v<T, float> ? std::ldexp(1.0, rng.range(60, 70))
                                             : std::ldexp(1.0, rng.range(500, 520));
            family = "a huge triangle (the cross product overflows)";
        } else if (kind == 1) {
            scale = std::is_same_v<T, float> ? std::ldexp(1.0, rng.range(-70, -60))
                                             : std::ldexp(1.0, rng.range(-540, -520));
            family = "a tiny triangle (the cross product underflows)";
        }
        Vec3d centre = rng.inCube(4.0) * scale;
        Vec3d a = centre + rng.inCube(1.0) * scale, b = centre + rng.inCube(1.0) * scale;
        Vec3d c = kind == 2 ? a + (b - a) * rng.uniform(-1.0, 2.0) + rng.inCube(1e-6) * scale
                            : centre + rng.inCube(1.0) * scale;
        if (kind == 2) family = "a sliver triangle";
        in = {Vec3T<T>(a), Vec3T<T>(b), Vec3T<T>(c)};
        return {in, family, false};
    }
    static Record run(const Input& in) {
        auto p = trianglePlane(TriangleT<T>{in.a, in.b, in.c});
        if (!p) return Record::absent();
        double size = sceneSize<T>({in.a, in.b, in.c});
        return Record().v3(p->normal, 0.0, kRel<T>).real(p->d, 0.0, kRel<T> * size);
    }
    static std::string given(const Input& in) {
        return "triangle a = " + vec(in.a) + ", b = " + vec(in.b) + ", c = " + vec(in.c) + " (" +
               kPrecision<T> + ")";
    }
    static std::string show(const Record& r) {
        if (r.state == Record::Absent) return "no plane (nullopt)";
        if (r.size() != 4) return "the numbers " + serialize(r);
        return "the plane N = (" + num(T(r[0])) + ", " + num(T(r[1])) + ", " + num(T(r[2])) +
               "), d = " + num(T(r[3]));
    }
    static void perturb(Input& in, Rng& rng) {
        in.a = nudge(in.a, rng);
        in.b = nudge(in.b, rng);
        in.c = nudge(in.c, rng);
    }
};

// ---- 1.2 ray/plane distance ----------------------------------------------------------------

template <typename T>
struct RayPlane {
    RayInput<T> ray;
    Vec3T<T> normal{0, 0, 1};
    T d = T(0);
};

template <typename T>
struct RayPlaneDistanceSpec {
    static constexpr const char* name = std::is_same_v<T, float> ? "1.2-float" : "1.2-double";
    static constexpr const char* exercise = "1.2";
    static constexpr int count = std::is_same_v<T, float> ? 1500 : 500;
    using Input = RayPlane<T>;
    static Case<Input> make(Rng& rng, int index) {
        Input in;
        if (index % 2 == 0) {
            // Axis or small integer normals, integer d, dyadic rays: D.N is exactly 0 for
            // parallel rays, and t is exact.
            const char* family = "a plane and a ray on the grid";
            Vec3d n(0.0);
            n[rng.below(3)] = rng.chance(50) ? 1.0 : -1.0;
            if (rng.chance(40)) n = Vec3d(rng.range(-1, 1), rng.range(-1, 1), rng.range(-1, 1));
            if (isZero(n)) n = Vec3d(0, 1, 0);
            Vec3d o(rng.grid(-4, 4, 2), rng.grid(-4, 4, 2), rng.grid(-4, 4, 2));
            Vec3d d(rng.grid(-2, 2, 1), rng.grid(-2, 2, 1), rng.grid(-2, 2, 1));
            for (int k = 0; k < 3; ++k)
                if (d[k] == 0.0) d[k] = signedZero(rng);
            int kind = rng.below(5);
            if (kind == 0) {
                // Parallel: D.N = 0 (in the plane when O is on it).
                Vec3d any(rng.range(-2, 2), rng.range(-2, 2), rng.range(-2, 2));
                d = glm::cross(n, any);
                family = "a ray parallel to the plane";
            }
            if (isZero(d)) d = Vec3d(0.5, 0.0, signedZero(rng));
            double planeD = rng.range(-4, 4);
            if (kind == 1) {
                planeD = -glm::dot(n, o);  // the origin on the plane: t = 0
                family = "the origin on the plane (t = 0)";
            } else if (kind == 2) {
                // Nearly parallel: D.N a subnormal power of two, so t = -(O.N + d) / (D.N)
                // overflows (no answer); exact, whatever the formula's order.
                n = Vec3d(0.0);
                n[rng.below(3)] = rng.chance(50) ? 1.0 : -1.0;
                d = Vec3d(signedZero(rng), signedZero(rng), signedZero(rng));
                d[(n.x != 0   ? 0
                   : n.y != 0 ? 1
                              : 2)] = rng.power(std::is_same_v<T, float> ? -140 : -1060,
                                                std::is_same_v<T, float> ? -135 : -1055, true);
                d[(n.x != 0 ? 1 : 0)] = 1.0;
                planeD = rng.range(1, 4) - glm::dot(n, o);
                family = "a ray so nearly parallel that t overflows (no answer)";
            }
            in.ray.origin = Vec3T<T>(o);
            in.ray.direction = Vec3T<T>(d);
            in.normal = Vec3T<T>(n);
            in.d = T(planeD);
            return {in, family, true};
        }
        const char* family = "a random plane and ray";
        double scale = rng.logUniform(-4, 4);
        Vec3d n = rng.direction();
        Vec3d d = rng.direction();
        int kind = rng.below(6);
        if (kind == 0) {
            d = glm::normalize(glm::cross(n, rng.direction())) + rng.logUniform(-30, -8) * n;
            family = "a grazing ray (D.N tiny)";
        } else if (kind == 1 && std::is_same_v<T, float>) {
            d = glm::normalize(glm::cross(n, rng.direction())) + rng.logUniform(-60, -50) * n;
            scale = std::ldexp(1.0, rng.range(20, 40));
            family = "a plane so far along a grazing ray that t overflows";
        }
        in.ray.origin = Vec3T<T>(rng.inCube(4.0) * scale);
        in.ray.direction = Vec3T<T>(d * rng.logUniform(-2, 2));
        in.normal = Vec3T<T>(n * (rng.chance(20) ? rng.logUniform(-3, 3) : 1.0));
        in.d = T(rng.uniform(-4.0, 4.0) * scale);
        if (isZero(in.ray.direction)) in.ray.direction = Vec3T<T>(1, 0, 0);
        return {in, family, false};
    }
    static Record run(const Input& in) {
        auto t = rayPlaneDistance(in.ray.ray(), PlaneT<T>{in.normal, in.d});
        if (!t) return Record::absent();
        double size = (sceneSize<T>({in.ray.origin}) + std::fabs(double(in.d))) /
                      std::max(1e-300, double(glm::length(Vec3d(in.ray.direction))));
        return Record().real(*t, kRel<T>, kRel<T> * size);
    }
    static std::string given(const Input& in) {
        return differential::given(in.ray) + "; plane N = " + vec(in.normal) +
               ", d = " + num(in.d) + " (" + kPrecision<T> + ")";
    }
    static std::string show(const Record& r) {
        if (r.state == Record::Absent) return "no distance (nullopt)";
        if (r.size() != 1) return "the numbers " + serialize(r);
        return "t = " + num(T(r[0]));
    }
    static void perturb(Input& in, Rng& rng) {
        differential::perturb(in.ray, rng);
        in.normal = nudge(in.normal, rng);
        in.d = nudge(in.d, rng);
    }
};

// ---- 1.3, 1.4, 1.5: rays and triangles -------------------------------------------------------

template <typename T>
struct InsideEdgePlanesSpec {
    static constexpr const char* name = std::is_same_v<T, float> ? "1.3-float" : "1.3-double";
    static constexpr const char* exercise = "1.3";
    static constexpr int count = std::is_same_v<T, float> ? 1500 : 500;
    using Input = RayTriangle<T>;
    static Case<Input> make(Rng& rng, int index) { return rayTriangleCase<T>(rng, index); }
    static Record run(const Input& in) {
        auto uv = insideEdgePlanes(in.ray.ray(), TriangleT<T>{in.a, in.b, in.c});
        if (!uv) return Record::absent();
        return Record().real(uv->x, 0.0, kRel<T>).real(uv->y, 0.0, kRel<T>);
    }
    static std::string given(const Input& in) {
        return differential::given(in) + " (" + kPrecision<T> + ")";
    }
    static std::string show(const Record& r) {
        if (r.state == Record::Absent) return "outside (nullopt)";
        if (r.size() != 2) return "the numbers " + serialize(r);
        return "inside at u = " + num(T(r[0])) + ", v = " + num(T(r[1]));
    }
    static void perturb(Input& in, Rng& rng) { differential::perturb(in, rng); }
};

template <typename T, int Exercise>
struct RayTriangleSpec {
    static constexpr bool f = std::is_same_v<T, float>;
    static constexpr const char* name =
        Exercise == 4 ? (f ? "1.4-float" : "1.4-double") : (f ? "1.5-float" : "1.5-double");
    static constexpr const char* exercise = Exercise == 4 ? "1.4" : "1.5";
    static constexpr int count = f ? 1500 : 500;
    using Input = RayTriangle<T>;
    static Case<Input> make(Rng& rng, int index) {
        return rayTriangleCase<T>(rng, index, Exercise);
    }
    static Record run(const Input& in) {
        TriangleT<T> tri{in.a, in.b, in.c};
        if constexpr (Exercise == 4)
            return hitRecord(intersectMollerTrumbore(in.ray.ray(), tri), in);
        else
            return hitRecord(intersectWatertight(in.ray.ray(), tri), in);
    }
    static std::string given(const Input& in) {
        return differential::given(in) + " (" + kPrecision<T> + ")";
    }
    static std::string show(const Record& r) { return showHit<T>(r); }
    static void perturb(Input& in, Rng& rng) { differential::perturb(in, rng); }
};

// ---- 1.6 interpolated normals -------------------------------------------------------------

struct NormalsInput {
    Vec3 na{0}, nb{0}, nc{0};
    float u = 0, v = 0;
};

struct InterpolateNormalSpec {
    static constexpr const char* name = "1.6";
    static constexpr const char* exercise = "1.6";
    static constexpr int count = 1000;
    using Input = NormalsInput;
    static Case<Input> make(Rng& rng, int index) {
        Input in;
        if (index % 2 == 0) {
            // Axis normals and dyadic weights: the sum is exact, zero where opposite
            // normals cancel (then the answer is na).
            auto axisNormal = [&] {
                Vec3 n(0.0f);
                n[rng.below(3)] = rng.chance(50) ? 1.0f : -1.0f;
                return n;
            };
            in.na = axisNormal();
            in.nb = rng.chance(30) ? -in.na : axisNormal();
            in.nc = rng.chance(20) ? -in.na : axisNormal();
            in.u = float(rng.grid(0, 1, 2));
            in.v = float(rng.grid(0, 1, 2));
            if (rng.chance(20)) in.u = float(rng.grid(-1, 2, 2));
            return {in, "axis normals and weights on the quarter grid", true};
        }
        in.na = Vec3(rng.direction());
        in.nb = Vec3(rng.direction());
        in.nc = Vec3(rng.direction());
        in.u = float(rng.uniform(0.0, 1.0));
        in.v = float(rng.uniform(0.0, 1.0 - double(in.u)));
        const char* family = "random unit normals, weights inside";
        if (rng.chance(20)) {
            in.u = float(rng.uniform(-0.5, 1.5));
            in.v = float(rng.uniform(-0.5, 1.5));
            family = "random unit normals, weights outside";
        }
        return {in, family, false};
    }
    static Record run(const Input& in) {
        return Record().v3(interpolateNormal(in.na, in.nb, in.nc, in.u, in.v), 0.0, 0x1p-17);
    }
    static std::string given(const Input& in) {
        return "normals na = " + vec(in.na) + ", nb = " + vec(in.nb) + ", nc = " + vec(in.nc) +
               "; u = " + num(in.u) + ", v = " + num(in.v);
    }
    static std::string show(const Record& r) {
        if (r.size() != 3) return "the numbers " + serialize(r);
        return "the normal (" + num(float(r[0])) + ", " + num(float(r[1])) + ", " +
               num(float(r[2])) + ")";
    }
    static void perturb(Input& in, Rng& rng) {
        in.na = nudge(in.na, rng);
        in.nb = nudge(in.nb, rng);
        in.nc = nudge(in.nc, rng);
        in.u = nudge(in.u, rng);
        in.v = nudge(in.v, rng);
    }
};

// Every data set of the step, for the generator and the tests.
using TrianglePlaneFloat = TrianglePlaneSpec<float>;
using TrianglePlaneDouble = TrianglePlaneSpec<double>;
using RayPlaneDistanceFloat = RayPlaneDistanceSpec<float>;
using RayPlaneDistanceDouble = RayPlaneDistanceSpec<double>;
using InsideEdgePlanesFloat = InsideEdgePlanesSpec<float>;
using InsideEdgePlanesDouble = InsideEdgePlanesSpec<double>;
using MollerTrumboreFloat = RayTriangleSpec<float, 4>;
using MollerTrumboreDouble = RayTriangleSpec<double, 4>;
using WatertightFloat = RayTriangleSpec<float, 5>;
using WatertightDouble = RayTriangleSpec<double, 5>;
#define BOXES_DIFFERENTIAL_STEP01(X)                                          \
    X(TrianglePlaneFloat)                                                     \
    X(TrianglePlaneDouble)                                                    \
    X(RayPlaneDistanceFloat)                                                  \
    X(RayPlaneDistanceDouble)                                                 \
    X(InsideEdgePlanesFloat) X(InsideEdgePlanesDouble) X(MollerTrumboreFloat) \
        X(MollerTrumboreDouble) X(WatertightFloat) X(WatertightDouble) X(InterpolateNormalSpec)

}  // namespace boxes::differential
