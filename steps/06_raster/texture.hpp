// Step 06: tangent space and texture coordinates. A floor quad carries a procedural texture
// (a checker of texels) addressed by texture coordinates: the point's coordinates in the
// floor's tangent space (tangent, bitangent, normal). The rasterizer interpolates the
// vertices' coordinates, perspective-correct or affine; the ray tracer computes them at its
// hit point. The two images are compared pixel for pixel.
#pragma once

#include <vector>

#include "06_raster/pipeline.hpp"
#include "core/scene.hpp"

namespace boxes {

// A surface's tangent space: tangent and bitangent span the surface, normal = tangent x
// bitangent. A point's texture coordinates are its tangent and bitangent coordinates from
// the origin, in texels.
struct TangentFrame {
    Vec3 origin{0.0f}, tangent{1, 0, 0}, bitangent{0, 0, -1}, normal{0, 1, 0};
    float texelSize = 1.0f;
    glm::dvec2 texcoord(const glm::dvec3& point) const {
        glm::dvec3 d = point - glm::dvec3(origin);
        return glm::dvec2(glm::dot(d, glm::dvec3(tangent)), glm::dot(d, glm::dvec3(bitangent))) /
               double(texelSize);
    }
};

// The textured floor: a 20 x 20 quad of two triangles at y = 0 (split along its diagonal
// from (-10, 0, -10) to (10, 0, 10)), a light above it, a camera looking along it at a low
// angle; one texel is one unit, so the floor shows 20 x 20 texels.
struct TexturedFloor {
    Scene scene;  // the mesh is the quad, no geometry yet
    TangentFrame frame;
};
// The ray tracer needs the mesh's geometry (attachGrid, measure.hpp), added where the scene
// stays: step 01's grid refers to the mesh.
TexturedFloor texturedFloor(float aspect);

// Every vertex's texture coordinates from the frame (the vertices lie on its surface).
void attachTexcoords(RasterScene& scene, const TangentFrame& frame);
// The floor as the rasterizer's triangles, each vertex with its texture coordinates.
RasterScene texturedRasterScene(const TexturedFloor& floor);

// The ray tracer's image of the textured floor: per pixel the primary ray's hit, its
// texture coordinates from the frame (exact up to the hit point's float rounding), the
// checker on the albedo, and the same direct light as the rasterizer's shading (no
// shadows: nothing on the floor casts one). `texcoords` gets each pixel's coordinates
// (NaN where the ray misses).
Image traceTexturedFloor(const Scene& scene, const TangentFrame& frame, const Camera& camera,
                         int width, int height, std::vector<glm::vec2>* texcoords = nullptr);

// The rasterizer's textured floor: the frame drawn with the settings (perspectiveCorrect or
// affine), shaded with the checker from the interpolated texture coordinates, no shadows.
Image rasterTexturedFloor(const Scene& scene, const RasterScene& raster, const Camera& camera,
                          const RasterSettings& settings, FrameBuffers& buffers);

// The rasterized floor against the traced one: pixels that show another texel of the
// checker (or the floor on one side only), pixels whose colour differs by more than 1e-3 in
// a channel (the texel or the shading: affine weights move the shaded point too), and the
// largest texture-coordinate error in texels where both see the floor.
struct TextureComparison {
    size_t pixels = 0, floorPixels = 0, differing = 0, colourDiffering = 0;
    double maxTexcoordError = 0.0;
    double differingShare() const {
        return floorPixels ? double(differing) / double(floorPixels) : 0.0;
    }
};
constexpr float kTextureColourTolerance = 1e-3f;
TextureComparison compareTexturedFloor(const Image& raster, const Image& traced,
                                       const RasterScene& scene, const FrameBuffers& buffers,
                                       const std::vector<glm::vec2>& tracedTexcoords);

}  // namespace boxes
