#include "core/mesh.hpp"

#include <tiny_obj_loader.h>

#include <charconv>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace boxes {

void Mesh::computeVertexNormals() {
    normals.assign(positions.size(), Vec3(0.0f));
    for (const auto& t : triangles) {
        // The unnormalized cross product weights each face by twice its area.
        Vec3 n = glm::cross(positions[t[1]] - positions[t[0]], positions[t[2]] - positions[t[0]]);
        for (uint32_t i : t) normals[i] += n;
    }
    for (Vec3& n : normals) {
        float len = glm::length(n);
        n = (len > 0.0f && std::isfinite(len)) ? n / len : Vec3(0.0f, 1.0f, 0.0f);
    }
}

void Mesh::translate(const Vec3& offset) {
    for (Vec3& p : positions) p += offset;
}

void Mesh::validate(const std::string& name) const {
    for (size_t i = 0; i < positions.size(); ++i)
        if (!isFinite(positions[i]))
            throw InputError(name + ": vertex " + std::to_string(i + 1) +
                             " has a non-finite coordinate");
    for (size_t t = 0; t < triangles.size(); ++t)
        for (uint32_t i : triangles[t])
            if (i >= positions.size())
                throw InputError(name + ": triangle " + std::to_string(t) +
                                 " uses vertex index " + std::to_string(i + 1) + " of only " +
                                 std::to_string(positions.size()));
    if (triangles.empty()) throw InputError(name + ": the mesh has no triangles");
}

namespace {

// tinyobjloader reads a non-numeric coordinate as 0 without a word; check the vertex
// lines ourselves so a malformed file is refused, not silently flattened.
void checkVertexLines(const std::string& text, const std::string& name) {
    std::istringstream in(text);
    std::string line;
    size_t lineNumber = 0;
    while (std::getline(in, line)) {
        ++lineNumber;
        if (line.size() < 2 || line[0] != 'v' || (line[1] != ' ' && line[1] != '\t')) continue;
        std::istringstream fields(line.substr(2));
        std::string field;
        int count = 0;
        while (fields >> field && count < 3) {
            float value = 0.0f;
            const char* end = field.data() + field.size();
            auto [ptr, ec] = std::from_chars(field.data(), end, value);
            if (ec == std::errc::result_out_of_range)
                throw InputError(name + ":" + std::to_string(lineNumber) +
                                 ": coordinate '" + field + "' is out of float range");
            if (ec != std::errc() || ptr != end)
                throw InputError(name + ":" + std::to_string(lineNumber) +
                                 ": coordinate '" + field.substr(0, 40) + "' is not a number");
            if (!std::isfinite(value))
                throw InputError(name + ":" + std::to_string(lineNumber) + ": coordinate '" +
                                 field.substr(0, 40) + "' is non-finite");
            ++count;
        }
        if (count < 3)
            throw InputError(name + ":" + std::to_string(lineNumber) +
                             ": a vertex needs 3 coordinates");
    }
}

std::string firstLine(const std::string& s) {
    std::string line = s.substr(0, s.find('\n'));
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '.'))
        line.pop_back();
    return line;
}

}  // namespace

Mesh parseObj(const std::string& text, const std::string& name) {
    if (text.find_first_not_of(" \t\r\n") == std::string::npos)
        throw InputError(name + ": the file is empty");
    checkVertexLines(text, name);

    tinyobj::ObjReaderConfig config;
    config.triangulate = false;  // we fan-triangulate ourselves, in file order
    config.vertex_color = false;
    config.mtl_search_path = "";
    tinyobj::ObjReader reader;
    // An empty material text: the mesh's own materials are not used by the workbook.
    if (!reader.ParseFromString(text, "", config))
        throw InputError(name + ": " + firstLine(reader.Error().empty() ? "cannot parse"
                                                                        : reader.Error()));
    const tinyobj::attrib_t& attrib = reader.GetAttrib();
    Mesh mesh;
    size_t vertexCount = attrib.vertices.size() / 3;
    mesh.positions.reserve(vertexCount);
    for (size_t i = 0; i < vertexCount; ++i)
        mesh.positions.emplace_back(attrib.vertices[3 * i], attrib.vertices[3 * i + 1],
                                    attrib.vertices[3 * i + 2]);
    for (const auto& shape : reader.GetShapes()) {
        size_t offset = 0;
        for (unsigned char faceSize : shape.mesh.num_face_vertices) {
            const auto* idx = &shape.mesh.indices[offset];
            for (unsigned k = 1; k + 1 < faceSize; ++k) {
                int a = idx[0].vertex_index, b = idx[k].vertex_index, c = idx[k + 1].vertex_index;
                if (a < 0 || b < 0 || c < 0 || size_t(a) >= vertexCount ||
                    size_t(b) >= vertexCount || size_t(c) >= vertexCount)
                    throw InputError(name + ": a face uses a vertex index out of range");
                mesh.triangles.push_back({uint32_t(a), uint32_t(b), uint32_t(c)});
            }
            offset += faceSize;
        }
    }
    mesh.validate(name);
    mesh.computeVertexNormals();
    return mesh;
}

Mesh loadObj(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw InputError(path + ": no such file");
    if (std::filesystem::is_directory(path, ec)) throw InputError(path + ": is a directory");
    auto size = std::filesystem::file_size(path, ec);
    if (ec) throw InputError(path + ": cannot read (" + ec.message() + ")");
    if (size > kMaxObjBytes)
        throw InputError(path + ": file of " + std::to_string(size >> 20) +
                         " MiB is larger than the limit of " + std::to_string(kMaxObjBytes >> 20) +
                         " MiB");
    std::ifstream file(path, std::ios::binary);
    if (!file) throw InputError(path + ": cannot open");
    std::string text(size, '\0');
    file.read(text.data(), std::streamsize(size));
    if (!file) throw InputError(path + ": read failed");
    return parseObj(text, path);
}

}  // namespace boxes
