// Step 04's engine: its builds. Every builder of the step, the exercises' three and two
// that are not exercises: the full-sweep SAH (the quality reference the binned SAH is
// measured against) and the SAH with spatial splits (bvh_spatial.cpp). The trees' arrays
// go on huge pages (largeArrayMemory) unless the options name other memory.
#pragma once

#include <span>
#include <vector>

#include "04_bvh/bvh.hpp"

namespace boxes {

// Any builder (options.builder) over a mesh's triangles.
Bvh buildEngineBvh(const Mesh& mesh, const BvhBuildOptions& options,
                   BvhBuildStats* stats = nullptr);
// Over bare bounds; sbvh, which has no triangles to cut there, is the binned SAH.
Bvh buildEngineBvh(std::span<const Bounds3f> primitiveBounds, const BvhBuildOptions& options,
                   BvhBuildStats* stats = nullptr);

// The full-sweep SAH split (every primitive boundary on every axis, O(n log n) per node),
// in the framework's shape (SplitRule).
size_t partitionSweepSah(std::span<BuildPrimitive> prims, const Bounds3f& nodeBounds,
                         const Bounds3f& centroidBounds, const BvhBuildOptions& options,
                         float& cost);
constexpr SplitRule kSweepSahRule{partitionSweepSah, true};

// The binned SAH with spatial splits (SBVH, Stich, Friedrich, Dietrich 2009): a triangle
// may be referenced by several leaves, each time with the box of its part there. Builds
// nodes and primitiveIndices from the triangles' boxes (`refs`).
Bvh buildSpatialSplitBvh(const Mesh& mesh, std::vector<BuildPrimitive> refs,
                         const BvhBuildOptions& options);

}  // namespace boxes
