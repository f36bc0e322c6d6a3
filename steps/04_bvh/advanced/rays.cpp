#include "04_bvh/advanced/rays.hpp"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "core/image.hpp"

namespace boxes {

std::vector<Ray> readRays(const std::string& path) {
    std::error_code ec;
    std::string name = "rays file '" + path + "'";
    if (!std::filesystem::is_regular_file(path, ec)) throw InputError(name + ": no such file");
    uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec) throw InputError(name + ": cannot read its size");
    // Refused before reading: a file too large for memory is a message, not an OOM kill.
    if (size / sizeof(RayRecord) > kMaxRays)
        throw InputError(name + ": " + std::to_string(size) + " bytes is more than the limit of " +
                         std::to_string(kMaxRays) + " rays");
    std::vector<char> bytes(size);
    std::ifstream in(path, std::ios::binary);
    if (!in.read(bytes.data(), std::streamsize(size))) throw InputError(name + ": read failed");
    return parseRays(bytes.data(), bytes.size(), name);
}

std::vector<Ray> parseRays(const void* data, size_t size, const std::string& name) {
    if (size % sizeof(RayRecord) != 0)
        throw InputError(name + ": size " + std::to_string(size) +
                         " bytes is not a multiple of 32 (8 float32 per ray)");
    if (size == 0) throw InputError(name + " is empty");
    if (size / sizeof(RayRecord) > kMaxRays)
        throw InputError(name + ": more than the limit of " + std::to_string(kMaxRays) + " rays");
    std::vector<Ray> rays;
    rays.reserve(size / sizeof(RayRecord));
    for (size_t i = 0; i < size / sizeof(RayRecord); ++i) {
        RayRecord r;
        std::memcpy(&r, static_cast<const char*>(data) + i * sizeof(RayRecord), sizeof r);
        Vec3 o(r.origin[0], r.origin[1], r.origin[2]),
            d(r.direction[0], r.direction[1], r.direction[2]);
        auto where = [&] { return name + ": ray " + std::to_string(i) + ": "; };
        if (std::isnan(o.x) || std::isnan(o.y) || std::isnan(o.z) || std::isnan(d.x) ||
            std::isnan(d.y) || std::isnan(d.z) || std::isnan(r.tmin) || std::isnan(r.tmax))
            throw InputError(where() + "NaN value");
        if (!isFinite(o) || !isFinite(d))
            throw InputError(where() + "infinite origin or direction");
        if (isZero(d)) throw InputError(where() + "zero direction");
        // Distances along a direction this short overflow float (fuzz_rays found a
        // subnormal direction whose brute-force "hit" lay at t = -infinity).
        if (maxComponent(glm::abs(d)) < kMinRayDirection)
            throw InputError(where() + "direction too short (largest component below 2^-32)");
        rays.emplace_back(o, d, r.tmin, r.tmax);
    }
    return rays;
}

void writeRays(const std::string& path, const std::vector<Ray>& rays) {
    std::vector<RayRecord> records(rays.size());
    for (size_t i = 0; i < rays.size(); ++i) {
        const Ray& r = rays[i];
        records[i] = {{r.origin.x, r.origin.y, r.origin.z},
                      r.tmin,
                      {r.direction.x, r.direction.y, r.direction.z},
                      r.tmax};
    }
    writeFileAtomically(path, records.data(), records.size() * sizeof(RayRecord));
}

void writeHits(const std::string& path, const std::vector<TraceHit>& hits) {
    writeFileAtomically(path, hits.data(), hits.size() * sizeof(TraceHit));
}

std::vector<TraceHit> readHits(const std::string& path) {
    std::error_code ec;
    uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec || size % sizeof(TraceHit) != 0)
        throw InputError("hits file '" + path + "': missing or not a multiple of 8 bytes");
    std::vector<TraceHit> hits(size / sizeof(TraceHit));
    std::ifstream in(path, std::ios::binary);
    in.read(reinterpret_cast<char*>(hits.data()), std::streamsize(size));
    return hits;
}

const char* rayKindName(RayKind kind) {
    switch (kind) {
        case RayKind::Primary:
            return "primary";
        case RayKind::Diffuse:
            return "diffuse";
        default:
            return "random";
    }
}

std::vector<Ray> makeRays(const Mesh& mesh, RayKind kind, size_t count, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    Bounds3f bounds;
    for (const Vec3& p : mesh.positions) bounds.extend(p);
    Vec3 centre = bounds.centroid();
    float diagonal = glm::length(bounds.diagonal());
    auto unitVector = [&] {
        float z = 1.0f - 2.0f * uniform(rng), phi = 2.0f * kPi * uniform(rng);
        float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
        return Vec3(r * std::cos(phi), r * std::sin(phi), z);
    };
    std::vector<Ray> rays;
    rays.reserve(count);
    if (kind == RayKind::Primary) {
        // A pinhole camera looking at the centre from (1,1,1), the bounding sphere in view.
        Camera camera;
        camera.fovYDegrees = 60.0f;
        camera.view = -glm::normalize(Vec3(1.0f));
        camera.eye = centre - camera.view * (0.5f * diagonal / std::sin(glm::radians(30.0f)));
        return makeCameraRays(camera, count);
    } else if (kind == RayKind::Diffuse) {
        // Area-weighted points on the surface, cosine-weighted directions about the normal.
        std::vector<double> cumulative(mesh.triangles.size());
        double sum = 0.0;
        for (size_t i = 0; i < mesh.triangles.size(); ++i) {
            sum += 0.5 * glm::length(Vec3d(glm::cross(mesh.vertex(i, 1) - mesh.vertex(i, 0),
                                                      mesh.vertex(i, 2) - mesh.vertex(i, 0))));
            cumulative[i] = sum;
        }
        std::uniform_real_distribution<double> pick(0.0, sum);
        while (rays.size() < count) {
            size_t tri = size_t(std::lower_bound(cumulative.begin(), cumulative.end(), pick(rng)) -
                                cumulative.begin());
            tri = std::min(tri, mesh.triangles.size() - 1);
            Vec3 a = mesh.vertex(tri, 0), b = mesh.vertex(tri, 1), c = mesh.vertex(tri, 2);
            Vec3 n = glm::cross(b - a, c - a);
            if (!(glm::length(n) > 0.0f)) continue;
            n = glm::normalize(n);
            float su = std::sqrt(uniform(rng)), v = uniform(rng);
            Vec3 p = (1.0f - su) * a + su * (1.0f - v) * b + su * v * c;
            Vec3 d = n + unitVector();  // cosine-weighted about n
            if (!(glm::length(d) > 1e-6f)) continue;
            rays.emplace_back(p, glm::normalize(d), 1e-4f * diagonal, kInfinity<float>);
        }
    } else {
        Vec3 lo = centre - 0.6f * bounds.diagonal(), size = 1.2f * bounds.diagonal();
        for (size_t i = 0; i < count; ++i) {
            Vec3 o = lo + Vec3(uniform(rng), uniform(rng), uniform(rng)) * size;
            rays.emplace_back(o, unitVector());
        }
    }
    return rays;
}

std::vector<Ray> makeCameraRays(const Camera& camera, size_t count) {
    Camera square = camera;
    square.aspect = 1.0f;
    int side = std::max(1, int(std::lround(std::sqrt(double(count)))));
    CameraBasisT<float> basis = square.basis();
    std::vector<Ray> rays;
    rays.reserve(count);
    for (size_t i = 0; i < count; ++i) {
        int x = int(i % size_t(side)), y = int(i / size_t(side)) % side;
        rays.emplace_back(square.eye,
                          square.directionThrough(basis, x + 0.5f, y + 0.5f, side, side));
    }
    return rays;
}

}  // namespace boxes
