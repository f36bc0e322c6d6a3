// Step 04's measurements: builds, trace speed against brute force, threads, cracks and
// frustum culling counts; and the top-down picture of the culled hierarchy.
#pragma once

#include <string>
#include <vector>

#include "04_bvh/frustum.hpp"
#include "04_bvh/trace.hpp"
#include "core/image.hpp"
#include "core/report.hpp"

namespace boxes {

struct NamedMesh {
    std::string name;
    const Mesh* mesh;
};

// Per builder: build ms (median), nodes, leaves, leaf sizes, depth, SAH cost and its
// excess over the full-sweep SAH tree. Table id "bvh_build".
Table measureBuilds(const NamedMesh& mesh, int bins, int repeats);

// Per builder and ray kind: Mrays/s on one thread (median of repeats) and the rays whose
// nearest hit differs from brute force on a sample. Table id "bvh_trace".
Table measureTraceSpeed(const NamedMesh& mesh, size_t rays, size_t bruteForceRays, int repeats,
                        uint64_t seed, int bins);

// 1 thread against 2 (binned SAH, primary and diffuse rays). Table id "bvh_threads".
Table measureThreads(const NamedMesh& mesh, size_t rays, int repeats, uint64_t seed);

// Rays aimed at shared edges and vertices (step 01's crack rays): rays for which the
// hierarchy finds no hit where a target triangle is hit. Table id "bvh_cracks".
Table measureBvhCracks(const std::vector<NamedMesh>& meshes, size_t raysPerFeature, uint64_t seed);

// Culled / kept / wrongly kept nodes for both tests from cameras around the mesh, close
// enough that the frustum cuts it. Table id "bvh_culling".
Table measureCulling(const NamedMesh& mesh, const Bvh& bvh, int cameras);

// The culling camera for view `index` of `count` around the mesh (used by the measure run
// and the window's starting view): near the surface, far plane at the mesh's centre.
struct CullingView {
    Camera camera;
    float nearDistance, farDistance;
};
CullingView cullingView(const Bounds3f& bounds, int index, int count, float aspect);

// Draws the hierarchy's boxes at `level` (leaves above it too) seen from above (along
// `up`), coloured by the test's verdict, and the frustum's outline.
void drawCullingMap(Image& image, int x0, int width, const Bvh& bvh, const Frustum& frustum,
                    CullTest test, int level, Vec3 up);

}  // namespace boxes
