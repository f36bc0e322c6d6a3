#include "04_bvh/cost_map.hpp"

#include <algorithm>
#include <cstdio>
#include <numeric>
#include <utility>

#include "04_bvh/leaf_test.hpp"
#include "04_bvh/traverse.hpp"
#include "core/heatmap.hpp"

namespace boxes {

RayCost nearestHitCost(const Bvh& bvh, const Ray& ray) {
    RayCost cost;
    if (bvh.nodes.empty()) return cost;
    // Exercise 4.4's reference loop (traverse.hpp's traverseNearest), counting.
    TraversalRay r(ray, bvh);
    WatertightRay watertight(ray);
    const LeafTriangle* tris = bvh.leafTriangles.data();
    float tBest = ray.tmax, tEntry;
    struct Entry {
        uint32_t node;
        float tEntry;
    } stack[kTraversalStackSize];
    int stackSize = 0;
    ++cost.boxTests;  // the root
    if (!intersectNodeBounds(bvh.nodes[0], r, tBest, tEntry)) return cost;
    uint32_t current = 0;
    for (;;) {
        const BvhNode& node = bvh.nodes[current];
        if (node.isLeaf()) {
            for (uint32_t slot = node.leftFirst; slot < node.leftFirst + node.count; ++slot) {
                ++cost.triangleTests;
                intersectLeafTriangle(watertight, tris[slot], tBest);
            }
        } else {
            uint32_t near = node.leftFirst, far = node.leftFirst + 1;
            float tNear, tFar;
            cost.boxTests += 2;
            bool hitNear = intersectNodeBounds(bvh.nodes[near], r, tBest, tNear);
            bool hitFar = intersectNodeBounds(bvh.nodes[far], r, tBest, tFar);
            if (hitNear && hitFar) {
                if (tFar < tNear) std::swap(near, far), std::swap(tNear, tFar);
                stack[stackSize++] = {far, tFar};
                current = near;
                continue;
            }
            if (hitNear || hitFar) {
                current = hitNear ? near : far;
                continue;
            }
        }
        bool found = false;
        while (stackSize > 0 && !found) {
            const Entry& e = stack[--stackSize];
            if (e.tEntry <= tBest) current = e.node, found = true;
        }
        if (!found) return cost;
    }
}

double CostMap::boxTestsPerRay() const {
    return std::accumulate(boxTests.begin(), boxTests.end(), 0.0) /
           std::max<double>(1.0, double(boxTests.size()));
}

double CostMap::triangleTestsPerRay() const {
    return std::accumulate(triangleTests.begin(), triangleTests.end(), 0.0) /
           std::max<double>(1.0, double(triangleTests.size()));
}

CostMap primaryRayCosts(const Bvh& bvh, const Camera& camera, int width, int height, int threads,
                        RenderControl* control) {
    CostMap map{width, height, {}, {}};
    map.boxTests.assign(size_t(width) * size_t(height), 0.0);
    map.triangleTests.assign(map.boxTests.size(), 0.0);
    Camera c = camera;
    c.aspect = float(width) / float(height);
    if (control) control->rowsDone = 0, control->rows = height;
    parallelRows(height, threads, [&](int y, int) {
        checkCancelled(control);
        for (int x = 0; x < width; ++x) {
            RayCost cost = nearestHitCost(bvh, c.primaryRay(x, y, width, height));
            size_t p = size_t(y) * size_t(width) + size_t(x);
            map.boxTests[p] = cost.boxTests;
            map.triangleTests[p] = cost.triangleTests;
        }
        if (control) control->rowsDone.fetch_add(1, std::memory_order_relaxed);
    });
    return map;
}

namespace {
double largest(const std::vector<double>& v) {
    return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end());
}
}  // namespace

Image costMapImage(const CostMap& costs, const std::string& builder, double boxTop,
                   double triangleTop) {
    char title[128];
    std::snprintf(title, sizeof title, "%s: box tests per ray (mean %.1f)", builder.c_str(),
                  costs.boxTestsPerRay());
    Image boxes = heatMapImage(costs.boxTests, costs.width, costs.height,
                               boxTop > 0.0 ? boxTop : scaleTop(largest(costs.boxTests)), title);
    std::snprintf(title, sizeof title, "%s: triangle tests per ray (mean %.1f)", builder.c_str(),
                  costs.triangleTestsPerRay());
    Image triangles = heatMapImage(
        costs.triangleTests, costs.width, costs.height,
        triangleTop > 0.0 ? triangleTop : scaleTop(largest(costs.triangleTests)), title);
    const int gap = 8;
    Image both(boxes.width() + gap + triangles.width(),
               std::max(boxes.height(), triangles.height()), Vec3(1.0f));
    for (int y = 0; y < boxes.height(); ++y)
        for (int x = 0; x < boxes.width(); ++x) both.at(x, y) = boxes.at(x, y);
    for (int y = 0; y < triangles.height(); ++y)
        for (int x = 0; x < triangles.width(); ++x)
            both.at(boxes.width() + gap + x, y) = triangles.at(x, y);
    return both;
}

Image viewCostMap(const Bvh& bvh, const Camera& camera, const RenderSettings& settings,
                  BvhBuilder builder) {
    return costMapImage(primaryRayCosts(bvh, camera, settings.width, settings.height,
                                        settings.threads, settings.control),
                        bvhBuilderName(builder));
}

void addCostMaps(Report& report, const Scene& scene, const std::string& png, int width, int height,
                 int bins, int threads) {
    Table t;
    t.id = "bvh_cost";
    t.title = "The cost of a primary ray of the image, per builder";
    t.columns = {"builder", "rays", "box tests/ray", "triangle tests/ray"};
    t.note = std::to_string(width) + "x" + std::to_string(height) +
             " primary rays of the image's camera, each traced to its nearest hit with the "
             "reference traversal of exercise 4.4 (nearer child first, early out); box tests "
             "include the root's";
    std::vector<std::pair<BvhBuilder, CostMap>> maps;
    for (BvhBuilder builder : kExerciseBuilders) {
        BvhBuildOptions options;
        options.builder = builder;
        options.bins = bins;
        Bvh bvh = buildBvh(scene.mesh, options);
        CostMap map = primaryRayCosts(bvh, scene.camera, width, height, threads);
        // The table sums the rays again, one by one, apart from the map.
        Camera c = scene.camera;
        c.aspect = float(width) / float(height);
        double boxes = 0.0, triangles = 0.0;
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                RayCost cost = nearestHitCost(bvh, c.primaryRay(x, y, width, height));
                boxes += cost.boxTests;
                triangles += cost.triangleTests;
            }
        double rays = double(width) * double(height);
        t.row({std::string(bvhBuilderName(builder)), (long long)rays, boxes / rays,
               triangles / rays});
        maps.emplace_back(builder, std::move(map));
    }
    report.add(t);
    double boxTop = 0.0, triangleTop = 0.0;  // one scale for every builder: they compare
    for (const auto& [_, map] : maps) {
        boxTop = std::max(boxTop, scaleTop(largest(map.boxTests)));
        triangleTop = std::max(triangleTop, scaleTop(largest(map.triangleTests)));
    }
    for (const auto& [builder, map] : maps) {
        std::string name = bvhBuilderName(builder);
        std::string file = pngWithSuffix(png, "-heat-" + name);
        costMapImage(map, name, boxTop, triangleTop).writePng(file);
        char caption[200];
        std::snprintf(caption, sizeof caption,
                      "%s hierarchy: box and triangle tests per pixel, log scales to %.0f and "
                      "%.0f (every builder alike); means per ray %.2f and %.2f",
                      name.c_str(), boxTop, triangleTop, map.boxTestsPerRay(),
                      map.triangleTestsPerRay());
        report.images.push_back({file, caption});
        report.facts["heat_box_tests_per_ray_" + name] = map.boxTestsPerRay();
        report.facts["heat_triangle_tests_per_ray_" + name] = map.triangleTestsPerRay();
    }
}

}  // namespace boxes
