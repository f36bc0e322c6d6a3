#include "exam/questions.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <functional>
#include <random>
#include <sstream>
#include <stdexcept>

#include "core/bounds.hpp"
#include "core/math.hpp"
#include "core/scene.hpp"
#include "exam/answer.hpp"
#include "exam/generate.hpp"
#include "exam/kinds.hpp"
#include "exam/reference.hpp"

namespace boxes::exam {

using gen::num;

namespace gen {

// A camera whose view is never parallel to up, with a field of view and an aspect ratio
// that give readable numbers.
Camerad randomCamera(Rng& rng) {
    Camerad c;
    c.eye = rng.vec(-3, 3);
    for (;;) {
        c.view = rng.nonZero(-2, 2);
        if (glm::length(glm::cross(c.view, Vec3d(0, 1, 0))) > 0.5) break;
    }
    c.up = Vec3d(0, 1, 0);
    c.fovYDegrees = rng.oneOf(std::vector<double>{45, 60, 90, 120});
    c.aspect = rng.oneOf(std::vector<double>{1.0, 4.0 / 3.0, 1.5, 16.0 / 9.0, 2.0});
    return c;
}

void giveCamera(Question& q, const Camerad& c) {
    q.given["eye"] = values(c.eye);
    q.given["view"] = values(c.view);
    q.given["up"] = values(c.up);
    q.given["fov"] = {c.fovYDegrees};
    q.given["aspect"] = {c.aspect};
}

std::string cameraText(const Camerad& c) {
    return "A camera at E = " + vec(c.eye) + " looks along V = " + vec(c.view) +
           " with up U = " + vec(c.up) + ", a vertical field of view of " + num(c.fovYDegrees) +
           " degrees and an aspect ratio (width / height) of " + num(c.aspect) + ".";
}

void cameraBasisSteps(Question& q, const Camerad& c) {
    CameraBasisT<double> b = c.basis();
    q.solution.push_back("w = V / |V| = " + vec(b.forward));
    q.solution.push_back("u = (w x U) / |w x U| = " + vec(b.right) + "   (right)");
    q.solution.push_back("v = u x w = " + vec(b.up) + "   (up on the screen)");
    q.solution.push_back("half height h = tan(fov / 2) = " + num(c.halfHeight()) +
                         ", half width = aspect * h = " + num(c.aspect * c.halfHeight()));
}

// --- the kinds ------------------------------------------------------------------------------

Question vectors(Rng& rng, Question q) {
    Vec3d a = rng.nonZero(-4, 4), b = rng.nonZero(-4, 4);
    q.given["a"] = values(a);
    q.given["b"] = values(b);
    q.statement = "Let a = " + vec(a) + " and b = " + vec(b) + ".";
    double dot = glm::dot(a, b);
    Vec3d cross = glm::cross(a, b), unit = glm::normalize(a);
    q.parts.push_back(numbersPart("a . b (the dot product)", {dot}, 1));
    q.parts.push_back(numbersPart("a x b (the cross product)", values(cross), 3));
    q.parts.push_back(numbersPart("a / |a| (a normalized)", values(unit), 3));
    q.solution = {"a . b = ax bx + ay by + az bz = " + num(dot),
                  "a x b = (ay bz - az by, az bx - ax bz, ax by - ay bx) = " + vec(cross),
                  "|a| = sqrt(ax^2 + ay^2 + az^2) = sqrt(" + num(glm::dot(a, a)) +
                      ") = " + num(glm::length(a)) + ", so a / |a| = " + vec(unit)};
    // A combination k a + m b, component by component.
    int k = rng.oneOf(std::vector<int>{-3, -2, 2, 3}),
        m = rng.oneOf(std::vector<int>{-3, -2, -1, 1, 2});
    q.given["k"] = {double(k)};
    q.given["m"] = {double(m)};
    Vec3d combination = double(k) * a + double(m) * b;
    std::string name = std::to_string(k) + " a " + (m < 0 ? "- " : "+ ") +
                       (std::abs(m) == 1 ? "" : std::to_string(std::abs(m)) + " ") + "b";
    q.parts.push_back(numbersPart(name, values(combination), 3));
    q.solution.push_back(name + " = " + vec(double(k) * a) + " + " + vec(double(m) * b) + " = " +
                         vec(combination));
    return q;
}

Question screenCorners(Rng& rng, Question q) {
    Camerad c = randomCamera(rng);
    giveCamera(q, c);
    q.statement =
        cameraText(c) +
        " The virtual screen lies at distance 1 in front of the eye. Give two of its corners.";
    ScreenCornersT<double> s = c.screenCorners();
    q.parts.push_back(numbersPart("the top-left corner", values(s.topLeft), 3));
    q.parts.push_back(numbersPart("the bottom-right corner", values(s.bottomRight), 3));
    cameraBasisSteps(q, c);
    q.solution.push_back("screen centre M = E + w = " + vec(c.eye + c.basis().forward));
    q.solution.push_back("top-left = M - (half width) u + h v = " + vec(s.topLeft));
    q.solution.push_back("bottom-right = M + (half width) u - h v = " + vec(s.bottomRight));
    q.solution.push_back("(top-right = " + vec(s.topRight) +
                         ", bottom-left = " + vec(s.bottomLeft) + ")");
    return q;
}

Question primaryRay(Rng& rng, Question q) {
    Camerad c = randomCamera(rng);
    int width = rng.oneOf(std::vector<int>{4, 8, 10, 16}),
        height = rng.oneOf(std::vector<int>{2, 4, 6, 8});
    c.aspect = double(width) / double(height);
    int x = rng.pick(0, width - 1), y = rng.pick(0, height - 1);
    giveCamera(q, c);
    q.given["image"] = {double(width), double(height)};
    q.given["pixel"] = {double(x), double(y)};
    q.statement = cameraText(c) + " The image is " + std::to_string(width) + " x " +
                  std::to_string(height) +
                  " pixels, pixel (0, 0) at the top left; a primary ray "
                  "goes through the centre of pixel (" +
                  std::to_string(x) + ", " + std::to_string(y) + ").";
    Rayd ray = c.primaryRay(x, y, width, height);
    q.parts.push_back(numbersPart("the ray's normalized direction", values(ray.direction), 3));
    cameraBasisSteps(q, c);
    double h = c.halfHeight();
    double sx = (2.0 * (x + 0.5) / width - 1.0) * c.aspect * h,
           sy = (1.0 - 2.0 * (y + 0.5) / height) * h;
    q.solution.push_back("pixel centre (" + num(x + 0.5) + ", " + num(y + 0.5) +
                         ") -> screen offsets sx = (2 (x+0.5)/W - 1) aspect h = " + num(sx) +
                         ", sy = (1 - 2 (y+0.5)/H) h = " + num(sy));
    CameraBasisT<double> b = c.basis();
    q.solution.push_back("d = w + sx u + sy v = " + vec(b.forward + sx * b.right + sy * b.up));
    q.solution.push_back("normalized: d / |d| = " + vec(ray.direction));
    return q;
}

Question rayPlane(Rng& rng, Question q) {
    bool wantHit = rng.chance(75);
    for (int attempt = 0;; ++attempt) {
        Vec3d o = rng.vec(-4, 4), d = rng.nonZero(-3, 3), n = rng.nonZero(-2, 2);
        double pd = rng.pick(-8, 8);
        if (glm::dot(o, n) + pd == 0.0) continue;  // the origin on the plane: t = 0 either way
        auto t = intersectPlane(Rayd(o, d), PlaneT<double>{n, pd});
        if (t.has_value() != wantHit && attempt < 500) continue;
        q.given["origin"] = values(o);
        q.given["direction"] = values(d);
        q.given["normal"] = values(n);
        q.given["d"] = {pd};
        q.statement = "A ray starts at O = " + vec(o) + " with direction D = " + vec(d) +
                      " (hits count for t >= 0). The plane is N . P + d = 0 with N = " + vec(n) +
                      " and d = " + num(pd) + ".";
        double denom = glm::dot(d, n);
        q.solution.push_back("D . N = " + num(denom) +
                             (denom == 0.0 ? ": the ray is parallel to the plane, no hit" : ""));
        if (denom != 0.0) {
            double tt = -(glm::dot(o, n) + pd) / denom;
            q.solution.push_back("t = -(O . N + d) / (D . N) = -(" + num(glm::dot(o, n)) +
                                 plus(pd) + ") / " + num(denom) + " = " + num(tt));
            q.solution.push_back(tt < 0.0 ? "t < 0: the plane lies behind the ray's origin, no hit"
                                          : "P = O + t D = " + vec(o + tt * d));
        }
        q.parts.push_back(numbersPart("the hit point P, or 'none'",
                                      t ? values(Rayd(o, d).at(*t)) : std::vector<double>{}, 3,
                                      true));
        return q;
    }
}

Question raySphere(Rng& rng, Question q) {
    bool wantHit = rng.chance(75);
    for (int attempt = 0;; ++attempt) {
        Vec3d o = rng.vec(-5, 5), d = rng.nonZero(-2, 2), centre = rng.vec(-3, 3);
        double r2 = rng.pick(1, 12);
        SphereT<double> s{centre, std::sqrt(r2)};
        Rayd ray(o, d);
        auto t = intersectSphere(ray, s);
        // No tangent rays and no origin on the surface: the answer must not hang on rounding.
        Vec3d f0 = o - centre;
        double half = glm::dot(f0, d), c0 = glm::dot(f0, f0) - r2;
        if (std::abs(half * half - glm::dot(d, d) * c0) < 0.5 || c0 == 0.0) continue;
        if (t.has_value() != wantHit && attempt < 500) continue;
        q.given["origin"] = values(o);
        q.given["direction"] = values(d);
        q.given["centre"] = values(centre);
        q.given["radius2"] = {r2};
        q.statement = "A ray starts at O = " + vec(o) + " with direction D = " + vec(d) +
                      " (hits count for t >= 0). The sphere has centre C = " + vec(centre) +
                      " and radius r = sqrt(" + num(r2) + ").";
        Vec3d f = o - centre;
        double a = glm::dot(d, d), b = 2.0 * glm::dot(f, d), cc = glm::dot(f, f) - r2;
        double disc = b * b - 4.0 * a * cc;
        q.solution.push_back(
            "|O + tD - C|^2 = r^2 gives a t^2 + b t + c = 0 with a = D.D = " + num(a) +
            ", b = 2 (O-C).D = " + num(b) + ", c = (O-C).(O-C) - r^2 = " + num(cc));
        q.solution.push_back("discriminant b^2 - 4ac = " + num(disc) +
                             (disc < 0 ? ": the line misses the sphere" : ""));
        if (disc >= 0) {
            double t0 = (-b - std::sqrt(disc)) / (2 * a), t1 = (-b + std::sqrt(disc)) / (2 * a);
            q.solution.push_back("t = (-b -+ sqrt(disc)) / 2a: t0 = " + num(t0) +
                                 ", t1 = " + num(t1) + " (the smallest t >= 0 is the hit" +
                                 (cc < 0 ? "; c < 0: O is inside, so the ray leaves at t1)" : ")"));
        }
        q.parts.push_back(numbersPart("the nearest hit point P (t >= 0), or 'none'",
                                      t ? values(ray.at(*t)) : std::vector<double>{}, 3, true));
        if (t) {
            Vec3d p = ray.at(*t), n = (p - centre) / s.radius;
            q.solution.push_back("P = O + t D = " + vec(p));
            q.solution.push_back("outward unit normal N = (P - C) / r = " + vec(n));
            q.parts.push_back(numbersPart("the outward unit normal at P", values(n), 3));
        }
        return q;
    }
}

// A miss by a margin: parallel, or outside by more than rounding in u, v, 1 - u - v or t.
bool clearMiss(const Rayd& ray, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    Vec3d e1 = b - a, e2 = c - a, p = glm::cross(ray.direction, e2);
    double det = glm::dot(e1, p);
    if (det == 0.0) return true;
    Vec3d s = ray.origin - a, q = glm::cross(s, e1);
    double u = glm::dot(s, p) / det, v = glm::dot(ray.direction, q) / det,
           t = glm::dot(e2, q) / det;
    return std::min({u, v, 1.0 - u - v}) < -0.01 || t < -0.1;
}

bool clearBoxMiss(const Rayd& ray, const Bounds3d& box) {
    double enter = -kInfinity<double>, exit = kInfinity<double>;
    for (int axis = 0; axis < 3; ++axis) {
        double o = ray.origin[axis], d = ray.direction[axis];
        if (d == 0.0) {
            if (o < box.min[axis] || o > box.max[axis]) return true;
            continue;
        }
        double t0 = (box.min[axis] - o) / d, t1 = (box.max[axis] - o) / d;
        enter = std::max(enter, std::min(t0, t1));
        exit = std::min(exit, std::max(t0, t1));
    }
    return enter > exit + 0.1 || exit < -0.1;
}

Question rayTriangleQuestion(Rng& rng, Question q) {
    bool wantHit = rng.chance(70);
    for (int attempt = 0;; ++attempt) {
        Vec3d a = rng.vec(-3, 3), b = rng.vec(-3, 3), c = rng.vec(-3, 3);
        if (glm::length(glm::cross(b - a, c - a)) < 2.0) continue;
        Vec3d o = rng.vec(-4, 4), d = rng.nonZero(-3, 3);
        Rayd ray(o, d);
        auto hit = rayTriangle(ray, a, b, c);
        // Hits well inside the triangle and in front of the origin: nothing hangs on rounding.
        bool clear = hit ? hit->t > 0.1 && hit->u > 0.01 && hit->v > 0.01 && hit->u + hit->v < 0.99
                         : clearMiss(ray, a, b, c);
        if ((hit.has_value() != wantHit || !clear) && attempt < 2000) continue;
        q.given["origin"] = values(o);
        q.given["direction"] = values(d);
        q.given["a"] = values(a);
        q.given["b"] = values(b);
        q.given["c"] = values(c);
        q.statement = "A ray starts at O = " + vec(o) + " with direction D = " + vec(d) +
                      " (hits count for t >= 0). The triangle has the vertices A = " + vec(a) +
                      ", B = " + vec(b) + ", C = " + vec(c) +
                      ". Write a hit as P = (1 - u - v) A + u B + v C.";
        Vec3d e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
        double det = glm::dot(e1, p);
        q.solution.push_back("Moller-Trumbore: E1 = B - A = " + vec(e1) +
                             ", E2 = C - A = " + vec(e2));
        q.solution.push_back("P' = D x E2 = " + vec(p) + ", det = E1 . P' = " + num(det) +
                             (det == 0.0 ? ": the ray is parallel to the triangle, no hit" : ""));
        if (det != 0.0) {
            Vec3d s = o - a, qq = glm::cross(s, e1);
            q.solution.push_back("S = O - A = " + vec(s) + ", Q = S x E1 = " + vec(qq));
            q.solution.push_back("u = S . P' / det = " + num(glm::dot(s, p) / det) +
                                 ", v = D . Q / det = " + num(glm::dot(d, qq) / det) +
                                 ", t = E2 . Q / det = " + num(glm::dot(e2, qq) / det));
            q.solution.push_back(hit ? "u >= 0, v >= 0, u + v <= 1 and t >= 0: a hit"
                                     : "u < 0, v < 0, u + v > 1 or t < 0: no hit");
        }
        q.parts.push_back(numbersPart(
            "t, u and v of the hit, or 'none'",
            hit ? std::vector<double>{hit->t, hit->u, hit->v} : std::vector<double>{}, 3, true));
        if (hit) q.solution.push_back("P = O + t D = " + vec(ray.at(hit->t)));
        return q;
    }
}

Question rayBox(Rng& rng, Question q) {
    bool wantHit = rng.chance(70);
    for (int attempt = 0;; ++attempt) {
        Bounds3d b = randomBox(rng, -3, 3);
        Vec3d o = rng.vec(-5, 5), d = rng.vec(-2, 2);
        if (isZero(d)) continue;
        // A zero direction component with the origin on that slab's plane is the NaN case
        // of step 03; the exam keeps it out of the numbers.
        bool onPlane = false;
        for (int axis = 0; axis < 3; ++axis)
            onPlane =
                onPlane || (d[axis] == 0.0 && (o[axis] == b.min[axis] || o[axis] == b.max[axis]));
        if (onPlane) continue;
        Rayd ray(o, d);
        auto hit = raySlabs(ray, b);
        // No grazing edge or corner, and misses that miss by a margin.
        bool clear = hit ? hit->exit - hit->enter > 0.1 : clearBoxMiss(ray, b);
        if ((hit.has_value() != wantHit || !clear) && attempt < 2000) continue;
        q.given["origin"] = values(o);
        q.given["direction"] = values(d);
        q.given["min"] = values(b.min);
        q.given["max"] = values(b.max);
        q.statement = "A ray starts at O = " + vec(o) + " with direction D = " + vec(d) +
                      ", the points O + t D for t in [0, +inf). The axis-aligned box is "
                      "[min, max] = " +
                      box(b) +
                      ". Use the slab test, and give the part of the ray inside the box as "
                      "exercise 3.6 returns it: the interval clipped to the ray's [0, +inf).";
        const char* names = "xyz";
        for (int axis = 0; axis < 3; ++axis) {
            std::string n(1, names[axis]);
            if (d[axis] == 0.0) {
                q.solution.push_back(n + ": D" + n + " = 0, the ray is parallel to the " + n +
                                     " slab; O" + n + " = " + num(o[axis]) +
                                     (o[axis] < b.min[axis] || o[axis] > b.max[axis]
                                          ? " is outside it: no hit"
                                          : " is inside it: t from -inf to +inf"));
                continue;
            }
            double t0 = (b.min[axis] - o[axis]) / d[axis], t1 = (b.max[axis] - o[axis]) / d[axis];
            q.solution.push_back(n + ": t = (" + n + "_plane - O" + n + ") / D" + n + " gives " +
                                 num(t0) + " and " + num(t1) + ", so [" + num(std::min(t0, t1)) +
                                 ", " + num(std::max(t0, t1)) + "]");
        }
        q.solution.push_back(
            "the line is inside the box for t from the largest entry to the smallest exit; "
            "clipped to the ray's [0, +inf): t_enter = max(0, largest entry), t_exit = smallest "
            "exit; a hit when t_enter <= t_exit");
        double enter = hit ? std::max(0.0, hit->enter) : 0.0;
        q.solution.push_back(
            hit ? "t_enter = " + num(enter) + ", t_exit = " + num(hit->exit) +
                      (hit->enter < 0 ? " (the largest entry, " + num(hit->enter) +
                                            ", is behind the origin: O is inside the box, and "
                                            "the ray's part inside starts at t = 0)"
                                      : "")
                : "no hit");
        q.parts.push_back(numbersPart(
            "t_enter and t_exit of the ray's part inside the box, or 'none'",
            hit ? std::vector<double>{enter, hit->exit} : std::vector<double>{}, 2, true));
        return q;
    }
}

Question reflection(Rng& rng, Question q) {
    Vec3d n = niceNormal(rng), d;
    do d = rng.nonZero(-3, 3);
    while (glm::dot(d, n) >= -0.1);
    q.given["d"] = values(d);
    q.given["n"] = values(n);
    q.statement = "A ray with direction d = " + vec(d) +
                  " hits a mirror with the unit normal n = " + vec(n) + ".";
    Vec3d r = reflect(d, n);
    q.parts.push_back(numbersPart("the reflected direction r (same length as d)", values(r), 3));
    q.solution = {"d . n = " + num(glm::dot(d, n)), "r = d - 2 (d . n) n = " + vec(d) + " - " +
                                                        num(2 * glm::dot(d, n)) + " n = " + vec(r)};
    return q;
}

Question refraction(Rng& rng, Question q) {
    double n1 = rng.oneOf(std::vector<double>{1.0, 1.0, 1.33, 1.5, 2.4});
    double n2 = rng.oneOf(std::vector<double>{1.0, 1.33, 1.5, 2.4});
    if (n1 == n2) n2 = n1 == 1.0 ? 1.5 : 1.0;
    double angle = rng.oneOf(std::vector<double>{0, 15, 30, 45, 60, 75});
    double a = glm::radians(angle);
    Vec3d n(0, 1, 0), d(std::sin(a), -std::cos(a), 0);
    q.given["d"] = values(d);
    q.given["n"] = values(n);
    q.given["n1"] = {n1};
    q.given["n2"] = {n2};
    q.statement = "Light travels from a medium with index n1 = " + num(n1) +
                  " into one with n2 = " + num(n2) + ". The unit direction is d = (sin " +
                  num(angle) + " deg, -cos " + num(angle) + " deg, 0) = " + vec(d) +
                  ", the surface normal n = (0, 1, 0) (towards the light).";
    Vec3d t;
    bool refracted = refract(d, n, n1 / n2, t);
    double sinT = n1 / n2 * std::sin(a);
    q.solution.push_back("Snell: n1 sin(theta_i) = n2 sin(theta_t), theta_i = " + num(angle) +
                         " deg, so sin(theta_t) = " + num(n1) + " / " + num(n2) + " * " +
                         num(std::sin(a)) + " = " + num(sinT));
    if (!refracted) {
        q.solution.push_back(
            "sin(theta_t) > 1: total internal reflection (critical angle asin(n2/n1) = " +
            num(glm::degrees(std::asin(n2 / n1))) + " deg), no refracted ray");
    } else {
        q.solution.push_back("cos(theta_t) = sqrt(1 - sin^2) = " + num(std::sqrt(1 - sinT * sinT)));
        q.solution.push_back("t = eta d + (eta cos(theta_i) - cos(theta_t)) n with eta = n1/n2 = " +
                             num(n1 / n2) + " gives " + vec(t));
    }
    q.parts.push_back(
        numbersPart("the refracted unit direction, or 'none' on total internal reflection",
                    refracted ? values(t) : std::vector<double>{}, 3, true));
    return q;
}

Question fresnel(Rng& rng, Question q) {
    double n2 = rng.oneOf(std::vector<double>{1.33, 1.5, 1.6, 2.0, 2.4});
    double angle = rng.oneOf(std::vector<double>{0, 30, 45, 60, 75, 80, 89});
    double cosI = std::cos(glm::radians(angle));
    q.given["n1"] = {1.0};
    q.given["n2"] = {n2};
    q.given["angle"] = {angle};
    q.statement = "Light in air (n1 = 1) meets a surface with n2 = " + num(n2) + " at " +
                  num(angle) + " degrees from the normal.";
    double r = fresnelSchlick(cosI, 1.0, n2);
    double r0 = (1.0 - n2) / (1.0 + n2);
    q.parts.push_back(numbersPart("the reflectance R by Schlick's approximation", {r}, 1));
    q.solution = {
        "R0 = ((n1 - n2) / (n1 + n2))^2 = " + num(r0 * r0), "cos(theta) = " + num(cosI),
        "R = R0 + (1 - R0) (1 - cos(theta))^5 = " + num(r),
        "(the exact Fresnel value would be " + num(fresnelDielectric(cosI, 1.0, n2)) + ")"};
    return q;
}

Question aabbPoints(Rng& rng, Question q) {
    int count = rng.pick(3, 5);
    Bounds3d b;
    std::string list;
    std::vector<double> flat;
    for (int i = 0; i < count; ++i) {
        Vec3d p = rng.vec(-6, 6);
        b.extend(p);
        list += (i ? ", " : "") + vec(p);
        flat.insert(flat.end(), {p.x, p.y, p.z});
    }
    q.given["points"] = flat;
    q.statement = "The points " + list + ".";
    q.parts.push_back(
        numbersPart("the min corner of their axis-aligned bounding box", values(b.min), 3));
    q.parts.push_back(numbersPart("the max corner", values(b.max), 3));
    q.solution = {"per axis, the smallest and the largest coordinate of all points",
                  "min = " + vec(b.min), "max = " + vec(b.max)};
    return q;
}

Question aabbUnion(Rng& rng, Question q) {
    Bounds3d a = randomBox(rng, -5, 5), b = randomBox(rng, -5, 5);
    q.given["amin"] = values(a.min);
    q.given["amax"] = values(a.max);
    q.given["bmin"] = values(b.min);
    q.given["bmax"] = values(b.max);
    q.statement = "Two axis-aligned boxes: A = " + box(a) + " and B = " + box(b) + ".";
    Bounds3d u(glm::min(a.min, b.min), glm::max(a.max, b.max));
    q.parts.push_back(
        numbersPart("the min corner of their union's bounding box", values(u.min), 3));
    q.parts.push_back(numbersPart("the max corner", values(u.max), 3));
    q.solution = {
        "min = (min(Ax, Bx), min(Ay, By), min(Az, Bz)) of the min corners = " + vec(u.min),
        "max = the same with max of the max corners = " + vec(u.max),
        "(mind each line uses its own axis: the lecture's bmin.y line reads B.bmin.x)"};
    return q;
}

Question aabbOverlap(Rng& rng, Question q) {
    bool wantOverlap = rng.chance(50);
    for (int attempt = 0;; ++attempt) {
        Bounds3d a = randomBox(rng, -3, 3), b = randomBox(rng, -3, 3);
        bool overlap = boxesOverlap(a, b);
        if (overlap != wantOverlap && attempt < 500) continue;
        q.given["amin"] = values(a.min);
        q.given["amax"] = values(a.max);
        q.given["bmin"] = values(b.min);
        q.given["bmax"] = values(b.max);
        q.statement = "Two closed axis-aligned boxes: A = " + box(a) + " and B = " + box(b) + ".";
        q.parts.push_back(yesNoPart("do they overlap (touching counts)?", overlap));
        const char* names = "xyz";
        for (int axis = 0; axis < 3; ++axis) {
            bool apart = a.min[axis] > b.max[axis] || b.min[axis] > a.max[axis];
            q.solution.push_back(
                std::string(1, names[axis]) + ": A [" + num(a.min[axis]) + ", " + num(a.max[axis]) +
                "], B [" + num(b.min[axis]) + ", " + num(b.max[axis]) + "]: " +
                (apart ? "Amin > Bmax or Bmin > Amax, separated" : "the intervals overlap"));
        }
        q.solution.push_back(
            overlap ? "overlap on every axis: the boxes overlap"
                    : "separated on an axis: no overlap (both directions of the test are needed)");
        return q;
    }
}

Question frustumCull(Rng& rng, Question q) {
    Vec3d n = rng.nonZero(-2, 2);
    double d = rng.pick(-6, 6);
    Bounds3d b = randomBox(rng, -4, 4);
    q.given["n"] = values(n);
    q.given["d"] = {d};
    q.given["min"] = values(b.min);
    q.given["max"] = values(b.max);
    q.statement = "A frustum plane N . P + d = 0 has N = " + vec(n) + " and d = " + num(d) +
                  "; the inside of the frustum is where N . P + d >= 0. The box is " + box(b) + ".";
    Vec3d p = positiveVertex(b, n);
    bool culled = culledByPlane(b, n, d);
    q.parts.push_back(numbersPart("the p-vertex (the box corner farthest along N)", values(p), 3));
    q.parts.push_back(yesNoPart("is the box culled by this plane?", culled));
    q.solution = {
        "p-vertex: per axis, max if N's component >= 0, else min: " + vec(p),
        "N . p + d = " + num(glm::dot(n, p) + d) +
            (culled ? " < 0: even the p-vertex is outside, so the whole box is: culled"
                    : " >= 0: part of the box may be inside: kept"),
        "(with all six planes the test is conservative: a box outside near a corner of the "
        "frustum may be kept, never a visible one culled)"};
    return q;
}

const std::vector<Term>& terms() {
    static const std::vector<Term> list = {
        {"AABB",
         "The smallest box with faces parallel to the coordinate axes that holds an object, "
         "stored as two corners bmin and bmax: by what four-letter abbreviation is it known, "
         "and what does it stand for?",
         {{"aabb"}},
         "AABB, an Axis-Aligned Bounding Box."},
        {"slab test",
         "By what name is the ray/AABB test known that intersects the ray with each pair of "
         "parallel planes and keeps the overlap of the t intervals?",
         {{"slab"}},
         "The slab test: per axis the ray is between the two planes for one interval of t; "
         "the ray meets the box where the three intervals overlap."},
        {"hierarchical grouping",
         "Objects are grouped in boxes, those boxes in bigger boxes, and so on, so that a ray "
         "that misses a box skips everything inside it. What is this called?",
         {{"hierarch", "bvh", "bounding volume"}},
         "Hierarchical grouping (a bounding volume hierarchy): a ray that misses the red box "
         "hits nothing at all; one that misses a blue box skips the green boxes inside it."},
        {"view frustum",
         "What is the volume of space that a camera sees called, the truncated pyramid bounded "
         "by six planes against which boxes are culled?",
         {{"frustum"}},
         "The view frustum: near and far plane and four side planes through the eye."},
        {"false negatives",
         "The lecture calls its single-vertex culling test conservative: it keeps some boxes "
         "that are outside the frustum but never culls one that is inside. In the lecture's "
         "words, what does the test produce, and what does it not?",
         {{"false negative"}},
         "False negatives, but no false positives: the test answers 'is the box outside?', and "
         "a box outside that it keeps is a wrong 'no'. (Counting 'visible' as the positive "
         "answer, the same box is a false positive; the workbook follows the lecture.)"},
        {"conservative",
         "Culling schemes that mark some objects as visible when they are not, but never the "
         "other way around: what is such a scheme called?",
         {{"conservative"}},
         "Conservative: its errors cost time (work on invisible objects), never pixels."},
        {"global data",
         "The rasterization pipeline renders triangles one at a time, so determining light "
         "visibility (shadows) is non-trivial. To what does rasterization not have access?",
         {{"global"}},
         "Global data: a triangle being drawn knows nothing of the others, so it cannot trace "
         "a shadow ray; shadow maps precompute that visibility in a pass of their own."},
        {"early out",
         "Stopping a calculation as soon as its result is known, for instance ending a shadow "
         "ray at the first occluder it finds: what is that optimization called?",
         {{"early"}},
         "An early out: the shadow ray needs any hit before the light, not the nearest one."},
        {"loop hoisting",
         "Moving a calculation whose value does not change inside a loop to before the loop: "
         "what is that called?",
         {{"hoist"}},
         "Loop hoisting, a form of precalculation: computed once instead of every iteration."},
        {"vertex shader",
         "Per-vertex work (transforming, lighting at the vertices) is done once per vertex "
         "instead of once per pixel, then interpolated. In which stage of the rasterization "
         "pipeline does that precalculation run?",
         {{"vertex"}},
         "The vertex shader: three vertices' work shared by every pixel of the triangle."},
        {"look-up table",
         "Instead of calling sin and cos, a program reads precomputed values from an array "
         "indexed by the angle. What is that array called?",
         {{"table", "lut"}},
         "A look-up table (the lecture's sintab and costab); its error is the step between "
         "entries, and its index must wrap."},
        {"z-buffer",
         "With which buffer does rasterization sort the pixels of primitives by depth, "
         "keeping per pixel the nearest one drawn so far?",
         {{"z-buffer", "z buffer", "zbuffer", "depth buffer", "depth-buffer"}},
         "The z-buffer (depth buffer): one depth per pixel, a fragment is kept when nearer."},
        {"tangent space",
         "Which coordinate system is attached to a point of a surface, with axes along the "
         "surface's tangent, bitangent and normal, and is used for normal and texture maps?",
         {{"tangent"}},
         "Tangent space: the frame in which a normal map's normals and the texture "
         "coordinates' directions are given."},
        {"clip space",
         "In which space, after the projection matrix and before the division by w, does the "
         "rasterizer clip triangles against the near plane?",
         {{"clip"}},
         "Clip space: homogeneous coordinates; clipping there, before the divide, keeps "
         "vertices behind the eye from being mirrored."},
        {"Moller-Trumbore",
         "Which ray/triangle algorithm (Journal of Graphics Tools, 1997) does the lecture cite "
         "as more efficient than intersecting the plane first?",
         {{"moller", "möller", "moeller"}, {"trumbore"}},
         "Moller and Trumbore, 'Fast, Minimum Storage Ray/Triangle Intersection'."},
        {"incremental rendering",
         "A renderer shows a quick preview while the camera moves and refines the image "
         "while it stands still. What does the lecture call this way of improving perceived "
         "performance?",
         {{"incremental", "progressive"}},
         "Incremental rendering: preview, then normal recursion, then 'photograph mode'."},
    };
    return list;
}

Question termQuestion(const Term& t, Question q) {
    q.statement = t.question;
    q.parts.push_back(wordsPart("the term", t.keywords, t.term));
    q.solution = {t.explanation};
    return q;
}

Question glassQuestion(Question q) {
    q.statement = "Glass causes two types of scattering. Name both.";
    q.parts.push_back(wordsPart("the two types of scattering that glass causes",
                                {{"reflect"}, {"refract", "transmi"}},
                                "reflection and refraction"));
    q.solution = {
        "At a glass surface part of the light is reflected (mirror direction, Fresnel "
        "reflectance) and the rest refracted (transmitted, bent by Snell's law).",
        "A Whitted ray tracer follows both: a reflection ray and a refraction ray."};
    return q;
}

Question terminology(Rng& rng, Question q) {
    // One of the lecture's terms, the glass question of its example exam, or the choice
    // question on what conservative means.
    int pick = rng.pick(0, int(terms().size()) + 1);
    if (pick < int(terms().size())) return termQuestion(terms()[size_t(pick)], std::move(q));
    if (pick == int(terms().size())) return glassQuestion(std::move(q));
    std::vector<std::string> options = {
        "it never removes an object that is visible, but may keep some that are not",
        "it removes every invisible object, but may also remove some visible ones",
        "it removes exactly the invisible objects", "it only works for spheres"};
    std::vector<size_t> order = {0, 1, 2, 3};
    for (size_t i = order.size() - 1; i > 0; --i)
        std::swap(order[i], order[size_t(rng.pick(0, int(i)))]);
    q.statement =
        "Frustum culling with the single-vertex test is conservative. What does that mean?";
    Part p;
    p.type = AnswerType::Choice;
    for (size_t i = 0; i < order.size(); ++i) {
        q.statement += std::string("\n  ") + char('a' + i) + ") " + options[order[i]];
        if (order[i] == 0) p.choice = char('a' + i);
    }
    p.prompt = "a, b, c or d";
    p.shown = std::string(1, p.choice);
    q.parts.push_back(p);
    q.solution = {
        std::string("(") + p.choice + ") " + options[0] + ".",
        "A box outside the frustum near its corners can have its p-vertex inside every "
        "plane: it is kept although it is outside. The lecture calls that a false negative "
        "(the test answers 'is the box outside?' and wrongly says no); counting 'visible' as "
        "the positive answer it would be a false positive. It costs time, never pixels.",
        "Testing the frustum's corners against the box's planes as well removes most of them."};
    return q;
}

// The worked example of the exam practice, with its exact numbers.
Question workedExample(Rng&, Question q) {
    Rayd ray({1, 1, 1}, {1, 0, 1});
    SphereT<double> s{{-1, 1, -1}, std::sqrt(20.0)};
    q.given["origin"] = {1, 1, 1};
    q.given["direction"] = {1, 0, 1};
    q.given["centre"] = {-1, 1, -1};
    q.given["radius2"] = {20};
    q.statement =
        "The eye is at E = (1, 1, 1) and looks along V = (1, 0, 1). The sphere is "
        "|p - C| = sqrt(20) with C = (-1, 1, -1). Exact forms such as sqrt(10)-1 are fine.\n"
        "(The first question of the lecture's example exam, parts b to e. Where its text is "
        "ambiguous this version decides: the ray r runs from E along V; the up vector, "
        "printed equal to V, is not needed here; E lies inside the sphere, so 'the "
        "intersection' is where r leaves it, the point P of part e, and the normal asked is "
        "the one pointing inside; the plane '-X - Z = 10' lies behind the eye, so x + z = 10 "
        "is asked too.)";
    auto t = intersectSphere(ray, s);
    Vec3d p = ray.at(*t), inward = -(p - s.centre) / s.radius;
    Part leave = numbersPart("where the ray from E along V leaves the sphere", values(p), 3);
    leave.shown = "(sqrt(10)-1, 1, sqrt(10)-1) = " + vec(p);
    Part normal = numbersPart("the unit normal there, pointing to the inside", values(inward), 3);
    normal.shown = "(-1, 0, -1)/sqrt(2) = " + vec(inward);
    auto front = intersectPlane(ray, PlaneT<double>{{1, 0, 1}, -10});
    auto behind = intersectPlane(ray, PlaneT<double>{{-1, 0, -1}, -10});
    q.parts = {leave, normal,
               numbersPart("the hit point with the plane x + z = 10, or 'none'",
                           values(ray.at(*front)), 3, true),
               numbersPart("the hit point with the plane -x - z = 10, or 'none'",
                           behind ? values(ray.at(*behind)) : std::vector<double>{}, 3, true)};
    q.solution = {
        "|E - C|^2 = 4 + 0 + 4 = 8 < 20: the eye is inside the sphere, so the ray leaves it",
        "E + tV - C = (2 + t, 0, 2 + t); 2 (2 + t)^2 = 20, so 2 + t = +-sqrt(10)",
        "t = sqrt(10) - 2 (the other root is negative): P = (sqrt(10)-1, 1, sqrt(10)-1)",
        "inward normal: -(P - C)/r = -(sqrt(10), 0, sqrt(10))/sqrt(20) = (-1, 0, -1)/sqrt(2)",
        "x + z = 10: (1 + t) + (1 + t) = 10 gives t = 4 >= 0: P = (5, 1, 5)",
        "-x - z = 10: -(2 + 2t) = 10 gives t = -6 < 0: the plane lies behind the eye, no hit"};
    return q;
}

}  // namespace gen

namespace {

using namespace gen;

using Generator = std::function<Question(Rng&, Question, const MeasuredCosts&)>;
// Most kinds need only their seeded numbers.
template <Question (*make)(Rng&, Question)>
Question seeded(Rng& rng, Question q, const MeasuredCosts&) {
    return make(rng, std::move(q));
}
struct KindEntry {
    QuestionKind kind;
    Generator make;
};

const std::vector<KindEntry>& kindTable() {
    static const std::vector<KindEntry> table = {
        {{"vectors", "dot and cross products and normalization"}, seeded<vectors>},
        {{"screen-corners",
          "the camera's virtual screen corners from eye, view, up, fov and aspect"},
         seeded<screenCorners>},
        {{"primary-ray", "a primary ray's normalized direction through a pixel centre"},
         seeded<primaryRay>},
        {{"ray-plane", "a ray's hit point with a plane N.P + d = 0"}, seeded<rayPlane>},
        {{"ray-sphere", "a ray's nearest hit on a sphere and the normal there"}, seeded<raySphere>},
        {{"ray-triangle", "t and the barycentrics (u, v) of a ray/triangle hit"},
         seeded<rayTriangleQuestion>},
        {{"ray-box",
          "the slab test: the interval [t_enter, t_exit] of a ray (t >= 0) inside an "
          "axis-aligned box, clipped as exercise 3.6 does"},
         seeded<rayBox>},
        {{"reflect", "a mirror reflection direction"}, seeded<reflection>},
        {{"refract", "a refraction direction by Snell's law, or total internal reflection"},
         seeded<refraction>},
        {{"fresnel", "reflectance by Schlick's approximation"}, seeded<fresnel>},
        {{"aabb-points", "the axis-aligned bounding box of a set of points"}, seeded<aabbPoints>},
        {{"aabb-union", "the union of two axis-aligned boxes"}, seeded<aabbUnion>},
        {{"aabb-overlap", "whether two closed axis-aligned boxes overlap"}, seeded<aabbOverlap>},
        {{"frustum-cull", "the single-vertex (p-vertex) test of a box against a frustum plane"},
         seeded<frustumCull>},
        {{"light-shading",
          "light transport: diffuse shading of a point by a point light, N.L and the 1/d^2 "
          "falloff"},
         seeded<lightShading>},
        {{"shadow-ray",
          "light transport: is the point in shadow? a shadow ray towards the light and one "
          "sphere"},
         seeded<shadowRay>},
        {{"ray-depth",
          "light transport: the reflected and refracted rays at each depth of a ray through "
          "a glass slab"},
         seeded<rayDepth>},
        {{"slide-union",
          "what the lecture's union code returns for two boxes, printed as on the slide"},
         seeded<slideUnion>},
        {{"slide-slab",
          "what the lecture's slab test returns for a ray and a box: its formulas or its "
          "pseudo-code, printed as on the slides"},
         seeded<slideSlab>},
        {{"cost-order",
          "the cost of sin, sqrt, /, *, + as your run of step 05 measured them, and the "
          "sine table against std::sin"},
         costOrder},
        {{"terminology",
          "the lecture's terms (AABB, slab test, frustum, false negatives, global data, ...); "
          "conservative culling; the two kinds of scattering glass causes"},
         seeded<terminology>},
        {{"example-1a",
          "the example exam's question 1a: the four corners of the virtual screen (seed 0: "
          "its own E = (1,1,1), V = (1,0,1))"},
         seeded<exampleCorners>},
        {{"example-1b",
          "the example exam's question 1b: the normalized direction of the ray r (seed 0: "
          "its own numbers)"},
         seeded<exampleDirection>},
        {{"worked-example",
          "the lecture's example exam, question 1: E = (1,1,1), V = (1,0,1), the sphere "
          "|p - C| = sqrt(20)"},
         seeded<workedExample>},
    };
    return table;
}

}  // namespace

std::vector<std::string> terminologyTerms() {
    std::vector<std::string> names;
    for (const gen::Term& t : gen::terms()) names.push_back(t.term);
    return names;
}

const std::vector<QuestionKind>& questionKinds() {
    static const std::vector<QuestionKind> kinds = [] {
        std::vector<QuestionKind> k;
        for (const KindEntry& e : kindTable()) k.push_back(e.kind);
        return k;
    }();
    return kinds;
}

Question makeQuestion(const std::string& kind, uint64_t seed, const MeasuredCosts& costs) {
    for (const KindEntry& e : kindTable()) {
        if (e.kind.name != kind) continue;
        Rng rng(seed);
        Question q;
        q.kind = kind;
        q.seed = seed;
        return e.make(rng, std::move(q), costs);
    }
    std::string names;
    for (const QuestionKind& k : questionKinds()) names += (names.empty() ? "" : ", ") + k.name;
    throw std::invalid_argument("unknown question kind '" + kind + "' (kinds: " + names + ")");
}

std::string formatNumbers(const std::vector<double>& v) {
    std::string s = "(";
    for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + num(v[i]);
    return s + ")";
}

Checked checkAnswer(const Part& part, const std::string& answer) {
    std::string a = normalizeWords(answer);
    if (a.empty()) return {Verdict::Unreadable, "no answer given"};
    switch (part.type) {
        case AnswerType::YesNo: {
            bool yes = a == "yes" || a == "y" || a == "true" || a == "culled" || a == "overlap";
            bool no = a == "no" || a == "n" || a == "false" || a == "kept" || a == "not culled";
            if (!yes && !no) return {Verdict::Unreadable, "answer yes or no"};
            return {yes == part.yes ? Verdict::Correct : Verdict::Wrong, ""};
        }
        case AnswerType::Choice: {
            char c = a[0];
            if (a.size() > 2 || c < 'a' || c > 'z' || (a.size() == 2 && a[1] != ')'))
                return {Verdict::Unreadable, "answer with one letter"};
            return {c == part.choice ? Verdict::Correct : Verdict::Wrong, ""};
        }
        case AnswerType::Words: {
            for (const auto& group : part.keywords) {
                bool found = false;
                for (const std::string& w : group) found = found || a.find(w) != std::string::npos;
                if (!found) return {Verdict::Wrong, "'" + group[0] + "...' is missing"};
            }
            return {Verdict::Correct, ""};
        }
        case AnswerType::Order: {
            // "c a b", "c, a, b", "cab", "c < a < b": the letters, in order.
            std::string letters;
            for (char c : a)
                if (std::isalpha(static_cast<unsigned char>(c))) letters += c;
            std::string wanted = part.order;
            std::sort(wanted.begin(), wanted.end());
            std::string given = letters;
            std::sort(given.begin(), given.end());
            if (given != wanted) {
                std::string names;
                for (size_t i = 0; i < wanted.size(); ++i)
                    names += (i == 0                   ? ""
                              : i + 1 == wanted.size() ? " and "
                                                       : ", ") +
                             std::string(1, wanted[i]);
                return {Verdict::Unreadable,
                        "give each of the letters " + names + " once, in order"};
            }
            return {letters == part.order ? Verdict::Correct : Verdict::Wrong, ""};
        }
        case AnswerType::Numbers:
            break;
    }
    bool saysNone = a == "none" || a == "no hit" || a == "miss" || a == "no" || a == "-" ||
                    a == "tir" || a.starts_with("total internal");
    if (saysNone) {
        if (!part.noneAllowed) return {Verdict::Unreadable, "this question has a number answer"};
        return {part.expected.empty() ? Verdict::Correct : Verdict::Wrong,
                part.expected.empty() ? "" : "there is an answer"};
    }
    std::vector<double> got;
    try {
        got = parseNumberList(answer);
    } catch (const std::invalid_argument& e) {
        return {Verdict::Unreadable, e.what()};
    }
    if (got.size() != part.count)
        return {Verdict::Unreadable, "expected " + std::to_string(part.count) + " number" +
                                         (part.count == 1 ? "" : "s") + ", read " +
                                         std::to_string(got.size())};
    if (part.expected.empty()) return {Verdict::Wrong, "there is none"};
    if (got.size() == 3) {
        // A unit answer given unnormalized: say so, it is the most common slip.
        Vec3d g(got[0], got[1], got[2]), e(part.expected[0], part.expected[1], part.expected[2]);
        double lg = glm::length(g);
        if (std::abs(glm::length(e) - 1.0) < 1e-9 && lg > 0.0 &&
            std::abs(lg - 1.0) > kAbsoluteTolerance && glm::length(g / lg - e) < kAbsoluteTolerance)
            return {Verdict::Wrong,
                    "the right direction, but not of unit length: divide by " + num(lg)};
    }
    for (size_t i = 0; i < got.size(); ++i)
        if (!withinTolerance(got[i], part.expected[i]))
            return {Verdict::Wrong, (got.size() == 1 ? std::string("you gave ")
                                                     : "number " + std::to_string(i + 1) + " is ") +
                                        num(got[i]) + ", not " + num(part.expected[i])};
    return {Verdict::Correct, ""};
}

}  // namespace boxes::exam
