// Step 04: view-frustum culling of boxes and of a hierarchy, for a rasterizer (step 06).
//
// The frustum is six planes whose normals point inside (N.P + d >= 0 inside) and its
// eight corners. Culling a box is conservative: a box is culled only when it is surely
// outside; the tests differ in how many outside boxes they still keep.
//  - planes (exercise 4.7): the box is outside when, for some plane, even its corner
//    furthest along the plane's normal (the "p-vertex") is outside. Boxes outside the
//    frustum near its corners pass every plane and are kept.
//  - corners (exercise 4.8, the refinement): swap roles: the frustum is outside the box
//    when all eight frustum corners lie outside one of the box's six planes.
// Planes + corners is the separating-axis test restricted to face normals; what it still
// keeps wrongly needs the edge-edge axes (boxIntersectsFrustumExact, used for counting).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "04_bvh/bvh.hpp"
#include "core/bounds.hpp"
#include "core/math.hpp"
#include "core/scene.hpp"

namespace boxes {

struct Frustum {
    // left, right, bottom, top, near, far; unit normals pointing inside.
    std::array<PlaneT<float>, 6> planes;
    // near plane: top-left, top-right, bottom-left, bottom-right; then the same at far.
    std::array<Vec3, 8> corners;
};
enum FrustumPlane { kLeftPlane, kRightPlane, kBottomPlane, kTopPlane, kNearPlane, kFarPlane };

// Exercise 4.6: the frustum of the core's camera (eye, view, up, vertical fov, aspect)
// between the distances nearDistance and farDistance along the view direction
// (0 < near < far). Throws std::invalid_argument for a bad near/far.
Frustum makeFrustum(const Camera& camera, float nearDistance, float farDistance);

// Exercise 4.7: the single-vertex test: true when the box is outside some plane (its
// p-vertex, the corner furthest along the plane's normal, is outside). Conservative.
bool cullByPlanes(const Frustum& frustum, const Bounds3f& box);

// Exercise 4.8: the refinement: true when all eight frustum corners lie outside one of
// the box's six face planes (x < min.x for all, or x > max.x for all, ... per axis).
bool cullByBoxPlanes(const Frustum& frustum, const Bounds3f& box);

enum class CullTest { Planes, PlanesAndCorners };
inline bool boxCulled(const Frustum& frustum, const Bounds3f& box, CullTest test) {
    if (cullByPlanes(frustum, box)) return true;
    return test == CullTest::PlanesAndCorners && cullByBoxPlanes(frustum, box);
}

// Not an exercise: the exact answer (separating axis theorem over the box's face
// normals, the frustum's face normals and the cross products of their edges, in double).
bool boxIntersectsFrustumExact(const Frustum& frustum, const Bounds3f& box);

// Counts over the nodes one culling traversal of a hierarchy visits.
struct CullCounts {
    size_t visited = 0;      // nodes whose box was tested
    size_t culled = 0;       // boxes the test culled (their subtrees are skipped)
    size_t kept = 0;         // boxes the test kept
    size_t wronglyKept = 0;  // kept, yet entirely outside the frustum (exact test)
    size_t keptLeaves = 0, keptTriangles = 0;  // triangles: distinct ones
};

// Walks the hierarchy from the root, skipping the subtree of every culled box, and
// returns the primitives (triangle indices in file order) of the leaves it keeps: what a
// rasterizer draws (step 06), each once (leaves of a tree with spatial splits share
// triangles), in the order first met. With `counts`, also counts the walk, and with
// `classify` every kept box with the exact test too (wronglyKept; it costs more than the
// walk).
std::vector<uint32_t> cullHierarchy(const Bvh& bvh, const Frustum& frustum, CullTest test,
                                    CullCounts* counts = nullptr, bool classify = true);

// For drawing: the test's verdict on every node (visited or not).
enum class NodeVisibility : uint8_t { NotVisited, Culled, Kept, WronglyKept };
std::vector<NodeVisibility> classifyNodes(const Bvh& bvh, const Frustum& frustum, CullTest test);

}  // namespace boxes
