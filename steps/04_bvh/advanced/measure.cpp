#include "04_bvh/advanced/measure.hpp"

#include <algorithm>

#include "01_triangle/measure.hpp"
#include "04_bvh/advanced/build.hpp"
#include "04_bvh/advanced/bvh4.hpp"
#include "core/timing.hpp"

namespace boxes {

Table measureBvhCracks(const std::vector<NamedMesh>& meshes, size_t raysPerFeature, uint64_t seed) {
    Table t("bvh_cracks", "Cracks through the hierarchy: rays aimed at shared edges and vertices",
            {"mesh", "builder", "feature", "rays", "cracks", "differ from brute force", "ns/ray",
             "min ns", "max ns"});
    t.note =
        "a crack: a ray that some triangle at the feature hits, for which the hierarchy "
        "reports nothing as near; watertight leaf test, conservative box test; 'differ' "
        "over the first 200 rays per row against brute force; ns/ray: the row's rays traced, "
        "median of 3 passes, one thread";
    t.timeAndError("ns/ray", "min ns", "max ns", "cracks");
    for (const NamedMesh& m : meshes) {
        CrackRaySet set = makeCrackRays(*m.mesh, raysPerFeature, raysPerFeature, seed);
        // The exercise builders, the SAH with spatial splits (whose split planes cut
        // triangles, edges and vertices included), then the binned SAH tree collapsed to 4-
        // and 8-wide nodes (bvh4.hpp).
        struct Variant {
            BvhBuilder builder;
            int width;
        };
        std::vector<Variant> variants;
        for (BvhBuilder b : kExerciseBuilders) variants.push_back({b, 2});
        variants.push_back({BvhBuilder::SpatialSah, 2});
        variants.push_back({BvhBuilder::BinnedSah, 4});
        variants.push_back({BvhBuilder::BinnedSah, 8});
        for (const Variant& variant : variants) {
            // Plain copies, not a structured binding: clang 14 (Debian 12's, the fuzz
            // build's compiler) cannot capture a binding in the lambda below.
            const BvhBuilder builder = variant.builder;
            const int width = variant.width;
            BvhBuildOptions options;
            options.builder = builder;
            Bvh bvh = buildEngineBvh(*m.mesh, options);
            Bvh4 bvh4 = width == 4 ? collapseToBvh4(bvh) : Bvh4{};
            Bvh8 bvh8 = width == 8 ? collapseToBvh8(bvh) : Bvh8{};
            for (int feature = 0; feature < 2; ++feature) {
                const auto& rays = feature == 0 ? set.edgeRays : set.vertexRays;
                auto trace = [&](const Ray& ray) {
                    return width == 4   ? traceNearest(bvh4, ray)
                           : width == 8 ? traceNearest(bvh8, ray)
                                        : traceNearest(bvh, ray);
                };
                Timing time = measure(3, [&] {
                    for (const CrackRay& cr : rays) keepValue(trace(cr.ray).t);
                });
                double scale = 1e9 / double(std::max<size_t>(1, rays.size()));
                size_t cracks = 0, differ = 0;
                for (const CrackRay& cr : rays) {
                    TraceHit h = trace(cr.ray);
                    float target = kInfinity<float>;
                    WatertightRay w(cr.ray);
                    for (uint32_t tri : cr.triangles) {
                        LeafTriangle lt = leafTriangleOf(*m.mesh, tri);
                        float tmax = cr.ray.tmax;
                        if (intersectLeafTriangle(w, lt, tmax)) target = std::min(target, tmax);
                    }
                    cracks += target < kInfinity<float> && !(h.t <= target);
                    if (&cr - rays.data() < 200)
                        differ += !hitsAgree(h, traceBruteForce(*m.mesh, cr.ray));
                }
                t.row({m.name,
                       width > 2 ? "sah " + std::to_string(width) + "-wide"
                                 : std::string(bvhBuilderName(builder)),
                       std::string(feature == 0 ? "edges" : "vertices"), (long long)rays.size(),
                       (long long)cracks, (long long)differ, time.median * scale, time.min * scale,
                       time.max * scale});
            }
        }
    }
    return t;
}

}  // namespace boxes
