// OBJ meshes through the product's loading path: tinyobjloader plus our checks
// (core/mesh.cpp parseObj). Promises:
// - a valid mesh (indices in range, finite coordinates, at least one triangle, unit or
//   fallback normals) or an InputError with one line;
// - the same answer as a small strict reader written here (a differential oracle): both
//   accept or both refuse, and when both accept, the same triangles with the same three
//   vertex indices. "In range" alone could not see an index that wrapped (2^32 + 3 read as
//   3 is in range); the oracle reads every number exactly, with std::from_chars.
#include <charconv>
#include <cmath>
#include <optional>
#include <sstream>
#include <string_view>
#include <vector>

#include "core/mesh.hpp"
#include "fuzz/fuzz_common.hpp"

namespace {

using Triangle = std::array<uint32_t, 3>;

std::vector<std::string_view> split(std::string_view s, const char* separators) {
    std::vector<std::string_view> out;
    size_t i = 0;
    while (i <= s.size()) {
        size_t j = s.find_first_of(separators, i);
        if (j == std::string_view::npos) j = s.size();
        out.push_back(s.substr(i, j - i));
        i = j + 1;
    }
    return out;
}

std::vector<std::string_view> words(std::string_view s) {
    std::vector<std::string_view> out;
    for (std::string_view w : split(s, " \t"))
        if (!w.empty()) out.push_back(w);
    return out;
}

template <typename T>
bool number(std::string_view s, T& value) {
    auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
    return ec == std::errc() && ptr == s.data() + s.size();
}

// A 1-based or relative (negative) OBJ index among `count` lines read so far, made 0-based.
bool index(std::string_view s, long long count, long long& out) {
    long long k = 0;
    if (!number(s, k) || k == 0 || k > count || k < -count) return false;
    out = k > 0 ? k - 1 : count + k;
    return true;
}

// The workbook's OBJ rules, written again from its documentation (docs/reliability.md):
// nullopt when the file must be refused, else its triangles (faces fanned from their first
// vertex, in file order).
std::optional<std::vector<Triangle>> strictRead(std::string_view text) {
    long long v = 0, vt = 0, vn = 0;
    std::vector<Triangle> triangles;
    bool anything = false;
    // Lines end at "\r\n", "\n" or "\r".
    std::string unified;
    for (size_t i = 0; i < text.size(); ++i) {
        if (text[i] == '\r' && i + 1 < text.size() && text[i + 1] == '\n') continue;
        unified += text[i] == '\r' ? '\n' : text[i];
    }
    for (std::string_view line : split(unified, "\n")) {
        if (line.find_first_not_of(" \t") != std::string_view::npos) anything = true;
        std::vector<std::string_view> w = words(line);
        if (w.empty()) continue;
        // A keyword counts only when a blank follows it on the line.
        std::string_view key = w[0];
        size_t after = line.find(key) + key.size();
        if (after >= line.size()) continue;
        std::vector<std::string_view> args(w.begin() + 1, w.end());
        if (key == "v") {
            if (args.size() < 3) return std::nullopt;
            for (int i = 0; i < 3; ++i) {
                float x = 0.0f;
                if (!number(args[i], x) || !std::isfinite(x)) return std::nullopt;
            }
            ++v;
        } else if (key == "vt") {
            ++vt;
        } else if (key == "vn") {
            ++vn;
        } else if (key == "f" || key == "l" || key == "p") {
            if (key == "f" && (args.size() < 3 || args.size() > 255)) return std::nullopt;
            if (key != "f" && args.empty()) return std::nullopt;
            std::vector<uint32_t> corners;
            for (std::string_view token : args) {
                std::vector<std::string_view> parts = split(token, "/");
                long long i = 0, ignored = 0;
                if (parts.size() > 3 || !index(parts[0], v, i)) return std::nullopt;
                if (parts.size() == 2 && !index(parts[1], vt, ignored)) return std::nullopt;
                if (parts.size() == 3) {
                    if (!parts[1].empty() && !index(parts[1], vt, ignored)) return std::nullopt;
                    if (!index(parts[2], vn, ignored)) return std::nullopt;
                }
                corners.push_back(uint32_t(i));
            }
            if (key == "f")
                for (size_t k = 1; k + 1 < corners.size(); ++k)
                    triangles.push_back({corners[0], corners[k], corners[k + 1]});
        } else if (key == "vw") {
            // Blanks after the last field are refused (tinyobjloader reads a missing joint).
            if (!args.empty() && (line.back() == ' ' || line.back() == '\t')) return std::nullopt;
            for (size_t i = 0; i < args.size(); ++i) {
                long long k = 0;
                double x = 0.0;
                bool ok = i == 0 || i % 2 == 1 ? number(args[i], k) && k >= 0 && k <= 2147483647
                                               : number(args[i], x) && std::isfinite(x);
                if (!ok) return std::nullopt;
            }
        } else if (key == "s") {
            long long group = 0;
            if (args.size() > 1) return std::nullopt;
            if (args.size() == 1 && args[0] != "off" &&
                !(number(args[0], group) && group >= 0 && group <= 2147483647))
                return std::nullopt;
        } else if (key == "t") {
            return std::nullopt;
        }
    }
    if (!anything || triangles.empty()) return std::nullopt;
    return triangles;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace boxes;
    std::string text(reinterpret_cast<const char*>(data), size);
    std::optional<std::vector<Triangle>> expected = strictRead(text);
    Mesh mesh;
    try {
        mesh = parseObj(text, "fuzz.obj");
    } catch (const InputError& e) {
        fuzz::checkMessage(e.what());
        if (expected)
            fuzz::fail(std::string("refused what the strict reader accepts: ") + e.what());
        return 0;
    }
    if (!expected) fuzz::fail("accepted what the strict reader refuses");
    if (mesh.triangles != *expected) {
        std::ostringstream s;
        s << "triangles differ from the strict reader's: " << mesh.triangles.size() << " vs "
          << expected->size();
        for (size_t i = 0; i < std::min(mesh.triangles.size(), expected->size()); ++i)
            if (mesh.triangles[i] != (*expected)[i]) {
                s << ", first at " << i;
                break;
            }
        fuzz::fail(s.str());
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
