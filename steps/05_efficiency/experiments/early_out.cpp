// Early out in step 04's tree: any-hit shadow rays (5.4) and skipping far nodes.
#include <algorithm>
#include <functional>

#include "05_efficiency/bvh_mesh.hpp"
#include "05_efficiency/experiments/lab_helpers.hpp"
#include "05_efficiency/measure.hpp"
#include "core/timing.hpp"

namespace boxes {

using namespace lab;

Table measureEarlyOut(LabBvhMesh& mesh, const LabOptions& o) {
    Table t("early_out", "Early out: box and triangle tests per ray and time, with and without",
            {"rays", "method", "count", "box tests/ray", "triangle tests/ray", "us/ray", "min us",
             "max us", "speed-up", "answers differing"});
    t.note =
        "the mesh in step 04's hierarchy (full-sweep SAH, leaves of at most 8 triangles), the "
        "lab's own traversal; primary rays of an 80x60 view, shadow rays from their hits to the "
        "light; one thread, median of repeats interleaved round-robin; speed-up: the first row of "
        "each pair over the second; answers differing: rays whose answer (occluded or not; the "
        "nearest t and triangle) differs from the second row of its pair, the full search";
    const Bounds3f b(mesh.boundsMin(), mesh.boundsMax());
    Camera cam = fitCamera(b.min, b.max, 4.0f / 3.0f);
    CameraBasisT<float> basis = cam.basis();
    Vec3 light = b.centroid() + glm::length(b.diagonal()) * Vec3(0.6f, 1.2f, 0.9f);
    std::vector<Ray> primary, shadow;
    const int w = sized(o, 80), h = sized(o, 60);
    mesh.setOptions({});
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            Ray r(cam.eye, cam.directionThrough(basis, x + 0.5f, y + 0.5f, w, h));
            primary.push_back(r);
            SurfaceHit hit;
            if (mesh.intersect(r, hit)) {
                Vec3 d = light - hit.point;
                shadow.emplace_back(offsetOrigin(hit.point, hit.geometricNormal, d), d, 0.0f, 1.0f);
            }
        }
    LabMeshOptions on, anyOff, skipOff;
    anyOff.anyHitShadows = false;
    skipOff.skipBeyondNearest = false;
    struct Variant {
        const char* kind;
        const char* method;
        const std::vector<Ray>* rays;
        LabMeshOptions opt;
        bool shadows;
    };
    const Variant variants[] = {
        {"shadow", "any hit (stop at the first occluder)", &shadow, on, true},
        {"shadow", "nearest hit, then 'is there one'", &shadow, anyOff, true},
        {"primary", "nearer child first, skip nodes beyond the nearest t", &primary, on, false},
        {"primary", "every node the ray meets, storage order", &primary, skipOff, false}};
    std::vector<std::function<void()>> passes;
    std::vector<double> boxes, tris;
    // Each variant's answers, to compare with the full search of its pair.
    std::vector<std::vector<std::pair<float, int>>> answers;
    for (const Variant& v : variants) {
        auto pass = [&mesh, &v] {
            mesh.setOptions(v.opt);
            int n = 0;
            SurfaceHit hit;
            for (const Ray& r : *v.rays) n += v.shadows ? mesh.occluded(r) : mesh.intersect(r, hit);
            keepValue(n);
        };
        mesh.resetCounters();
        pass();
        const double count = double(std::max<size_t>(1, v.rays->size()));
        boxes.push_back(double(mesh.boxTests()) / count);
        tris.push_back(double(mesh.triangleTests()) / count);
        mesh.setOptions(v.opt);
        std::vector<std::pair<float, int>> a;
        for (const Ray& r : *v.rays) {
            SurfaceHit hit;
            if (v.shadows)
                a.emplace_back(0.0f, int(mesh.occluded(r)));
            else if (mesh.intersect(r, hit))
                a.emplace_back(hit.t, hit.primitive);
            else
                a.emplace_back(-1.0f, -1);
        }
        answers.push_back(std::move(a));
        passes.push_back(pass);
    }
    std::vector<Timing> times = measureInterleaved(o.repeats, passes);
    mesh.setOptions({});
    for (size_t i = 0; i < std::size(variants); ++i) {
        const Variant& v = variants[i];
        double per = 1e6 / double(std::max<size_t>(1, v.rays->size()));
        size_t first = i - i % 2;
        long long differ = 0;
        for (size_t k = 0; k < answers[i].size(); ++k)
            differ += answers[i][k] != answers[first + 1][k];
        t.row({std::string(v.kind), std::string(v.method), (long long)v.rays->size(), boxes[i],
               tris[i], times[i].median * per, times[i].min * per, times[i].max * per,
               times[first + 1].median / times[i].median, differ});
    }
    t.timeAndError("us/ray", "min us", "max us", "answers differing");
    return t;
}

}  // namespace boxes
