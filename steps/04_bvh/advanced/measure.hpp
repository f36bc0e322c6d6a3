// Step 04's engine: its measurement over every tree, exercises' and engine's alike. The
// `check` command and the chapter's tables both use it.
#pragma once

#include <string>
#include <vector>

#include "core/mesh.hpp"
#include "core/report.hpp"

namespace boxes {

struct NamedMesh {
    std::string name;
    const Mesh* mesh;
};

// Rays aimed at shared edges and vertices (step 01's crack rays): rays for which the
// hierarchy finds no hit where a target triangle is hit, per exercise builder, the SAH
// with spatial splits and the binned SAH tree's 4- and 8-wide collapses. Table id
// "bvh_cracks".
Table measureBvhCracks(const std::vector<NamedMesh>& meshes, size_t raysPerFeature, uint64_t seed);

}  // namespace boxes
