// What every scene a program may render promises: known materials, a valid camera whose
// basis is finite, finite lights.
#pragma once

#include "core/scene.hpp"
#include "fuzz/fuzz_common.hpp"

namespace boxes::fuzz {

inline void checkScene(const Scene& scene) {
    if (scene.hasMesh() && scene.geometries.empty()) {
        // A mesh scene: a step adds the geometry; the materials must still exist.
        if (scene.meshMaterial < 0 || size_t(scene.meshMaterial) >= scene.materials.size())
            fail("mesh material out of range");
    } else {
        scene.checkRenderable();
    }
    try {
        scene.camera.validate();
    } catch (const std::exception& e) {
        fail(std::string("a returned scene has an invalid camera: ") + e.what());
    }
    auto basis = scene.camera.basis();
    if (!isFinite(basis.right) || !isFinite(basis.up) || !isFinite(basis.forward))
        fail("camera basis is not finite");
    for (const auto& light : scene.lights)
        if (!isFinite(light.position) || !isFinite(light.intensity)) fail("non-finite light");
}

}  // namespace boxes::fuzz
