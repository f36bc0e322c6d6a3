// Step 06: the rasterization pipeline put together from the exercises: the scene as a
// list of triangles, a frame (transform, clip, rasterize, z-buffer), deferred shading with
// the ray tracer's direct light, and shadows two ways (a shadow map, or shadow rays from
// the rasterized positions: the hybrid).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "06_raster/raster.hpp"
#include "core/image.hpp"
#include "core/scene.hpp"

namespace boxes {

// Everything the rasterizer draws, as triangles. The mesh comes first, triangle i of the
// OBJ being triangle i here; spheres are tessellated and planes become large quads after
// it (the rasterizer cannot draw an infinite plane: the quad reaches past the far plane).
struct RasterScene {
    std::vector<Vec3> positions;
    std::vector<Vec3> normals;  // per vertex, for shading
    std::vector<std::array<uint32_t, 3>> triangles;
    std::vector<int> material;  // per triangle
    std::vector<int> object;    // per triangle: the scene object, numbered as the ray tracer does
    // Per vertex, texture coordinates (the vertex in its surface's tangent space, in texels);
    // empty when the scene has none.
    std::vector<Vec2> texcoords;
    size_t meshTriangles = 0;  // triangles [0, meshTriangles) are the mesh's, in file order
    Vec3 boundsMin{0.0f}, boundsMax{0.0f};  // of everything but the planes
    bool hasPlanes = false;

    // Throws InputError when the mesh has non-finite coordinates.
    static RasterScene fromScene(const Scene& scene, int sphereSegments = 48);
    float diagonal() const { return glm::length(boundsMax - boundsMin); }
};

// Where the per-vertex work (the transform to clip space, and for the pixels' weights the
// divide by w and the viewport) is done: once per vertex before any triangle, as a vertex
// shader does (the lecture's "precalculate"); again at every corner of every triangle that
// uses the vertex; or again for every pixel a triangle covers. All three give the same bits.
enum class VertexWork { OncePerVertex, PerCorner, PerPixel };
const char* vertexWorkName(VertexWork work);

struct RasterSettings {
    int width = 640, height = 480;
    double near = 0.0, far = 0.0;  // 0: chosen from the scene's bounds (see nearFarFor)
    bool backfaceCulling = false;
    bool perspectiveCorrect = true;  // false: affine weights (textures and normals warp)
    double guardBand = 64.0;         // clip |x|, |y| <= guardBand * w
    bool depthOnly = false;          // only the depth buffer (a shadow map)
    VertexWork vertexWork = VertexWork::OncePerVertex;
};

// Near and far planes for a view: the settings' own when given (checked: 0 < near < far),
// else near = 1e-5 of the scene's diagonal and far just beyond its farthest corner (and
// far enough for the planes' quads).
std::pair<double, double> nearFarFor(const RasterScene& scene, const Camera& camera,
                                     const RasterSettings& settings);

// The frame's buffers: per pixel the visible triangle, its depth along the view, and the
// interpolation weights of its vertices 1 and 2 (vertex 0 gets 1 - w1 - w2).
struct FrameBuffers {
    int width = 0, height = 0;
    std::vector<uint32_t> triangle;  // kNoPrimitive where nothing is drawn
    std::vector<float> depth;        // +infinity where nothing is drawn
    std::vector<float> weight1, weight2;
    std::vector<Vec4d> clipPositions;  // per vertex, when the vertex work is done once
    std::vector<uint32_t> piece;  // per pixel, for rasterizeFrame's resolve: the fan piece seen
    void reset(int w, int h, bool depthOnly = false);
    size_t index(int x, int y) const { return size_t(y) * size_t(width) + size_t(x); }
};

struct FrameStats {
    size_t trianglesIn = 0;       // offered to the pipeline
    size_t trianglesDrawn = 0;    // that reached the rasterizer with some area
    size_t culledOutside = 0;     // entirely outside a clip plane (behind the eye, beyond far, ...)
    size_t culledBackface = 0;    // back faces (when culling is on) and zero-area triangles
    size_t clipped = 0;           // cut by a plane into a smaller polygon
    size_t fragments = 0;         // pixel centres covered (before the depth test)
    size_t pixelsCovered = 0;     // pixels with a triangle after the frame
    size_t vertexTransforms = 0;  // vertices taken to clip space (see VertexWork)
    double milliseconds = 0.0;
};

// Draws every triangle into the buffers; with meshSubset, only those mesh triangles (in
// increasing order, e.g. what frustum culling kept) and every non-mesh triangle.
FrameStats rasterizeFrame(const RasterScene& scene, const Camera& camera,
                          const RasterSettings& settings, FrameBuffers& buffers,
                          const std::vector<uint32_t>* meshSubset = nullptr);

// A shadow map for one point light: the scene's depth seen from the light, through a
// square perspective view aimed at the scene's bounds (Williams 1978).
struct ShadowMap {
    Camera lightCamera;
    Mat4d viewProjection{1.0};
    int size = 0;
    std::vector<float> depth;  // depth along the light's view; +infinity where empty
};
ShadowMap buildShadowMap(const RasterScene& scene, const PointLight& light, int size);

// Exercise 6.8: is the point lit according to the shadow map? Its depth from the light,
// less the bias, must not lie behind the nearest depth the map stored in its texel
// (nearest texel). Points outside the map's view count as lit.
bool litByShadowMap(const ShadowMap& map, const Vec3& point, double bias);

// Exercise 6.9: the hybrid: is the point lit, by a shadow ray traced from the rasterized
// position towards the light through the scene's geometry (the same ray the ray tracer
// traces: offsetOrigin, t in [0, 1 - 1e-5])?
bool litByShadowRay(const Scene& scene, const Vec3& point, const Vec3& geometricNormal,
                    const PointLight& light);

enum class ShadowMode { None, Map, Rays };
const char* shadowModeName(ShadowMode mode);

struct ShadeSettings {
    ShadowMode shadows = ShadowMode::Rays;
    double mapBias = 0.0;  // world units; 0: 2e-3 of the scene's diagonal
    int mapSize = 2048;
    bool checker = false;  // modulate the albedo with a checker on the interpolated position
    // Modulate the albedo with a checker of texels from the interpolated texture
    // coordinates (where the scene has them).
    bool texture = false;
};

// What the shading pass found per pixel, for comparisons with the ray tracer.
struct ShadedFrame {
    Image image;
    std::vector<int8_t> litByFirstLight;  // -1: the light cannot contribute there; 0/1
    double milliseconds = 0.0;            // shading and shadows (and building shadow maps)
    uint64_t shadowRays = 0;
};

// The surface seen at a pixel, rebuilt from the buffers (position and normals interpolated
// with the stored weights).
bool surfaceAt(const RasterScene& scene, const FrameBuffers& buffers, int x, int y,
               SurfaceHit& hit);

// The texture coordinates at a pixel: the vertices' interpolated with the stored weights
// (perspective-correct unless the frame was drawn affine); false where no triangle is seen
// or the scene has no texture coordinates.
bool texcoordAt(const RasterScene& scene, const FrameBuffers& buffers, int x, int y, Vec2& uv);

// The procedural texture: a checker of unit texels, 1 on even cells and `dark` on odd ones.
float checkerTexel(Vec2 uv, float dark = 0.3f);

ShadedFrame shadeFrame(const Scene& scene, const RasterScene& raster, const Camera& camera,
                       const FrameBuffers& buffers, const ShadeSettings& settings,
                       const std::vector<ShadowMap>* maps = nullptr);

// Mesh triangle ids and depths as the --ids / --depth files want them (non-mesh triangles
// such as the floor count as nothing).
std::vector<uint32_t> meshIds(const RasterScene& scene, const FrameBuffers& buffers);
std::vector<float> meshDepths(const RasterScene& scene, const FrameBuffers& buffers);

}  // namespace boxes
