// Light transport, as the lecture expects it for the exam: a diffuse point lit by a point
// light (N.L and the 1/d^2 falloff), a shadow ray, and the rays a Whitted ray tracer spawns
// at each depth where a ray meets glass.
#include <algorithm>
#include <cmath>
#include <optional>

#include "core/math.hpp"
#include "exam/kinds.hpp"

namespace boxes::exam::gen {

namespace {

// Offsets with an integer length, so that the distance to the light is exact:
// 1^2 + 2^2 + 2^2 = 3^2 and the like.
Vec3d integerLengthOffset(Rng& rng) {
    static const std::vector<Vec3d> offsets = {{1, 2, 2},  {2, 3, 6},  {1, 4, 8}, {2, 6, 9},
                                               {0, 3, 4},  {4, 4, 7},  {6, 6, 7}, {0, 0, 5},
                                               {3, 4, 12}, {2, 10, 11}};
    Vec3d o = rng.oneOf(offsets);
    std::vector<double> c = {o.x, o.y, o.z};
    rng.shuffle(c);
    for (double& v : c)
        if (rng.chance(50)) v = -v;
    return {c[0], c[1], c[2]};
}

std::string degrees(double d) {
    return num(d) + " deg";
}

}  // namespace

Question lightShading(Rng& rng, Question q) {
    bool front = rng.chance(85);
    Vec3d p, n, toLight;
    for (int attempt = 0;; ++attempt) {
        p = rng.vec(-3, 3);
        n = niceNormal(rng);
        toLight = integerLengthOffset(rng);
        double c = glm::dot(n, toLight);
        if (std::abs(c) < 0.1) continue;  // grazing light: no question of its sign
        if ((c > 0.0) == front || attempt > 200) break;
    }
    Vec3d light = p + toLight;
    double intensity = rng.oneOf(std::vector<double>{10, 20, 50, 100, 200});
    double albedo = rng.oneOf(std::vector<double>{0.5, 0.8, 1.0});
    q.given["p"] = values(p);
    q.given["n"] = values(n);
    q.given["light"] = values(light);
    q.given["intensity"] = {intensity};
    q.given["albedo"] = {albedo};
    q.statement =
        "A point P = " + vec(p) + " of a diffuse surface with the unit normal N = " + vec(n) +
        " is lit by a point light at S = " + vec(light) + " of intensity I = " + num(intensity) +
        ", with nothing in between; the surface's diffuse reflectance "
        "is a = " +
        num(albedo) +
        ". Shade P as a Whitted ray tracer does: C = a I max(0, N . L) / d^2, with L "
        "the unit vector from P towards the light and d the distance to it.";
    double d = glm::length(toLight);
    Vec3d l = toLight / d;
    double cosine = glm::dot(n, l);
    double shaded = albedo * intensity * std::max(0.0, cosine) / (d * d);
    q.parts.push_back(numbersPart("L, the unit vector from P towards the light", values(l), 3));
    q.parts.push_back(numbersPart("N . L", {cosine}, 1));
    q.parts.push_back(numbersPart("the shaded value C", {shaded}, 1));
    q.solution = {
        "S - P = " + vec(toLight) + ", d = |S - P| = sqrt(" + num(glm::dot(toLight, toLight)) +
            ") = " + num(d),
        "L = (S - P) / d = " + vec(l),
        "N . L = " + num(cosine) + (cosine < 0.0 ? ": the light is behind the surface" : ""),
        "C = a I max(0, N . L) / d^2 = " + num(albedo) + " * " + num(intensity) + " * " +
            num(std::max(0.0, cosine)) + " / " + num(d * d) + " = " + num(shaded),
        "(N . L is the cosine of the angle of incidence: light arriving at a slant spreads over "
        "more surface; 1/d^2: the same light spreads over a sphere of area 4 pi d^2)"};
    return q;
}

Question shadowRay(Rng& rng, Question q) {
    // Wanted: the sphere between P and the light (in shadow), beyond the light, behind P, or
    // beside the shadow ray: the three ways a point is lit are the three classic mistakes.
    int wanted = rng.pick(1, 100);
    int kind = wanted <= 45 ? 0 : wanted <= 65 ? 1 : wanted <= 80 ? 2 : 3;
    for (int attempt = 0;; ++attempt) {
        Vec3d p = rng.vec(-3, 3), toLight = rng.nonZero(-6, 6);
        if (glm::dot(toLight, toLight) < 16.0) continue;
        Vec3d light = p + toLight;
        static const std::vector<std::vector<double>> along = {
            {0.3, 0.4, 0.5, 0.6, 0.7}, {1.4, 1.6, 1.8}, {-0.8, -0.6, -0.4}, {0.3, 0.5, 0.7}};
        double s = rng.oneOf(along[size_t(kind)]);
        Vec3d c = glm::round(p + s * toLight) + rng.vec(-1, 1);
        if (kind == 3) c += rng.nonZero(-1, 1) * 3.0;  // pushed off the ray
        double r2 = rng.pick(1, 6);
        // P and the light outside the sphere.
        double cp = glm::dot(p - c, p - c) - r2, cl = glm::dot(light - c, light - c) - r2;
        if (cp <= 0.0 || cl <= 0.0) continue;
        double a = glm::dot(toLight, toLight), b = 2.0 * glm::dot(p - c, toLight);
        double disc = b * b - 4.0 * a * cp;
        // Nothing hangs on rounding: no tangent line, no hit within rounding of t = 0 or 1.
        if (std::abs(disc) < 0.05 * a) continue;
        std::optional<double> t;
        if (disc > 0.0) {
            double t0 = (-b - std::sqrt(disc)) / (2.0 * a), t1 = (-b + std::sqrt(disc)) / (2.0 * a);
            if (t0 > 0.0)
                t = t0;
            else if (t1 > 0.0)
                t = t1;
        }
        if (t && std::abs(*t - 1.0) < 0.05) continue;
        int got = !t ? (disc < 0.0 ? 3 : 2) : *t < 1.0 ? 0 : 1;
        if (got != kind && attempt < 2000) continue;
        bool shadow = t && *t < 1.0;
        q.given["p"] = values(p);
        q.given["light"] = values(light);
        q.given["centre"] = values(c);
        q.given["radius2"] = {r2};
        q.statement = "A point P = " + vec(p) + " is lit by a point light at S = " + vec(light) +
                      ". One sphere, centre C = " + vec(c) + " and radius r = sqrt(" + num(r2) +
                      "), may block the light. The shadow ray is R(t) = P + t (S - P): t = 0 at "
                      "P, t = 1 at the light.";
        q.parts.push_back(numbersPart(
            "the smallest t > 0 where the shadow ray's line meets the sphere, or 'none'",
            t ? std::vector<double>{*t} : std::vector<double>{}, 1, true));
        q.parts.push_back(yesNoPart("is P in the sphere's shadow?", shadow));
        q.solution = {
            "S - P = " + vec(toLight) + "; |P + t (S - P) - C|^2 = r^2 gives a t^2 + b t + c = 0",
            "a = (S-P).(S-P) = " + num(a) + ", b = 2 (P-C).(S-P) = " + num(b) +
                ", c = (P-C).(P-C) - r^2 = " + num(cp),
            "discriminant b^2 - 4ac = " + num(disc) +
                (disc < 0.0 ? ": the line misses the sphere: no t, P is lit" : "")};
        if (disc > 0.0) {
            double t0 = (-b - std::sqrt(disc)) / (2.0 * a), t1 = (-b + std::sqrt(disc)) / (2.0 * a);
            q.solution.push_back("t = (-b -+ sqrt(disc)) / 2a: " + num(t0) + " and " + num(t1));
            q.solution.push_back(
                !t         ? "both roots < 0: the sphere is behind P, away from the light: P is lit"
                : *t < 1.0 ? "0 < t = " + num(*t) +
                                 " < 1: the sphere lies between P and the light: in shadow"
                           : "t = " + num(*t) +
                                 " > 1: the sphere is beyond the light and cannot block it: "
                                 "P is lit");
        }
        q.solution.push_back(
            "(a shadow ray needs any hit with 0 < t < 1, not the nearest: it may stop at the "
            "first, an early out)");
        return q;
    }
}

Question rayDepth(Rng& rng, Question q) {
    struct Media {
        double above, slab, below;
    };
    static const std::vector<Media> media = {{1.0, 1.5, 1.0},  {1.0, 1.5, 1.33},  {1.33, 1.5, 1.0},
                                             {1.0, 2.4, 1.0},  {1.33, 2.4, 1.33}, {1.0, 1.33, 1.0},
                                             {1.33, 1.5, 1.0}, {1.0, 1.5, 1.0}};
    Media m = rng.oneOf(media);
    double angle = rng.oneOf(std::vector<double>{30, 45, 60});
    double h = rng.pick(1, 3);
    Vec3d across = rng.oneOf(std::vector<Vec3d>{{1, 0, 0}, {-1, 0, 0}, {0, 0, 1}, {0, 0, -1}});
    double a = glm::radians(angle);
    Vec3d d = std::sin(a) * across - std::cos(a) * Vec3d(0, 1, 0);
    Vec3d o(rng.pick(-3, 3), rng.pick(1, 3), rng.pick(-3, 3));
    q.given["origin"] = values(o);
    q.given["direction"] = values(d);
    q.given["thickness"] = {h};
    q.given["n1"] = {m.above};
    q.given["n2"] = {m.slab};
    q.given["n3"] = {m.below};
    std::string axis = across.x != 0.0 ? "x" : "z";
    std::string sign = (across.x + across.z) > 0.0 ? "" : "-";
    std::string exact = across.x != 0.0
                            ? "(" + sign + "sin " + num(angle) + ", -cos " + num(angle) + ", 0)"
                            : "(0, -cos " + num(angle) + ", " + sign + "sin " + num(angle) + ")";
    q.statement =
        "A slab of glass (index n2 = " + num(m.slab) +
        ") lies between the planes y = 0 and y = " + num(-h) +
        "; above it the index is n1 = " + num(m.above) + ", below it n3 = " + num(m.below) +
        ". A ray starts at O = " + vec(o) + " with the unit direction D = " + exact + " = " +
        vec(d) + " (" + degrees(angle) +
        " from the normal). It is the ray of depth 1. Where it meets the slab's top (P1), the "
        "reflected and the refracted ray of depth 2 start; where that refracted ray meets the "
        "bottom (P2), the rays of depth 3 start.";
    Vec3d up(0, 1, 0);
    Rayd ray(o, d);
    double t1 = -o.y / d.y;
    Vec3d p1 = ray.at(t1);
    Vec3d r1 = reflect(d, up), inside, leaving;
    refract(d, up, m.above / m.slab, inside);
    Vec3d p2 = p1 + (h / -inside.y) * inside;
    bool out = refract(inside, up, m.slab / m.below, leaving);
    q.parts.push_back(numbersPart("P1, where the ray of depth 1 meets the top", values(p1), 3));
    q.parts.push_back(numbersPart("the direction of the reflected ray of depth 2", values(r1), 3));
    q.parts.push_back(numbersPart(
        "the unit direction of the refracted ray of depth 2 (into the glass)", values(inside), 3));
    q.parts.push_back(numbersPart("P2, where that refracted ray meets the bottom", values(p2), 3));
    q.parts.push_back(numbersPart(
        "the unit direction of the refracted ray of depth 3 (out of the bottom), or 'none' on "
        "total internal reflection",
        out ? values(leaving) : std::vector<double>{}, 3, true));
    double sin2 = m.above / m.slab * std::sin(a), sin3 = m.above / m.below * std::sin(a);
    q.solution = {
        "depth 1: t = (0 - Oy) / Dy = " + num(t1) + ", P1 = O + t D = " + vec(p1),
        "the normal at the top, facing the ray: N = (0, 1, 0); reflected: D - 2 (D . N) N = " +
            vec(r1),
        "refracted (Snell, n1 sin(theta1) = n2 sin(theta2)): sin(theta2) = " + num(m.above) +
            " / " + num(m.slab) + " * sin " + num(angle) + " = " + num(sin2) +
            ", cos(theta2) = " + num(std::sqrt(1.0 - sin2 * sin2)) + ": T = " + vec(inside),
        "depth 2: T goes down " + num(h) + " through the slab: t = " + num(h) + " / " +
            num(-inside.y) + " = " + num(h / -inside.y) + ", P2 = P1 + t T = " + vec(p2),
        "at the bottom n2 sin(theta2) = n1 sin(theta1) (parallel faces), so sin(theta3) = " +
            num(m.above) + " / " + num(m.below) + " * sin " + num(angle) + " = " + num(sin3) +
            (out ? ": the ray leaves along " + vec(leaving)
                 : " > 1: total internal reflection, no refracted ray of depth 3 (only the "
                   "reflected one, back up into the glass)")};
    return q;
}

}  // namespace boxes::exam::gen
