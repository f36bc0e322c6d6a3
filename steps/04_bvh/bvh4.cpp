#include "04_bvh/bvh4.hpp"

#include <algorithm>

namespace boxes {

namespace {

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

    // A binary node that becomes one leaf: a leaf, or a subtree of at most two packets'
    // triangles. The four-triangle test costs about one triangle test, so the binned SAH's
    // usual leaves of 2 (equal costs) left packets half full and nodes half useful; merged
    // up to 8, motorbike diffuse rays ran about 1.2x faster than up to 4, the bunny alike.
    bool becomesLeaf(uint32_t index) const {
        return binary.nodes[index].isLeaf() ||
               (ranges[index].count != 0 && ranges[index].count <= kBvh4MergedLeafSize);
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
            wide.leafTriangles.push_back(tri);
        }
        return first;
    }

    // Emits the wide node for the binary inner node `inner` (and, depth first, its
    // subtree); returns its index.
    uint32_t emit(uint32_t inner) {
        const BvhNode* b = binary.nodes.data();
        uint32_t kids[W] = {b[inner].leftFirst, b[inner].leftFirst + 1};
        int n = 2;
        while (n < W) {
            // Open the inner child with the largest surface area (-1: flat and point boxes
            // have area 0 and are still opened).
            // (In double: in float the area of a box 1e20 across is infinite.)
            // Failing that, a merged subtree is opened rather than a slot left empty: the
            // node test costs the same, and smaller leaves test fewer triangles.
            int open = -1;
            double openArea = -1.0;
            for (int pass = 0; pass < 2 && open < 0; ++pass)
                for (int i = 0; i < n; ++i) {
                    if (b[kids[i]].isLeaf() || (pass == 0 && becomesLeaf(kids[i]))) continue;
                    Bounds3d box(Vec3d(b[kids[i]].boundsMin), Vec3d(b[kids[i]].boundsMax));
                    double area = box.surfaceArea();
                    if (area > openArea) {
                        open = i;
                        openArea = area;
                    }
                }
            if (open < 0) break;
            uint32_t opened = kids[open];
            kids[open] = b[opened].leftFirst;
            kids[n++] = b[opened].leftFirst + 1;
        }
        uint32_t index = uint32_t(wide.nodes.size());
        wide.nodes.push_back(emptyNode());
        for (int i = 0; i < n; ++i) {
            const BvhNode& c = b[kids[i]];
            bool leaf = becomesLeaf(kids[i]);
            uint32_t child = leaf ? emitLeaf(ranges[kids[i]]) : emit(kids[i]);
            BvhWideNode<W>& node = wide.nodes[index];  // after emit: the vector may have moved
            setChild(node, i, c.bounds(), child, leaf ? ranges[kids[i]].count : 0);
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
    Collapser<W> collapser{binary, wide,
                           std::vector<typename Collapser<W>::SlotRange>(binary.nodes.size())};
    collapser.computeRanges(0);
    // Reserved for leaves padded to whole packets (more only makes a vector grow), on huge
    // pages. What is never touched costs no memory, so there is no shrink_to_fit at the
    // end: it copied every array once more, into pages faulted in one by one (with it the
    // motorbike's collapse took about 200 ms, without it and on huge pages about 60).
    size_t slots = binary.primitiveIndices.size();
    bool triangles = !binary.leafTriangles.empty();
    reserveOnHugePages(wide.primitiveIndices, slots + slots / 2);
    reserveOnHugePages(wide.leafTriangles, triangles ? slots + slots / 2 : 0);
    reserveOnHugePages(wide.packets, triangles ? slots / 2 + 1 : 0);
    const BvhNode& root = binary.nodes[0];
    if (collapser.becomesLeaf(0)) {
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
    std::vector<std::pair<uint32_t, int>> stack = {{0, 0}};
    while (!stack.empty()) {
        auto [index, depth] = stack.back();
        stack.pop_back();
        const BvhWideNode<W>& node = bvh.nodes[index];
        for (int i = 0; i < W; ++i) {
            if (node.isEmpty(i)) {
                ++s.emptySlots;
            } else if (node.isLeaf(i)) {
                ++s.leaves;
                s.depth = std::max(s.depth, depth + 1);
            } else {
                stack.push_back({node.child[i], depth + 1});
            }
        }
    }
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

}  // namespace boxes
