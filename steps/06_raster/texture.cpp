#include "06_raster/texture.hpp"

#include <cmath>
#include <limits>

#include "core/render.hpp"

namespace boxes {

TexturedFloor texturedFloor(float aspect) {
    TexturedFloor f;
    Scene& s = f.scene;
    s.name = "textured floor";
    s.mesh.positions = {{-10, 0, -10}, {10, 0, -10}, {10, 0, 10}, {-10, 0, 10}};
    s.mesh.triangles = {{0, 2, 1}, {0, 3, 2}};
    s.mesh.computeVertexNormals();
    s.lights.push_back({Vec3(0, 6, 0), Vec3(60.0f), kInfinity<float>});
    s.camera =
        Camera::lookingAt(Vec3(0, 2.5f, 13.0f), Vec3(0, 0, 2.0f), Vec3(0, 1, 0), 60.0f, aspect);
    f.frame.origin = Vec3(-10, 0, 10);  // texel (0, 0) at the near left corner
    return f;
}

void attachTexcoords(RasterScene& scene, const TangentFrame& frame) {
    scene.texcoords.resize(scene.positions.size());
    for (size_t i = 0; i < scene.positions.size(); ++i)
        scene.texcoords[i] = Vec2(frame.texcoord(glm::dvec3(scene.positions[i])));
}

RasterScene texturedRasterScene(const TexturedFloor& floor) {
    RasterScene r = RasterScene::fromScene(floor.scene);
    attachTexcoords(r, floor.frame);
    return r;
}

namespace {

// The colour of a diffuse surface point without shadows, as shadeFrame computes it.
Vec3 shadeUnshadowed(const Scene& scene, const SurfaceHit& hit, const Vec3& direction,
                     Vec3 albedo) {
    FacingNormals normals = facingNormals(direction, hit);
    Material m = Material::diffuse(albedo);
    Vec3 colour = scene.ambient * m.albedo;
    for (const PointLight& light : scene.lights) {
        DirectLight d = directLight(m, light, hit.point, normals);
        if (d.contributes()) colour += d.radiance;
    }
    return colour;
}

}  // namespace

Image traceTexturedFloor(const Scene& scene, const TangentFrame& frame, const Camera& camera,
                         int width, int height, std::vector<glm::vec2>* texcoords) {
    Image image(width, height, scene.background);
    if (texcoords)
        texcoords->assign(size_t(width) * size_t(height),
                          Vec2(std::numeric_limits<float>::quiet_NaN()));
    const CameraBasisT<float> basis = camera.basis();
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            Vec3 d =
                camera.directionThrough(basis, float(x) + 0.5f, float(y) + 0.5f, width, height);
            SurfaceHit hit;
            if (!scene.intersect(Ray(camera.eye, d), hit)) continue;
            Vec2 uv(frame.texcoord(glm::dvec3(hit.point)));
            if (texcoords) (*texcoords)[size_t(y) * size_t(width) + size_t(x)] = uv;
            Vec3 albedo = scene.materials[size_t(hit.material)].albedo * checkerTexel(uv);
            image.at(x, y) = shadeUnshadowed(scene, hit, d, albedo);
        }
    return image;
}

Image rasterTexturedFloor(const Scene& scene, const RasterScene& raster, const Camera& camera,
                          const RasterSettings& settings, FrameBuffers& buffers) {
    rasterizeFrame(raster, camera, settings, buffers);
    ShadeSettings ss;
    ss.shadows = ShadowMode::None;
    ss.texture = true;
    return shadeFrame(scene, raster, camera, buffers, ss).image;
}

TextureComparison compareTexturedFloor(const Image& raster, const Image& traced,
                                       const RasterScene& scene, const FrameBuffers& buffers,
                                       const std::vector<glm::vec2>& tracedTexcoords) {
    TextureComparison c;
    c.pixels = size_t(raster.width()) * size_t(raster.height());
    for (int y = 0; y < raster.height(); ++y)
        for (int x = 0; x < raster.width(); ++x) {
            size_t i = buffers.index(x, y);
            Vec2 uv;
            bool seen = texcoordAt(scene, buffers, x, y, uv);
            bool tracedSeen = !std::isnan(tracedTexcoords[i].x);
            c.floorPixels += seen || tracedSeen;
            Vec3 a = raster.at(x, y), b = traced.at(x, y);
            float diff = std::max({std::abs(a.x - b.x), std::abs(a.y - b.y), std::abs(a.z - b.z)});
            c.colourDiffering += diff > kTextureColourTolerance;
            c.differing += seen != tracedSeen ||
                           (seen && checkerTexel(uv) != checkerTexel(tracedTexcoords[i]));
            if (seen && tracedSeen)
                c.maxTexcoordError =
                    std::max(c.maxTexcoordError,
                             double(glm::length(glm::dvec2(uv) - glm::dvec2(tracedTexcoords[i]))));
        }
    return c;
}

}  // namespace boxes
