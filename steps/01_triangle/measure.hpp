// Step 01's measurements: time per ray/triangle test, cracks on shared edges and vertices
// of closed meshes for each test in float and in double, and the pixels where the tests
// disagree.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "01_triangle/triangle.hpp"
#include "01_triangle/triangle_grid.hpp"
#include "core/mesh.hpp"
#include "core/report.hpp"
#include "core/step.hpp"

namespace boxes {

// Rays aimed exactly at shared features of a closed mesh: each ray, its target triangles
// (the ones that share the feature), and what the feature is.
struct CrackRay {
    Ray ray;
    std::vector<uint32_t> triangles;
};
struct CrackRaySet {
    std::vector<CrackRay> edgeRays, vertexRays;
};

// Rays from outside towards points on shared edges and at shared vertices, from
// directions that every triangle there faces (so a ray is never tangent to them; features
// without such a direction, like sharp creases, are skipped).
// `offset` translates the mesh (and the rays) away from the origin, in float.
CrackRaySet makeCrackRays(const Mesh& mesh, size_t edgeRays, size_t vertexRays, uint64_t seed,
                          Vec3 offset = Vec3(0.0f));

// Rays for which no target triangle reports a hit, with the given test and precision.
template <typename T>
size_t countCracks(const Mesh& mesh, const std::vector<CrackRay>& rays, TriangleTest test,
                   Vec3 offset = Vec3(0.0f));

struct CrackCase {
    std::string mesh;
    const Mesh* data;
    Vec3 offset;
};
Table measureCracks(const std::vector<CrackCase>& cases, size_t raysPerFeature, uint64_t seed);

// Median time per test over a fixed mix of hitting and missing ray/triangle pairs.
Table measureTriangleSpeed(const Mesh& mesh, uint64_t seed, int repeats);

// One row per test and precision: its time per test (from the speed table) beside its
// cracks over every case (from the cracks table).
Table accuracyVersusTime(const Table& speed, const Table& cracks);

// Rings in magenta, on the image greyed (markPixels), the pixels of the camera's image where
// the three tests see different nearest triangles; returns their count.
size_t markDisagreements(const TriangleGrid& grid, const Camera& camera, Image& image, int threads);

// The program's --measure: the disagreement image beside the PNG (FILE-disagree.png), the
// speed and crack tables (the bunny and sh1, at the origin and far from it), and accuracy
// against time with its plot.
void measureTriangleTests(const StepRun& run, const TriangleGrid& grid, size_t crackRays,
                          Report& report);

}  // namespace boxes
