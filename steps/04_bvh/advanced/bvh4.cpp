#include "04_bvh/advanced/bvh4.hpp"

#include <algorithm>
#include <cmath>

#include "04_bvh/advanced/memory.hpp"

namespace boxes {

namespace {

// A box's surface area in double: in float the area of a box 1e20 across is infinite.
double areaInDouble(const Bounds3f& b) {
    return Bounds3d(Vec3d(b.min), Vec3d(b.max)).surfaceArea();
}

template <int W>
struct Collapser {
    const Bvh& binary;
    BvhWide<W>& wide;
    // Per binary node: the slots of its subtree, when they are one contiguous range (the
    // builders partition in place, so they are), else count 0.
    struct SlotRange {
        uint32_t first = 0, count = 0;
    };
    std::vector<SlotRange> ranges;

    SlotRange computeRanges(uint32_t index) {
        const BvhNode& node = binary.nodes[index];
        SlotRange r;
        if (node.isLeaf()) {
            r = {node.leftFirst, node.count};
        } else {
            SlotRange left = computeRanges(node.leftFirst),
                      right = computeRanges(node.leftFirst + 1);
            if (left.count != 0 && right.count != 0 && left.first + left.count == right.first)
                r = {left.first, left.count + right.count};
        }
        return ranges[index] = r;
    }

    // Which binary subtrees become the wide tree's nodes and leaves: the choice of least
    // SAH cost (Ylitie, Karras, Laine 2017, "Efficient incoherent ray traversal on GPUs
    // through compressed wide BVHs", section 4.1), by dynamic programming over the binary
    // tree. cost[n * W + i - 1] is the least cost of subtree n when it may take up to i
    // slots of its parent's node: one slot holds n as a leaf or as a wide node; more slots
    // open n and share them between its two subtrees (leftSlots, 0 when fewer slots are
    // as cheap). A wide node costs its area times kCollapseNodeCost, a leaf its area times
    // its packets (four triangles each).
    std::vector<double> cost;
    std::vector<uint8_t> leftSlots;
    std::vector<uint8_t> asLeaf;  // n in one slot: a leaf (else a wide node)

    // A leaf may be a binary leaf or a subtree of at most kBvh4MergedLeafSize primitives.
    bool mayBeLeaf(uint32_t n) const {
        return binary.nodes[n].isLeaf() ||
               (ranges[n].count != 0 && ranges[n].count <= kBvh4MergedLeafSize);
    }
    // The least cost of the inner node n opened into up to `slots` slots (at least 2), with
    // `left` of them for its left subtree (at least 1, whatever the costs, NaN included).
    double opened(uint32_t n, int slots, int& left) const {
        const double* l = &cost[size_t(binary.nodes[n].leftFirst) * W];
        const double* r = l + W;  // the right child follows the left one
        double best = l[0] + r[slots - 2];
        left = 1;
        for (int k = 2; k < slots; ++k) {
            double c = l[k - 1] + r[slots - k - 1];
            if (c < best) best = c, left = k;
        }
        return best;
    }
    void computeCosts(uint32_t n) {
        const BvhNode& node = binary.nodes[n];
        double area = areaInDouble(node.bounds());
        double asLeafCost =
            mayBeLeaf(n) ? area * double((ranges[n].count + 3) / 4) : kInfinity<double>;
        double* c = &cost[size_t(n) * W];
        if (node.isLeaf()) {
            asLeaf[n] = 1;
            std::fill(c, c + W, asLeafCost);
            return;
        }
        computeCosts(node.leftFirst);
        computeCosts(node.leftFirst + 1);
        int left = 0;
        double asNodeCost = area * kCollapseNodeCost + opened(n, W, left);
        asLeaf[n] = asLeafCost <= asNodeCost;
        c[0] = std::min(asLeafCost, asNodeCost);
        for (int i = 2; i <= W; ++i) {
            double split = opened(n, i, left);
            c[i - 1] = std::min(split, c[i - 2]);
            if (split < c[i - 2]) leftSlots[size_t(n) * W + i - 1] = uint8_t(left);
        }
    }
    // Appends the subtrees that fill subtree n's (up to) `slots` slots.
    void collectSlots(uint32_t n, int slots, uint32_t kids[W], int& count) const {
        while (slots > 1 && leftSlots[size_t(n) * W + slots - 1] == 0) --slots;
        if (slots == 1) {
            kids[count++] = n;
            return;
        }
        int left = leftSlots[size_t(n) * W + slots - 1];
        collectSlots(binary.nodes[n].leftFirst, left, kids, count);
        collectSlots(binary.nodes[n].leftFirst + 1, slots - left, kids, count);
    }

    // Copies a leaf's slots to the next whole packets; returns its first slot.
    uint32_t emitLeaf(SlotRange leaf) {
        uint32_t first = uint32_t(wide.primitiveIndices.size());
        uint32_t padded = (leaf.count + 3) / 4 * 4;
        bool triangles = !binary.leafTriangles.empty();
        for (uint32_t i = 0; i < padded; ++i) {
            uint32_t slot = leaf.first + std::min(i, leaf.count - 1);
            wide.primitiveIndices.push_back(binary.primitiveIndices[slot]);
            if (!triangles) continue;
            const LeafTriangle& tri = binary.leafTriangles[slot];
            if (i % 4 == 0) wide.packets.emplace_back();
            TrianglePacket4& packet = wide.packets.back();
            const Vec3* vertices[3] = {&tri.a, &tri.b, &tri.c};
            for (int v = 0; v < 3; ++v)
                for (int axis = 0; axis < 3; ++axis)
                    packet.vertex[v][axis][i % 4] = (*vertices[v])[axis];
            packet.primitive[i % 4] = binary.primitiveIndices[slot];
            wide.leafTriangles.push_back(tri);
        }
        return first;
    }

    // Emits the wide node for the binary inner node `inner` (and, depth first, its
    // subtree); returns its index.
    uint32_t emit(uint32_t inner) {
        uint32_t kids[W];
        int n = 0, left = 0;
        opened(inner, W, left);
        collectSlots(binary.nodes[inner].leftFirst, left, kids, n);
        collectSlots(binary.nodes[inner].leftFirst + 1, W - left, kids, n);
        uint32_t index = uint32_t(wide.nodes.size());
        wide.nodes.push_back(emptyNode());
        for (int i = 0; i < n; ++i) {
            bool leaf = asLeaf[kids[i]];
            uint32_t child = leaf ? emitLeaf(ranges[kids[i]]) : emit(kids[i]);
            BvhWideNode<W>& node = wide.nodes[index];  // after emit: the vector may have moved
            setChild(node, i, binary.nodes[kids[i]].bounds(), child,
                     leaf ? ranges[kids[i]].count : 0);
        }
        return index;
    }

    static BvhWideNode<W> emptyNode() {
        BvhWideNode<W> node{};
        for (int i = 0; i < W; ++i) setChild(node, i, Bounds3f(), 0, 0);
        return node;
    }
    static void setChild(BvhWideNode<W>& node, int i, const Bounds3f& bounds, uint32_t child,
                         uint32_t count) {
        for (int axis = 0; axis < 3; ++axis) {
            node.boundsMin[axis][i] = bounds.min[axis];
            node.boundsMax[axis][i] = bounds.max[axis];
        }
        node.child[i] = child;
        node.count[i] = count;
    }
};

}  // namespace

template <int W>
BvhWide<W> collapseToWide(const Bvh& binary) {
    BvhWide<W> wide;
    if (binary.empty()) return wide;
    wide.root.boundsMin = binary.nodes[0].boundsMin;
    wide.root.boundsMax = binary.nodes[0].boundsMax;
    Collapser<W> collapser{
        binary, wide, std::vector<typename Collapser<W>::SlotRange>(binary.nodes.size()),
        {},     {},   {}};
    collapser.computeRanges(0);
    collapser.cost.resize(binary.nodes.size() * W);
    collapser.leftSlots.assign(binary.nodes.size() * W, 0);
    collapser.asLeaf.assign(binary.nodes.size(), 0);
    collapser.computeCosts(0);
    // Reserved for leaves padded to whole packets (more only makes a vector grow), on huge
    // pages. What is never touched costs no memory, so there is no shrink_to_fit at the
    // end: it would copy every array once more, into pages faulted in one by one.
    size_t slots = binary.primitiveIndices.size();
    bool triangles = !binary.leafTriangles.empty();
    reserveOnHugePages(wide.primitiveIndices, slots + slots / 2);
    reserveOnHugePages(wide.leafTriangles, triangles ? slots + slots / 2 : 0);
    reserveOnHugePages(wide.packets, triangles ? slots / 2 + 1 : 0);
    const BvhNode& root = binary.nodes[0];
    if (collapser.asLeaf[0]) {
        wide.nodes.push_back(Collapser<W>::emptyNode());
        uint32_t first = collapser.emitLeaf(collapser.ranges[0]);
        Collapser<W>::setChild(wide.nodes[0], 0, root.bounds(), first, collapser.ranges[0].count);
    } else {
        reserveOnHugePages(wide.nodes, binary.nodes.size() / 2 + 1);
        collapser.emit(0);
    }
    return wide;
}
template Bvh4 collapseToWide<4>(const Bvh&);
template Bvh8 collapseToWide<8>(const Bvh&);

template <int W>
BvhWideStats bvhWideStats(const BvhWide<W>& bvh) {
    BvhWideStats s;
    s.nodes = bvh.nodes.size();
    if (bvh.empty()) return s;
    double rootArea = areaInDouble(bvh.bounds());
    struct Entry {
        uint32_t index;
        int depth;
        double area;
    };
    std::vector<Entry> stack = {{0, 0, rootArea}};
    while (!stack.empty()) {
        auto [index, depth, area] = stack.back();
        stack.pop_back();
        s.nodeSahCost += area;
        const BvhWideNode<W>& node = bvh.nodes[index];
        for (int i = 0; i < W; ++i) {
            if (node.isEmpty(i)) {
                ++s.emptySlots;
            } else if (node.isLeaf(i)) {
                ++s.leaves;
                s.depth = std::max(s.depth, depth + 1);
                s.leafSahCost += areaInDouble(node.bounds(i)) * double((node.count[i] + 3) / 4);
            } else {
                stack.push_back({node.child[i], depth + 1, areaInDouble(node.bounds(i))});
            }
        }
    }
    // Relative to the root's area; a root without area (a flat or one-point scene) has no
    // meaningful ratio, and the costs stay 0.
    bool ratio = rootArea > 0.0 && std::isfinite(rootArea);
    s.nodeSahCost = ratio ? s.nodeSahCost / rootArea : 0.0;
    s.leafSahCost = ratio ? s.leafSahCost / rootArea : 0.0;
    return s;
}

template BvhWideStats bvhWideStats<4>(const Bvh4&);
template BvhWideStats bvhWideStats<8>(const Bvh8&);

void traceBatch(const Bvh4& bvh, const std::vector<Ray>& rays, std::vector<TraceHit>& hits,
                int threads) {
    traceBatchOf(bvh, rays, hits, threads);
}
void traceBatch(const Bvh8& bvh, const std::vector<Ray>& rays, std::vector<TraceHit>& hits,
                int threads) {
    traceBatchOf(bvh, rays, hits, threads);
}
TraversalCounts countWork(const Bvh4& bvh, const std::vector<Ray>& rays) {
    return countWorkOf(bvh, rays);
}
TraversalCounts countWork(const Bvh8& bvh, const std::vector<Ray>& rays) {
    return countWorkOf(bvh, rays);
}

}  // namespace boxes
