// Step 06: view-frustum culling with step 04's hierarchy. The mesh's bounding volume
// hierarchy is walked from the root; a box that step 04's conservative test proves to lie
// outside the camera's frustum is skipped with its whole subtree, and only the triangles
// of the kept leaves go down the pipeline. Culling only saves work: the image must be
// identical to the unculled one (a culled box cannot cover a pixel centre).
#pragma once

#include <cstdint>
#include <vector>

#include "04_bvh/bvh.hpp"
#include "04_bvh/frustum.hpp"
#include "06_raster/pipeline.hpp"
#include "core/mesh.hpp"
#include "core/scene.hpp"

namespace boxes {

struct CullStats {
    size_t boxesVisited = 0, boxesCulled = 0, boxesKept = 0;
    size_t trianglesKept = 0;
    double milliseconds = 0.0;
};

class FrustumCuller {
public:
    // Builds the hierarchy over the mesh (step 04's binned SAH).
    explicit FrustumCuller(const Mesh& mesh);

    // The mesh triangles in the kept leaves, in file order (so that z-buffer ties fall as
    // in the full frame), for the frustum between near and far along the view.
    std::vector<uint32_t> visibleTriangles(const Camera& camera, double near, double far,
                                           CullTest test, CullStats& stats) const;
    const Bvh& bvh() const { return bvh_; }

private:
    Bvh bvh_;
};

// A frame drawn with culling (no culling when culler is null): the kept mesh triangles and
// every other triangle. The frame's time includes the culling walk.
FrameStats rasterizeCulled(const RasterScene& scene, const FrustumCuller* culler,
                           const Camera& camera, const RasterSettings& settings,
                           FrameBuffers& buffers, CullStats& cull,
                           CullTest test = CullTest::PlanesAndCorners);

}  // namespace boxes
