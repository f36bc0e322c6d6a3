// Step 04's exercises on generated inputs (harness.hpp says how).
#pragma once

#include <algorithm>
#include <bit>
#include <numeric>

#include "04_bvh/bvh.hpp"
#include "04_bvh/frustum.hpp"
#include "04_bvh/traverse.hpp"
#include "differential/step03.hpp"

namespace boxes::differential {

// ---- 4.1 to 4.3: split rules -------------------------------------------------------------------

// A node's primitives (at most 40: their left side fits one exact number) and, for the SAH,
// its options.
struct SplitInput {
    std::vector<Bounds3f> boxes;
    int bins = 16;
    float traversalCost = 1.0f, intersectionCost = 0.5f;
};

inline std::vector<BuildPrimitive> buildPrimitives(const SplitInput& in) {
    std::vector<BuildPrimitive> prims;
    for (size_t i = 0; i < in.boxes.size(); ++i)
        prims.push_back({in.boxes[i], in.boxes[i].centroid(), uint32_t(i)});
    return prims;
}
// The same two helpers as tests/step04_support.hpp: these headers build without doctest and
// the tests' support, for the data generator (generate.cpp) as well as the tests.
inline Bounds3f centroidBoundsOf(const std::vector<BuildPrimitive>& prims) {
    Bounds3f b;
    for (const auto& p : prims) b.extend(p.centroid);
    return b;
}
inline Bounds3f boundsOf(const std::vector<BuildPrimitive>& prims) {
    Bounds3f b;
    for (const auto& p : prims) {
        b.extend(p.bounds.min);
        b.extend(p.bounds.max);
    }
    return b;
}

// Exact: centroids on the integer grid, the three extents different (so the longest axis is
// one), many equal centroids, some exactly at the middle, sometimes all equal. Random: boxes
// at a scale, the longest axis any of the three.
inline Case<SplitInput> splitCase(Rng& rng, int index) {
    SplitInput in;
    int n = rng.chance(15) ? rng.range(2, 3) : rng.range(4, 40);
    in.bins = rng.pick({2, 3, 4, 8, 16, 32});
    in.traversalCost = float(rng.pick({1.0, 0.5, 2.0}));
    in.intersectionCost = float(rng.pick({0.5, 1.0, 0.25}));
    if (index % 2 == 0) {
        int extents[3] = {8, 4, 2};
        int order = rng.below(6);
        for (int i = 0; i < order; ++i) std::next_permutation(extents, extents + 3);
        const char* family = "centroids on the grid";
        bool allEqual = rng.chance(8);
        bool coarse = rng.chance(40);  // few distinct values: ties, centroids at the middle
        for (int i = 0; i < n; ++i) {
            Vec3 c;
            for (int k = 0; k < 3; ++k) {
                int v =
                    coarse ? rng.pick({0, extents[k] / 2, extents[k]}) : rng.range(0, extents[k]);
                // The extremes present on every axis: the extents are as chosen.
                if (i == 0) v = 0;
                if (i == 1) v = extents[k];
                c[k] = float(allEqual ? 3 : v);
            }
            Vec3 half(float(rng.grid(0, 2, 1)), float(rng.grid(0, 2, 1)), float(rng.grid(0, 2, 1)));
            in.boxes.push_back({c - half, c + half});
        }
        if (allEqual)
            family = "identical centroids";
        else if (coarse)
            family = "centroids at the ends and exactly at the middle";
        return {in, family, true};
    }
    double scale = rng.logUniform(-6, 6);
    Vec3d stretch(rng.logUniform(-2, 2), rng.logUniform(-2, 2), rng.logUniform(-2, 2));
    const char* family = "random boxes";
    for (int i = 0; i < n; ++i) {
        Vec3d c = rng.inCube(1.0) * stretch * scale;
        Vec3d half = Vec3d(rng.unit(), rng.unit(), rng.unit()) * scale * rng.uniform(0.0, 0.5);
        if (rng.chance(5)) half = Vec3d(0.0);
        in.boxes.push_back({Vec3(c - half), Vec3(c + half)});
    }
    if (rng.chance(10)) {
        // Flat: every box in one plane (the node has no volume, but an area).
        int axis = rng.below(3);
        for (auto& b : in.boxes) b.min[axis] = b.max[axis] = 0.0f;
        family = "boxes in one plane";
    }
    return {in, family, false};
}

inline std::string givenSplit(const SplitInput& in, bool sah) {
    std::string s = std::to_string(in.boxes.size()) + " primitives with bounds";
    for (size_t i = 0; i < in.boxes.size(); ++i)
        s += (i ? ", " : " ") + std::to_string(i) + ": " + differential::given(in.boxes[i]);
    if (sah)
        s += "; " + std::to_string(in.bins) + " bins, traversal cost " + num(in.traversalCost) +
             ", intersection cost " + num(in.intersectionCost);
    return s;
}

inline void perturbSplit(SplitInput& in, Rng& rng) {
    for (auto& b : in.boxes) {
        differential::perturb(b, rng);
        b.min = glm::min(b.min, b.max);
    }
}

// What a split rule did: the count it returned, the primitives (by index) in the left part
// as the bits of one number, and whether the span still holds each primitive once.
inline Record splitRecord(const std::vector<BuildPrimitive>& after, size_t left, size_t n) {
    double mask = 0.0;
    std::vector<int> seen(n, 0);
    bool permutation = after.size() == n;
    for (size_t i = 0; i < after.size(); ++i) {
        if (after[i].index >= n || seen[after[i].index]++) {
            permutation = false;
            continue;
        }
        if (i < left) mask += std::ldexp(1.0, int(after[i].index));
    }
    return Record().i(int64_t(left)).i(int64_t(mask)).i(permutation);
}

inline std::vector<int> leftSet(double mask, size_t n) {
    std::vector<int> out;
    for (size_t i = 0; i < n; ++i)
        if (std::fmod(std::floor(mask / std::ldexp(1.0, int(i))), 2.0) == 1.0)
            out.push_back(int(i));
    return out;
}

inline std::string showSplit(const Record& r, size_t offset, size_t n) {
    if (r.size() != offset + 3) return "the numbers " + serialize(r);
    if (r[offset + 2] != 1.0) return "a span that no longer holds each primitive once";
    std::string s = num(int64_t(r[offset])) + " on the left:";
    for (int i : leftSet(r[offset + 1], n)) s += " " + std::to_string(i);
    return s;
}

inline bool inLeft(double mask, size_t i) {
    return std::fmod(std::floor(mask / std::ldexp(1.0, int(i))), 2.0) == 1.0;
}

// The longest axis of the centroid bounds (the inputs have no ties) and its middle.
inline int longestAxis(const Bounds3f& b) {
    Vec3 d = b.diagonal();
    return d.x >= d.y && d.x >= d.z ? 0 : d.y >= d.z ? 1 : 2;
}

struct MidpointSpec {
    static constexpr const char* name = "4.1";
    static constexpr const char* exercise = "4.1";
    static constexpr int count = 1500;
    using Input = SplitInput;
    static Case<Input> make(Rng& rng, int index) { return splitCase(rng, index); }
    static Record run(const Input& in) {
        auto prims = buildPrimitives(in);
        size_t left = partitionMidpoint(prims, centroidBoundsOf(prims));
        return splitRecord(prims, left, in.boxes.size());
    }
    // A centroid exactly at the middle may go either way (the README does not say), and
    // 0 and n both say "no useful split".
    static std::string compare(const Input& in, const Record& got, const Record& expected, int) {
        std::string why =
            compareRecords(got, expected, 0, {"the count", "the left side", "the span"});
        if (why.empty() || got.size() != 3 || expected.size() != 3 || got[2] != 1.0) return why;
        size_t n = in.boxes.size();
        auto noSplit = [&](double c) { return c == 0.0 || c == double(n); };
        if (noSplit(got[0]) && noSplit(expected[0])) return "";
        auto prims = buildPrimitives(in);
        Bounds3f cb = centroidBoundsOf(prims);
        int axis = longestAxis(cb);
        float middle = cb.centroid()[axis];
        for (size_t i = 0; i < n; ++i)
            if (prims[i].centroid[axis] != middle && inLeft(got[1], i) != inLeft(expected[1], i))
                return "primitive " + std::to_string(i) + " is on the wrong side of the middle " +
                       num(middle) + " of axis " + "xyz"[axis];
        return "";
    }
    static std::string given(const Input& in) { return givenSplit(in, false); }
    static std::string show(const Record& r) { return showSplit(r, 0, 40); }
    static void perturb(Input& in, Rng& rng) { perturbSplit(in, rng); }
};

struct MedianSpec {
    static constexpr const char* name = "4.2";
    static constexpr const char* exercise = "4.2";
    static constexpr int count = 1500;
    using Input = SplitInput;
    static Case<Input> make(Rng& rng, int index) { return splitCase(rng, index); }
    static Record run(const Input& in) {
        auto prims = buildPrimitives(in);
        size_t left = partitionMedian(prims, centroidBoundsOf(prims));
        return splitRecord(prims, left, in.boxes.size());
    }
    // Equal centroids at the median may go either way, and for an odd count either half
    // may get the extra one: the left side must hold count primitives no further along the
    // longest axis than any on the right.
    static std::string compare(const Input& in, const Record& got, const Record& expected, int) {
        std::string why =
            compareRecords(got, expected, 0, {"the count", "the left side", "the span"});
        if (why.empty() || got.size() != 3 || expected.size() != 3 || got[2] != 1.0) return why;
        size_t n = in.boxes.size();
        if (got[0] != double(n / 2) && got[0] != double((n + 1) / 2))
            return "the count is not half";
        auto prims = buildPrimitives(in);
        int axis = longestAxis(centroidBoundsOf(prims));
        float leftMax = -kInfinity<float>, rightMin = kInfinity<float>;
        for (size_t i = 0; i < n; ++i) {
            float key = prims[i].centroid[axis];
            if (inLeft(got[1], i))
                leftMax = std::max(leftMax, key);
            else
                rightMin = std::min(rightMin, key);
        }
        if (leftMax <= rightMin) return "";
        return std::string("a centroid on the left lies beyond one on the right along axis ") +
               "xyz"[axis];
    }
    static std::string given(const Input& in) { return givenSplit(in, false); }
    static std::string show(const Record& r) { return showSplit(r, 0, 40); }
    static void perturb(Input& in, Rng& rng) { perturbSplit(in, rng); }
};

struct BinnedSahSpec {
    static constexpr const char* name = "4.3";
    static constexpr const char* exercise = "4.3";
    static constexpr int count = 1500;
    using Input = SplitInput;
    static Case<Input> make(Rng& rng, int index) { return splitCase(rng, index); }
    static BvhBuildOptions options(const Input& in) {
        BvhBuildOptions o;
        o.builder = BvhBuilder::BinnedSah;
        o.bins = in.bins;
        o.traversalCost = in.traversalCost;
        o.intersectionCost = in.intersectionCost;
        return o;
    }
    static Record run(const Input& in) {
        auto prims = buildPrimitives(in);
        float cost = -1.0f;
        size_t left =
            partitionBinnedSah(prims, boundsOf(prims), centroidBoundsOf(prims), options(in), cost);
        Record r;
        r.f(cost, 0x1p-17);
        Record s = splitRecord(prims, left, in.boxes.size());
        r.values.insert(r.values.end(), s.values.begin(), s.values.end());
        return r;
    }
    // The SAH cost of a partition by `mask`, in double.
    static double sahCost(const Input& in, double mask) {
        auto prims = buildPrimitives(in);
        Bounds3d l, r;
        double nl = 0, nr = 0;
        for (size_t i = 0; i < prims.size(); ++i) {
            Bounds3d& side = inLeft(mask, i) ? l : r;
            side.extend(Vec3d(prims[i].bounds.min));
            side.extend(Vec3d(prims[i].bounds.max));
            (inLeft(mask, i) ? nl : nr) += 1.0;
        }
        double node = double(boundsOf(prims).surfaceArea());
        return double(in.traversalCost) +
               double(in.intersectionCost) * (l.surfaceArea() * nl + r.surfaceArea() * nr) / node;
    }
    // Two planes can price the same (a symmetric node): another partition is as good when it
    // is a plane's (its centroids separable along an axis) and its SAH cost is the same.
    static std::string compare(const Input& in, const Record& got, const Record& expected,
                               int scale) {
        std::string why = compareRecords(got, expected, scale,
                                         {"the cost", "the count", "the left side", "the span"});
        if (why.empty() || got.size() != 4 || expected.size() != 4 || got[3] != 1.0 ||
            !valueMatches(got.values[0], expected[0], scale) || !std::isfinite(expected[0]))
            return why;
        size_t n = in.boxes.size();
        if (got[1] <= 0.0 || got[1] >= double(n)) return why;
        auto prims = buildPrimitives(in);
        bool separable = false;
        for (int axis = 0; axis < 3 && !separable; ++axis) {
            float leftMax = -kInfinity<float>, rightMin = kInfinity<float>;
            for (size_t i = 0; i < n; ++i) {
                float key = prims[i].centroid[axis];
                if (inLeft(got[2], i))
                    leftMax = std::max(leftMax, key);
                else
                    rightMin = std::min(rightMin, key);
            }
            separable = leftMax < rightMin;
        }
        double mine = sahCost(in, got[2]);
        if (separable &&
            std::fabs(mine - expected[0]) <= std::ldexp(0x1p-17 * std::fabs(expected[0]), scale))
            return "";
        return separable ? why + "; its partition costs " + num(mine) + ", not the cost found"
                         : why + "; its partition is not a plane's";
    }
    static std::string given(const Input& in) { return givenSplit(in, true); }
    static std::string show(const Record& r) {
        if (r.size() != 4) return "the numbers " + serialize(r);
        return "cost " + num(float(r[0])) + ", " + showSplit(r, 1, 40);
    }
    static void perturb(Input& in, Rng& rng) { perturbSplit(in, rng); }
};

// ---- 4.4 and 4.5: traversals -----------------------------------------------------------------

struct TraversalInput {
    std::vector<Triangle> triangles;
    RayInput<float> ray;
    float tClosest = kInfinity<float>;  // 4.4: what the caller hands in
    int leafSize = 2;
};

// The tree, built here with a split rule of the test's own (the object median by sorting,
// along the longest centroid axis): the traversal is tested on its own, whatever the
// student's builders do.
inline size_t testSplit(std::span<BuildPrimitive> prims, const Bounds3f&, const Bounds3f& centroids,
                        const BvhBuildOptions&, float&) {
    Vec3 d = centroids.diagonal();
    int axis = d.x >= d.y && d.x >= d.z ? 0 : d.y >= d.z ? 1 : 2;
    std::sort(prims.begin(), prims.end(), [&](const BuildPrimitive& a, const BuildPrimitive& b) {
        return a.centroid[axis] < b.centroid[axis] ||
               (a.centroid[axis] == b.centroid[axis] && a.index < b.index);
    });
    return prims.size() / 2;
}

inline Bvh testTree(const TraversalInput& in) {
    std::vector<Bounds3f> bounds;
    for (const auto& t : in.triangles) {
        Bounds3f b;
        for (const Vec3& v : {t.a, t.b, t.c}) b.extend(v);
        bounds.push_back(b);
    }
    BvhBuildOptions o;
    o.leafSize = in.leafSize;
    return buildBvh(bounds, SplitRule{testSplit, false}, o);
}

// The test's own triangle test (Moller-Trumbore in double, its t rounded to float): a hit
// in [tmin, tmax].
inline std::optional<float> triangleDistance(const RayInput<float>& r, const Triangle& tri,
                                             float tmax) {
    Vec3d o(r.origin), d(r.direction), a(tri.a), e1 = Vec3d(tri.b) - a, e2 = Vec3d(tri.c) - a;
    Vec3d p = glm::cross(d, e2);
    double det = glm::dot(e1, p);
    if (det == 0.0 || !std::isfinite(det)) return std::nullopt;
    Vec3d s = o - a;
    double u = glm::dot(s, p) / det;
    if (!(u >= 0.0 && u <= 1.0)) return std::nullopt;
    Vec3d q = glm::cross(s, e1);
    double v = glm::dot(d, q) / det;
    if (!(v >= 0.0 && u + v <= 1.0)) return std::nullopt;
    float t = float(glm::dot(e2, q) / det);
    if (!(t >= r.tmin && t <= tmax)) return std::nullopt;
    return t;
}

// The leaf that holds each slot.
inline std::vector<uint32_t> leafOfSlot(const Bvh& bvh) {
    std::vector<uint32_t> leaf(bvh.primitiveIndices.size(), 0);
    for (uint32_t i = 0; i < bvh.nodes.size(); ++i)
        if (bvh.nodes[i].isLeaf())
            for (uint32_t s = bvh.nodes[i].leftFirst;
                 s < bvh.nodes[i].leftFirst + bvh.nodes[i].count; ++s)
                leaf[s] = i;
    return leaf;
}

// Exact: unit right triangles on the grid in planes across an axis-parallel ray (shared
// edges and vertices, several at the same distance, origins on slab planes), t at tmin
// or tmax. Random: a soup of triangles and a ray from anywhere.
inline Case<TraversalInput> traversalCase(Rng& rng, int index) {
    TraversalInput in;
    in.leafSize = rng.range(1, 4);
    int n = rng.range(1, 32);
    if (index % 2 == 0) {
        AxisMap m = AxisMap::random(rng);
        for (int i = 0; i < n; ++i) {
            double z = rng.range(-4, 4);
            double x = rng.range(-3, 2), y = rng.range(-3, 2);
            double leg = rng.pick({1.0, 2.0});
            Vec3d a(x, y, z), b(x + leg, y, z), c(x, y + leg, z);
            if (rng.chance(50)) a = Vec3d(x + leg, y + leg, z);  // the square's other half
            in.triangles.push_back({Vec3(m.apply(a)), Vec3(m.apply(b)), Vec3(m.apply(c))});
        }
        // Aimed at a vertex, an edge's midpoint or the inside of one of the triangles (before
        // the map: their planes are across z), from either side.
        const Triangle& aim = in.triangles[size_t(rng.below(n))];
        Vec3d a = m.invert(Vec3d(aim.a)), b = m.invert(Vec3d(aim.b)), c = m.invert(Vec3d(aim.c));
        double wb = rng.pick({0.0, 0.5, 0.25}), wc = rng.pick({0.0, 0.5, 0.25});
        Vec3d p = a + wb * (b - a) + wc * (c - a);
        double side = rng.chance(50) ? 1.0 : -1.0;
        double distance = rng.range(0, 6);
        Vec3d o(p.x, p.y, p.z - side * distance);
        Vec3d d(signedZero(rng), signedZero(rng), side);
        if (rng.chance(20)) {
            o = Vec3d(rng.grid(-3, 3, 1), rng.grid(-3, 3, 1), rng.range(-6, 6));
            d = Vec3d(rng.pick({0.25, -0.25, 0.0}), rng.pick({0.25, 0.0}), side);
        }
        in.ray.origin = Vec3(m.apply(o));
        in.ray.direction = Vec3(m.apply(d));
        const char* family = "triangles on the grid and an axis-parallel ray";
        int kind = rng.below(5);
        if (kind == 0) {
            in.ray.tmin = float(distance);
            family = "t exactly at tmin (triangles on the grid)";
        } else if (kind == 1) {
            in.ray.tmax = float(distance);
            family = "t exactly at tmax (triangles on the grid)";
        }
        if (rng.chance(40)) in.tClosest = float(rng.range(0, 8));
        return {in, family, true};
    }
    double scale = rng.logUniform(-4, 4);
    for (int i = 0; i < n; ++i) {
        Vec3d c = rng.inCube(3.0) * scale;
        double size = rng.uniform(0.05, 1.0) * scale;
        in.triangles.push_back(
            {Vec3(c + rng.inCube(size)), Vec3(c + rng.inCube(size)), Vec3(c + rng.inCube(size))});
    }
    // Mostly aimed at a point of one of the triangles.
    Vec3d target = rng.inCube(3.0) * scale;
    if (rng.chance(80)) {
        const Triangle& aim = in.triangles[size_t(rng.below(n))];
        double u = rng.unit(), v = rng.unit() * (1.0 - u);
        target =
            Vec3d(aim.a) + u * (Vec3d(aim.b) - Vec3d(aim.a)) + v * (Vec3d(aim.c) - Vec3d(aim.a));
    }
    Vec3d d = rng.direction();
    double t = rng.uniform(-1.0, 8.0) * scale;
    in.ray.origin = Vec3(target - t * d);
    in.ray.direction = Vec3(d);
    if (rng.chance(20)) {
        in.ray.tmin = float(rng.uniform(0.0, 4.0) * scale);
        in.ray.tmax = float(double(in.ray.tmin) + rng.uniform(0.0, 6.0) * scale);
    }
    if (rng.chance(40)) in.tClosest = float(rng.uniform(0.0, 10.0) * scale);
    return {in, "a random triangle soup", false};
}

inline std::string givenTraversal(const TraversalInput& in, bool closest) {
    std::string s = differential::given(in.ray);
    if (closest) s += ", tClosest handed in " + num(in.tClosest);
    s += "; " + std::to_string(in.triangles.size()) + " triangles (leaves of up to " +
         std::to_string(in.leafSize) + ")";
    for (size_t i = 0; i < in.triangles.size(); ++i)
        s += (i ? ", " : ": ") + std::to_string(i) + " = " + vec(in.triangles[i].a) + " " +
             vec(in.triangles[i].b) + " " + vec(in.triangles[i].c);
    return s;
}

inline void perturbTraversal(TraversalInput& in, Rng& rng) {
    perturb(in.ray, rng);
    for (auto& t : in.triangles) {
        t.a = nudge(t.a, rng);
        t.b = nudge(t.b, rng);
        t.c = nudge(t.c, rng);
    }
}

struct NearestHitSpec {
    static constexpr const char* name = "4.4";
    static constexpr const char* exercise = "4.4";
    static constexpr int count = 1500;
    using Input = TraversalInput;
    static Case<Input> make(Rng& rng, int index) { return traversalCase(rng, index); }
    // The triangle found (-1: none), tClosest after the call, and the leaves opened although
    // the ray enters them beyond the nearest hit known then (none: early out).
    static Record run(const Input& in) {
        Bvh bvh = testTree(in);
        Ray ray = in.ray.ray();
        TraversalRay tr(ray, bvh);
        auto leaf = leafOfSlot(bvh);
        int64_t late = 0;
        uint32_t lastLeaf = ~0u;
        float tClosest = in.tClosest;
        uint32_t slot = traverseNearest(bvh, tr, tClosest, [&](uint32_t s, float& tBest) {
            if (s >= leaf.size()) return false;
            if (leaf[s] != lastLeaf) {
                lastLeaf = leaf[s];
                float entry;
                if (!intersectNodeBounds(bvh.nodes[leaf[s]], tr, tBest, entry)) ++late;
            }
            auto t = triangleDistance(in.ray, in.triangles[bvh.primitiveIndices[s]], tBest);
            if (!t) return false;
            tBest = *t;
            return true;
        });
        int64_t found = slot == kTraversalMiss || slot >= bvh.primitiveIndices.size()
                            ? -1
                            : int64_t(bvh.primitiveIndices[slot]);
        return Record().i(found).f(tClosest).i(late);
    }
    // Two triangles can be hit at the same t (a shared edge): either is the nearest.
    static std::string compare(const Input& in, const Record& got, const Record& expected,
                               int scale) {
        std::string why = compareRecords(got, expected, scale,
                                         {"the triangle", "tClosest", "the leaves opened late"});
        if (why.empty() || got.size() != 3 || expected.size() != 3 || got[0] == expected[0] ||
            got[0] < 0 || got[0] >= double(in.triangles.size()) || got[1] != expected[1] ||
            got[2] != 0.0)
            return why;
        auto t = triangleDistance(in.ray, in.triangles[size_t(got[0])], float(got[1]));
        return t && *t == float(got[1]) ? "" : why;
    }
    static std::string given(const Input& in) { return givenTraversal(in, true); }
    static std::string show(const Record& r) {
        if (r.size() != 3) return "the numbers " + serialize(r);
        std::string s =
            r[0] < 0 ? "no hit, tClosest " + num(float(r[1]))
                     : "triangle " + num(int64_t(r[0])) + " at tClosest = " + num(float(r[1]));
        if (r[2] > 0)
            s += ", " + num(int64_t(r[2])) + " leaves opened beyond the nearest hit known then";
        return s;
    }
    static void perturb(Input& in, Rng& rng) { perturbTraversal(in, rng); }
};

struct AnyHitSpec {
    static constexpr const char* name = "4.5";
    static constexpr const char* exercise = "4.5";
    static constexpr int count = 1500;
    using Input = TraversalInput;
    static Case<Input> make(Rng& rng, int index) { return traversalCase(rng, index); }
    // The answer, the primitive tests after the first hit (none: it stops), and the leaves
    // opened that the ray does not enter in [tmin, tmax].
    static Record run(const Input& in) {
        Bvh bvh = testTree(in);
        Ray ray = in.ray.ray();
        TraversalRay tr(ray, bvh);
        auto leaf = leafOfSlot(bvh);
        int64_t afterHit = 0, outside = 0;
        bool hitSeen = false;
        uint32_t lastLeaf = ~0u;
        bool hit = traverseAny(bvh, tr, [&](uint32_t s, float tmax) {
            if (s >= leaf.size()) return false;
            if (hitSeen) ++afterHit;
            if (leaf[s] != lastLeaf) {
                lastLeaf = leaf[s];
                float entry;
                if (!intersectNodeBounds(bvh.nodes[leaf[s]], tr, ray.tmax, entry)) ++outside;
            }
            bool h =
                triangleDistance(in.ray, in.triangles[bvh.primitiveIndices[s]], tmax).has_value();
            hitSeen = hitSeen || h;
            return h;
        });
        return Record().i(hit).i(afterHit).i(outside);
    }
    static std::string given(const Input& in) { return givenTraversal(in, false); }
    static std::string show(const Record& r) {
        if (r.size() != 3) return "the numbers " + serialize(r);
        std::string s = r[0] ? "blocked (true)" : "not blocked (false)";
        if (r[1] > 0) s += ", " + num(int64_t(r[1])) + " triangles tested after a hit";
        if (r[2] > 0)
            s += ", " + num(int64_t(r[2])) +
                 " leaves opened that the ray does not enter in [tmin, tmax]";
        return s;
    }
    static void perturb(Input& in, Rng& rng) { perturbTraversal(in, rng); }
};

// ---- 4.6 to 4.8: the frustum ---------------------------------------------------------------

struct FrustumInput {
    Camera camera;
    float nearDistance = 0.1f, farDistance = 10.0f;
};

struct MakeFrustumSpec {
    static constexpr const char* name = "4.6";
    static constexpr const char* exercise = "4.6";
    static constexpr int count = 160;
    using Input = FrustumInput;
    static Case<Input> make(Rng& rng, int) {
        Input in;
        double scale = rng.logUniform(-3, 3);
        in.camera.eye = Vec3(rng.inCube(4.0) * scale);
        in.camera.view = Vec3(rng.direction() * rng.logUniform(-2, 2));
        in.camera.up = Vec3(rng.direction());
        const char* family = "a random camera";
        int kind = rng.below(10);
        if (kind == 0) {
            in.camera.up = in.camera.view * float(rng.pick({1.0, -2.0}));
            family = "a view parallel to up";
        } else if (kind == 1) {
            Vec3 v(0.0f);
            v[rng.below(3)] = rng.chance(50) ? 1.0f : -1.0f;
            in.camera.view = v;
            in.camera.up = Vec3(0, 1, 0);
            family = "a view along an axis";
        }
        in.camera.fovYDegrees = float(rng.uniform(1.0, 170.0));
        in.camera.aspect = float(rng.logUniform(-2, 1));
        in.nearDistance = float(rng.logUniform(-6, 0) * scale);
        in.farDistance = in.nearDistance * float(rng.logUniform(0, 10));
        if (kind == 2) {
            in.nearDistance = float(rng.pick({0.0, -1.0}));
            family = "near <= 0 (refused)";
        } else if (kind == 3) {
            in.farDistance = in.nearDistance * float(rng.pick({1.0, 0.5}));
            family = "far <= near (refused)";
        } else if (kind == 4 && rng.chance(50)) {
            in.farDistance = kInfinity<float>;
            family = "far = infinity (refused)";
        }
        return {in, family, false};
    }
    static Record run(const Input& in) {
        Frustum f = makeFrustum(in.camera, in.nearDistance, in.farDistance);
        double size =
            sceneSize<float>({in.camera.eye}) +
            double(in.farDistance) * (1.0 + std::tan(double(in.camera.fovYDegrees) * M_PI / 360.0) *
                                                (1.0 + double(in.camera.aspect)));
        Record r;
        for (const auto& p : f.planes) r.v3(p.normal, 0.0, 0x1p-16).f(p.d, 0.0, 0x1p-16 * size);
        for (const auto& c : f.corners) r.v3(c, 0.0, 0x1p-16 * size);
        return r;
    }
    static std::string given(const Input& in) {
        return "camera eye " + vec(in.camera.eye) + ", view " + vec(in.camera.view) + ", up " +
               vec(in.camera.up) + ", fov " + num(in.camera.fovYDegrees) + " degrees, aspect " +
               num(in.camera.aspect) + "; near " + num(in.nearDistance) + ", far " +
               num(in.farDistance);
    }
    static std::string show(const Record& r) {
        if (r.size() != 48) return "the numbers " + serialize(r);
        static constexpr const char* planes[6] = {"left", "right", "bottom", "top", "near", "far"};
        std::string s;
        for (int p = 0; p < 6; ++p)
            s += std::string(planes[p]) + " N = (" + num(float(r[size_t(4 * p)])) + ", " +
                 num(float(r[size_t(4 * p + 1)])) + ", " + num(float(r[size_t(4 * p + 2)])) +
                 "), d = " + num(float(r[size_t(4 * p + 3)])) + "; ";
        s += "corners";
        for (int c = 0; c < 8; ++c)
            s += " (" + num(float(r[size_t(24 + 3 * c)])) + ", " +
                 num(float(r[size_t(25 + 3 * c)])) + ", " + num(float(r[size_t(26 + 3 * c)])) + ")";
        return s;
    }
    static void perturb(Input& in, Rng& rng) {
        in.camera.eye = nudge(in.camera.eye, rng);
        in.camera.view = nudge(in.camera.view, rng);
        in.camera.up = nudge(in.camera.up, rng);
        in.camera.fovYDegrees = nudge(in.camera.fovYDegrees, rng);
        in.camera.aspect = nudge(in.camera.aspect, rng);
        in.nearDistance = nudge(in.nearDistance, rng);
        in.farDistance = nudge(in.farDistance, rng);
    }
};

struct CullInput {
    Frustum frustum;
    Bounds3f box;
};

// Exact: axis-aligned planes (normals with zeros of either sign) and corners on the grid,
// boxes touching them; random: planes and corners around a box at a scale.
inline Case<CullInput> cullCase(Rng& rng, int index) {
    CullInput in;
    Vec3 lo(float(rng.range(-3, 2)), float(rng.range(-3, 2)), float(rng.range(-3, 2)));
    in.box = {lo,
              lo + Vec3(float(rng.range(0, 3)), float(rng.range(0, 3)), float(rng.range(0, 3)))};
    if (index % 2 == 0) {
        // Each plane across an axis, either way, its boundary one before the box's p-vertex
        // (kept), at it (touching: kept) or one beyond (culled).
        for (auto& p : in.frustum.planes) {
            int axis = rng.below(3);
            float sign = rng.chance(50) ? 1.0f : -1.0f;
            Vec3 n(float(signedZero(rng)), float(signedZero(rng)), float(signedZero(rng)));
            n[axis] = sign;
            float pVertex = sign > 0 ? in.box.max[axis] : in.box.min[axis];
            float boundary = pVertex - sign * float(rng.pick({2, 1, 0, 0, 0, 0, 0, 0, 0, -1}));
            p.normal = n;
            p.d =
                -sign * boundary;  // inside: sign * x + d >= 0, that is sign * x >= sign * boundary
        }
        for (auto& c : in.frustum.corners) {
            for (int k = 0; k < 3; ++k) {
                int where = rng.below(4);
                c[k] = where == 0   ? in.box.min[k]
                       : where == 1 ? in.box.max[k]
                                    : float(rng.range(-6, 6));
            }
        }
        return {in, "planes and corners on the grid, boxes touching them", true};
    }
    double scale = rng.logUniform(-4, 4);
    in.box = {Vec3(rng.inCube(1.0) * scale), Vec3(0.0f)};
    in.box.max = in.box.min + Vec3(rng.unit(), rng.unit(), rng.unit()) * float(scale);
    // Planes facing a point near the box (the point inside them all), at random distances.
    Vec3d centre = Vec3d(in.box.centroid()) + rng.inCube(1.0) * scale;
    for (auto& p : in.frustum.planes) {
        Vec3d n = rng.direction();
        double distance = rng.uniform(-0.3, 2.0) * scale;
        p.normal = Vec3(n);
        p.d = float(distance - glm::dot(n, centre));
    }
    Vec3d shift = rng.inCube(2.0) * scale;
    for (auto& c : in.frustum.corners) c = Vec3(centre + shift + rng.inCube(1.5) * scale);
    return {in, "random planes and corners around a box", false};
}

template <int Exercise>
struct CullSpec {
    static constexpr const char* name = Exercise == 7 ? "4.7" : "4.8";
    static constexpr const char* exercise = Exercise == 7 ? "4.7" : "4.8";
    static constexpr int count = 2000;
    using Input = CullInput;
    static Case<Input> make(Rng& rng, int index) { return cullCase(rng, index); }
    static Record run(const Input& in) {
        return Record().i(Exercise == 7 ? cullByPlanes(in.frustum, in.box)
                                        : cullByBoxPlanes(in.frustum, in.box));
    }
    static std::string given(const Input& in) {
        std::string s = "box " + differential::given(in.box) + "; ";
        if (Exercise == 7) {
            s += "planes (normals inside: N.P + d >= 0)";
            for (const auto& p : in.frustum.planes)
                s += " N = " + vec(p.normal) + ", d = " + num(p.d) + ";";
        } else {
            s += "frustum corners";
            for (const auto& c : in.frustum.corners) s += " " + vec(c);
        }
        return s;
    }
    static std::string show(const Record& r) {
        if (r.size() != 1) return "the numbers " + serialize(r);
        return r[0] ? "culled (true)" : "kept (false)";
    }
    static void perturb(Input& in, Rng& rng) {
        differential::perturb(in.box, rng);
        for (auto& p : in.frustum.planes) {
            p.normal = nudge(p.normal, rng);
            p.d = nudge(p.d, rng);
        }
        for (auto& c : in.frustum.corners) c = nudge(c, rng);
    }
};

using CullByPlanesSpec = CullSpec<7>;
using CullByBoxPlanesSpec = CullSpec<8>;
#define BOXES_DIFFERENTIAL_STEP04(X) \
    X(MidpointSpec)                  \
    X(MedianSpec)                    \
    X(BinnedSahSpec)                 \
    X(NearestHitSpec) X(AnyHitSpec) X(MakeFrustumSpec) X(CullByPlanesSpec) X(CullByBoxPlanesSpec)

}  // namespace boxes::differential
