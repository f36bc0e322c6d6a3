// Step 02's exercises on generated inputs (harness.hpp says how).
#pragma once

#include "02_box/box.hpp"
#include "differential/step01.hpp"

namespace boxes::differential {

// ---- Oriented boxes -------------------------------------------------------------------------

template <typename T>
std::string given(const OrientedBoxT<T>& b) {
    return "box centre " + vec(b.centre) + ", axes " + vec(b.axes[0]) + " " + vec(b.axes[1]) + " " +
           vec(b.axes[2]) + ", half extents " + vec(b.halfExtents);
}

template <typename T>
void perturb(OrientedBoxT<T>& b, Rng& rng) {
    b.centre = nudge(b.centre, rng);
    b.halfExtents = nudge(b.halfExtents, rng);
    for (auto& a : b.axes) a = nudge(a, rng);
}

// A rotation from a random unit quaternion: orthonormal axes up to rounding.
inline std::array<Vec3d, 3> randomAxes(Rng& rng) {
    double q[4];
    for (;;) {
        double l2 = 0.0;
        for (double& c : q) {
            c = rng.uniform(-1.0, 1.0);
            l2 += c * c;
        }
        if (l2 > 1e-3 && l2 <= 1.0) {
            for (double& c : q) c /= std::sqrt(l2);
            break;
        }
    }
    double w = q[0], x = q[1], y = q[2], z = q[3];
    return {Vec3d(1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y)),
            Vec3d(2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x)),
            Vec3d(2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y))};
}

// Exact: the ray and box of exactRayBox (no empty box), the box's axes the world's axes in
// another order and with other signs (left-handed frames too), the whole scene turned with
// them. Random: rotated boxes at a scale and rays aimed near them.
template <typename T>
Case<std::pair<RayInput<T>, OrientedBoxT<T>>> rayOrientedBoxCase(Rng& rng, int index) {
    std::pair<RayInput<T>, OrientedBoxT<T>> in;
    if (index % 2 == 0) {
        auto c = exactRayBox<double>(rng, false);
        AxisMap m = AxisMap::random(rng);
        AxisMap frame = AxisMap::random(rng);
        in.second.centre = Vec3T<T>(m.apply(0.5 * (c.input.lo + c.input.hi)));
        Vec3d half = 0.5 * (c.input.hi - c.input.lo);
        // The box's axis k is the world axis m maps k to, in the frame's order and signs.
        for (int k = 0; k < 3; ++k) {
            Vec3d axis(0.0);
            axis[k] = 1.0;
            in.second.axes[size_t(frame.axis[k])] = Vec3T<T>(m.apply(axis) * double(frame.sign[k]));
            in.second.halfExtents[frame.axis[k]] = T(half[k]);
        }
        in.first.origin = Vec3T<T>(m.apply(c.input.ray.origin));
        in.first.direction = Vec3T<T>(m.apply(c.input.ray.direction));
        in.first.tmin = T(c.input.ray.tmin);
        in.first.tmax = T(c.input.ray.tmax);
        return {in, c.family, true};
    }
    double scale = rng.logUniform(-4, 4);
    auto axes = randomAxes(rng);
    Vec3d centre = rng.inCube(4.0) * scale;
    Vec3d half(rng.uniform(0.05, 1.0) * scale, rng.uniform(0.05, 1.0) * scale,
               rng.uniform(0.05, 1.0) * scale);
    Vec3d target = centre;
    for (int k = 0; k < 3; ++k) target += rng.uniform(-1.3, 1.3) * half[k] * axes[size_t(k)];
    Vec3d d = rng.direction() * rng.logUniform(-2, 2);
    const char* family = "a random ray and rotated box";
    if (rng.chance(20)) {
        // Parallel to a face: the direction along one of the box's axes.
        d = axes[size_t(rng.below(3))] * (rng.chance(50) ? 1.0 : -1.0);
        family = "a ray along one of the box's axes";
    }
    double t = rng.uniform(-1.0, 5.0) * scale / glm::length(d);
    in.second.centre = Vec3T<T>(centre);
    for (int k = 0; k < 3; ++k) in.second.axes[size_t(k)] = Vec3T<T>(axes[size_t(k)]);
    in.second.halfExtents = Vec3T<T>(half);
    in.first.origin = Vec3T<T>(target - t * d);
    in.first.direction = Vec3T<T>(d);
    if (rng.chance(25)) {
        in.first.tmin = T(rng.uniform(-1.0, 3.0) * scale / glm::length(d));
        in.first.tmax = T(double(in.first.tmin) + rng.uniform(0.0, 4.0) * scale / glm::length(d));
    }
    return {in, family, false};
}

// The box's six face planes, worked out here (not with exercise 2.1's code): face 2k is
// -axis_k at centre - h_k axis_k, face 2k + 1 is +axis_k at centre + h_k axis_k.
template <typename T>
std::array<PlaneT<T>, 6> facePlanesOf(const OrientedBoxT<T>& box) {
    std::array<PlaneT<T>, 6> planes;
    for (int f = 0; f < 6; ++f) {
        Vec3T<T> n = box.axes[size_t(f / 2)];
        if (f % 2 == 0) n = -n;
        planes[size_t(f)] = {n, -(glm::dot(n, box.centre) + box.halfExtents[f / 2])};
    }
    return planes;
}

constexpr const char* kFaceNames[6] = {"-x", "+x", "-y", "+y", "-z", "+z"};

// A box hit as t, face, entering, and whether its normal is its face's unit outward normal.
template <typename T>
Record boxHitRecord(const std::optional<BoxHit<T>>& h, const RayInput<T>& ray,
                    const std::array<PlaneT<T>, 6>& planes, double size) {
    if (!h) return Record::absent();
    bool faceValid = h->face >= 0 && h->face < 6;
    bool normalOfFace = faceValid && h->normal == planes[size_t(h->face)].normal;
    double tScale = size / std::max(1e-300, double(glm::length(Vec3d(ray.direction))));
    return Record().real(h->t, kRel<T>, kRel<T> * tScale).i(h->face).i(h->entering).i(normalOfFace);
}

template <typename T>
std::string showBoxHit(const Record& r) {
    if (r.state == Record::Absent) return "a miss (nullopt)";
    if (r.size() != 4) return "the numbers " + serialize(r);
    int face = int(r[1]);
    return "a hit at t = " + num(T(r[0])) + " on face " + std::to_string(face) +
           (face >= 0 && face < 6 ? std::string(" (") + kFaceNames[face] + ")" : "") +
           (r[2] ? ", entering" : ", leaving") +
           (r[3] ? "" : ", with a normal that is not that face's unit outward normal");
}

// Two box hits agree when t does and the face does; at an edge or a corner two or three
// faces meet at the same t, and the README does not say which one a hit names: any face
// whose plane holds the hit point will do, with entering as that face says (D.N < 0).
template <typename T>
std::string compareBoxHits(const RayInput<T>& ray, const std::array<PlaneT<T>, 6>& planes,
                           const Record& got, const Record& expected, int scale) {
    std::string why =
        compareRecords(got, expected, scale, {"t", "the face", "entering", "the normal"});
    if (why.empty() || got.state != Record::Values || expected.state != Record::Values ||
        got.size() != 4 || expected.size() != 4 ||
        !valueMatches(got.values[0], expected[0], scale) || got[3] != 1.0 ||
        got[1] == expected[1] || got[1] < 0 || got[1] > 5)
        return why;
    const PlaneT<T>& p = planes[size_t(got[1])];
    Vec3d point = Vec3d(ray.origin) + expected[0] * Vec3d(ray.direction);
    double off = std::fabs(glm::dot(Vec3d(p.normal), point) + double(p.d));
    double size = glm::length(point) + std::fabs(double(p.d)) + 1.0;
    bool onFace = off <= std::ldexp(64.0 * kRel<T> * size, scale);
    bool entering = glm::dot(Vec3d(ray.direction), Vec3d(p.normal)) < 0.0;
    if (onFace && (got[2] != 0.0) == entering) return "";
    return onFace ? "entering or leaving does not match the face"
                  : "the hit point is not on that face";
}

// ---- 2.1 the face planes ---------------------------------------------------------------------

template <typename T>
struct BoxFacePlanesSpec {
    static constexpr const char* name = std::is_same_v<T, float> ? "2.1-float" : "2.1-double";
    static constexpr const char* exercise = "2.1";
    static constexpr int count = std::is_same_v<T, float> ? 200 : 80;
    using Input = OrientedBoxT<T>;
    static Case<Input> make(Rng& rng, int index) {
        auto c = rayOrientedBoxCase<T>(rng, index);
        return {c.input.second,
                c.exact ? "a box on the grid (axes in any order and sign)" : "a random rotated box",
                c.exact};
    }
    static Record run(const Input& box) {
        auto planes = boxFacePlanes(box);
        double size = sceneSize<T>({box.centre}) + double(glm::length(Vec3d(box.halfExtents)));
        Record r;
        for (const auto& p : planes) r.v3(p.normal, 0.0, kRel<T>).real(p.d, 0.0, kRel<T> * size);
        return r;
    }
    static std::string given(const Input& box) {
        return differential::given(box) + " (" + kPrecision<T> + ")";
    }
    static std::string show(const Record& r) {
        if (r.size() != 24) return "the numbers " + serialize(r);
        std::string s;
        for (int f = 0; f < 6; ++f)
            s += std::string(f ? "; " : "") + "face " + std::to_string(f) + " N = (" +
                 num(T(r[size_t(4 * f)])) + ", " + num(T(r[size_t(4 * f + 1)])) + ", " +
                 num(T(r[size_t(4 * f + 2)])) + "), d = " + num(T(r[size_t(4 * f + 3)]));
        return s;
    }
    static void perturb(Input& box, Rng& rng) { differential::perturb(box, rng); }
};

// ---- 2.2 six planes and 2.4 slabs --------------------------------------------------------

template <typename T, int Exercise>
struct BoxIntersectionSpec {
    static constexpr bool f = std::is_same_v<T, float>;
    static constexpr const char* name =
        Exercise == 2 ? (f ? "2.2-float" : "2.2-double") : (f ? "2.4-float" : "2.4-double");
    static constexpr const char* exercise = Exercise == 2 ? "2.2" : "2.4";
    static constexpr int count = f ? 1500 : 500;
    using Input = std::pair<RayInput<T>, OrientedBoxT<T>>;
    static Case<Input> make(Rng& rng, int index) { return rayOrientedBoxCase<T>(rng, index); }
    static double size(const Input& in) {
        return sceneSize<T>({in.first.origin, in.second.centre}) +
               double(glm::length(Vec3d(in.second.halfExtents)));
    }
    static Record run(const Input& in) {
        auto planes = facePlanesOf(in.second);
        if constexpr (Exercise == 2)
            return boxHitRecord(intersectSixPlanes(in.first.ray(), planes), in.first, planes,
                                size(in));
        else
            return boxHitRecord(intersectBoxSlabs(in.first.ray(), in.second), in.first, planes,
                                size(in));
    }
    static std::string compare(const Input& in, const Record& got, const Record& expected,
                               int scale) {
        return compareBoxHits(in.first, facePlanesOf(in.second), got, expected, scale);
    }
    static std::string given(const Input& in) {
        std::string s = differential::given(in.first) + "; " + differential::given(in.second);
        if (Exercise == 2)
            s += " (its six planes as N.P + d = 0 with unit outward N, faces -x +x -y +y -z +z)";
        return s + " (" + kPrecision<T> + ")";
    }
    static std::string show(const Record& r) { return showBoxHit<T>(r); }
    static void perturb(Input& in, Rng& rng) {
        differential::perturb(in.first, rng);
        differential::perturb(in.second, rng);
    }
};

// ---- 2.3 the axis-aligned plane distance ---------------------------------------------------

template <typename T>
struct AxisDistance {
    T plane = T(0), origin = T(0), direction = T(1);
};

template <typename T>
struct AxisPlaneDistanceSpec {
    static constexpr const char* name = std::is_same_v<T, float> ? "2.3-float" : "2.3-double";
    static constexpr const char* exercise = "2.3";
    static constexpr int count = std::is_same_v<T, float> ? 1500 : 500;
    using Input = AxisDistance<T>;
    static Case<Input> make(Rng& rng, int index) {
        Input in;
        if (index % 2 == 0) {
            in.plane = T(rng.grid(-8, 8, 2));
            in.origin = rng.chance(15) ? in.plane : T(rng.grid(-8, 8, 2));
            in.direction = rng.chance(15) ? T(signedZero(rng)) : T(rng.power(-3, 3, true));
            const char* family =
                in.direction == T(0)
                    ? (in.origin == in.plane ? "D = +-0 and the origin on the plane (0/0)"
                                             : "D = +-0 (t = +-inf)")
                    : "on the quarter grid";
            return {in, family, true};
        }
        const char* family = "random";
        double scale = rng.logUniform(-6, 6);
        in.plane = T(rng.uniform(-4.0, 4.0) * scale);
        in.origin = T(rng.uniform(-4.0, 4.0) * scale);
        in.direction = T(rng.uniform(-1.0, 1.0) * rng.logUniform(-4, 4));
        int kind = rng.below(6);
        if (kind == 0) {
            in.direction = T(std::is_same_v<T, float> ? rng.logUniform(-140, -130)
                                                      : rng.logUniform(-1060, -1030));
            family = "a subnormal direction component (t overflows)";
        } else if (kind == 1) {
            in.plane =
                T(std::is_same_v<T, float> ? rng.logUniform(120, 126) : rng.logUniform(1000, 1020));
            in.origin = -in.plane;
            family = "a difference that overflows";
        }
        if (in.direction == T(0)) in.direction = T(1);
        return {in, family, false};
    }
    static Record run(const Input& in) {
        T t = axisPlaneDistance(in.plane, in.origin, in.direction);
        return Record().real(t, std::is_same_v<T, float> ? 0x1p-21 : 0x1p-50);
    }
    static std::string given(const Input& in) {
        return "x_plane = " + num(in.plane) + ", O_x = " + num(in.origin) +
               ", D_x = " + num(in.direction) + " (" + kPrecision<T> + ")";
    }
    static std::string show(const Record& r) {
        if (r.size() != 1) return "the numbers " + serialize(r);
        return "t = " + num(T(r[0]));
    }
    static void perturb(Input& in, Rng& rng) {
        in.plane = nudge(in.plane, rng);
        in.origin = nudge(in.origin, rng);
        in.direction = nudge(in.direction, rng);
    }
};

using BoxFacePlanesFloat = BoxFacePlanesSpec<float>;
using BoxFacePlanesDouble = BoxFacePlanesSpec<double>;
using SixPlanesFloat = BoxIntersectionSpec<float, 2>;
using SixPlanesDouble = BoxIntersectionSpec<double, 2>;
using AxisPlaneDistanceFloat = AxisPlaneDistanceSpec<float>;
using AxisPlaneDistanceDouble = AxisPlaneDistanceSpec<double>;
using BoxSlabsFloat = BoxIntersectionSpec<float, 4>;
using BoxSlabsDouble = BoxIntersectionSpec<double, 4>;
#define BOXES_DIFFERENTIAL_STEP02(X) \
    X(BoxFacePlanesFloat)            \
    X(BoxFacePlanesDouble)           \
    X(SixPlanesFloat)                \
    X(SixPlanesDouble)               \
    X(AxisPlaneDistanceFloat) X(AxisPlaneDistanceDouble) X(BoxSlabsFloat) X(BoxSlabsDouble)

}  // namespace boxes::differential
