// Triangle meshes read from Wavefront OBJ files (through tinyobjloader), exactly as given:
// the file's own coordinates, triangles in file order, polygons fan-triangulated.
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/math.hpp"

namespace boxes {

// Bad input (files, flags, values): the message is one line that names the problem.
struct InputError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

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

// Reads an OBJ file. Throws InputError for a missing, empty or malformed file (non-numeric
// fields, indices out of range, no triangles, non-finite coordinates).
Mesh loadObj(const std::string& path);
// The same from text in memory (for tests and fuzzing).
Mesh parseObj(const std::string& text, const std::string& name = "<memory>");

}  // namespace boxes
