// Precalculation (exercises 5.6, 5.7) and early out on a mesh, added one at a time.
#include <functional>
#include <memory>

#include "05_efficiency/bvh_mesh.hpp"
#include "05_efficiency/experiments/lab_helpers.hpp"
#include "05_efficiency/measure.hpp"
#include "core/timing.hpp"

namespace boxes {

using namespace lab;

Table measurePrecalculation(LabBvhMesh& mesh, const LabOptions& o) {
    Table t(
        "precalc",
        "Precalculation and early out: time per frame of a mesh, each optimization added in turn",
        {"variant", "ms/frame", "min ms", "max ms", "speed-up", "box tests/pixel",
         "triangle tests/pixel", "pixels differing"},
        "the mesh alone (no floor) in step 04's hierarchy, the lab's traversal with each switch "
        "(Moller-Trumbore and the lab's slab tests, not step 04's robust ones), "
        "96x72, primary and shadow rays, one thread, median of repeats interleaved "
        "(one frame of each variant per round); pixels "
        "differing: "
        "against the first row, any float difference");
    // The scene refers to the caller's mesh (no ownership: it outlives the scene).
    std::shared_ptr<LabBvhMesh> cm(&mesh, [](LabBvhMesh*) {});
    Scene scene;
    scene.name = "mesh";
    scene.geometries.push_back(cm);
    Bounds3f b(cm->boundsMin(), cm->boundsMax());
    float diag = glm::length(b.diagonal());
    scene.lights.push_back(
        {b.centroid() + diag * Vec3(0.6f, 1.2f, 0.9f), Vec3(1.6f * diag * diag)});
    scene.setLightRadii();
    scene.camera = fitCamera(b.min, b.max, 4.0f / 3.0f);
    struct Variant {
        const char* name;
        LabMeshOptions opt;
    };
    std::vector<Variant> variants = {
        {"naive: divisions, edges per test, every node, nearest for shadows",
         {false, false, false, false, false}},
        {"+ reciprocal direction and signs per ray", {true, false, false, false, false}},
        {"+ precomputed triangle edges", {true, true, false, false, false}},
        {"+ early out (skip far nodes, any-hit shadows)", {true, true, true, true, false}}};
    Renderer r(scene, scene.camera, oneThread(sized(o, 96), sized(o, 72)));
    const double px = double(sized(o, 96) * sized(o, 72));
    std::vector<Image> images;
    std::vector<double> boxes, tris;
    for (const Variant& v : variants) {
        cm->setOptions(v.opt);
        cm->resetCounters();
        images.push_back(r.render());
        boxes.push_back(double(cm->boxTests()) / px);
        tris.push_back(double(cm->triangleTests()) / px);
    }
    // Interleaved: one frame of each variant per round, so a change in the machine's load
    // (other processes) affects every variant alike instead of one.
    std::vector<std::function<void()>> frames;
    for (const Variant& v : variants)
        frames.push_back([&, opt = v.opt] {
            cm->setOptions(opt);
            keepValue(r.render());
        });
    std::vector<Timing> times = measureInterleaved(o.repeats, frames);
    cm->setOptions({});
    for (size_t i = 0; i < variants.size(); ++i) {
        size_t differ = compareImages(images[i], images[0]).pixelsDiffering;
        t.row({std::string(variants[i].name), ms(times[i].median), ms(times[i].min),
               ms(times[i].max), times[0].median / times[i].median, boxes[i], tris[i],
               (long long)differ});
    }
    t.timeAndError("ms/frame", "min ms", "max ms", "pixels differing");
    return t;
}

}  // namespace boxes
