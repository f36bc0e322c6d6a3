// The lecture's figure of three levels of boxes (a red box around two blue ones, each
// around two green ones around the objects) as a fixed, hand-built tree, and one ray
// through it with exercise 4.4's traversal. The README's worked example
// (steps/04_bvh/README.md, "A worked example") is this test's scene and numbers.
#include <doctest/doctest.h>

#include <vector>

#include "step04_support.hpp"

using namespace boxes;
using namespace boxes::test04;

namespace {

// Every object is an upright triangle in the plane x = c, its base from (c, m - 1, -1) to
// (c, m + 1, -1), its apex (c, m, 1): its box is [c, c] x [m - 1, m + 1] x [-1, 1], and in
// the ray's plane z = 0 it covers y in [m - 1/2, m + 1/2].
struct Wall {
    float c, m;
};
// Slots 0-1 in G1, 2-3 in G2, 4-5 in G3, 6-7 in G4.
constexpr Wall kWalls[8] = {{2, 2}, {3, 4.5f}, {1, 5},    {2, 6.5f},
                            {6, 4}, {7, 2},    {9, 6.5f}, {10, 6}};

Mesh groupingMesh() {
    Mesh m;
    for (const Wall& w : kWalls) {
        uint32_t first = uint32_t(m.positions.size());
        m.positions.push_back(Vec3(w.c, w.m - 1, -1));
        m.positions.push_back(Vec3(w.c, w.m + 1, -1));
        m.positions.push_back(Vec3(w.c, w.m, 1));
        m.triangles.push_back({first, first + 1, first + 2});
    }
    return m;
}

// The tree, each node's box the union of its children's: R = node 0, its children B1 and B2
// (nodes 1, 2), B1's G1 and G2 (3, 4), B2's G3 and G4 (5, 6). z is [-1, 1] everywhere.
Bvh groupingTree(const Mesh& mesh) {
    Bvh bvh;
    auto box = [](float x0, float y0, float x1, float y1, uint32_t leftFirst, uint32_t count) {
        return BvhNode{Vec3(x0, y0, -1), leftFirst, Vec3(x1, y1, 1), count};
    };
    bvh.nodes = {box(1, 1, 10, 7.5f, 1, 0),   // R
                 box(1, 1, 3, 7.5f, 3, 0),    // B1
                 box(6, 1, 10, 7.5f, 5, 0),   // B2
                 box(2, 1, 3, 5.5f, 0, 2),    // G1: slots 0, 1
                 box(1, 4, 2, 7.5f, 2, 2),    // G2: slots 2, 3
                 box(6, 1, 7, 5, 4, 2),       // G3: slots 4, 5
                 box(9, 5, 10, 7.5f, 6, 2)};  // G4: slots 6, 7
    for (uint32_t i = 0; i < 8; ++i) bvh.primitiveIndices.push_back(i);
    fillLeafTriangles(bvh, mesh);
    return bvh;
}

}  // namespace

TEST_SUITE("exercise 4.4") {
    TEST_CASE("the lecture's three levels of boxes: what one ray visits and skips") {
        // The ray P(t) = (t, 1 + t/2, 0): at x = c it is at t = c, y = 1 + c/2.
        // Box by box (entry t = the larger of the x and y slabs' near distances):
        //   R   x [1, 10] y [1, 7.5]: entered at t = 1 (y = 1.5).        visited
        //   B1  x [1, 3]  y [1, 7.5]: entered at t = 1, left at t = 3.   visited first
        //   B2  x [6, 10] y [1, 7.5]: entered at t = 6.                  pushed for later
        //   G1  x [2, 3]  y [1, 5.5]: entered at t = 2.                  its 2 objects tested
        //   G2  x [1, 2]  y [4, 7.5]: x gives t in [1, 2], y >= 4 needs t >= 6: missed,
        //       its 2 objects never tested.
        //   G1's objects: (2, 2) at t = 2, y = 2, |2 - 2| <= 1/2: hit; (3, 4.5) at y = 2.5,
        //       |2.5 - 4.5| > 1/2: missed.  Nearest hit so far: t = 2.
        //   B2 popped: entered at t = 6 > 2, skipped, G3 and G4 never tested, though the
        //       ray enters both (t = 6 and t = 9) and hits an object in each ((6, 4) at
        //       t = 6, (10, 6) at t = 10). A traversal without this check at the pop
        //       still tests none of their objects (G3's and G4's boxes, tested against
        //       t = 2, are missed): only one that tests boxes against the ray's own tmax,
        //       or visits B2 first, tests the four objects, and fails below.
        // So the traversal tests 2 of the 8 objects and returns slot 0 at t = 2.
        Mesh mesh = groupingMesh();
        Bvh bvh = groupingTree(mesh);
        checkStructure(bvh, triangleBounds(mesh));  // a valid hierarchy, as a builder's

        Ray ray(Vec3(0, 1, 0), Vec3(1, 0.5f, 0));
        TraversalRay r(ray);
        enum { R, B1, B2, G1, G2, G3, G4 };
        const float entry[7] = {1, 1, 6, 2, -1, 6, 9};  // -1: missed
        for (int node = R; node <= G4; ++node) {
            CAPTURE(node);
            float tEntry = -1;
            bool hit = intersectNodeBounds(bvh.nodes[size_t(node)], r, ray.tmax, tEntry);
            CHECK(hit == (entry[node] >= 0));
            if (hit) CHECK(tEntry == entry[node]);
        }
        // After the hit at t = 2, B2's box no longer passes the test.
        float tEntry;
        CHECK_FALSE(intersectNodeBounds(bvh.nodes[B2], r, 2.0f, tEntry));

        double tBest = kInfinity<double>;
        auto leafTest = referenceLeafTest(bvh, ray, tBest);
        std::vector<uint32_t> tested;
        float tClosest = ray.tmax;
        uint32_t slot = traverseNearest(bvh, r, tClosest, [&](uint32_t s, float& tmax) {
            tested.push_back(s);
            return leafTest(s, tmax);
        });
        CHECK(tested == std::vector<uint32_t>{0, 1});
        CHECK(slot == 0);
        CHECK(tClosest == 2.0f);

        // Brute force agrees, and the objects of the skipped B2 are hit, only farther.
        double tBrute;
        CHECK(bruteWithReference(mesh, ray, tBrute) == 0);
        CHECK(tBrute == 2.0);
        std::vector<double> hits;
        for (uint32_t s = 0; s < 8; ++s) {
            double t;
            if (referenceTriangle(ray, bvh.leafTriangles[s], t)) hits.push_back(t);
        }
        CHECK(hits == std::vector<double>{2.0, 6.0, 10.0});
    }
}
