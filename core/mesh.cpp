#include "core/mesh.hpp"

#include <tiny_obj_loader.h>

#include <charconv>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>

namespace boxes {

void Mesh::computeVertexNormals() {
    // In double: any float coordinates give a finite, non-subnormal cross product there.
    // In float, a 1e-10 triangle's squared length was subnormal (a normal of length 0.6)
    // and a 1e38 one overflowed to NaN (both found by fuzzing).
    std::vector<Vec3d> sums(positions.size(), Vec3d(0.0));
    for (const auto& t : triangles) {
        // The unnormalized cross product weights each face by twice its area.
        Vec3d a(positions[t[0]]), b(positions[t[1]]), c(positions[t[2]]);
        Vec3d n = glm::cross(b - a, c - a);
        for (uint32_t i : t) sums[i] += n;
    }
    normals.resize(positions.size());
    for (size_t i = 0; i < sums.size(); ++i) {
        double len = glm::length(sums[i]);
        normals[i] =
            (len > 0.0 && std::isfinite(len)) ? Vec3(sums[i] / len) : Vec3(0.0f, 1.0f, 0.0f);
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
                throw InputError(name + ": triangle " + std::to_string(t) + " uses vertex index " +
                                 std::to_string(i + 1) + " of only " +
                                 std::to_string(positions.size()));
    if (triangles.empty()) throw InputError(name + ": the mesh has no triangles");
}

namespace {

// Checks the text before tinyobjloader sees it, line by line as tinyobjloader splits
// them ("\n", "\r" or "\r\n"; leading blanks skipped):
// - vertex lines: tinyobjloader reads a non-numeric coordinate as 0 without a word, so a
//   malformed file would be silently flattened;
// - face, line and point lines: tinyobjloader reads an index with atoi, so 2^32 + 3 wrapped
//   to 3, "3.5" and "3abc" became 3 and a missing vt or vn was not noticed. Each number
//   must be a decimal integer and nothing else, within the v, vt or vn lines read so far;
// - faces of 3 to kMaxFaceVertices vertices (tinyobjloader's count is one byte; a face of
//   two made no triangle and was dropped silently);
// - "s" (smoothing group) lines: "off" or an integer in int range (atoi again); "t" (tag)
//   lines, which the workbook does not use and tinyobjloader reads with atoi, are refused;
// - the totals: at most kMaxObjVertices vertices and kMaxObjTriangles triangles, counted
//   here so memory is bounded before anything is allocated.
// tinyobjloader's "vw VERTEX JOINT WEIGHT ..." (skin weights, unused here) converts each
// joint to int unchecked: 1e38 is undefined behaviour (found by fuzzing). Every field must
// be a plain number, the vertex and joints decimal integers in int range (checkSkinWeights), and
// no blanks may follow the last field).
bool isBlank(char c) {
    return c == ' ' || c == '\t';
}

// Whitespace-separated fields (tinyobjloader also splits at blanks only), at most `max`.
std::vector<std::string_view> splitFields(std::string_view rest, size_t max) {
    std::vector<std::string_view> fields;
    for (size_t i = 0; i < rest.size() && fields.size() < max;) {
        while (i < rest.size() && isBlank(rest[i])) ++i;
        size_t j = i;
        while (j < rest.size() && !isBlank(rest[j])) ++j;
        if (j > i) fields.push_back(rest.substr(i, j - i));
        i = j;
    }
    return fields;
}

// An exact decimal integer: an optional "-", digits, nothing else (no "+", no blanks).
enum class IntegerText { Ok, NotInteger, TooLarge };
IntegerText exactInteger(std::string_view text, int64_t& value) {
    const char* end = text.data() + text.size();
    auto [ptr, ec] = std::from_chars(text.data(), end, value);
    if (ec == std::errc::result_out_of_range && ptr == end) return IntegerText::TooLarge;
    return ec == std::errc() && ptr == end ? IntegerText::Ok : IntegerText::NotInteger;
}

template <typename Where>
void checkSkinWeights(std::string_view rest, const Where& where) {
    size_t index = 0;
    for (size_t i = 0; i < rest.size();) {
        while (i < rest.size() && (rest[i] == ' ' || rest[i] == '\t')) ++i;
        size_t j = i;
        while (j < rest.size() && rest[j] != ' ' && rest[j] != '\t') ++j;
        if (j == i) break;
        std::string_view field = rest.substr(i, j - i);
        bool integer = index == 0 || index % 2 == 1;  // the vertex, then joint, weight, ...
        bool ok = false;
        if (integer) {
            int64_t k = 0;
            ok = exactInteger(field, k) == IntegerText::Ok && k >= 0 && k <= INT32_MAX;
        } else {
            double value = 0.0;
            auto [ptr, ec] = std::from_chars(field.data(), field.data() + field.size(), value);
            ok = ec == std::errc() && ptr == field.data() + field.size() && std::isfinite(value);
        }
        if (!ok)
            throw InputError(where() + "vertex weight field '" + printable(field, 40) +
                             "' is not " + (integer ? "an index" : "a number"));
        ++index;
        i = j;
    }
    // tinyobjloader reads another joint while the line goes on: after trailing blanks it
    // finds none, takes -1 and refuses the file as "joint_id is negative" (found by the
    // fuzz target's strict reader). Say what is wrong instead.
    if (index > 0 && (rest.back() == ' ' || rest.back() == '\t'))
        throw InputError(where() + "vertex weight line ends in blanks after its last field");
}

// How many v, vt and vn lines came before: a face may use only those.
struct ObjCounts {
    size_t vertices = 0, texcoords = 0, normals = 0;
};

// One face, line or point token: "V", "V/T", "V//N" or "V/T/N". Each number k is 1..count
// (from the first line read so far) or -count..-1 (back from the last one).
void checkIndexToken(std::string_view token, const ObjCounts& counts, const std::string& where) {
    const std::string shown = "'" + printable(token, 40) + "'";
    std::string_view parts[3];
    size_t n = 0;
    for (size_t start = 0;; ++n) {
        size_t slash = token.find('/', start);
        if (n == 3 || (n == 2 && slash != std::string_view::npos)) {
            n = 0;  // more than three parts
            break;
        }
        parts[n] = token.substr(start, slash == std::string_view::npos ? slash : slash - start);
        if (slash == std::string_view::npos) {
            ++n;
            break;
        }
        start = slash + 1;
    }
    // The vertex always; the texture coordinate empty only in V//N; the normal, when there.
    if (n == 0 || parts[0].empty() || (n == 2 && parts[1].empty()) || (n == 3 && parts[2].empty()))
        throw InputError(where + "index " + shown + " is not V, V/T, V//N or V/T/N");
    const char* what[3] = {"vertex", "texture coordinate", "normal"};
    const char* lines[3] = {"v", "vt", "vn"};
    const size_t available[3] = {counts.vertices, counts.texcoords, counts.normals};
    for (size_t p = 0; p < n; ++p) {
        if (parts[p].empty()) continue;  // V//N
        const std::string number = printable(parts[p], 40);
        int64_t k = 0;
        IntegerText kind = exactInteger(parts[p], k);
        if (kind == IntegerText::NotInteger)
            throw InputError(where + "index " + shown + ": " + what[p] + " '" + number +
                             "' is not a decimal integer");
        uint64_t size = kind == IntegerText::Ok ? (k < 0 ? 0 - uint64_t(k) : uint64_t(k)) : 0;
        if (kind == IntegerText::TooLarge || k == 0 || size > available[p])
            throw InputError(where + "index " + shown + ": " + what[p] + " " + number +
                             " is out of range (" + std::to_string(available[p]) + " " + lines[p] +
                             " lines so far)");
    }
}

// Returns the vertices' coordinates as it read them (std::from_chars: correctly rounded),
// which the mesh keeps instead of tinyobjloader's own reading: that one multiplies by
// pow(10, exponent) and made 0e3800 NaN (found by the fuzz target's strict reader).
std::vector<Vec3> checkLines(std::string_view text, const std::string& name,
                             const ObjLimits& limits) {
    std::vector<Vec3> positions;
    size_t lineNumber = 0, triangles = 0;
    ObjCounts counts;
    size_t pos = 0;
    while (pos < text.size()) {
        size_t end = text.find_first_of("\r\n", pos);
        if (end == std::string_view::npos) end = text.size();
        std::string_view line = text.substr(pos, end - pos);
        // "\r\n" is one line end, as in tinyobjloader.
        pos = end + ((end + 1 < text.size() && text[end] == '\r' && text[end + 1] == '\n') ? 2 : 1);
        ++lineNumber;
        size_t first = 0;
        while (first < line.size() && isBlank(line[first])) ++first;
        line.remove_prefix(first);
        auto where = [&] { return name + ":" + std::to_string(lineNumber) + ": "; };
        // The keyword: tinyobjloader's test is the letters followed by a blank.
        auto keyword = [&](std::string_view k) {
            return line.size() > k.size() && line.substr(0, k.size()) == k &&
                   isBlank(line[k.size()]);
        };
        if (keyword("vw")) {
            checkSkinWeights(line.substr(3), where);
        } else if (keyword("vt")) {
            ++counts.texcoords;
        } else if (keyword("vn")) {
            ++counts.normals;
        } else if (keyword("f") || keyword("l") || keyword("p")) {
            // Faces: one more than the limit is enough to refuse them.
            auto fields = splitFields(
                line.substr(2), line[0] == 'f' ? kMaxFaceVertices + 1 : std::string_view::npos);
            if (line[0] == 'f') {
                if (fields.size() > kMaxFaceVertices)
                    throw InputError(where() + "a face of more than " +
                                     std::to_string(kMaxFaceVertices) + " vertices");
                if (fields.size() < 3)
                    throw InputError(where() + "a face of " + std::to_string(fields.size()) +
                                     " vertices (at least 3)");
                triangles += fields.size() - 2;
                if (triangles > limits.triangles)
                    throw InputError(name + ": more than " + std::to_string(limits.triangles) +
                                     " triangles (the limit)");
            }
            // tinyobjloader reads a line or point element after the keyword's blank without
            // skipping further blanks: with none but blanks it reads index 0 and refuses the
            // file, with none at all it keeps an empty one (found by the fuzz target's strict
            // reader). An element that names no vertex is refused either way.
            else if (fields.empty())
                throw InputError(where() + "a '" + std::string(1, line[0]) +
                                 "' line names no vertex");
            for (std::string_view field : fields) checkIndexToken(field, counts, where());
        } else if (keyword("s")) {
            auto fields = splitFields(line.substr(2), 2);
            int64_t group = 0;
            if (fields.size() > 1 || (fields.size() == 1 && fields[0] != "off" &&
                                      !(exactInteger(fields[0], group) == IntegerText::Ok &&
                                        group >= 0 && group <= INT32_MAX)))
                throw InputError(where() + "smoothing group '" + printable(line.substr(2), 40) +
                                 "' is not 'off' or one integer from 0 to 2147483647");
        } else if (keyword("t")) {
            throw InputError(where() + "tag lines ('t') are not read by the workbook");
        } else if (keyword("v")) {
            auto fields = splitFields(line.substr(2), 3);
            float xyz[3] = {0.0f, 0.0f, 0.0f};
            for (size_t k = 0; k < fields.size(); ++k) {
                std::string_view field = fields[k];
                float& value = xyz[k];
                const char* fieldEnd = field.data() + field.size();
                auto [ptr, ec] = std::from_chars(field.data(), fieldEnd, value);
                std::string shown = printable(field, 40);
                if (ec == std::errc::result_out_of_range)
                    throw InputError(where() + "coordinate '" + shown + "' is out of float range");
                if (ec != std::errc() || ptr != fieldEnd)
                    throw InputError(where() + "coordinate '" + shown + "' is not a number");
                if (!std::isfinite(value))
                    throw InputError(where() + "coordinate '" + shown + "' is non-finite");
            }
            if (fields.size() < 3) throw InputError(where() + "a vertex needs 3 coordinates");
            if (++counts.vertices > limits.vertices)
                throw InputError(name + ": more than " + std::to_string(limits.vertices) +
                                 " vertices (the limit)");
            positions.emplace_back(xyz[0], xyz[1], xyz[2]);
        }
    }
    return positions;
}

std::string firstLine(const std::string& s) {
    std::string line = s.substr(0, s.find('\n'));
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '.'))
        line.pop_back();
    return line;
}

}  // namespace

Mesh parseObj(const std::string& text, const std::string& name, const ObjLimits& limits) {
    if (text.find_first_not_of(" \t\r\n") == std::string::npos)
        throw InputError(name + ": the file is empty");
    std::vector<Vec3> positions = checkLines(text, name, limits);

    // No material reader: tinyobjloader then skips "mtllib" lines, so a path an OBJ file
    // names is never opened (the workbook's materials come from the scene, not the file).
    // No triangulation: we fan-triangulate ourselves, in file order.
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warning, error;
    std::istringstream stream(text);
    if (!tinyobj::LoadObj(&attrib, &shapes, &materials, &warning, &error, &stream,
                          /*readMatFn=*/nullptr, /*triangulate=*/false,
                          /*default_vcols_fallback=*/false))
        throw InputError(name + ": " + firstLine(error.empty() ? "cannot parse" : error));
    Mesh mesh;
    size_t vertexCount = attrib.vertices.size() / 3;
    if (vertexCount != positions.size())
        throw InputError(name + ": cannot parse (" + std::to_string(vertexCount) +
                         " vertices read, " + std::to_string(positions.size()) + " v lines)");
    mesh.positions = std::move(positions);
    for (const auto& shape : shapes) {
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
    const std::string shown = printable(path, 200);  // a path in a message stays one line
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw InputError(shown + ": no such file");
    if (std::filesystem::is_directory(path, ec)) throw InputError(shown + ": is a directory");
    auto size = std::filesystem::file_size(path, ec);
    if (ec) throw InputError(shown + ": cannot read (" + ec.message() + ")");
    if (size > kMaxObjBytes)
        throw InputError(shown + ": file of " + std::to_string(size >> 20) +
                         " MiB is larger than the limit of " + std::to_string(kMaxObjBytes >> 20) +
                         " MiB");
    std::ifstream file(path, std::ios::binary);
    if (!file) throw InputError(shown + ": cannot open");
    std::string text(size, '\0');
    file.read(text.data(), std::streamsize(size));
    if (!file) throw InputError(shown + ": read failed");
    return parseObj(text, shown);
}

// ---- A hit on a mesh triangle --------------------------------------------------------------

SurfaceHit triangleSurface(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                           const std::array<uint32_t, 3>& triangle, float u, float v) {
    const Vec3 &a = positions[triangle[0]], &b = positions[triangle[1]],
               &c = positions[triangle[2]];
    const float w = 1.0f - u - v;
    SurfaceHit hit;
    hit.point = w * a + u * b + v * c;
    Vec3 n = glm::cross(b - a, c - a);
    float length = glm::length(n);
    hit.geometricNormal = length > 0.0f ? n / length : Vec3(0, 1, 0);
    hit.shadingNormal = hit.geometricNormal;
    if (normals.size() == positions.size()) {
        Vec3 s = w * normals[triangle[0]] + u * normals[triangle[1]] + v * normals[triangle[2]];
        float sLength = glm::length(s);
        if (sLength > 0.0f) hit.shadingNormal = s / sLength;
    }
    hit.u = u;
    hit.v = v;
    hit.kind = SurfaceHit::Kind::Triangle;
    return hit;
}

SurfaceHit triangleHit(const Mesh& mesh, uint32_t index, const Ray& ray, float t, float u, float v,
                       int material) {
    SurfaceHit hit = triangleSurface(mesh.positions, mesh.normals, mesh.triangles[index], u, v);
    hit.t = t;
    hit.point = ray.at(t);
    hit.material = material;
    hit.primitive = index;
    return hit;
}

}  // namespace boxes
