#include "04_bvh/frustum.hpp"

#include <stdexcept>

namespace boxes {

namespace {

// The plane through three points with its normal on the side of `inside`.
PlaneT<float> planeThrough(Vec3 a, Vec3 b, Vec3 c, Vec3 inside) {
    Vec3 n = glm::normalize(glm::cross(b - a, c - a));
    float d = -glm::dot(n, a);
    if (glm::dot(n, inside) + d < 0.0f) {
        n = -n;
        d = -d;
    }
    return {n, d};
}

}  // namespace

// EXERCISE 4.6: the six frustum planes and eight corners from the camera (2 points)
Frustum makeFrustum(const Camera& camera, float nearDistance, float farDistance) {
    // BEGIN SOLUTION
    if (!(nearDistance > 0.0f) || !(farDistance > nearDistance) || !std::isfinite(farDistance))
        throw std::invalid_argument("frustum needs 0 < near < far (finite)");
    CameraBasisT<float> b = camera.basis();
    float h = camera.halfHeight(), w = camera.aspect * h;
    Frustum f;
    auto corner = [&](float distance, float sx, float sy) {
        return camera.eye + distance * (b.forward + sx * w * b.right + sy * h * b.up);
    };
    for (int i = 0; i < 2; ++i) {
        float distance = i == 0 ? nearDistance : farDistance;
        f.corners[size_t(4 * i + 0)] = corner(distance, -1, 1);
        f.corners[size_t(4 * i + 1)] = corner(distance, 1, 1);
        f.corners[size_t(4 * i + 2)] = corner(distance, -1, -1);
        f.corners[size_t(4 * i + 3)] = corner(distance, 1, -1);
    }
    // A point surely inside: on the axis, halfway between near and far.
    Vec3 inside = camera.eye + 0.5f * (nearDistance + farDistance) * b.forward;
    const auto& c = f.corners;
    // The side planes pass through the eye and two far corners.
    f.planes[kLeftPlane] = planeThrough(camera.eye, c[4], c[6], inside);
    f.planes[kRightPlane] = planeThrough(camera.eye, c[5], c[7], inside);
    f.planes[kBottomPlane] = planeThrough(camera.eye, c[6], c[7], inside);
    f.planes[kTopPlane] = planeThrough(camera.eye, c[4], c[5], inside);
    // Near and far: normal along the view direction, through a point at the distance.
    f.planes[kNearPlane] = {b.forward, -glm::dot(b.forward, camera.eye + nearDistance * b.forward)};
    f.planes[kFarPlane] = {-b.forward, glm::dot(b.forward, camera.eye + farDistance * b.forward)};
    return f;
    // END SOLUTION
}

// EXERCISE 4.7: the single-vertex (p-vertex) test against each plane (2 points)
bool cullByPlanes(const Frustum& frustum, const Bounds3f& box) {
    // BEGIN SOLUTION
    for (const PlaneT<float>& plane : frustum.planes) {
        // The corner furthest along the normal: max where the normal is positive.
        Vec3 p(plane.normal.x >= 0.0f ? box.max.x : box.min.x,
               plane.normal.y >= 0.0f ? box.max.y : box.min.y,
               plane.normal.z >= 0.0f ? box.max.z : box.min.z);
        if (glm::dot(plane.normal, p) + plane.d < 0.0f) return true;
    }
    return false;
    // END SOLUTION
}

// EXERCISE 4.8: the refinement: the frustum's corners against the box's planes (2 points)
bool cullByBoxPlanes(const Frustum& frustum, const Bounds3f& box) {
    // BEGIN SOLUTION
    for (int axis = 0; axis < 3; ++axis) {
        bool allBelow = true, allAbove = true;
        for (const Vec3& corner : frustum.corners) {
            allBelow = allBelow && corner[axis] < box.min[axis];
            allAbove = allAbove && corner[axis] > box.max[axis];
        }
        if (allBelow || allAbove) return true;
    }
    return false;
    // END SOLUTION
}

bool boxIntersectsFrustumExact(const Frustum& frustum, const Bounds3f& box) {
    if (box.isEmpty()) return false;
    std::array<Vec3d, 8> boxCorners, frustumCorners;
    for (int i = 0; i < 8; ++i) {
        boxCorners[size_t(i)] = Vec3d(i & 1 ? box.max.x : box.min.x, i & 2 ? box.max.y : box.min.y,
                                      i & 4 ? box.max.z : box.min.z);
        frustumCorners[size_t(i)] = Vec3d(frustum.corners[size_t(i)]);
    }
    const auto& c = frustumCorners;
    // Frustum edge directions: the four side edges and the near rectangle's two sides.
    std::array<Vec3d, 6> frustumEdges = {c[4] - c[0], c[5] - c[1], c[6] - c[2],
                                         c[7] - c[3], c[1] - c[0], c[2] - c[0]};
    std::vector<Vec3d> axes = {Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(0, 0, 1)};
    for (const auto& plane : frustum.planes) axes.push_back(Vec3d(plane.normal));
    for (int a = 0; a < 3; ++a)
        for (const Vec3d& e : frustumEdges) {
            Vec3d unit(0.0);
            unit[a] = 1.0;
            Vec3d axis = glm::cross(unit, e);
            if (glm::dot(axis, axis) > 1e-24 * glm::dot(e, e)) axes.push_back(axis);
        }
    for (const Vec3d& axis : axes) {
        double boxMin = kInfinity<double>, boxMax = -kInfinity<double>;
        double frMin = kInfinity<double>, frMax = -kInfinity<double>;
        for (int i = 0; i < 8; ++i) {
            double b = glm::dot(axis, boxCorners[size_t(i)]);
            double f = glm::dot(axis, frustumCorners[size_t(i)]);
            boxMin = std::min(boxMin, b);
            boxMax = std::max(boxMax, b);
            frMin = std::min(frMin, f);
            frMax = std::max(frMax, f);
        }
        if (boxMax < frMin || frMax < boxMin) return false;  // a separating axis
    }
    return true;
}

std::vector<uint32_t> cullHierarchy(const Bvh& bvh, const Frustum& frustum, CullTest test,
                                    CullCounts* counts, bool classify) {
    std::vector<uint32_t> visible;
    if (bvh.empty()) return visible;
    CullCounts local;
    std::vector<bool> seen(bvh.primitiveIndices.size(), false);
    std::vector<uint32_t> stack = {0};
    while (!stack.empty()) {
        const BvhNode& node = bvh.nodes[stack.back()];
        stack.pop_back();
        ++local.visited;
        if (boxCulled(frustum, node.bounds(), test)) {
            ++local.culled;
            continue;
        }
        ++local.kept;
        if (counts && classify && !boxIntersectsFrustumExact(frustum, node.bounds()))
            ++local.wronglyKept;
        if (node.isLeaf()) {
            ++local.keptLeaves;
            for (uint32_t s = node.leftFirst; s < node.leftFirst + node.count; ++s) {
                uint32_t triangle = bvh.primitiveIndices[s];
                if (triangle >= seen.size()) seen.resize(size_t(triangle) + 1, false);
                if (seen[triangle]) continue;  // already kept through another leaf
                seen[triangle] = true;
                visible.push_back(triangle);
            }
        } else {
            stack.push_back(node.leftFirst + 1);
            stack.push_back(node.leftFirst);
        }
    }
    local.keptTriangles = visible.size();
    if (counts) *counts = local;
    return visible;
}

std::vector<NodeVisibility> classifyNodes(const Bvh& bvh, const Frustum& frustum, CullTest test) {
    std::vector<NodeVisibility> result(bvh.nodes.size(), NodeVisibility::NotVisited);
    if (bvh.empty()) return result;
    std::vector<uint32_t> stack = {0};
    while (!stack.empty()) {
        uint32_t index = stack.back();
        stack.pop_back();
        const BvhNode& node = bvh.nodes[index];
        if (boxCulled(frustum, node.bounds(), test)) {
            result[index] = NodeVisibility::Culled;
            continue;
        }
        result[index] = boxIntersectsFrustumExact(frustum, node.bounds())
                            ? NodeVisibility::Kept
                            : NodeVisibility::WronglyKept;
        if (!node.isLeaf()) {
            stack.push_back(node.leftFirst + 1);
            stack.push_back(node.leftFirst);
        }
    }
    return result;
}

}  // namespace boxes
