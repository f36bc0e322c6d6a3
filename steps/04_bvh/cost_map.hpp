// What a ray costs in the hierarchy, as a picture: the boxes and triangles the nearest-hit
// traversal tests for each pixel's primary ray, per builder (a heat map, core/heatmap.hpp).
// Part of the program, not of the chapter: it counts with its own copy of the reference
// traversal, so the exercises' code stays as the student writes it.
#pragma once

#include <string>
#include <vector>

#include "04_bvh/bvh.hpp"
#include "core/image.hpp"
#include "core/render.hpp"
#include "core/report.hpp"
#include "core/scene.hpp"

namespace boxes {

struct RayCost {
    uint32_t boxTests = 0, triangleTests = 0;
};
// The tests of one ray's nearest hit in the reference traversal of exercise 4.4 (trace.cpp's
// nearestSlot): the root's box, both children of every inner node it enters, the triangles
// of every leaf it enters, nearer child first and every node beyond the nearest hit so far
// skipped.
RayCost nearestHitCost(const Bvh& bvh, const Ray& ray);

// The cost of each pixel's primary ray, rows top to bottom.
struct CostMap {
    int width = 0, height = 0;
    std::vector<double> boxTests, triangleTests;
    double boxTestsPerRay() const;
    double triangleTestsPerRay() const;
};
// A control stops it between rows.
CostMap primaryRayCosts(const Bvh& bvh, const Camera& camera, int width, int height,
                        int threads = 0, RenderControl* control = nullptr);

// Box tests (left) and triangle tests (right) per pixel, side by side, each with its colour
// bar and its mean per ray in its title; `tops` the scales' tops (0: the map's own).
Image costMapImage(const CostMap& costs, const std::string& builder, double boxTop = 0.0,
                   double triangleTop = 0.0);

// The window's heat map: the view's costs at the settings' size (a control stops it).
Image viewCostMap(const Bvh& bvh, const Camera& camera, const RenderSettings& settings,
                  BvhBuilder builder);

// --measure: per exercise builder the image's primary rays' tests per ray (table bvh_cost,
// the sums over the rays) and its heat maps beside `png` (PNG-heat-BUILDER.png, on one scale
// for every builder), with their means per ray as facts (the pixels' means, which must equal
// the table's counts).
void addCostMaps(Report& report, const Scene& scene, const std::string& png, int width, int height,
                 int bins, int threads);

}  // namespace boxes
