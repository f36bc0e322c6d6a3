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
    if (bvh_.empty()) return {};
    const Frustum frustum = makeFrustum(camera, float(near), float(far));
    // Step 04's walk, counting boxes without its exact classification (which costs more
    // than drawing).
    CullCounts counts;
    std::vector<uint32_t> visible = cullHierarchy(bvh_, frustum, test, &counts, false);
    stats.boxesVisited = counts.visited;
    stats.boxesCulled = counts.culled;
    stats.boxesKept = counts.kept;
    // Back to file order through a mark per triangle: linear, where sorting the kept list
    // cost more than the walk itself on a mesh seen whole.
    std::vector<char> kept(bvh_.primitiveIndices.size(), 0);
    for (uint32_t t : visible) {
        if (t >= kept.size()) kept.resize(size_t(t) + 1, 0);
        kept[t] = 1;
    }
    visible.clear();
    for (size_t t = 0; t < kept.size(); ++t)
        if (kept[t]) visible.push_back(uint32_t(t));
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
