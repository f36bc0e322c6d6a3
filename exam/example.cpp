// The first question of the lecture's example exam, a to e on one set of givens: the corners
// of the virtual screen, the normalized direction of a ray r from the eye, r against a plane,
// r against a sphere, and the sphere's normal there. With the exam's own numbers or seeded.
#include <cmath>
#include <optional>

#include "core/math.hpp"
#include "exam/kinds.hpp"

namespace boxes::exam::gen {

namespace {

// "2x - y + 3z = 7" for the plane N.P + d = 0.
std::string planeText(const Vec3d& n, double d) {
    std::string s;
    const char* names[] = {"x", "y", "z"};
    for (int i = 0; i < 3; ++i) {
        double c = n[i];
        if (c == 0.0) continue;
        std::string sign = c < 0.0 ? (s.empty() ? "-" : " - ") : (s.empty() ? "" : " + ");
        double m = std::abs(c);
        s += sign + (m == 1.0 ? "" : num(m)) + names[i];
    }
    return s + " = " + num(-d);
}

struct Givens {
    Vec3d eye, view, up{0, 1, 0};
    double distance = 1, width = 2, height = 2;
    double sx = 0, sy = 0;  // the point r passes through, from the screen's centre
    Vec3d planeNormal;
    double planeD = 0;
    Vec3d centre;
    double radius2 = 1;
    bool inwardNormal = false;
};

struct Screen {
    Vec3d w, u, v, centre, topLeft, topRight, bottomLeft, bottomRight;
};

Screen screenOf(const Givens& g) {
    Screen s;
    s.w = glm::normalize(g.view);
    s.u = glm::normalize(glm::cross(s.w, g.up));
    s.v = glm::cross(s.u, s.w);
    s.centre = g.eye + g.distance * s.w;
    double hw = g.width / 2, hh = g.height / 2;
    s.topLeft = s.centre - hw * s.u + hh * s.v;
    s.topRight = s.centre + hw * s.u + hh * s.v;
    s.bottomLeft = s.centre - hw * s.u - hh * s.v;
    s.bottomRight = s.centre + hw * s.u - hh * s.v;
    return s;
}

Vec3d directionOf(const Givens& g, const Screen& s) {
    return glm::normalize(s.centre + g.sx * s.u + g.sy * s.v - g.eye);
}

// Seeded givens whose answers hang on no rounding: a plane crossed at a slant (or clearly
// behind), a sphere that r meets clearly.
Givens seededGivens(Rng& rng) {
    Givens g;
    g.eye = rng.vec(-3, 3);
    do g.view = rng.nonZero(-2, 2);
    while (glm::length(glm::cross(glm::normalize(g.view), g.up)) < 0.5);
    g.distance = rng.oneOf(std::vector<double>{1, 2});
    static const std::vector<std::pair<double, double>> sizes = {{2, 2}, {4, 2}, {2, 1}, {4, 3}};
    auto [w, h] = rng.oneOf(sizes);
    g.width = w;
    g.height = h;
    if (rng.chance(75)) {
        g.sx = rng.oneOf(std::vector<double>{-0.5, -0.25, 0.0, 0.25, 0.5}) * w;
        g.sy = rng.oneOf(std::vector<double>{-0.5, 0.0, 0.5}) * h;
    }
    Vec3d d = directionOf(g, screenOf(g));
    bool planeHit = rng.chance(75);
    for (int attempt = 0;; ++attempt) {
        g.planeNormal = rng.nonZero(-2, 2);
        g.planeD = rng.pick(-12, 12);
        double nd = glm::dot(g.planeNormal, d);
        if (std::abs(nd) < 0.15) continue;
        double t = -(glm::dot(g.planeNormal, g.eye) + g.planeD) / nd;
        if (std::abs(t) < 0.3) continue;
        if ((t > 0.0) == planeHit || attempt > 500) break;
    }
    for (;;) {
        Vec3d q = g.eye + double(rng.pick(2, 6)) * d;
        g.centre = glm::round(q) + rng.vec(-1, 1);
        Vec3d l = g.eye - g.centre;
        double along = glm::dot(l, d), dist2 = glm::dot(l, l) - along * along;
        g.radius2 = std::ceil(dist2) + rng.pick(1, 6);
        double disc = along * along - (glm::dot(l, l) - g.radius2);
        double tFar = -along + std::sqrt(disc);
        if (disc > 0.25 && tFar > 0.5 && std::abs(glm::dot(l, l) - g.radius2) > 0.25) break;
    }
    g.inwardNormal = rng.chance(50);
    return g;
}

Givens lectureGivens() {
    Givens g;
    g.eye = {1, 1, 1};
    g.view = {1, 0, 1};
    g.planeNormal = {-1, 0, -1};
    g.planeD = -10;  // -x - z = 10
    g.centre = {-1, 1, -1};
    g.radius2 = 20;
    g.inwardNormal = true;
    return g;
}

void give(Question& q, const Givens& g) {
    q.given["eye"] = values(g.eye);
    q.given["view"] = values(g.view);
    q.given["up"] = values(g.up);
    q.given["screen"] = {g.distance, g.width, g.height};
    q.given["through"] = {g.sx, g.sy};
    q.given["plane"] = {g.planeNormal.x, g.planeNormal.y, g.planeNormal.z, g.planeD};
    q.given["centre"] = values(g.centre);
    q.given["radius2"] = {g.radius2};
    q.given["inward"] = {g.inwardNormal ? 1.0 : 0.0};
}

std::string throughText(const Givens& g) {
    if (g.sx == 0.0 && g.sy == 0.0) return "the centre of the screen";
    std::string across = g.sx == 0.0  ? ""
                         : g.sx > 0.0 ? num(g.sx) + " to the right"
                                      : num(-g.sx) + " to the left";
    std::string along = g.sy == 0.0 ? "" : g.sy > 0.0 ? num(g.sy) + " up" : num(-g.sy) + " down";
    return "the point of the screen " + across + (across.empty() || along.empty() ? "" : " and ") +
           along + " from its centre (along the screen's own right and up directions)";
}

}  // namespace

ChainedQuestion exampleQuestionOne(Rng& rng, bool lectureNumbers) {
    Givens g = lectureNumbers ? lectureGivens() : seededGivens(rng);
    ChainedQuestion c;
    give(c.givens, g);
    c.givens.statement =
        "Given: an eye position E = " + vec(g.eye) + ", a view vector V = " + vec(g.view) +
        " and an up vector U = " + vec(g.up) +
        ". The virtual screen is perpendicular to V at distance " + num(g.distance) + " from E, " +
        num(g.width) + " wide and " + num(g.height) + " high, its top edge towards U.";
    if (lectureNumbers)
        c.givens.statement +=
            " (The example exam's own numbers. Where its text is ambiguous or cut off, this "
            "version decides: its up vector is printed equal to V, which leaves no screen, so "
            "U = (0, 1, 0); its text gives no distance or size of the screen, so they are "
            "stated; its plane, printed as -X - Z \u2248 10, is read as -x - z = 10.)";
    Screen s = screenOf(g);
    Vec3d d = directionOf(g, s);
    Rayd r(g.eye, d);

    Question a;
    a.statement = "a. Calculate the four corners of the virtual screen.";
    a.parts = {numbersPart("the top-left corner", values(s.topLeft), 3),
               numbersPart("the top-right corner", values(s.topRight), 3),
               numbersPart("the bottom-left corner", values(s.bottomLeft), 3),
               numbersPart("the bottom-right corner", values(s.bottomRight), 3)};
    a.solution = {"w = V / |V| = " + vec(s.w),
                  "u = (w x U) / |w x U| = " + vec(s.u) + "   (the screen's right)",
                  "v = u x w = " + vec(s.v) + "   (the screen's up)",
                  "centre M = E + " + num(g.distance) + " w = " + vec(s.centre),
                  "top-left = M - " + num(g.width / 2) + " u + " + num(g.height / 2) +
                      " v = " + vec(s.topLeft) + ", top-right = M + " + num(g.width / 2) + " u + " +
                      num(g.height / 2) + " v = " + vec(s.topRight),
                  "bottom-left = M - " + num(g.width / 2) + " u - " + num(g.height / 2) +
                      " v = " + vec(s.bottomLeft) + ", bottom-right = " + vec(s.bottomRight)};
    c.parts.emplace_back("the four corners of the virtual screen", a);

    Question b;
    b.statement = "b. Ray r originates from E and extends through " + throughText(g) +
                  ". Determine the normalized direction of r.";
    b.parts = {numbersPart("the normalized direction of r", values(d), 3)};
    Vec3d point = s.centre + g.sx * s.u + g.sy * s.v;
    b.solution = {"the point: M" + plus(g.sx) + " u" + plus(g.sy) + " v = " + vec(point),
                  "r = (point - E) / |point - E| = " + vec(point - g.eye) + " / " +
                      num(glm::length(point - g.eye)) + " = " + vec(d)};
    if (g.sx == 0.0 && g.sy == 0.0) b.solution.push_back("(through the centre: simply V / |V|)");
    c.parts.emplace_back("the normalized direction of r", b);

    Question cq;
    cq.statement =
        "c. Determine the 3D coordinate of the intersection of r (t >= 0) with the "
        "plane " +
        planeText(g.planeNormal, g.planeD) + ", or 'none'.";
    auto tp = intersectPlane(r, PlaneT<double>{g.planeNormal, g.planeD});
    cq.parts = {numbersPart("the intersection point, or 'none'",
                            tp ? values(r.at(*tp)) : std::vector<double>{}, 3, true)};
    double nd = glm::dot(g.planeNormal, d), ne = glm::dot(g.planeNormal, g.eye);
    double tPlane = -(ne + g.planeD) / nd;
    cq.solution = {
        "the plane is N . P + d = 0 with N = " + vec(g.planeNormal) + ", d = " + num(g.planeD),
        "t = -(N . E + d) / (N . r) = -(" + num(ne) + plus(g.planeD) + ") / " + num(nd) + " = " +
            num(tPlane),
        tPlane < 0.0 ? "t < 0: the plane lies behind the eye, no intersection"
                     : "P = E + t r = " + vec(r.at(tPlane))};
    c.parts.emplace_back("r against a plane", cq);

    Question dq;
    dq.statement =
        "d. Calculate the first intersection of r (t > 0) with the sphere "
        "|p - C| = sqrt(" +
        num(g.radius2) + "), where C = " + vec(g.centre) + ".";
    SphereT<double> sphere{g.centre, std::sqrt(g.radius2)};
    auto ts = intersectSphere(r, sphere);
    Vec3d hit = r.at(*ts);
    dq.parts = {numbersPart("the intersection point", values(hit), 3)};
    Vec3d l = g.eye - g.centre;
    double half = glm::dot(d, l), cc = glm::dot(l, l) - g.radius2, disc = half * half - cc;
    dq.solution = {
        "|E + t r - C|^2 = R^2 with |r| = 1: t^2 + 2 (r . L) t + |L|^2 - R^2 = 0, L = E - C = " +
            vec(l),
        "r . L = " + num(half) + ", |L|^2 - R^2 = " + num(cc) +
            (cc < 0.0 ? " < 0: E is inside the sphere, so r leaves it ahead" : ""),
        "t = -(r . L) -+ sqrt((r . L)^2 - |L|^2 + R^2) = " + num(-half - std::sqrt(disc)) +
            " and " + num(-half + std::sqrt(disc)) + "; the first with t > 0: " + num(*ts),
        "P = E + t r = " + vec(hit)};
    c.parts.emplace_back("r against a sphere", dq);

    Question e;
    std::string side = g.inwardNormal ? "inside" : "outside";
    e.statement = "e. Calculate the unit normal of the sphere at the point of d, pointing to the " +
                  side + " of the sphere.";
    Vec3d outward = (hit - g.centre) / sphere.radius;
    Vec3d normal = g.inwardNormal ? -outward : outward;
    e.parts = {numbersPart("the unit normal, pointing to the " + side, values(normal), 3)};
    e.solution = {"outward: (P - C) / R = " + vec(hit - g.centre) + " / " + num(sphere.radius) +
                      " = " + vec(outward),
                  g.inwardNormal ? "pointing inside: its negative, " + vec(normal)
                                 : "pointing outside: " + vec(normal)};
    c.parts.emplace_back("the sphere's normal", e);
    return c;
}

namespace {

Question onePart(Rng& rng, Question q, size_t index) {
    ChainedQuestion c = exampleQuestionOne(rng, q.seed == 0);
    const Question& part = c.parts[index].second;
    q.given = c.givens.given;
    q.statement = c.givens.statement + "\n" + part.statement;
    if (q.seed == 0)
        q.statement += "\n(seed 0: the example exam's own numbers; every other seed, others.)";
    q.parts = part.parts;
    q.solution = part.solution;
    return q;
}

}  // namespace

Question exampleCorners(Rng& rng, Question q) {
    return onePart(rng, std::move(q), 0);
}

Question exampleDirection(Rng& rng, Question q) {
    return onePart(rng, std::move(q), 1);
}

}  // namespace boxes::exam::gen
