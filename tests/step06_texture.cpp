// Step 06: the vertex work precalculated once per vertex against per corner and per pixel,
// and texture coordinates on a floor: perspective-correct against the exact ray-plane
// intersection and the ray tracer, affine against its own screen-space value.
#include <cmath>

#include "06_raster/measure.hpp"
#include "06_raster/pipeline.hpp"
#include "06_raster/texture.hpp"
#include "support.hpp"

using namespace boxes;

namespace {

constexpr int kWidth = 64, kHeight = 48;

// The floor's camera in double, by hand: the basis of Camera::basis, a pixel centre's
// direction, a point's position on the screen.
struct HandCamera {
    glm::dvec3 eye, right, up, forward;
    double halfHeight, aspect;
    explicit HandCamera(const Camera& c)
        : eye(c.eye),
          halfHeight(std::tan(glm::radians(double(c.fovYDegrees)) / 2.0)),
          aspect(double(c.aspect)) {
        forward = glm::normalize(glm::dvec3(c.view));
        right = glm::normalize(glm::cross(forward, glm::normalize(glm::dvec3(c.up))));
        up = glm::cross(right, forward);
    }
    glm::dvec3 direction(int x, int y) const {
        double sx = (2.0 * (x + 0.5) / kWidth - 1.0) * aspect * halfHeight;
        double sy = (1.0 - 2.0 * (y + 0.5) / kHeight) * halfHeight;
        return forward + sx * right + sy * up;
    }
    glm::dvec2 screen(glm::dvec3 p) const {
        glm::dvec3 q = p - eye;
        double z = glm::dot(q, forward);
        return {(glm::dot(q, right) / z / (aspect * halfHeight) + 1.0) * 0.5 * kWidth,
                (1.0 - glm::dot(q, up) / z / halfHeight) * 0.5 * kHeight};
    }
};

// The exact texture coordinates at a pixel centre: the ray meets the plane y = 0 at
// eye + t d with t = -eye.y / d.y; texel (0, 0) is at the corner (-10, 0, 10), u runs
// along +x and v along -z.
glm::dvec2 exactTexcoord(const HandCamera& cam, int x, int y) {
    glm::dvec3 d = cam.direction(x, y);
    glm::dvec3 p = cam.eye + (-cam.eye.y / d.y) * d;
    return {p.x + 10.0, 10.0 - p.z};
}

// The affine value: the vertices' texture coordinates weighted by the pixel centre's
// barycentrics on the screen, in the triangle of the quad that holds the point.
glm::dvec2 affineTexcoord(const HandCamera& cam, int x, int y) {
    glm::dvec2 uvExact = exactTexcoord(cam, x, y);
    // The quad's diagonal runs from (-10, 0, -10), texel (0, 20), to (10, 0, 10), texel
    // (20, 0): u + v = 20 on it, and the triangle with the corner (10, 0, -10) has u + v > 20.
    glm::dvec3 a(-10, 0, -10), b(10, 0, 10),
        c = uvExact.x + uvExact.y > 20.0 ? glm::dvec3(10, 0, -10) : glm::dvec3(-10, 0, 10);
    auto uvOf = [](glm::dvec3 p) { return glm::dvec2(p.x + 10.0, 10.0 - p.z); };
    glm::dvec2 sa = cam.screen(a), sb = cam.screen(b), sc = cam.screen(c);
    glm::dvec2 p(x + 0.5, y + 0.5);
    auto cross = [](glm::dvec2 u, glm::dvec2 v) { return u.x * v.y - u.y * v.x; };
    double area = cross(sb - sa, sc - sa);
    double la = cross(sc - sb, p - sb) / area, lb = cross(sa - sc, p - sc) / area,
           lc = cross(sb - sa, p - sa) / area;
    return la * uvOf(a) + lb * uvOf(b) + lc * uvOf(c);
}

}  // namespace

TEST_SUITE("textures 06") {
    TEST_CASE("texture coordinates: perspective-correct at worked pixels equal the ray-plane hit") {
        TexturedFloor floor = texturedFloor(float(kWidth) / float(kHeight));
        RasterScene raster = texturedRasterScene(floor);
        const Camera& camera = floor.scene.camera;
        HandCamera cam(camera);
        RasterSettings rs;
        rs.width = kWidth;
        rs.height = kHeight;
        FrameBuffers correct, affine;
        rasterizeFrame(raster, camera, rs, correct);
        rs.perspectiveCorrect = false;
        rasterizeFrame(raster, camera, rs, affine);
        // Near the bottom, in the middle, near the far edge; either side of the diagonal.
        // Affine is off there by (worked in double) 0.50, 5.66, 6.41, 9.92, 11.71 and 10.11
        // texels.
        struct Worked {
            int x, y;
            double affineError;
        };
        const Worked points[] = {{32, 44, 0.49}, {8, 36, 5.6},   {56, 36, 6.4},
                                 {20, 26, 9.9},  {44, 26, 11.7}, {32, 22, 10.1}};
        for (const Worked& pt : points) {
            const int x = pt.x, y = pt.y;
            INFO("pixel " << x << ", " << y);
            glm::dvec2 exact = exactTexcoord(cam, x, y), hand = affineTexcoord(cam, x, y);
            Vec2 uv, uvAffine;
            REQUIRE(texcoordAt(raster, correct, x, y, uv));
            REQUIRE(texcoordAt(raster, affine, x, y, uvAffine));
            // Float weights and the float camera: a few 1e-5 texels.
            CHECK(glm::length(glm::dvec2(uv) - exact) < 1e-3);
            // Affine is its own screen-space value, and that is not the floor's.
            CHECK(glm::length(glm::dvec2(uvAffine) - hand) < 1e-3);
            CHECK(glm::length(hand - exact) > pt.affineError);
            CHECK(glm::length(glm::dvec2(uvAffine) - exact) > pt.affineError);
        }
    }
    TEST_CASE("texture coordinates: one worked pixel perspective-correct and affine") {
        // Pixel (20, 26) of 64 x 48: its ray meets the floor at x = -2.468, z = 4.421, so
        // (u, v) = (7.532, 5.579). Affine, its screen barycentrics in the triangle (-10, -10),
        // (10, 10), (-10, 10) weight the corners' (0, 20), (20, 0), (0, 0) to (2.938, 14.375):
        // 9.92 texels away, mostly along v (towards the horizon).
        TexturedFloor floor = texturedFloor(float(kWidth) / float(kHeight));
        RasterScene raster = texturedRasterScene(floor);
        RasterSettings rs;
        rs.width = kWidth;
        rs.height = kHeight;
        FrameBuffers buffers;
        Vec2 uv;
        rasterizeFrame(raster, floor.scene.camera, rs, buffers);
        REQUIRE(texcoordAt(raster, buffers, 20, 26, uv));
        CHECK(uv.x == doctest::Approx(7.532).epsilon(2e-4));
        CHECK(uv.y == doctest::Approx(5.579).epsilon(2e-4));
        rs.perspectiveCorrect = false;
        rasterizeFrame(raster, floor.scene.camera, rs, buffers);
        REQUIRE(texcoordAt(raster, buffers, 20, 26, uv));
        CHECK(uv.x == doctest::Approx(2.938).epsilon(2e-4));
        CHECK(uv.y == doctest::Approx(14.375).epsilon(2e-4));
    }
    TEST_CASE(
        "the textured floor shows the ray tracer's texel at every pixel but affine does not") {
        TexturedFloor floor = texturedFloor(4.0f / 3.0f);
        attachGrid(floor.scene);
        RasterScene raster = texturedRasterScene(floor);
        const Camera& camera = floor.scene.camera;
        const int w = 96, h = 72;
        std::vector<glm::vec2> tracedUv;
        Image traced = traceTexturedFloor(floor.scene, floor.frame, camera, w, h, &tracedUv);
        RasterSettings rs;
        rs.width = w;
        rs.height = h;
        FrameBuffers buffers;
        Image image = rasterTexturedFloor(floor.scene, raster, camera, rs, buffers);
        TextureComparison c = compareTexturedFloor(image, traced, raster, buffers, tracedUv);
        CHECK(c.floorPixels > size_t(w * h / 3));
        // At most 0.1 percent of the floor's pixels (a texel edge through a pixel centre).
        CHECK(c.differingShare() <= 1e-3);
        CHECK(double(c.colourDiffering) <= 1e-3 * double(c.floorPixels));
        CHECK(c.maxTexcoordError < 1e-3);
        rs.perspectiveCorrect = false;
        image = rasterTexturedFloor(floor.scene, raster, camera, rs, buffers);
        c = compareTexturedFloor(image, traced, raster, buffers, tracedUv);
        // Affine: the wrong texel on a fifth of the floor or more.
        CHECK(c.differingShare() > 0.2);
        CHECK(c.maxTexcoordError > 2.0);
    }
}

TEST_SUITE("vertex work 06") {
    TEST_CASE("vertex work once per vertex per corner and per pixel: identical buffers") {
        Scene scene = makeScene("bunny", {test::dataDir(), 4.0f / 3.0f});
        RasterScene raster = RasterScene::fromScene(scene);
        Camera close = scene.camera;
        close.eye = Vec3(-0.35f, 0.55f, 0.9f);
        close.view = Vec3(-0.45f, 0.5f, 0.0f) - close.eye;
        close.fovYDegrees = 40.0f;
        RasterSettings rs;
        rs.width = 80;
        rs.height = 60;
        // The same buffers drawn from one camera, then the other: a precalculation left
        // from the previous frame would show.
        FrameBuffers once;
        for (const Camera& camera : {scene.camera, close}) {
            rs.vertexWork = VertexWork::OncePerVertex;
            FrameStats s = rasterizeFrame(raster, camera, rs, once);
            CHECK(s.vertexTransforms == raster.positions.size());
            for (VertexWork work : {VertexWork::PerCorner, VertexWork::PerPixel}) {
                INFO(vertexWorkName(work));
                rs.vertexWork = work;
                FrameBuffers other;
                FrameStats t = rasterizeFrame(raster, camera, rs, other);
                if (work == VertexWork::PerCorner) CHECK(t.vertexTransforms == 3 * t.trianglesIn);
                if (work == VertexWork::PerPixel) CHECK(t.vertexTransforms > 3 * t.trianglesIn);
                CHECK(other.triangle == once.triangle);
                CHECK(other.depth == once.depth);
                CHECK(other.weight1 == once.weight1);
                CHECK(other.weight2 == once.weight2);
                CHECK(t.pixelsCovered == s.pixelsCovered);
            }
        }
    }
}
