// OBJ meshes through the product's loading path: tinyobjloader plus our checks
// (core/mesh.cpp parseObj). Promise: a valid mesh (indices in range, finite coordinates,
// at least one triangle, unit or fallback normals) or an InputError with one line.
#include <cmath>

#include "core/mesh.hpp"
#include "fuzz/fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace boxes;
    std::string text(reinterpret_cast<const char*>(data), size);
    Mesh mesh;
    try {
        mesh = parseObj(text, "fuzz.obj");
    } catch (const InputError& e) {
        fuzz::checkMessage(e.what());
        return 0;
    }
    if (mesh.triangles.empty()) fuzz::fail("a mesh without triangles was accepted");
    if (mesh.normals.size() != mesh.positions.size()) fuzz::fail("one normal per vertex");
    for (const auto& t : mesh.triangles)
        for (uint32_t i : t)
            if (i >= mesh.positions.size()) fuzz::fail("vertex index out of range");
    for (const Vec3& p : mesh.positions)
        if (!isFinite(p)) fuzz::fail("non-finite vertex accepted");
    for (const Vec3& n : mesh.normals)
        if (!isFinite(n) || std::abs(glm::length(n) - 1.0f) > 1e-3f)
            fuzz::fail("vertex normal not of unit length");
    return 0;
}
