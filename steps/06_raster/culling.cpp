#include "06_raster/culling.hpp"

#include <algorithm>

#include "core/timing.hpp"

namespace boxes {

FrustumCuller::FrustumCuller(const Mesh& mesh) {
    BvhBuildOptions options;
    options.builder = BvhBuilder::BinnedSah;
    bvh_ = buildBvh(mesh, options);
}

std::vector<uint32_t> FrustumCuller::visibleTriangles(const Camera& camera, double near, double far,
                                                      CullTest test, CullStats& stats) const {
    Stopwatch watch;
    stats = CullStats{};
    std::vector<uint32_t> visible;
    if (bvh_.empty()) return visible;
    const Frustum frustum = makeFrustum(camera, float(near), float(far));
    // Depth first from the root, a culled box's subtree never visited (step 04's walk,
    // counting boxes without its exact classification, which costs more than drawing).
    std::vector<uint32_t> stack = {0};
    while (!stack.empty()) {
        const BvhNode& node = bvh_.nodes[stack.back()];
        stack.pop_back();
        ++stats.boxesVisited;
        if (boxCulled(frustum, node.bounds(), test)) {
            ++stats.boxesCulled;
            continue;
        }
        ++stats.boxesKept;
        if (node.isLeaf()) {
            for (uint32_t s = node.leftFirst; s < node.leftFirst + node.count; ++s)
                visible.push_back(bvh_.primitiveIndices[s]);
        } else {
            stack.push_back(node.leftFirst + 1);
            stack.push_back(node.leftFirst);
        }
    }
    std::sort(visible.begin(), visible.end());
    stats.trianglesKept = visible.size();
    stats.milliseconds = watch.milliseconds();
    return visible;
}

FrameStats rasterizeCulled(const RasterScene& scene, const FrustumCuller* culler,
                           const Camera& camera, const RasterSettings& settings,
                           FrameBuffers& buffers, CullStats& cull, CullTest test) {
    cull = CullStats{};
    if (!culler) return rasterizeFrame(scene, camera, settings, buffers);
    auto [near, far] = nearFarFor(scene, camera, settings);
    std::vector<uint32_t> visible = culler->visibleTriangles(camera, near, far, test, cull);
    FrameStats stats = rasterizeFrame(scene, camera, settings, buffers, &visible);
    stats.milliseconds += cull.milliseconds;
    return stats;
}

}  // namespace boxes
