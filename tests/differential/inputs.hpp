// The hard-case families the differential tests draw from, shared by the steps' specs:
// rays and triangles, rays and boxes. Each family either builds inputs for exact arithmetic
// (small dyadic coordinates and power-of-two determinants, so every correct formula makes
// the same decision, even on an edge or at t == tmin) or draws them at random.
#pragma once

#include <algorithm>
#include <utility>

#include "differential/harness.hpp"

namespace boxes::differential {

// A ray as numbers (RayT refuses a zero direction when it is made; the families never
// make one, and a -0.0 component is kept as it is).
template <typename T>
struct RayInput {
    Vec3T<T> origin{0}, direction{0, 0, 1};
    T tmin = T(0), tmax = kInfinity<T>;
    RayT<T> ray() const { return RayT<T>(origin, direction, tmin, tmax); }
};

template <typename T>
std::string given(const RayInput<T>& r) {
    return "ray O = " + vec(r.origin) + ", D = " + vec(r.direction) + ", t in [" + num(r.tmin) +
           ", " + num(r.tmax) + "]";
}

template <typename T>
void perturb(RayInput<T>& r, Rng& rng) {
    r.origin = nudge(r.origin, rng);
    r.direction = nudge(r.direction, rng);
}

// Axis order and signs: the same configuration seen along every axis, both ways.
struct AxisMap {
    int axis[3] = {0, 1, 2};
    int sign[3] = {1, 1, 1};
    static AxisMap random(Rng& rng) {
        AxisMap m;
        static constexpr int perms[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1},
                                            {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
        int p = rng.below(6);
        for (int k = 0; k < 3; ++k) {
            m.axis[k] = perms[p][k];
            m.sign[k] = rng.chance(50) ? -1 : 1;
        }
        return m;
    }
    // Coordinate k of the input goes to axis[k], times sign[k]; a zero keeps its own sign
    // bit (a -0.0 stays -0.0 whatever the sign).
    Vec3d apply(const Vec3d& v) const {
        Vec3d out(0.0);
        for (int k = 0; k < 3; ++k) out[axis[k]] = v[k] == 0.0 ? v[k] : sign[k] * v[k];
        return out;
    }
    Vec3d invert(const Vec3d& v) const {
        Vec3d out(0.0);
        for (int k = 0; k < 3; ++k) out[k] = v[axis[k]] == 0.0 ? v[axis[k]] : sign[k] * v[axis[k]];
        return out;
    }
};

// ---- Rays and triangles -------------------------------------------------------------------

template <typename T>
struct RayTriangle {
    RayInput<T> ray;
    Vec3T<T> a{0}, b{0}, c{0};
};

template <typename T>
std::string given(const RayTriangle<T>& in) {
    return given(in.ray) + "; triangle a = " + vec(in.a) + ", b = " + vec(in.b) +
           ", c = " + vec(in.c);
}

template <typename T>
void perturb(RayTriangle<T>& in, Rng& rng) {
    perturb(in.ray, rng);
    in.a = nudge(in.a, rng);
    in.b = nudge(in.b, rng);
    in.c = nudge(in.c, rng);
}

// A zero component with a random sign bit: +0.0 or -0.0.
inline double signedZero(Rng& rng) {
    return rng.chance(50) ? 0.0 : -0.0;
}

// Exact: a right triangle with power-of-two legs in a plane z = const, sheared and moved on
// the integer grid (its doubled area stays a power of two), hit at chosen barycentrics (a
// vertex, an edge, inside, a quarter outside) by a ray with dyadic components whose z part
// is a power of two: the determinant of every test is a power of two, so u, v and t are
// exact, and so is each decision. Then the whole scene is turned to another axis and sign.
template <typename T>
Case<RayTriangle<T>> exactRayTriangle(Rng& rng) {
    const char* family = "";
    double legA = rng.power(0, 2, true), legB = rng.power(0, 2, true);
    Vec3d a(0, 0, 0), b(legA, 0, 0), c(0, legB, 0);
    int shearX = rng.range(-1, 1), shearY = rng.range(-1, 1);
    Vec3d move(rng.range(-3, 3), rng.range(-3, 3), rng.range(-3, 3));
    for (Vec3d* p : {&a, &b, &c}) {
        p->x += shearX * p->y;
        p->y += shearY * p->x;
        *p += move;
    }
    // A degenerate triangle: a repeated vertex or three on one line.
    int shape = rng.below(20);
    if (shape == 0) {
        c = b;
        family = "a degenerate triangle (repeated vertex)";
    } else if (shape == 1) {
        c = a + 2.0 * (b - a);
        family = "a degenerate triangle (three vertices on a line)";
    }
    // Where the ray crosses the plane, in barycentrics of (a, b, c).
    static constexpr double spots[][2] = {
        {0, 0},         {1, 0},       {0, 1},        // vertices
        {0.5, 0},       {0, 0.5},     {0.5, 0.5},    // edge midpoints
        {0.25, 0},      {0, 0.75},    {0.75, 0.25},  // edges
        {0.25, 0.25},   {0.5, 0.25},  {0.25, 0.5},   // inside
        {-0.25, 0.5},   {0.5, -0.25}, {0.75, 0.5},   // a quarter outside
        {-0.25, -0.25}, {1.25, 0},    {0, -0.25}};
    int spot = rng.below(int(std::size(spots)));
    double u = spots[spot][0], v = spots[spot][1];
    if (!*family)
        family = spot < 3    ? "a ray through a vertex"
                 : spot < 9  ? "a ray through an edge"
                 : spot < 12 ? "a ray through the inside"
                             : "a ray a quarter outside an edge";
    Vec3d p = a + u * (b - a) + v * (c - a);
    // The direction: z a power of two, x and y small dyadics (zeros of either sign).
    double dz = rng.power(-1, 1, true);
    auto small = [&] {
        int k = rng.range(-2, 2);
        return k == 0 ? signedZero(rng) : k * 0.25 * std::fabs(dz);
    };
    Vec3d d(small(), small(), dz);
    int kind = rng.below(12);
    if (kind == 0) {
        // Parallel to the plane: in it (through the triangle's plane) or beside it.
        d = Vec3d(rng.pick({1.0, -1.0, 0.5}), rng.pick({0.0, 0.25, -1.0}), signedZero(rng));
        bool beside = rng.chance(50);
        family = beside ? "a ray parallel to the triangle's plane, beside it"
                        : "a ray parallel to the triangle's plane, in it";
        if (beside) p.z += 1.0;
    }
    double t = rng.pick({0.0, 0.5, 1.0, 2.0, 3.0, -1.0});
    Vec3d o = p - t * d;
    RayTriangle<T> in;
    AxisMap m = AxisMap::random(rng);
    in.a = Vec3T<T>(m.apply(a));
    in.b = Vec3T<T>(m.apply(b));
    in.c = Vec3T<T>(m.apply(c));
    // A random winding: the same triangle from the other side.
    if (rng.chance(50)) std::swap(in.b, in.c);
    in.ray.origin = Vec3T<T>(m.apply(o));
    in.ray.direction = Vec3T<T>(m.apply(d));
    switch (rng.below(6)) {
        case 0:
            in.ray.tmin = T(t);  // exactly at tmin: a hit (closed interval)
            family = kind == 0 ? family : "t exactly at tmin";
            break;
        case 1:
            in.ray.tmax = T(t);  // exactly at tmax: a hit
            family = kind == 0 ? family : "t exactly at tmax";
            break;
        case 2:
            in.ray.tmin = T(t + 0.25);  // just beyond the interval
            break;
        case 3:
            in.ray.tmax = T(t - 0.25);
            in.ray.tmin = T(-4);
            break;
        default:
            break;
    }
    return {in, family, true};
}

// At random: a triangle at a scale, a ray aimed at barycentrics in [-0.2, 1.2]^2 from a
// random direction; grazing rays nearly in the plane; huge and tiny scenes.
template <typename T>
Case<RayTriangle<T>> randomRayTriangle(Rng& rng, int hugeExponent, int tinyExponent,
                                       int forcedKind = -1) {
    const char* family = "a random ray and triangle";
    int kind = rng.below(10);
    if (forcedKind >= 0) kind = forcedKind;
    double scale = rng.logUniform(-3, 3);
    if (kind == 8) {
        scale = std::ldexp(1.0, rng.range(hugeExponent - 8, hugeExponent));
        family = "a huge triangle far away";
    } else if (kind == 9) {
        scale = std::ldexp(1.0, rng.range(tinyExponent, tinyExponent + 8));
        family = "a tiny triangle";
    }
    Vec3d centre = rng.inCube(4.0) * scale;
    Vec3d a = centre + rng.inCube(1.0) * scale, b = centre + rng.inCube(1.0) * scale,
          c = centre + rng.inCube(1.0) * scale;
    // Inside the triangle for two rays in three, else anywhere near it.
    double u = rng.uniform(-0.2, 1.2), v = rng.uniform(-0.2, 1.2);
    if (rng.chance(67)) {
        u = rng.unit();
        v = rng.unit() * (1.0 - u);
    }
    Vec3d p = a + u * (b - a) + v * (c - a);
    Vec3d d = rng.direction();
    if (kind == 6) {
        // Grazing: nearly in the triangle's plane.
        Vec3d n = glm::normalize(glm::cross(b - a, c - a));
        Vec3d inPlane = glm::normalize(b - a);
        d = inPlane + rng.logUniform(-24, -6) * (rng.chance(50) ? n : -n);
        family = "a grazing ray";
    } else if (kind == 7) {
        // Along an axis: two zero components of either sign.
        int axis = rng.below(3);
        d = Vec3d(signedZero(rng), signedZero(rng), signedZero(rng));
        d[axis] = rng.chance(50) ? 1.0 : -1.0;
        family = "an axis-parallel ray";
    }
    d *= rng.logUniform(-2, 2);
    double t = rng.uniform(0.1, 4.0) * scale / glm::length(d);
    if (rng.chance(10)) t = -t;
    Vec3d o = p - t * d;
    RayTriangle<T> in;
    in.a = Vec3T<T>(a);
    in.b = Vec3T<T>(b);
    in.c = Vec3T<T>(c);
    in.ray.origin = Vec3T<T>(o);
    in.ray.direction = Vec3T<T>(d);
    if (isZero(in.ray.direction)) in.ray.direction = Vec3T<T>(0, 0, 1);
    if (!isFinite(in.ray.origin)) in.ray.origin = Vec3T<T>(0);
    if (rng.chance(20)) {
        double lo = t * rng.uniform(0.5, 1.5), hi = lo + std::fabs(t) * rng.uniform(0.0, 1.0);
        in.ray.tmin = T(lo);
        in.ray.tmax = T(hi);
    }
    return {in, family, false};
}

// ---- Rays and axis-aligned boxes -------------------------------------------------------------

template <typename T>
struct RayBox {
    RayInput<T> ray;
    Vec3T<T> lo{0}, hi{0};
};

template <typename T>
std::string given(const RayBox<T>& in) {
    return given(in.ray) + "; box min " + vec(in.lo) + ", max " + vec(in.hi);
}

template <typename T>
void perturb(RayBox<T>& in, Rng& rng) {
    perturb(in.ray, rng);
    in.lo = nudge(in.lo, rng);
    in.hi = nudge(in.hi, rng);
}

// Exact: a box on the integer grid (flat on some axes now and then), a ray with dyadic
// components (zeros of either sign, origins on slab planes, along faces, edges and corners)
// and t at the planes exactly; intervals that end exactly where the ray enters or leaves.
template <typename T>
Case<RayBox<T>> exactRayBox(Rng& rng, bool allowEmpty = true) {
    const char* family = "a ray and a box on the grid";
    Vec3d lo(rng.range(-3, 2), rng.range(-3, 2), rng.range(-3, 2));
    Vec3d hi = lo + Vec3d(rng.range(1, 3), rng.range(1, 3), rng.range(1, 3));
    int kind = rng.below(16);
    if (kind == 0) {
        int axis = rng.below(3);
        hi[axis] = lo[axis];
        family = "a flat box (zero thickness)";
    } else if (kind == 1 && allowEmpty) {
        int axis = rng.below(3);
        std::swap(lo[axis], hi[axis]);
        family = "an empty box (min > max)";
    }
    // A target on the box's surface or near it, on the quarter grid.
    Vec3d target;
    for (int k = 0; k < 3; ++k) {
        int where = rng.below(20);  // on a face plane half the time, outside 3 in 20
        target[k] = where < 5     ? lo[k]
                    : where < 10  ? hi[k]
                    : where == 10 ? lo[k] - 0.25
                    : where < 13  ? hi[k] + 0.25
                                  : rng.grid(int(lo[k]), int(hi[k]), 2);
    }
    // Powers of two (1/D exact, so every t is) and zeros of either sign.
    Vec3d d;
    for (int k = 0; k < 3; ++k) d[k] = rng.chance(20) ? signedZero(rng) : rng.power(-2, 1, true);
    if (rng.chance(30)) {
        // Axis-parallel: two zero components.
        int axis = rng.below(3);
        for (int k = 0; k < 3; ++k)
            if (k != axis) d[k] = signedZero(rng);
        if (d[axis] == 0.0) d[axis] = rng.chance(50) ? 1.0 : -1.0;
        family = kind <= 1 ? family : "an axis-parallel ray (zero components of either sign)";
    }
    if (isZero(d)) d = Vec3d(0.0, 0.0, 1.0);
    double t = rng.pick({0.0, 1.0, 2.0, 4.0, -2.0});
    Vec3d o = target - t * d;
    if (rng.chance(15)) {
        // The origin on a slab plane.
        int axis = rng.below(3);
        o[axis] = rng.chance(50) ? lo[axis] : hi[axis];
        family = kind <= 1 ? family : "the origin on a slab plane";
    } else if (rng.chance(15)) {
        // On a slab plane and parallel to it: (plane - O) * (1/D) = 0 * inf = NaN.
        int axis = rng.below(3);
        o[axis] = rng.chance(50) ? lo[axis] : hi[axis];
        d[axis] = signedZero(rng);
        if (isZero(d)) d[(axis + 1) % 3] = rng.power(-2, 1, true);
        family = kind <= 1 ? family : "the origin on a slab plane with D = +-0 along it (0 * inf)";
    }
    RayBox<T> in;
    in.lo = Vec3T<T>(lo);
    in.hi = Vec3T<T>(hi);
    in.ray.origin = Vec3T<T>(o);
    in.ray.direction = Vec3T<T>(d);
    switch (rng.below(6)) {
        case 0:
            in.ray.tmin = T(t);
            family = kind <= 1 ? family : "an interval starting at t = the target's";
            break;
        case 1:
            in.ray.tmax = T(t);
            family = kind <= 1 ? family : "an interval ending at t = the target's";
            break;
        case 2:
            in.ray.tmin = T(rng.grid(-2, 4, 2));
            in.ray.tmax = T(double(in.ray.tmin) + rng.grid(0, 4, 2));
            break;
        default:
            break;
    }
    return {in, family, true};
}

// At random: boxes at a scale, rays aimed near them from anywhere (inside too).
template <typename T>
Case<RayBox<T>> randomRayBox(Rng& rng) {
    double scale = rng.logUniform(-4, 4);
    Vec3d centre = rng.inCube(4.0) * scale;
    Vec3d half(rng.uniform(0.01, 1.0) * scale, rng.uniform(0.01, 1.0) * scale,
               rng.uniform(0.01, 1.0) * scale);
    Vec3d target =
        centre +
        Vec3d(rng.uniform(-1.3, 1.3), rng.uniform(-1.3, 1.3), rng.uniform(-1.3, 1.3)) * half;
    Vec3d d = rng.direction() * rng.logUniform(-2, 2);
    double t = rng.uniform(-1.0, 5.0) * scale / glm::length(d);
    Vec3d o = target - t * d;
    RayBox<T> in;
    in.lo = Vec3T<T>(centre - half);
    in.hi = Vec3T<T>(centre + half);
    in.ray.origin = Vec3T<T>(o);
    in.ray.direction = Vec3T<T>(d);
    if (rng.chance(25)) {
        in.ray.tmin = T(rng.uniform(-1.0, 3.0) * scale / glm::length(d));
        in.ray.tmax = T(double(in.ray.tmin) + rng.uniform(0.0, 4.0) * scale / glm::length(d));
    }
    return {in, "a random ray and box", false};
}

}  // namespace boxes::differential
