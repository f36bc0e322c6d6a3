// Step 06's exercises on generated inputs (harness.hpp says how).
#pragma once

#include "06_raster/pipeline.hpp"
#include "06_raster/raster.hpp"
#include "core/render.hpp"
#include "differential/step04.hpp"

namespace boxes::differential {

inline std::string matrixText(const Record& r, size_t at) {
    std::string s = "[";
    for (int c = 0; c < 4; ++c) {
        s += c ? "; " : "";
        for (int k = 0; k < 4; ++k) s += (k ? " " : "") + num(r[at + size_t(4 * c + k)]);
    }
    return s + "] (by columns)";
}

// ---- 6.1 the matrices ----------------------------------------------------------------------

struct MatricesInput {
    Camera camera;
    double nearDistance = 0.1, farDistance = 100.0;
};

struct SpaceMatricesSpec {
    static constexpr const char* name = "6.1";
    static constexpr const char* exercise = "6.1";
    static constexpr int count = 150;
    using Input = MatricesInput;
    static Case<Input> make(Rng& rng, int) {
        Input in;
        double scale = rng.logUniform(-3, 3);
        in.camera.eye = Vec3(rng.inCube(4.0) * scale);
        in.camera.view = Vec3(rng.direction() * rng.logUniform(-2, 2));
        in.camera.up = Vec3(rng.direction());
        const char* family = "a random camera";
        int kind = rng.below(6);
        if (kind == 0) {
            in.camera.up = in.camera.view * float(rng.pick({1.0, -3.0}));
            family = "a view parallel to up";
        } else if (kind == 1) {
            Vec3 v(0.0f);
            v[rng.below(3)] = rng.chance(50) ? 1.0f : -1.0f;
            in.camera.view = v;
            in.camera.up = Vec3(0, 1, 0);
            family = "a view along an axis";
        }
        in.camera.fovYDegrees = float(rng.uniform(1.0, 170.0));
        in.camera.aspect = float(rng.logUniform(-2, 1));
        in.nearDistance = rng.logUniform(-6, 0) * scale;
        in.farDistance = in.nearDistance * rng.logUniform(1, 10);
        return {in, family, false};
    }
    // The view matrix and the projection, entries within float's precision (the camera is
    // in float).
    static Record run(const Input& in) {
        SpaceMatrices m = spaceMatrices(in.camera, in.nearDistance, in.farDistance);
        Record r;
        double size = sceneSize<float>({in.camera.eye});
        for (int c = 0; c < 4; ++c)
            for (int k = 0; k < 4; ++k) r.d(m.view[c][k], 0x1p-18, 0x1p-18 * (1.0 + size));
        for (int c = 0; c < 4; ++c)
            for (int k = 0; k < 4; ++k) r.d(m.projection[c][k], 0x1p-18, 0x1p-18);
        return r;
    }
    static std::string given(const Input& in) {
        return "camera eye " + vec(in.camera.eye) + ", view " + vec(in.camera.view) + ", up " +
               vec(in.camera.up) + ", fov " + num(in.camera.fovYDegrees) + " degrees, aspect " +
               num(in.camera.aspect) + "; near " + num(in.nearDistance) + ", far " +
               num(in.farDistance);
    }
    static std::string show(const Record& r) {
        if (r.size() != 32) return "the numbers " + serialize(r);
        return "view " + matrixText(r, 0) + ", projection " + matrixText(r, 16);
    }
    static void perturb(Input& in, Rng& rng) {
        in.camera.eye = nudge(in.camera.eye, rng);
        in.camera.view = nudge(in.camera.view, rng);
        in.camera.up = nudge(in.camera.up, rng);
        in.camera.fovYDegrees = nudge(in.camera.fovYDegrees, rng);
        in.camera.aspect = nudge(in.camera.aspect, rng);
        in.nearDistance = nudge(in.nearDistance, rng);
        in.farDistance = nudge(in.farDistance, rng);
    }
};

// ---- 6.2 clip space to the screen ---------------------------------------------------------

struct ClipInput {
    Vec4d clip{0.0, 0.0, 0.0, 1.0};
    int width = 64, height = 48;
};

struct ClipToScreenSpec {
    static constexpr const char* name = "6.2";
    static constexpr const char* exercise = "6.2";
    static constexpr int count = 1000;
    using Input = ClipInput;
    static Case<Input> make(Rng& rng, int index) {
        Input in;
        in.width = rng.range(1, 4096);
        in.height = rng.range(1, 4096);
        if (index % 2 == 0) {
            double w = rng.power(-2, 3, rng.chance(10));
            in.clip =
                Vec4d(rng.grid(-2, 2, 2) * w, rng.grid(-2, 2, 2) * w, rng.grid(-1, 1, 2) * w, w);
            return {in, in.clip.w < 0 ? "w < 0 (behind the eye)" : "clip coordinates on a grid",
                    true};
        }
        double w = rng.logUniform(-6, 6);
        in.clip = Vec4d(rng.uniform(-1.5, 1.5) * w, rng.uniform(-1.5, 1.5) * w,
                        rng.uniform(-1.0, 1.0) * w, w);
        return {in, "random clip coordinates", false};
    }
    static Record run(const Input& in) {
        glm::dvec3 s = clipToScreen(in.clip, in.width, in.height);
        double size = double(std::max(in.width, in.height));
        return Record()
            .d(s.x, 0x1p-40, 0x1p-40 * size)
            .d(s.y, 0x1p-40, 0x1p-40 * size)
            .d(s.z, 0x1p-40, 0x1p-40);
    }
    static std::string given(const Input& in) {
        return "clip " + vec(in.clip) + ", a " + std::to_string(in.width) + " x " +
               std::to_string(in.height) + " image";
    }
    static std::string show(const Record& r) {
        if (r.size() != 3) return "the numbers " + serialize(r);
        return "screen (" + num(r[0]) + ", " + num(r[1]) + "), depth " + num(r[2]);
    }
    static void perturb(Input& in, Rng& rng) {
        for (int k = 0; k < 4; ++k) in.clip[k] = nudge(in.clip[k], rng);
    }
};

// ---- 6.3 clipping a polygon against a plane -------------------------------------------------

struct PolygonInput {
    ClipPolygon polygon;
    Vec4d plane{0.0, 0.0, 1.0, 1.0};
};

struct ClipPolygonSpec {
    static constexpr const char* name = "6.3";
    static constexpr const char* exercise = "6.3";
    static constexpr int count = 400;
    using Input = PolygonInput;
    static Case<Input> make(Rng& rng, int index) {
        Input in;
        int n = rng.chance(60) ? 3 : rng.range(4, 7);
        bool exact = index % 2 == 0;
        for (int i = 0; i < n; ++i) {
            ClipVertex v;
            if (exact)
                v.position =
                    Vec4d(rng.grid(-4, 4), rng.grid(-4, 4), rng.grid(-4, 4), rng.grid(1, 4));
            else
                v.position = Vec4d(rng.uniform(-4, 4), rng.uniform(-4, 4), rng.uniform(-4, 4),
                                   rng.uniform(0.1, 4));
            v.weights = glm::dvec3(0.0);
            v.weights[i % 3] = 1.0;
            if (i >= 3)
                v.weights = glm::dvec3(rng.grid(0, 4), rng.grid(0, 4), rng.grid(0, 4)) / 4.0;
            in.polygon.add(v);
        }
        const char* family = exact ? "a polygon on the grid" : "a random polygon";
        int kind = rng.below(4);
        if (kind == 0) {
            in.plane = kClipNearPlane;
        } else if (kind == 1) {
            in.plane = kClipFarPlane;
        } else if (kind == 2) {
            in.plane = guardBandPlanes(rng.pick({1.0, 2.0}))[size_t(rng.below(4))];
        } else {
            in.plane = exact ? Vec4d(rng.range(-1, 1), rng.range(-1, 1), rng.range(-1, 1),
                                     rng.range(-2, 2))
                             : Vec4d(rng.direction(), rng.uniform(-2.0, 2.0));
        }
        if (exact && rng.chance(30)) {
            // Vertices exactly on the plane (inside: dot >= 0).
            int on = rng.below(n);
            ClipVertex& v = in.polygon.vertices[size_t(on)];
            for (int k = 0; k < 4; ++k)
                if (in.plane[k] != 0.0) {
                    double rest = glm::dot(in.plane, v.position) - in.plane[k] * v.position[k];
                    double value = -rest / in.plane[k];
                    if (k != 3 || value > 0.0) v.position[k] = value;
                    break;
                }
            family = "a vertex exactly on the plane";
        }
        if (rng.chance(50)) {
            // The other winding.
            std::reverse(in.polygon.vertices.begin(), in.polygon.vertices.begin() + n);
        }
        return {in, family, exact};
    }
    static Record run(const Input& in) {
        ClipPolygon out = clipAgainstPlane(in.polygon, in.plane);
        Record r;
        r.i(out.count);
        double size = 1.0;
        for (int i = 0; i < in.polygon.count; ++i)
            for (int k = 0; k < 4; ++k)
                size = std::max(size, std::fabs(in.polygon.vertices[size_t(i)].position[k]));
        for (int i = 0; i < out.count && i < int(out.vertices.size()); ++i) {
            const ClipVertex& v = out.vertices[size_t(i)];
            for (int k = 0; k < 4; ++k) r.d(v.position[k], 0x1p-34, 0x1p-34 * size);
            for (int k = 0; k < 3; ++k) r.d(v.weights[k], 0x1p-34, 0x1p-34);
        }
        return r;
    }
    // The same polygon may start at another vertex (processing the edges from the previous
    // vertex instead of to the next one): the vertices must match in cyclic order.
    static std::string compare(const Input&, const Record& got, const Record& expected, int scale) {
        std::string why = compareRecords(got, expected, scale);
        if (why.empty() || got.size() != expected.size() || got.size() < 8 || got[0] != expected[0])
            return why;
        size_t n = size_t(got[0]);
        for (size_t shift = 1; shift < n; ++shift) {
            bool same = true;
            for (size_t i = 0; i < n && same; ++i)
                for (size_t k = 0; k < 7 && same; ++k)
                    same = valueMatches(got.values[1 + 7 * ((i + shift) % n) + k],
                                        expected[1 + 7 * i + k], scale);
            if (same) return "";
        }
        return why;
    }
    static std::string given(const Input& in) {
        std::string s = "polygon";
        for (int i = 0; i < in.polygon.count; ++i)
            s += " " + vec(in.polygon.vertices[size_t(i)].position) + " weights " +
                 vec(in.polygon.vertices[size_t(i)].weights) + ";";
        return s + " plane " + vec(in.plane) + " (inside: dot >= 0)";
    }
    static std::string show(const Record& r) {
        if (r.size() < 1) return "the numbers " + serialize(r);
        std::string s = num(int64_t(r[0])) + " vertices";
        for (size_t i = 1; i + 6 < r.size(); i += 7)
            s += " (" + num(r[i]) + ", " + num(r[i + 1]) + ", " + num(r[i + 2]) + ", " +
                 num(r[i + 3]) + ") weights (" + num(r[i + 4]) + ", " + num(r[i + 5]) + ", " +
                 num(r[i + 6]) + ")";
        return s;
    }
    static void perturb(Input& in, Rng& rng) {
        for (int i = 0; i < in.polygon.count; ++i)
            for (int k = 0; k < 4; ++k)
                in.polygon.vertices[size_t(i)].position[k] =
                    nudge(in.polygon.vertices[size_t(i)].position[k], rng);
    }
};

// ---- 6.4 and 6.5 the edge function and the fill rule --------------------------------------------

struct EdgeInput {
    FixedPoint2 a, b, p;
};

inline int64_t fixedCoordinate(Rng& rng, bool exact) {
    return exact ? int64_t(rng.range(-4, 4)) * kSubpixelOne / 2
                 : int64_t(rng.range(-(1 << 23), 1 << 23));
}

inline std::string givenPoint(const FixedPoint2& p) {
    return "(" + std::to_string(p.x) + ", " + std::to_string(p.y) + ")";
}

struct EdgeFunctionSpec {
    static constexpr const char* name = "6.4";
    static constexpr const char* exercise = "6.4";
    static constexpr int count = 1500;
    using Input = EdgeInput;
    static Case<Input> make(Rng& rng, int index) {
        bool exact = index % 2 == 0;
        Input in;
        for (FixedPoint2* q : {&in.a, &in.b, &in.p})
            *q = {fixedCoordinate(rng, exact), fixedCoordinate(rng, exact)};
        if (rng.chance(15)) in.p = rng.chance(50) ? in.a : in.b;
        return {
            in,
            exact ? "half-pixel positions (points on the line, at the ends)" : "random positions",
            true};
    }
    static Record run(const Input& in) { return Record().i(edgeFunction(in.a, in.b, in.p)); }
    static std::string given(const Input& in) {
        return "a = " + givenPoint(in.a) + ", b = " + givenPoint(in.b) +
               ", p = " + givenPoint(in.p) + " (fixed point, 256 per pixel)";
    }
    static std::string show(const Record& r) {
        if (r.size() != 1) return "the numbers " + serialize(r);
        return "E = " + num(int64_t(r[0]));
    }
    static void perturb(Input&, Rng&) {}
};

struct TopLeftSpec {
    static constexpr const char* name = "6.5";
    static constexpr const char* exercise = "6.5";
    static constexpr int count = 1000;
    using Input = EdgeInput;
    static Case<Input> make(Rng& rng, int index) {
        bool exact = index % 2 == 0;
        Input in;
        in.a = {fixedCoordinate(rng, exact), fixedCoordinate(rng, exact)};
        int64_t dx = exact ? int64_t(rng.range(-2, 2)) : fixedCoordinate(rng, false);
        int64_t dy = exact ? int64_t(rng.range(-2, 2)) : fixedCoordinate(rng, false);
        if (rng.chance(30)) dy = 0;
        if (rng.chance(15)) dx = 0;
        in.b = {in.a.x + dx, in.a.y + dy};
        return {in, dy == 0 ? "a horizontal edge" : dx == 0 ? "a vertical edge" : "an edge", true};
    }
    static Record run(const Input& in) { return Record().i(isTopLeftEdge(in.a, in.b)); }
    static std::string given(const Input& in) {
        return "the edge a = " + givenPoint(in.a) + " -> b = " + givenPoint(in.b) +
               " (screen y down)";
    }
    static std::string show(const Record& r) {
        if (r.size() != 1) return "the numbers " + serialize(r);
        return r[0] ? "a top or left edge (true)" : "neither top nor left (false)";
    }
    static void perturb(Input&, Rng&) {}
};

// ---- 6.6 the depth test, 6.7 perspective-correct weights ----------------------------------------

struct DepthInput {
    float stored = 1.0f, incoming = 0.5f;
};

struct DepthTestSpec {
    static constexpr const char* name = "6.6";
    static constexpr const char* exercise = "6.6";
    static constexpr int count = 1000;
    using Input = DepthInput;
    static Case<Input> make(Rng& rng, int) {
        Input in;
        auto depth = [&] {
            switch (rng.below(10)) {
                case 0:
                    return kInfinity<float>;
                case 1:
                    return float(rng.pick({0.0, -0.0, 1.0, -1.0}));
                case 2:
                    return std::numeric_limits<float>::quiet_NaN();
                default:
                    return float(rng.grid(-4, 4, 2));
            }
        };
        in.stored = depth();
        in.incoming = rng.chance(25) ? in.stored : depth();
        const char* family =
            in.incoming == in.stored ? "a tie (the first drawn keeps the pixel)" : "depths";
        if (std::isnan(in.stored) || std::isnan(in.incoming)) family = "a NaN depth";
        return {in, family, true};
    }
    static Record run(const Input& in) {
        float stored = in.stored;
        bool drawn = depthTest(stored, in.incoming);
        return Record().i(drawn).f(stored);
    }
    static std::string given(const Input& in) {
        return "stored depth " + num(in.stored) + ", incoming " + num(in.incoming);
    }
    static std::string show(const Record& r) {
        if (r.size() != 2) return "the numbers " + serialize(r);
        return std::string(r[0] ? "drawn (true)" : "not drawn (false)") + ", stored depth then " +
               num(float(r[1]));
    }
    static void perturb(Input&, Rng&) {}
};

struct WeightsInput {
    glm::dvec3 screen{1.0 / 3.0}, w{1.0};
};

struct PerspectiveWeightsSpec {
    static constexpr const char* name = "6.7";
    static constexpr const char* exercise = "6.7";
    static constexpr int count = 1000;
    using Input = WeightsInput;
    static Case<Input> make(Rng& rng, int index) {
        Input in;
        if (index % 2 == 0) {
            in.screen = glm::dvec3(rng.grid(0, 4), rng.grid(0, 4), rng.grid(0, 4)) / 4.0;
            if (in.screen == glm::dvec3(0.0)) in.screen.x = 1.0;
            in.w = glm::dvec3(rng.power(-3, 3), rng.power(-3, 3), rng.power(-3, 3));
            return {in, "weights on the quarter grid, w powers of two", true};
        }
        double u = rng.unit(), v = rng.unit() * (1.0 - u);
        in.screen = glm::dvec3(1.0 - u - v, u, v);
        in.w = glm::dvec3(rng.logUniform(-6, 6), rng.logUniform(-6, 6), rng.logUniform(-6, 6));
        return {in, "random weights and depths", false};
    }
    static Record run(const Input& in) {
        glm::dvec3 q = perspectiveCorrectWeights(in.screen, in.w);
        return Record().d(q.x, 0x1p-40, 0x1p-44).d(q.y, 0x1p-40, 0x1p-44).d(q.z, 0x1p-40, 0x1p-44);
    }
    static std::string given(const Input& in) {
        return "screen weights " + vec(in.screen) + ", w " + vec(in.w);
    }
    static std::string show(const Record& r) {
        if (r.size() != 3) return "the numbers " + serialize(r);
        return "weights (" + num(r[0]) + ", " + num(r[1]) + ", " + num(r[2]) + ")";
    }
    static void perturb(Input& in, Rng& rng) {
        for (int k = 0; k < 3; ++k) {
            in.screen[k] = nudge(in.screen[k], rng);
            in.w[k] = nudge(in.w[k], rng);
        }
    }
};

// ---- 6.8 the shadow map, 6.9 the hybrid's shadow ray ------------------------------------------

struct ShadowMapInput {
    ShadowMap map;
    Vec3 point{0.0f};
    double bias = 0.0;
};

struct ShadowMapSpec {
    static constexpr const char* name = "6.8";
    static constexpr const char* exercise = "6.8";
    static constexpr int count = 2000;
    using Input = ShadowMapInput;
    // Exact: a projection with dyadic entries (clip = (s x, s y, z, z): the texel and the
    // depth exact, points on texel borders and at the stored depth); random: any matrix
    // whose w is mostly positive.
    static Case<Input> make(Rng& rng, int index) {
        Input in;
        in.map.size = rng.range(1, 8);
        for (int i = 0; i < in.map.size * in.map.size; ++i)
            in.map.depth.push_back(rng.chance(15) ? kInfinity<float> : float(rng.grid(1, 8, 1)));
        const char* family = "a shadow map on a grid";
        if (index % 2 == 0) {
            double s = rng.power(-1, 1);
            in.map.viewProjection = Mat4d(0.0);
            in.map.viewProjection[0][0] = s;
            in.map.viewProjection[1][1] = s;
            in.map.viewProjection[2][2] = 1.0;
            in.map.viewProjection[2][3] = 1.0;  // w = z
            double z = rng.chance(10) ? -rng.grid(0, 4) : rng.grid(1, 8, 1);
            double cells = in.map.size;
            // x/w over [-1, 1]: texel borders at every 2 / size.
            double nx = rng.grid(-int(cells) - 1, int(cells) + 1) / cells,
                   ny = rng.grid(-int(cells) - 1, int(cells) + 1) / cells;
            if (rng.chance(50)) nx += 0.5 / cells, ny += 0.5 / cells;
            in.point = Vec3(float(nx * z / s), float(ny * z / s), float(z));
            in.bias = rng.pick({0.0, 0.5, 0.25, -0.5});
            if (rng.chance(30)) {
                // Exactly at the stored depth after the bias.
                int tx = std::clamp(int((nx + 1.0) * 0.5 * cells), 0, in.map.size - 1);
                int ty = std::clamp(int((1.0 - ny) * 0.5 * cells), 0, in.map.size - 1);
                in.map.depth[size_t(ty * in.map.size + tx)] = float(z - in.bias);
                family = "a point at the stored depth (after the bias)";
            }
            if (z <= 0.0) family = "a point behind the light (w <= 0)";
            return {in, family, true};
        }
        for (int c = 0; c < 4; ++c)
            for (int k = 0; k < 4; ++k) in.map.viewProjection[c][k] = rng.uniform(-1.0, 1.0);
        in.map.viewProjection[2][3] = rng.uniform(0.5, 2.0);
        in.point = Vec3(rng.inCube(2.0));
        in.point.z = float(rng.uniform(-1.0, 6.0));
        in.bias = rng.uniform(-0.5, 0.5);
        return {in, "a random projection", false};
    }
    static Record run(const Input& in) {
        return Record().i(litByShadowMap(in.map, in.point, in.bias));
    }
    static std::string given(const Input& in) {
        std::string s = "a " + std::to_string(in.map.size) + " x " + std::to_string(in.map.size) +
                        " map, depths";
        for (float d : in.map.depth) s += " " + num(d);
        Record m;
        for (int c = 0; c < 4; ++c)
            for (int k = 0; k < 4; ++k) m.d(in.map.viewProjection[c][k]);
        return s + " (row 0 first); view-projection " + matrixText(m, 0) + "; point " +
               vec(in.point) + ", bias " + num(in.bias);
    }
    static std::string show(const Record& r) {
        if (r.size() != 1) return "the numbers " + serialize(r);
        return r[0] ? "lit (true)" : "in shadow (false)";
    }
    static void perturb(Input& in, Rng& rng) {
        in.point = nudge(in.point, rng);
        in.bias = nudge(in.bias, rng);
    }
};

struct ShadowRayInput {
    std::vector<Sphere> spheres;
    std::vector<Plane> planes;
    Vec3 point{0.0f}, normal{0, 1, 0};
    PointLight light;
};

struct ShadowRaySpec {
    static constexpr const char* name = "6.9";
    static constexpr const char* exercise = "6.9";
    static constexpr int count = 1500;
    using Input = ShadowRayInput;
    static Case<Input> make(Rng& rng, int) {
        Input in;
        double scale = rng.logUniform(-2, 14);
        // The point on a sphere or a plane, its geometric normal; the light anywhere.
        const char* family = "a point on a sphere";
        if (rng.chance(50)) {
            Vec3d n = rng.direction();
            Vec3d c = rng.inCube(2.0) * scale;
            double r = rng.uniform(0.2, 1.0) * scale;
            in.spheres.push_back({Vec3(c), float(r)});
            in.point = Vec3(c + r * n);
            in.normal = Vec3(n);
        } else {
            Vec3d n = rng.direction();
            double d = rng.uniform(-2.0, 2.0) * scale;
            in.planes.push_back({Vec3(n), float(d)});
            Vec3d p = rng.inCube(2.0) * scale;
            in.point = Vec3(p - (glm::dot(n, p) + d) * n);
            in.normal = Vec3(n);
            family = "a point on a plane";
        }
        Vec3d light = Vec3d(in.point) + rng.direction() * rng.uniform(0.5, 6.0) * scale;
        in.light.position = Vec3(light);
        int occluders = rng.range(0, 3);
        for (int i = 0; i < occluders; ++i) {
            // Between the point and the light, or beyond the light, or beside the segment.
            double at = rng.pick({0.5, 0.9, 1.1, 1.5, 0.3});
            Vec3d c = Vec3d(in.point) + at * (light - Vec3d(in.point)) + rng.inCube(0.3) * scale;
            in.spheres.push_back({Vec3(c), float(rng.uniform(0.02, 0.3) * scale)});
        }
        if (rng.chance(15)) {
            // A sphere whose surface passes through the light.
            Vec3d n = rng.direction();
            double r = rng.uniform(0.1, 0.5) * scale;
            in.spheres.push_back({Vec3(light + r * n), float(r)});
            family = "an occluder touching the light";
        }
        return {in, family, false};
    }
    static Record run(const Input& in) {
        Scene scene;
        for (const auto& s : in.spheres) scene.spheres.push_back({s, 0});
        for (const auto& p : in.planes) scene.planes.push_back({p, 0});
        scene.lights.push_back(in.light);
        return Record().i(litByShadowRay(scene, in.point, in.normal, in.light));
    }
    static std::string given(const Input& in) {
        std::string s = "point " + vec(in.point) + ", geometric normal " + vec(in.normal) +
                        ", light at " + vec(in.light.position) + "; spheres";
        for (const auto& sp : in.spheres) s += " " + vec(sp.centre) + " r " + num(sp.radius) + ";";
        for (const auto& p : in.planes) s += " plane N " + vec(p.normal) + " d " + num(p.d) + ";";
        return s;
    }
    static std::string show(const Record& r) {
        if (r.size() != 1) return "the numbers " + serialize(r);
        return r[0] ? "lit (true)" : "in shadow (false)";
    }
    static void perturb(Input& in, Rng& rng) {
        in.point = nudge(in.point, rng);
        in.light.position = nudge(in.light.position, rng);
        for (auto& s : in.spheres) {
            s.centre = nudge(s.centre, rng);
            s.radius = nudge(s.radius, rng);
        }
    }
};

#define BOXES_DIFFERENTIAL_STEP06(X)                                                               \
    X(SpaceMatricesSpec)                                                                           \
    X(ClipToScreenSpec)                                                                            \
    X(ClipPolygonSpec)                                                                             \
    X(EdgeFunctionSpec) X(TopLeftSpec) X(DepthTestSpec) X(PerspectiveWeightsSpec) X(ShadowMapSpec) \
        X(ShadowRaySpec)

}  // namespace boxes::differential
