// Step 04: tracing triangle meshes through the hierarchy: the leaf test, the ray and hit
// files of the `trace` command, batch tracing on threads, and brute force to check it.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "04_bvh/bvh.hpp"
#include "core/hit.hpp"
#include "core/scene.hpp"

namespace boxes {

// The work of tracing a batch of rays, summed over the rays (`trace --count`): a count of
// what the traversal does, the same on every machine, where a time is not. The binary
// tree's loop is exercise 4.4, so only its triangle tests are counted (from the leaf test
// it calls); the wide trees' loops count their nodes, leaves and packets too.
struct TraversalCounts {
    uint64_t rays = 0;
    uint64_t nodes = 0;      // wide nodes whose boxes were tested (wide trees only)
    uint64_t leaves = 0;     // leaves tested (wide trees only)
    uint64_t packets = 0;    // packets of four triangles tested (wide trees only)
    uint64_t triangles = 0;  // triangles tested (a packet's padding lanes not counted)
};
// The counting policies of the traversal templates: no count (the timed loops), or into
// a TraversalCounts.
struct NoTraversalCount {
    void node() {}
    void leaf(uint32_t) {}
    void triangles(uint32_t) {}
};
struct TraversalCounter {
    TraversalCounts* counts;
    void node() { ++counts->nodes; }
    void leaf(uint32_t packets) {
        ++counts->leaves;
        counts->packets += packets;
    }
    void triangles(uint32_t n) { counts->triangles += n; }
};

// The watertight ray/triangle test of Woop, Benthin and Wald (JCGT 2013), prepared once
// per ray. This is a performance copy of step 01's exercise 1.5 (which stays the teaching
// version): the permutation and shear are computed once per ray instead of per triangle,
// and the arithmetic per triangle is otherwise the same, operation for operation, so the
// two give bit-identical t. The hierarchy's hot loop calls this one, inlined.
struct WatertightRay {
    Vec3 origin;
    int kx, ky, kz;
    float sx, sy, sz;
    float tmin;

    explicit WatertightRay(const Ray& ray) : origin(ray.origin), tmin(ray.tmin) {
        Vec3 absD = glm::abs(ray.direction);
        kz = maxDimension(absD);
        kx = (kz + 1) % 3;
        ky = (kx + 1) % 3;
        if ((&ray.direction.x)[kz] < 0.0f) std::swap(kx, ky);
        const float* d = &ray.direction.x;
        sx = d[kx] / d[kz];
        sy = d[ky] / d[kz];
        sz = 1.0f / d[kz];
    }
};

// The six axis orders (kz the dominant axis, kx and ky swapped for a negative d[kz]),
// as compile-time constants: the leaf test then reads components from registers instead
// of through a run-time index (a store and an indexed load per component), and the
// traversal is instantiated once per order, chosen once per ray (withWatertightAxes).
template <int Kz, bool Swap>
struct WatertightAxes {
    static constexpr int kz = Kz;
    static constexpr int kx = Swap ? (Kz + 2) % 3 : (Kz + 1) % 3;
    static constexpr int ky = Swap ? (Kz + 1) % 3 : (Kz + 2) % 3;
};

// Calls f(WatertightAxes<...>{}) with the ray's axis order.
template <typename F>
decltype(auto) withWatertightAxes(const WatertightRay& r, F&& f) {
    bool swap = r.kx != (r.kz + 1) % 3;
    switch (r.kz * 2 + int(swap)) {
        case 0:
            return f(WatertightAxes<0, false>{});
        case 1:
            return f(WatertightAxes<0, true>{});
        case 2:
            return f(WatertightAxes<1, false>{});
        case 3:
            return f(WatertightAxes<1, true>{});
        case 4:
            return f(WatertightAxes<2, false>{});
        default:
            return f(WatertightAxes<2, true>{});
    }
}

// The same test in double, for the rare triangle whose float edge functions overflow
// (coordinates beyond about 1e19 from the ray origin: their products pass 3.4e38, and
// inf - inf is NaN). The sheared vertices are still finite floats; in double the products
// cannot overflow, so such a triangle is hit instead of silently missed.
template <typename Axes>
[[gnu::noinline]] bool intersectLeafTriangleDouble(Axes, const WatertightRay& r,
                                                   const LeafTriangle& tri, float& tmax,
                                                   float* uOut, float* vOut) {
    constexpr int kx = Axes::kx, ky = Axes::ky, kz = Axes::kz;
    const glm::dvec3 o(r.origin);
    const glm::dvec3 av = glm::dvec3(tri.a) - o, bv = glm::dvec3(tri.b) - o,
                     cv = glm::dvec3(tri.c) - o;
    const double sx = r.sx, sy = r.sy, sz = r.sz;
    double ax = av[kx] - sx * av[kz], ay = av[ky] - sy * av[kz];
    double bx = bv[kx] - sx * bv[kz], by = bv[ky] - sy * bv[kz];
    double cx = cv[kx] - sx * cv[kz], cy = cv[ky] - sy * cv[kz];
    double u = cx * by - cy * bx, v = ax * cy - ay * cx, w = bx * ay - by * ax;
    if ((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)) return false;
    double det = u + v + w;
    if (det == 0.0 || !std::isfinite(det)) return false;
    float t = float((u * sz * av[kz] + v * sz * bv[kz] + w * sz * cv[kz]) / det);
    if (!(t >= r.tmin && t <= tmax && std::fabs(t) <= std::numeric_limits<float>::max()))
        return false;
    tmax = t;
    if (uOut) *uOut = float(v / det);
    if (vOut) *vOut = float(w / det);
    return true;
}

// A hit in [ray.tmin, tmax] lowers tmax to it; (u, v) are the barycentrics of b and c.
// Axes must be the ray's order (r.kx, r.ky, r.kz); the arithmetic is exercise 1.5's.
template <typename Axes>
inline bool intersectLeafTriangle(Axes, const WatertightRay& r, const LeafTriangle& tri,
                                  float& tmax, float* uOut = nullptr, float* vOut = nullptr) {
    constexpr int kx = Axes::kx, ky = Axes::ky, kz = Axes::kz;
    const Vec3 av = tri.a - r.origin, bv = tri.b - r.origin, cv = tri.c - r.origin;
    const float *a = &av.x, *b = &bv.x, *c = &cv.x;
    float ax = a[kx] - r.sx * a[kz], ay = a[ky] - r.sy * a[kz];
    float bx = b[kx] - r.sx * b[kz], by = b[ky] - r.sy * b[kz];
    float cx = c[kx] - r.sx * c[kz], cy = c[ky] - r.sy * c[kz];
    float u = cx * by - cy * bx;
    float v = ax * cy - ay * cx;
    float w = bx * ay - by * ax;
    // Exactly zero: recompute in double so neighbours agree on the shared edge.
    if (u == 0.0f || v == 0.0f || w == 0.0f) [[unlikely]] {
        u = float(double(cx) * double(by) - double(cy) * double(bx));
        v = float(double(ax) * double(cy) - double(ay) * double(cx));
        w = float(double(bx) * double(ay) - double(by) * double(ax));
    }
    float det = u + v + w;  // not finite exactly when an edge function overflowed
    if (!std::isfinite(det)) [[unlikely]]
        return intersectLeafTriangleDouble(Axes{}, r, tri, tmax, uOut, vOut);
    // Bitwise | and & on the comparisons: one branch, mostly taken (most tests miss),
    // instead of a chain of unpredictable ones.
    bool negative = (u < 0.0f) | (v < 0.0f) | (w < 0.0f);
    bool positive = (u > 0.0f) | (v > 0.0f) | (w > 0.0f);
    if ((negative & positive) | (det == 0.0f)) return false;
    float az = r.sz * a[kz], bz = r.sz * b[kz], cz = r.sz * c[kz];
    float tScaled = u * az + v * bz + w * cz;
    // Outside the normal range the products may have underflowed to zeros whose signs no
    // longer add up (t = -0 for a triangle behind the ray, |d| = 1e28) or overflowed (t =
    // inf for a triangle 3e38 away): both found by fuzz_rays. Decide in double instead.
    float magnitude = std::fabs(tScaled);
    if (!(magnitude >= std::numeric_limits<float>::min() &&
          magnitude <= std::numeric_limits<float>::max())) [[unlikely]]
        return intersectLeafTriangleDouble(Axes{}, r, tri, tmax, uOut, vOut);
    float t = tScaled / det;
    // A hit beyond the float range (t = +-inf) is a miss: HITS.bin has no t for it.
    if (!(t >= r.tmin && t <= tmax && std::fabs(t) <= std::numeric_limits<float>::max()))
        return false;
    tmax = t;
    if (uOut) *uOut = v / det;
    if (vOut) *vOut = w / det;
    return true;
}

// The same with the axis order chosen at run time (one switch per call: not for loops).
inline bool intersectLeafTriangle(const WatertightRay& r, const LeafTriangle& tri, float& tmax,
                                  float* uOut = nullptr, float* vOut = nullptr) {
    return withWatertightAxes(
        r, [&](auto axes) { return intersectLeafTriangle(axes, r, tri, tmax, uOut, vOut); });
}

// The nearest hit of one ray: t (+infinity on a miss) and the triangle in file order.
struct TraceHit {
    float t = kInfinity<float>;
    uint32_t triangle = kNoPrimitive;
    bool operator==(const TraceHit&) const = default;
};
static_assert(sizeof(TraceHit) == 8, "the HITS.bin record");

// Does the ray enter the tree's root box (a Bvh or a Bvh4: anything with empty() and
// rootNode())? The tracers decide that before the triangle test's per-ray set-up. The
// root is read where it lies: from a copy built here on the stack, the loads through
// the ray's run-time plane offsets waited on the copy's stores (4-wide primary rays on
// the bunny ran 1.07x faster without it).
template <typename Tree>
[[gnu::always_inline]] inline bool entersRoot(const Tree& tree, const TraversalRay& traversal) {
    if (tree.empty()) return false;
    float tEntry;
    return intersectNodeBounds(tree.rootNode(), traversal, traversal.tmax, tEntry);
}

// kAvx selects the wide trees' AVX box test (bvh4.hpp); the binary tree has none and
// ignores it. The parameter lets one batch loop (traceBatchOf below) serve every tree.
// With a TraversalCounter, the triangle tests are counted (countWork); the hit is the same.
template <bool kAvx = false, typename Counter = NoTraversalCount>
inline TraceHit traceNearest(const Bvh& bvh, const Ray& ray, Counter counter = {}) {
    TraversalRay traversal(ray, bvh);
    // Most rays of a camera framing a mesh miss its root box: decide that before the
    // triangle test's per-ray set-up (three divisions) and the dispatch on its axes.
    if (!entersRoot(bvh, traversal)) return {};
    WatertightRay watertight(ray);
    float tClosest = ray.tmax;
    const LeafTriangle* tris = bvh.leafTriangles.data();
    uint32_t slot = withWatertightAxes(watertight, [&](auto axes) {
        return traverseNearest(bvh, traversal, tClosest, [&](uint32_t s, float& tmax) {
            counter.triangles(1);
            return intersectLeafTriangle(axes, watertight, tris[s], tmax);
        });
    });
    if (slot == kTraversalMiss) return {};
    return {tClosest, bvh.primitiveIndices[slot]};
}

inline bool traceOccluded(const Bvh& bvh, const Ray& ray) {
    TraversalRay traversal(ray, bvh);
    if (!entersRoot(bvh, traversal)) return false;
    WatertightRay watertight(ray);
    const LeafTriangle* tris = bvh.leafTriangles.data();
    return withWatertightAxes(watertight, [&](auto axes) {
        return traverseAny(bvh, traversal, [&](uint32_t s, float tmax) {
            return intersectLeafTriangle(axes, watertight, tris[s], tmax);
        });
    });
}

// Every triangle, in file order (as leafTriangleOf stores it: one without area is never
// hit); the first of equally near triangles wins.
TraceHit traceBruteForce(const Mesh& mesh, const Ray& ray);

// RAYS.bin: float32 ox oy oz tmin dx dy dz tmax per ray (little-endian).
struct RayRecord {
    float origin[3];
    float tmin;
    float direction[3];
    float tmax;
};
static_assert(sizeof(RayRecord) == 32, "the RAYS.bin record");

// Reads and checks a rays file: size a multiple of 32 bytes, at most kMaxRays rays (a
// larger file is refused before anything is read), finite origins and directions, each
// direction's largest component at least kMinRayDirection, no NaN in tmin/tmax. tmin
// and tmax may be infinite, and tmin > tmax is an empty interval: that ray misses. Throws
// InputError naming the file and the first bad ray.
constexpr size_t kMaxRays = size_t(1) << 25;  // 1 GiB of records
constexpr float kMinRayDirection = 0x1p-32f;
std::vector<Ray> readRays(const std::string& path);
// The same checks on the bytes of a rays file in memory; `name` starts the messages
// ("rays file 'r.bin'").
std::vector<Ray> parseRays(const void* data, size_t size, const std::string& name);
void writeRays(const std::string& path, const std::vector<Ray>& rays);
// HITS.bin: float32 t, uint32 triangle per ray; written atomically (temp file + rename).
void writeHits(const std::string& path, const std::vector<TraceHit>& hits);
std::vector<TraceHit> readHits(const std::string& path);

// Traces every ray on `threads` threads: the calling thread and workers kept between
// batches, chunks of 1,024 rays handed out dynamically.
void traceBatch(const Bvh& bvh, const std::vector<Ray>& rays, std::vector<TraceHit>& hits,
                int threads);
void traceBatchBruteForce(const Mesh& mesh, const std::vector<Ray>& rays,
                          std::vector<TraceHit>& hits, int threads);
// The batch loop itself: f(begin, end) on chunks of 1,024 of [0, count), handed out
// dynamically to `threads` threads (0: all cores): the calling thread and the workers core
// keeps between calls (core/parallel.hpp). The first exception ends the batch early and
// reaches the caller.
// Every batch tracer of the step runs on it (traceBatchOf below, brute force).
void forEachRayChunk(size_t count, int threads, const std::function<void(size_t, size_t)>& f);

// The batch tracers' inner loop is compiled twice: for baseline x86-64 and, with every
// call inlined into it (gnu::flatten), for AVX2, chosen at run time as Embree chooses its
// instruction set. The arithmetic is the same (AVX2 brings no FMA, and -ffp-contract=off
// forbids contraction anyway), so are the bits of every hit; the AVX encoding's
// three-operand instructions save the register copies of the SSE one.
#if defined(__x86_64__) && defined(__GNUC__)
#define BOXES_TARGET_AVX2 [[gnu::target("avx2"), gnu::flatten]]
#endif
// True when the batch tracers run their AVX2 loop: the CPU has AVX2 and the environment
// does not set BOXES_NO_AVX2 (to measure or test the baseline loop). Read per batch.
bool traceUsesAvx2();

namespace detail {
template <bool kAvx, typename Tree>
void traceRange(const Tree& tree, const Ray* rays, TraceHit* hits, size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) hits[i] = traceNearest<kAvx>(tree, rays[i]);
}
#if defined(BOXES_TARGET_AVX2)
template <typename Tree>
BOXES_TARGET_AVX2 void traceRangeAvx2(const Tree& tree, const Ray* rays, TraceHit* hits,
                                      size_t begin, size_t end) {
    traceRange<true>(tree, rays, hits, begin, end);
}
#endif
}  // namespace detail

// The batch loop of every tree (Bvh, Bvh4, Bvh8): traceNearest on each ray, on `threads`
// threads, in the AVX2 copy where traceUsesAvx2(). Each tree's traceBatch instantiates it.
template <typename Tree>
void traceBatchOf(const Tree& tree, const std::vector<Ray>& rays, std::vector<TraceHit>& hits,
                  int threads) {
    hits.resize(rays.size());
    auto range = &detail::traceRange<false, Tree>;
#if defined(BOXES_TARGET_AVX2)
    if (traceUsesAvx2()) range = &detail::traceRangeAvx2<Tree>;
#endif
    forEachRayChunk(rays.size(), threads, [&](size_t begin, size_t end) {
        range(tree, rays.data(), hits.data(), begin, end);
    });
}

// Counts the work of tracing `rays` (one thread, in order: the same counts every run).
template <typename Tree>
TraversalCounts countWorkOf(const Tree& tree, const std::vector<Ray>& rays) {
    TraversalCounts counts;
    counts.rays = rays.size();
    for (const Ray& ray : rays) traceNearest(tree, ray, TraversalCounter{&counts});
    return counts;
}
TraversalCounts countWork(const Bvh& bvh, const std::vector<Ray>& rays);

// Does a hierarchy's hit agree with brute force: the same triangle, or the same t (two
// triangles sharing the hit point)?
inline bool hitsAgree(const TraceHit& a, const TraceHit& b) {
    return a.triangle == b.triangle || a.t == b.t;
}

// Ray sets like peer-bench's make_rays.py (for tests and the measure run): primary rays of
// a camera framing the mesh, diffuse rays from points on its surface, random rays in its
// inflated bounds.
enum class RayKind { Primary, Diffuse, Random };
const char* rayKindName(RayKind kind);
std::vector<Ray> makeRays(const Mesh& mesh, RayKind kind, size_t count, uint64_t seed);

// The mesh as renderer geometry, through the hierarchy.
class MeshBvhGeometry : public Geometry {
public:
    MeshBvhGeometry(const Mesh& mesh, int material, const BvhBuildOptions& options);
    bool intersect(const Ray& ray, SurfaceHit& hit) const override;
    bool occluded(const Ray& ray) const override;
    Vec3 boundsMin() const override { return bvh_.bounds().min; }
    Vec3 boundsMax() const override { return bvh_.bounds().max; }
    std::vector<int> materialsUsed() const override { return {material_}; }
    const Bvh& bvh() const { return bvh_; }
    const BvhBuildStats& stats() const { return stats_; }

private:
    const Mesh& mesh_;
    int material_;
    BvhBuildStats stats_;  // before bvh_: the build fills it
    Bvh bvh_;
};

}  // namespace boxes
