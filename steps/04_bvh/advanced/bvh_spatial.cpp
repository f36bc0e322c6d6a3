// Step 04's engine: the binned SAH with spatial splits (Stich, Friedrich, Dietrich 2009,
// "Spatial splits in bounding volume hierarchies"). Where the two children of the best
// object split overlap a lot (long thin triangles, large triangles crossing a room), the
// builder also tries planes that cut triangles: a triangle crossing the plane goes to
// both children, each with the box of its part on that side. More references, but
// boxes that hug the geometry: fewer boxes a ray enters in vain.
//
// The hierarchy stays conservative. Every reference's box contains the part of its
// triangle inside the reference's region (the node's space cut by the spatial planes
// above it): the clipped parts are computed in double and rounded outward. A point of a
// triangle lies in the region of one leaf on each path, and in that leaf's reference box.
#include <algorithm>
#include <cmath>

#include "04_bvh/advanced/build.hpp"

namespace boxes {

namespace {

inline double at(const Vec3d& v, int axis) {
    return (&v.x)[axis];
}
inline float at(const Vec3& v, int axis) {
    return (&v.x)[axis];
}

// The box of the part of `tri` with lo <= x_axis <= hi (a slab; lo or hi may be
// infinite), computed in the precision Real: the vertices inside the slab and the points
// where edges cross its planes. Empty when the triangle misses the slab.
template <typename Real>
Bounds3T<Real> slabPart(const LeafTriangle& tri, int axis, Real lo, Real hi) {
    using V = Vec3T<Real>;
    const V v[3] = {V(tri.a), V(tri.b), V(tri.c)};
    Bounds3T<Real> part;
    for (int i = 0; i < 3; ++i) {
        const V &p0 = v[i], &p1 = v[(i + 1) % 3];
        Real a0 = (&p0.x)[axis], a1 = (&p1.x)[axis];
        if (a0 >= lo && a0 <= hi) part.extend(p0);
        for (Real plane : {lo, hi}) {
            if ((a0 < plane && plane < a1) || (a1 < plane && plane < a0)) {
                V q = p0 + (plane - a0) / (a1 - a0) * (p1 - p0);
                (&q.x)[axis] = plane;
                part.extend(q);
            }
        }
    }
    return part;
}

Bounds3f intersection(const Bounds3f& a, const Bounds3f& b) {
    Bounds3f o(glm::max(a.min, b.min), glm::min(a.max, b.max));
    return o.isEmpty() ? Bounds3f() : o;
}

// The same part as a reference's box, conservative: computed in double, each corner
// rounded to float and then one float step outward, so the double arithmetic's own error
// (far below a float step) cannot shrink it; then cut to the slab and to `within` (the
// reference's box so far).
Bounds3f clipTriangle(const LeafTriangle& tri, int axis, float lo, float hi,
                      const Bounds3f& within) {
    Bounds3d part = slabPart<double>(tri, axis, lo, hi);
    if (part.isEmpty()) return Bounds3f();
    Bounds3f out;
    for (int k = 0; k < 3; ++k) {
        (&out.min.x)[k] = std::nextafter(float(at(part.min, k)), -kInfinity<float>);
        (&out.max.x)[k] = std::nextafter(float(at(part.max, k)), kInfinity<float>);
    }
    (&out.min.x)[axis] = std::max(at(out.min, axis), lo);
    (&out.max.x)[axis] = std::min(at(out.max, axis), hi);
    return intersection(out, within);
}

Bounds3f boundsOf(std::span<const BuildPrimitive> refs) {
    Bounds3f b;
    for (const BuildPrimitive& r : refs) {
        b.extend(r.bounds.min);
        b.extend(r.bounds.max);
    }
    return b;
}

struct SpatialSplit {
    float cost = kInfinity<float>;
    int axis = -1;
    float plane = 0.0f;
};

class SpatialBuildJob {
public:
    SpatialBuildJob(const Mesh& mesh, const BvhBuildOptions& options, Bvh& bvh)
        : mesh_(mesh), options_(options), bvh_(bvh) {}

    void build(std::vector<BuildPrimitive> refs) {
        bvh_.nodes.clear();
        bvh_.primitiveIndices.clear();
        if (refs.empty()) return;
        Bounds3f root = boundsOf(refs);
        // Stich et al.: spatial splits only where the object split's children overlap by
        // more than alpha of the root's area.
        minOverlapArea_ = options_.spatialSplitAlpha * root.surfaceArea();
        referenceBudget_ = size_t(double(refs.size()) * options_.spatialSplitBudget);
        bvh_.nodes.reserve(2 * refs.size());
        bvh_.nodes.emplace_back();
        buildNode(0, std::move(refs), 0);
    }

private:
    LeafTriangle triangle(uint32_t index) const {
        return {mesh_.vertex(index, 0), mesh_.vertex(index, 1), mesh_.vertex(index, 2)};
    }

    void buildNode(uint32_t nodeIndex, std::vector<BuildPrimitive> refs, int depth) {
        Bounds3f bounds = boundsOf(refs), centroids;
        for (const BuildPrimitive& r : refs) centroids.extend(r.centroid);
        size_t n = refs.size();
        bvh_.nodes[nodeIndex].boundsMin = bounds.min;
        bvh_.nodes[nodeIndex].boundsMax = bounds.max;
        auto makeLeaf = [&] {
            bvh_.nodes[nodeIndex].leftFirst = uint32_t(bvh_.primitiveIndices.size());
            bvh_.nodes[nodeIndex].count = uint32_t(n);
            for (const BuildPrimitive& r : refs) bvh_.primitiveIndices.push_back(r.index);
        };
        if (n == 1 || depth >= options_.maxDepth - 1) return makeLeaf();

        float objectCost = kInfinity<float>;
        size_t left = partitionBinnedSah(refs, bounds, centroids, options_, objectCost);
        bool objectSplit = left > 0 && left < n;
        SpatialSplit spatial;
        if (referenceBudget_ > 0 && objectSplit) {
            std::span<const BuildPrimitive> all(refs);
            Bounds3f both = intersection(boundsOf(all.first(left)), boundsOf(all.subspan(left)));
            if (both.surfaceArea() > minOverlapArea_) spatial = findSpatialSplit(refs, bounds);
        }
        float bestCost = std::min(objectCost, spatial.cost);
        size_t leafLimit = size_t(std::max(1, options_.maxLeafSize));
        if (n <= leafLimit && !(bestCost < options_.intersectionCost * float(n))) return makeLeaf();

        std::vector<BuildPrimitive> leftRefs, rightRefs;
        if (spatial.cost < objectCost) {
            splitReferences(refs, spatial, leftRefs, rightRefs);
            // The bins promised both sides fewer references; should rounding at the plane
            // break that promise, the object split runs instead (no endless duplication).
            if (leftRefs.size() == n || rightRefs.size() == n) {
                leftRefs.clear();
                rightRefs.clear();
                spatial = {};
            }
        }
        if (leftRefs.empty() && rightRefs.empty()) {
            if (!objectSplit) {
                // Identical centroids or a line: as the other builders, a leaf when small
                // enough, else halves in array order.
                if (n <= leafLimit) return makeLeaf();
                left = n / 2;
            }
            // The left child takes the node's own array (no copy, no new pages).
            rightRefs.assign(refs.begin() + std::ptrdiff_t(left), refs.end());
            refs.resize(left);
            leftRefs = std::move(refs);
        }
        refs = {};  // the children own the references now
        uint32_t leftChild = uint32_t(bvh_.nodes.size());
        bvh_.nodes.emplace_back();
        bvh_.nodes.emplace_back();
        bvh_.nodes[nodeIndex].leftFirst = leftChild;
        bvh_.nodes[nodeIndex].count = 0;
        buildNode(leftChild, std::move(leftRefs), depth + 1);
        buildNode(leftChild + 1, std::move(rightRefs), depth + 1);
    }

    // Binned spatial split: the node's box cut into equal bins per axis; each reference
    // clipped into every bin it spans; the bin planes priced by the SAH with a reference
    // counted on each side it reaches ("entries" left, "exits" right).
    SpatialSplit findSpatialSplit(const std::vector<BuildPrimitive>& refs, const Bounds3f& node) {
        SpatialSplit best;
        const int bins = std::clamp(options_.bins, 2, 256);
        const float nodeArea = node.surfaceArea();
        if (!(nodeArea > 0.0f)) return best;
        const size_t binCount = size_t(bins);
        std::vector<Bounds3f> binBounds(binCount);
        std::vector<uint32_t> entries(binCount), exits(binCount), rightCount(binCount);
        std::vector<float> rightArea(binCount);
        for (int axis = 0; axis < 3; ++axis) {
            float lo = at(node.min, axis), hi = at(node.max, axis), width = (hi - lo) / float(bins);
            if (!(width > 0.0f) || !std::isfinite(width)) continue;
            auto plane = [&](int b) { return b == bins ? hi : lo + width * float(b); };
            float perWidth = 1.0f / width;  // bins only price planes: no exact division needed
            // Clamped in float before the conversion: a subnormal width makes perWidth
            // infinite, and 0 * infinity a NaN (fuzz_sbvh found it); NaN goes to bin 0.
            auto binOf = [&](float x) {
                float f = (x - lo) * perWidth;
                return f >= float(bins - 1) ? bins - 1 : f > 0.0f ? int(f) : 0;
            };
            std::fill(binBounds.begin(), binBounds.end(), Bounds3f());
            std::fill(entries.begin(), entries.end(), 0u);
            std::fill(exits.begin(), exits.end(), 0u);
            for (const BuildPrimitive& r : refs) {
                int first = binOf(at(r.bounds.min, axis)), last = binOf(at(r.bounds.max, axis));
                entries[size_t(first)]++;
                exits[size_t(last)]++;
                if (first == last) {
                    binBounds[size_t(first)].extend(r.bounds.min);
                    binBounds[size_t(first)].extend(r.bounds.max);
                    continue;
                }
                // Binning only prices planes: float arithmetic, no outward rounding (the
                // references themselves are cut conservatively in splitReferences).
                LeafTriangle tri = triangle(r.index);
                for (int b = first; b <= last; ++b) {
                    Bounds3f part =
                        intersection(slabPart<float>(tri, axis, plane(b), plane(b + 1)), r.bounds);
                    if (part.isEmpty()) continue;
                    binBounds[size_t(b)].extend(part.min);
                    binBounds[size_t(b)].extend(part.max);
                }
            }
            Bounds3f side;
            uint32_t count = 0;
            for (int b = bins - 1; b > 0; --b) {
                side.extend(binBounds[size_t(b)].min);
                side.extend(binBounds[size_t(b)].max);
                count += exits[size_t(b)];
                rightArea[size_t(b)] = side.surfaceArea();
                rightCount[size_t(b)] = count;
            }
            side = Bounds3f();
            count = 0;
            for (int b = 1; b < bins; ++b) {
                side.extend(binBounds[size_t(b - 1)].min);
                side.extend(binBounds[size_t(b - 1)].max);
                count += entries[size_t(b - 1)];
                // Progress: each side must hold fewer references than the node.
                if (count == 0 || rightCount[size_t(b)] == 0 || count == refs.size() ||
                    rightCount[size_t(b)] == refs.size())
                    continue;
                float c = options_.traversalCost +
                          options_.intersectionCost *
                              (side.surfaceArea() * float(count) +
                               rightArea[size_t(b)] * float(rightCount[size_t(b)])) /
                              nodeArea;
                if (c < best.cost) best = {c, axis, plane(b)};
            }
        }
        return best;
    }

    // A reference wholly on one side of the plane goes there; one crossing it goes to both,
    // clipped to each side (a part that turns out empty is dropped).
    void splitReferences(const std::vector<BuildPrimitive>& refs, const SpatialSplit& split,
                         std::vector<BuildPrimitive>& leftRefs,
                         std::vector<BuildPrimitive>& rightRefs) {
        for (const BuildPrimitive& r : refs) {
            float lo = at(r.bounds.min, split.axis), hi = at(r.bounds.max, split.axis);
            if (hi <= split.plane) {
                leftRefs.push_back(r);
            } else if (lo >= split.plane) {
                rightRefs.push_back(r);
            } else {
                LeafTriangle tri = triangle(r.index);
                Bounds3f l =
                    clipTriangle(tri, split.axis, -kInfinity<float>, split.plane, r.bounds);
                Bounds3f h = clipTriangle(tri, split.axis, split.plane, kInfinity<float>, r.bounds);
                if (!l.isEmpty()) leftRefs.push_back({l, l.centroid(), r.index});
                if (!h.isEmpty()) rightRefs.push_back({h, h.centroid(), r.index});
                if (!l.isEmpty() && !h.isEmpty() && referenceBudget_ > 0) --referenceBudget_;
            }
        }
    }

    const Mesh& mesh_;
    const BvhBuildOptions& options_;
    Bvh& bvh_;
    float minOverlapArea_ = 0.0f;
    size_t referenceBudget_ = 0;
};

}  // namespace

Bvh buildSpatialSplitBvh(const Mesh& mesh, std::vector<BuildPrimitive> refs,
                         const BvhBuildOptions& options) {
    Bvh bvh(options.memory ? options.memory : std::pmr::get_default_resource());
    SpatialBuildJob(mesh, options, bvh).build(std::move(refs));
    return bvh;
}

}  // namespace boxes
