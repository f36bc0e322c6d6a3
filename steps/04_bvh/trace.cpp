#include "04_bvh/trace.hpp"

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "core/image.hpp"
#include "core/parallel.hpp"

namespace boxes {

TraceHit traceBruteForce(const Mesh& mesh, const Ray& ray) {
    WatertightRay watertight(ray);
    TraceHit best;
    float tClosest = ray.tmax;
    withWatertightAxes(watertight, [&](auto axes) {
        for (size_t i = 0; i < mesh.triangles.size(); ++i) {
            LeafTriangle tri = leafTriangleOf(mesh, i);
            float t = tClosest;
            // Strictly nearer only: the first of equally near triangles stays.
            if (intersectLeafTriangle(axes, watertight, tri, t) &&
                (best.triangle == kNoPrimitive || t < tClosest)) {
                tClosest = t;
                best = {t, uint32_t(i)};
            }
        }
    });
    return best;
}

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
        // Distances along a direction this short overflow float (issue 10's fuzzing: a
        // subnormal direction gave a "hit" at t = -infinity).
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

bool traceUsesAvx2() {
#if defined(BOXES_TARGET_AVX2)
    static const bool cpu = __builtin_cpu_supports("avx2");  // checks the OS saves YMM too
    return cpu && std::getenv("BOXES_NO_AVX2") == nullptr;
#else
    return false;
#endif
}

void traceBatch(const Bvh& bvh, const std::vector<Ray>& rays, std::vector<TraceHit>& hits,
                int threads) {
    traceBatchOf(bvh, rays, hits, threads);
}

TraversalCounts countWork(const Bvh& bvh, const std::vector<Ray>& rays) {
    return countWorkOf(bvh, rays);
}

void forEachRayChunk(size_t count, int threads, const std::function<void(size_t, size_t)>& f) {
    constexpr size_t kChunk = 1024;
    std::atomic<size_t> next{0};
    auto drain = [&](int) {
        try {
            for (size_t begin; (begin = next.fetch_add(kChunk, std::memory_order_relaxed)) < count;)
                f(begin, std::min(count, begin + kChunk));
        } catch (...) {
            next.store(count, std::memory_order_relaxed);  // stop the others
            throw;
        }
    };
    if (count <= kChunk) return drain(0);
    runOnThreads(threads, drain);
}

void traceBatchBruteForce(const Mesh& mesh, const std::vector<Ray>& rays,
                          std::vector<TraceHit>& hits, int threads) {
    hits.assign(rays.size(), TraceHit{});
    // The same answer as traceBruteForce per ray (triangles in file order, strictly nearer
    // wins), blocked for the cache: a block of triangles (small enough for L2) is tested
    // against every ray of a chunk before the next block, instead of streaming the whole
    // mesh once per ray (the motorbike's vertices are 9.5 MB).
    constexpr size_t kTriangleBlock = 2048;
    size_t triangleCount = mesh.triangles.size();
    std::vector<LeafTriangle> triangles(triangleCount);
    for (size_t i = 0; i < triangleCount; ++i) triangles[i] = leafTriangleOf(mesh, i);
    forEachRayChunk(rays.size(), threads, [&](size_t begin, size_t end) {
        std::vector<WatertightRay> prepared;
        std::vector<float> tClosest;
        for (size_t r = begin; r < end; ++r) {
            prepared.emplace_back(rays[r]);
            tClosest.push_back(rays[r].tmax);
        }
        for (size_t block = 0; block < triangleCount; block += kTriangleBlock) {
            size_t blockEnd = std::min(triangleCount, block + kTriangleBlock);
            for (size_t r = begin; r < end; ++r) {
                const WatertightRay& watertight = prepared[r - begin];
                float& closest = tClosest[r - begin];
                TraceHit& best = hits[r];
                withWatertightAxes(watertight, [&](auto axes) {
                    for (size_t i = block; i < blockEnd; ++i) {
                        float t = closest;
                        if (intersectLeafTriangle(axes, watertight, triangles[i], t) &&
                            (best.triangle == kNoPrimitive || t < closest)) {
                            closest = t;
                            best = {t, uint32_t(i)};
                        }
                    }
                });
            }
        }
    });
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
        int side = std::max(1, int(std::lround(std::sqrt(double(count)))));
        Camera camera;
        camera.fovYDegrees = 60.0f;
        camera.aspect = 1.0f;
        camera.view = -glm::normalize(Vec3(1.0f));
        camera.eye = centre - camera.view * (0.5f * diagonal / std::sin(glm::radians(30.0f)));
        CameraBasisT<float> basis = camera.basis();
        for (size_t i = 0; i < count; ++i) {
            int x = int(i % size_t(side)), y = int(i / size_t(side)) % side;
            rays.emplace_back(camera.eye,
                              camera.directionThrough(basis, x + 0.5f, y + 0.5f, side, side));
        }
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

MeshBvhGeometry::MeshBvhGeometry(const Mesh& mesh, int material, const BvhBuildOptions& options)
    : mesh_(mesh), material_(material), stats_(), bvh_(buildBvh(mesh, options, &stats_)) {}

bool MeshBvhGeometry::intersect(const Ray& ray, SurfaceHit& hit) const {
    TraversalRay traversal(ray, bvh_);
    WatertightRay watertight(ray);
    float tClosest = ray.tmax, u = 0.0f, v = 0.0f;
    const LeafTriangle* tris = bvh_.leafTriangles.data();
    uint32_t slot = withWatertightAxes(watertight, [&](auto axes) {
        return traverseNearest(bvh_, traversal, tClosest, [&](uint32_t s, float& tmax) {
            return intersectLeafTriangle(axes, watertight, tris[s], tmax, &u, &v);
        });
    });
    if (slot == kTraversalMiss) return false;
    uint32_t tri = bvh_.primitiveIndices[slot];
    const auto& idx = mesh_.triangles[tri];
    const LeafTriangle& lt = tris[slot];
    Vec3 n = glm::cross(lt.b - lt.a, lt.c - lt.a);
    float len = glm::length(n);
    hit.t = tClosest;
    hit.point = ray.at(tClosest);
    hit.geometricNormal = len > 0.0f ? n / len : Vec3(0, 1, 0);
    hit.u = u;
    hit.v = v;
    if (mesh_.normals.size() == mesh_.positions.size()) {
        Vec3 s = (1.0f - u - v) * mesh_.normals[idx[0]] + u * mesh_.normals[idx[1]] +
                 v * mesh_.normals[idx[2]];
        float sl = glm::length(s);
        hit.shadingNormal = sl > 0.0f ? s / sl : hit.geometricNormal;
    } else {
        hit.shadingNormal = hit.geometricNormal;
    }
    hit.material = material_;
    hit.primitive = tri;
    hit.kind = SurfaceHit::Kind::Triangle;
    return true;
}

bool MeshBvhGeometry::occluded(const Ray& ray) const {
    return traceOccluded(bvh_, ray);
}

}  // namespace boxes
