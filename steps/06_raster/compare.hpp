// Step 06: the rasterizer against the ray tracer, pixel for pixel: which triangle each
// names, the depth where they agree, the shadows, and the time per frame.
#pragma once

#include <cstdint>
#include <vector>

#include "06_raster/pipeline.hpp"
#include "core/scene.hpp"

namespace boxes {

// The ray tracer's primary visibility (the scene's geometry: step 01's grid for the mesh):
// per pixel the visible mesh triangle (kNoPrimitive where a sphere, a plane or nothing is
// seen), its depth along the view, and for the first light whether the point is lit
// (-1: the light cannot contribute there).
struct TracedFrame {
    int width = 0, height = 0;
    std::vector<uint32_t> ids;
    std::vector<float> depth;
    std::vector<int8_t> litByFirstLight;
    double milliseconds = 0.0;
};
TracedFrame traceFrame(const Scene& scene, const Camera& camera, int width, int height,
                       bool shadows, int threads = 1);

struct VisibilityComparison {
    size_t pixels = 0;
    size_t coveredRaster = 0, coveredTraced = 0;
    size_t coveredEither = 0, sameTriangle = 0;
    size_t differOnEdge = 0;  // disagreements where the other's triangle is within a pixel
    size_t differElsewhere = 0;
    double maxDepthError = 0.0, meanDepthError = 0.0;  // relative, where both agree
    double agreement() const {
        return coveredEither ? double(sameTriangle) / double(coveredEither) : 1.0;
    }
    double coverageDifference() const {
        return pixels ? std::abs(double(coveredRaster) - double(coveredTraced)) / double(pixels)
                      : 0.0;
    }
};
// Both id buffers row-major, the same size; depths as in the --depth file. A pixel where
// they name different triangles counts as "on an edge" when the two triangles share a
// vertex of `mesh` (the pixel centre is near their common edge or corner) or the other's
// triangle is seen within one pixel; a pixel covered by one only, when the other's
// neighbourhood shows the covering triangle (a silhouette edge).
VisibilityComparison compareVisibility(int width, int height,
                                       const std::vector<uint32_t>& rasterIds,
                                       const std::vector<float>& rasterDepth,
                                       const std::vector<uint32_t>& tracedIds,
                                       const std::vector<float>& tracedDepth,
                                       const Mesh* mesh = nullptr);

struct ShadowComparison {
    size_t compared = 0;  // pixels where both see the same triangle and the light can reach
    size_t acne = 0;      // shadowed by the rasterizer's method, lit for the ray tracer
    size_t leaks = 0;     // lit by the method, shadowed for the ray tracer (peter-panning)
    double disagreement() const { return compared ? double(acne + leaks) / double(compared) : 0.0; }
};
ShadowComparison compareShadows(const std::vector<uint32_t>& rasterIds,
                                const std::vector<int8_t>& rasterLit,
                                const std::vector<uint32_t>& tracedIds,
                                const std::vector<int8_t>& tracedLit);

// An image of where they differ: grey where both agree, red where only the rasterizer
// draws a triangle, blue where only the ray tracer does, yellow where they name different
// triangles.
Image differenceImage(int width, int height, const std::vector<uint32_t>& rasterIds,
                      const std::vector<uint32_t>& tracedIds);

}  // namespace boxes
