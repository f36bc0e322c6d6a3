// Helpers shared by the reliability tests (reliability*.cpp): an OBJ text's refusal, a
// triangle to build OBJ texts on, the closed cube.
#pragma once

#include <string>

#include "core/mesh.hpp"

namespace boxes::test {

// The message parseObj refuses a text with, or "(accepted)".
inline std::string refusal(const std::string& text, ObjLimits limits = {}) {
    try {
        parseObj(text, "x.obj", limits);
    } catch (const InputError& e) {
        return e.what();
    }
    return "(accepted)";
}

// Three vertices, then `rest` (a face or more lines).
inline std::string triangleThen(const std::string& rest) {
    return "v 0 0 0\nv 1 0 0\nv 0 1 0\n" + rest;
}

// The closed cube [-1, 1]^3, two triangles a face, facing out.
inline Mesh cube() {
    Mesh m;
    m.positions = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                   {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
    m.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                   {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
    m.computeVertexNormals();
    return m;
}

}  // namespace boxes::test
