// Step 04's engine: rays for the `trace` command and the measurements. The files it reads
// and writes (RAYS.bin, HITS.bin) and the ray sets of the bench and the tests.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "04_bvh/trace.hpp"
#include "core/scene.hpp"

namespace boxes {

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

// Ray sets (for the bench, the tests and the measure run): primary rays of
// a camera framing the mesh, diffuse rays from points on its surface, random rays in its
// inflated bounds.
enum class RayKind { Primary, Diffuse, Random };
const char* rayKindName(RayKind kind);
std::vector<Ray> makeRays(const Mesh& mesh, RayKind kind, size_t count, uint64_t seed);
// Primary rays of a given camera (its aspect ignored): a square image of round(sqrt(count))
// pixels a side, row 0 at the top, pixel centres, repeated from the top when count is not a
// square. The `rays` command uses it for a camera inside a scene.
std::vector<Ray> makeCameraRays(const Camera& camera, size_t count);

}  // namespace boxes
