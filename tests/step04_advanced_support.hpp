// Step 04's tests of the engine (advanced/): what its topic files share.
#pragma once

#include "01_triangle/measure.hpp"
#include "step04_support.hpp"

namespace boxes::test04 {

// Rays aimed exactly at shared edges and vertices (`rays` counts them): how many find
// nothing as near as the nearest of the triangles at the feature, with the same leaf test.
template <typename Nearest>
size_t countCracks(const Mesh& m, const CrackRaySet& set, Nearest&& nearest, size_t& rays) {
    size_t cracks = 0;
    for (const auto* group : {&set.edgeRays, &set.vertexRays})
        for (const CrackRay& cr : *group) {
            ++rays;
            float target = kInfinity<float>;
            WatertightRay w(cr.ray);
            for (uint32_t tri : cr.triangles) {
                LeafTriangle lt = leafTriangleOf(m, tri);
                float tmax = cr.ray.tmax;
                if (intersectLeafTriangle(w, lt, tmax)) target = std::min(target, tmax);
            }
            cracks += target < kInfinity<float> && !(nearest(cr.ray).t <= target);
        }
    return cracks;
}

}  // namespace boxes::test04
