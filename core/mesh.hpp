// Triangle meshes read from Wavefront OBJ files (through tinyobjloader), exactly as given:
// the file's own coordinates, triangles in file order, polygons fan-triangulated; and the
// surface at a ray's hit on one of their triangles.
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "core/math.hpp"

namespace boxes {

// Bad input (files and their contents): the message is one line that names the problem.
// The programs exit with 1 (core/app.hpp's runMain).
struct InputError : std::runtime_error {
    using std::runtime_error::runtime_error;
};
// A bad command line: an unknown flag, or a flag's value that is not one it takes (a
// malformed X,Y,Z, an unknown scene name, a zero view direction). Exit code 2.
struct UsageError : InputError {
    using InputError::InputError;
};

// User text quoted in such a message: control bytes escaped as \xNN so the message stays
// one line (a name with a newline would cut it short), and at most `max` characters (then
// "...").
inline std::string printable(std::string_view text, size_t max = 60) {
    std::string out;
    for (size_t i = 0; i < text.size(); ++i) {
        if (out.size() >= max) return out + "...";
        unsigned char c = static_cast<unsigned char>(text[i]);
        if (c < 0x20 || c == 0x7f) {
            const char* hex = "0123456789abcdef";
            out += {'\\', 'x', hex[c >> 4], hex[c & 15]};
        } else {
            out += char(c);
        }
    }
    return out;
}

struct Mesh {
    std::vector<Vec3> positions;
    std::vector<Vec3> normals;  // one per position: area-weighted average of face normals
    std::vector<std::array<uint32_t, 3>> triangles;

    size_t triangleCount() const { return triangles.size(); }
    Vec3 vertex(size_t tri, int corner) const { return positions[triangles[tri][corner]]; }
    void computeVertexNormals();
    void translate(const Vec3& offset);
    // Checks indices and coordinates; throws InputError naming the first problem.
    void validate(const std::string& name) const;
};

// Largest OBJ file we read (bytes); larger files are refused with a message.
constexpr size_t kMaxObjBytes = size_t(1) << 30;
// Counted before parsing, so a small file cannot ask for unbounded memory (a mesh at the
// limits needs a few GiB): more vertices or triangles than this are refused.
constexpr size_t kMaxObjVertices = size_t(1) << 25;
constexpr size_t kMaxObjTriangles = size_t(1) << 25;
// tinyobjloader stores a face's vertex count in one byte: larger faces are refused, not
// silently cut (a 300-vertex face would become 42 wrong triangles).
constexpr size_t kMaxFaceVertices = 255;

struct ObjLimits {
    size_t vertices = kMaxObjVertices;
    size_t triangles = kMaxObjTriangles;
};

// Reads an OBJ file. Throws InputError for a missing, empty or malformed file (non-numeric
// fields, indices out of range, no triangles, non-finite coordinates).
Mesh loadObj(const std::string& path);
// The same from text in memory (for tests and fuzzing).
// limits: lower ones for tests.
Mesh parseObj(const std::string& text, const std::string& name = "<memory>",
              const ObjLimits& limits = {});

// ---- A hit on a mesh triangle --------------------------------------------------------------

// A hit on a mesh triangle, filled the same way by every mesh geometry of the steps (the
// idea of pbrt-v4's Triangle::InteractionFromIntersection): the geometric normal is the
// unit normal of the winding, (b - a) x (c - a); the shading normal interpolates the
// vertex normals with the barycentrics, (1 - u - v) na + u nb + v nc, normalized.

// The surface at barycentrics (u, v) of one triangle, given as vertex indices into
// positions and normals (the layout of Mesh): the point (1 - u - v) a + u b + v c, both
// normals, u, v, and the kind. A zero-area triangle (hit only edge-on) gets the normal +y;
// without vertex normals (normals not one per position), or where they cancel out, the
// shading normal is the geometric one.
SurfaceHit triangleSurface(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                           const std::array<uint32_t, 3>& triangle, float u, float v);

// A ray's hit at t on triangle `index` of `mesh`, with barycentrics (u, v): the surface as
// above, the point on the ray, t, the material and the triangle's index as the primitive.
SurfaceHit triangleHit(const Mesh& mesh, uint32_t index, const Ray& ray, float t, float u, float v,
                       int material);

}  // namespace boxes
