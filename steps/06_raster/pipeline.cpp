#include "06_raster/pipeline.hpp"

#include <string>

#include "core/bounds.hpp"
#include "core/exercise.hpp"
#include "core/mesh.hpp"
#include "core/render.hpp"
#include "core/timing.hpp"

namespace boxes {

namespace {

// How far a plane's quad reaches, in scene diagonals: far past anything a view shows.
constexpr float kPlaneReach = 1000.0f;

void addTriangle(RasterScene& s, uint32_t a, uint32_t b, uint32_t c, int material, int object) {
    s.triangles.push_back({a, b, c});
    s.material.push_back(material);
    s.object.push_back(object);
}

// A quantity affine in the pixel (the screen weights, 1/w): its value at the centre of
// pixel (x, y) and its steps per pixel to the right and down (Pineda 1988, as the edge
// functions), so a pixel's value costs two multiplications and an addition.
template <typename T>
struct AffineInPixel {
    int x = 0, y = 0;
    T at{0.0}, right{0.0}, down{0.0};
    T operator()(int px, int py) const {
        return at + double(py - y) * down + double(px - x) * right;
    }
};

}  // namespace

RasterScene RasterScene::fromScene(const Scene& scene, int sphereSegments) {
    RasterScene s;
    const Mesh& mesh = scene.mesh;
    for (size_t i = 0; i < mesh.positions.size(); ++i)
        if (!isFinite(mesh.positions[i]))
            throw InputError("mesh '" + scene.name + "': vertex " + std::to_string(i + 1) +
                             " has a coordinate that is not a finite number");
    Bounds3f bounds;
    const int meshObject = int(scene.spheres.size() + scene.planes.size());
    s.positions = mesh.positions;
    s.normals = mesh.normals;
    if (s.normals.size() != s.positions.size()) s.normals.assign(s.positions.size(), Vec3(0.0f));
    for (const auto& t : mesh.triangles)
        addTriangle(s, t[0], t[1], t[2], scene.meshMaterial, meshObject);
    s.meshTriangles = mesh.triangles.size();
    for (const Vec3& p : mesh.positions) bounds.extend(p);

    // Spheres: a latitude-longitude tessellation, vertex normals from the centre.
    const int rings = std::max(2, sphereSegments / 2), segments = std::max(3, sphereSegments);
    for (size_t k = 0; k < scene.spheres.size(); ++k) {
        const Sphere& sphere = scene.spheres[k].shape;
        uint32_t base = uint32_t(s.positions.size());
        for (int r = 0; r <= rings; ++r) {
            float theta = kPi * float(r) / float(rings);
            for (int g = 0; g <= segments; ++g) {
                float phi = 2.0f * kPi * float(g) / float(segments);
                Vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta),
                       -std::sin(theta) * std::sin(phi));
                s.positions.push_back(sphere.centre + sphere.radius * n);
                s.normals.push_back(n);
            }
        }
        for (int r = 0; r < rings; ++r)
            for (int g = 0; g < segments; ++g) {
                uint32_t a = base + uint32_t(r * (segments + 1) + g), b = a + 1;
                uint32_t c = a + uint32_t(segments + 1), d = c + 1;
                // Outward winding: (b - a) x (c - a) points away from the centre.
                if (r > 0) addTriangle(s, a, c, b, scene.spheres[k].material, int(k));
                if (r < rings - 1) addTriangle(s, b, c, d, scene.spheres[k].material, int(k));
            }
        bounds.extend(sphere.centre - Vec3(sphere.radius));
        bounds.extend(sphere.centre + Vec3(sphere.radius));
    }
    if (bounds.isEmpty()) bounds = Bounds3f(Vec3(-1.0f), Vec3(1.0f));
    s.boundsMin = bounds.min;
    s.boundsMax = bounds.max;

    // Planes: a quad around the point of the plane nearest the scene's centre.
    float reach = kPlaneReach * std::max(s.diagonal(), 1e-3f);
    for (size_t k = 0; k < scene.planes.size(); ++k) {
        const Plane& plane = scene.planes[k].shape;
        Vec3 n = glm::normalize(plane.normal);
        Vec3 c = bounds.centroid();
        c -= (glm::dot(plane.normal, c) + plane.d) / glm::dot(plane.normal, plane.normal) *
             plane.normal;
        Vec3 helper = std::abs(n.x) < 0.9f ? Vec3(1, 0, 0) : Vec3(0, 0, 1);
        Vec3 t = glm::normalize(glm::cross(n, helper)), b = glm::cross(n, t);
        uint32_t base = uint32_t(s.positions.size());
        for (Vec3 corner : {c - reach * t - reach * b, c + reach * t - reach * b,
                            c + reach * t + reach * b, c - reach * t + reach * b}) {
            s.positions.push_back(corner);
            s.normals.push_back(n);
        }
        int object = int(scene.spheres.size() + k);
        // Counter-clockwise seen from the side the normal points to.
        addTriangle(s, base, base + 3, base + 1, scene.planes[k].material, object);
        addTriangle(s, base + 1, base + 3, base + 2, scene.planes[k].material, object);
        s.hasPlanes = true;
    }
    return s;
}

std::pair<double, double> nearFarFor(const RasterScene& scene, const Camera& camera,
                                     const RasterSettings& settings) {
    const double diagonal = std::max(double(scene.diagonal()), 1e-6);
    double near = settings.near, far = settings.far;
    if (settings.near != 0.0 && !(settings.near > 0.0 && std::isfinite(settings.near)))
        throw InputError("--near must be a positive distance");
    if (settings.far != 0.0 && !(settings.far > 0.0 && std::isfinite(settings.far)))
        throw InputError("--far must be a positive distance");
    if (near == 0.0) near = 1e-5 * diagonal;
    if (far == 0.0) {
        CameraBasisT<float> b = camera.basis();
        double deepest = 0.0;
        for (int i = 0; i < 8; ++i) {
            Vec3 corner((i & 1) ? scene.boundsMax.x : scene.boundsMin.x,
                        (i & 2) ? scene.boundsMax.y : scene.boundsMin.y,
                        (i & 4) ? scene.boundsMax.z : scene.boundsMin.z);
            deepest =
                std::max(deepest, glm::dot(glm::dvec3(corner - camera.eye), glm::dvec3(b.forward)));
        }
        if (scene.hasPlanes)
            deepest = std::max(
                deepest, 1.5 * double(kPlaneReach) * diagonal +
                             glm::length(glm::dvec3(camera.eye) -
                                         glm::dvec3(0.5f * (scene.boundsMin + scene.boundsMax))));
        far = std::max(deepest * (1.0 + 1e-3) + near, 2.0 * near);
    }
    if (!(far > near))
        throw InputError("--far must be greater than --near (near " + std::to_string(near) + ")");
    return {near, far};
}

void FrameBuffers::reset(int w, int h, bool depthOnly) {
    if (w <= 0 || h <= 0) throw InputError("image size must be positive");
    width = w;
    height = h;
    size_t n = size_t(w) * size_t(h);
    depth.assign(n, kInfinity<float>);
    triangle.assign(depthOnly ? 0 : n, kNoPrimitive);
    weight1.assign(depthOnly ? 0 : n, 0.0f);
    weight2.assign(depthOnly ? 0 : n, 0.0f);
    piece.resize(depthOnly ? 0 : n);  // written wherever a triangle is
}

FrameStats rasterizeFrame(const RasterScene& scene, const Camera& camera,
                          const RasterSettings& settings, FrameBuffers& buffers,
                          const std::vector<uint32_t>* meshSubset) {
    Stopwatch watch;
    FrameStats stats;
    auto [near, far] = nearFarFor(scene, camera, settings);
    const Mat4d viewProjection = projectionMatrix(camera, near, far) * viewMatrix(camera);
    buffers.reset(settings.width, settings.height, settings.depthOnly);
    const int width = settings.width, height = settings.height;
    std::array<Vec4d, 6> planes{kClipNearPlane, kClipFarPlane};
    auto band = guardBandPlanes(settings.guardBand);
    std::copy(band.begin(), band.end(), planes.begin() + 2);

    // The vertex shader's work for one vertex: model (here world) space to clip space.
    auto transform = [&](uint32_t vertex) {
        ++stats.vertexTransforms;
        return viewProjection * Vec4d(glm::dvec3(scene.positions[vertex]), 1.0);
    };
    const VertexWork work = settings.vertexWork;
    if (work == VertexWork::OncePerVertex) {
        buffers.clipPositions.resize(scene.positions.size());
        for (size_t k = 0; k < scene.positions.size(); ++k)
            buffers.clipPositions[k] = transform(uint32_t(k));
    }
    // What a fan triangle's pixels need of its corners: their unsnapped screen positions
    // and w, and the screen weights as affine functions of the pixel, from the pixel
    // holding corner 0.
    struct Corners {
        glm::dvec2 exact[3];
        glm::dvec3 w, inverseW;
        AffineInPixel<glm::dvec3> screen;
    };
    auto cross = [](glm::dvec2 a, glm::dvec2 b) { return a.x * b.y - a.y * b.x; };
    auto setUp = [&](const Vec4d* clip[3], Corners& c) {
        for (int i = 0; i < 3; ++i) {
            c.exact[i] = glm::dvec2(clipToScreen(*clip[i], width, height));
            c.w[i] = clip[i]->w;
        }
        c.inverseW = 1.0 / c.w;
        const glm::dvec2* e = c.exact;
        double area = cross(e[1] - e[0], e[2] - e[0]);
        // Too thin unsnapped: the snapped corners (exact in double) give the weights.
        if (!(std::abs(area) > 1e-9)) {
            for (int i = 0; i < 3; ++i) {
                FixedPoint2 f = snapToSubpixel(c.exact[i].x, c.exact[i].y);
                c.exact[i] = glm::dvec2(double(f.x), double(f.y)) / double(kSubpixelOne);
            }
            area = cross(e[1] - e[0], e[2] - e[0]);
        }
        // Weight i is E(e[i+1], e[i+2], p) / area; from the unsnapped corners, so snapping
        // moves edges by at most 1/512 pixel but never tilts the interpolated plane.
        AffineInPixel<glm::dvec3>& l = c.screen;
        l.x = int(std::floor(e[0].x));
        l.y = int(std::floor(e[0].y));
        const glm::dvec2 p(double(l.x) + 0.5, double(l.y) + 0.5);
        const double inverseArea = 1.0 / area;
        for (int i = 0; i < 3; ++i) {
            const glm::dvec2 a = e[(i + 1) % 3], edge = e[(i + 2) % 3] - a;
            l.at[i] = cross(edge, p - a) * inverseArea;
            l.right[i] = -edge.y * inverseArea;
            l.down[i] = edge.x * inverseArea;
        }
    };
    // 1/w is affine in screen space too (the screen weights dotted with the corners' 1/w),
    // so a fragment's depth costs two multiplications and one division.
    auto inversePlane = [](const Corners& c) {
        const AffineInPixel<glm::dvec3>& l = c.screen;
        return AffineInPixel<double>{l.x, l.y, glm::dot(l.at, c.inverseW),
                                     glm::dot(l.right, c.inverseW), glm::dot(l.down, c.inverseW)};
    };

    // Deferred attributes (a visibility buffer, Burns, Hunt 2013): a fragment that passes
    // the depth test stores its triangle and which fan piece drew it; the weights are
    // computed once per visible pixel after the last triangle, not for every fragment that
    // is later overdrawn. A piece that won a fragment keeps what the resolve needs (its
    // screen weights' affine set-up and w), so the resolve reads one record per pixel
    // instead of setting the triangle's corners up again. A clipped triangle's piece (and,
    // when the vertex work is not done once per vertex, every piece) also keeps its
    // corners' weights of the original triangle's vertices.
    struct Drawn {
        AffineInPixel<glm::dvec3> screen;
        glm::dvec3 w;
        uint32_t weights = 0;  // in cornerWeights, or kWholeTriangle
    };
    std::vector<Drawn> drawnPieces;
    std::vector<std::array<glm::dvec3, 3>> cornerWeights;
    constexpr uint32_t kWholeTriangle = ~uint32_t(0);
    float* const depthBuffer = buffers.depth.data();
    uint32_t* const triangleBuffer = buffers.triangle.data();
    size_t fragments = 0;
    // A fragment certainly behind a stored depth (1/w smaller than 1/stored by far more than
    // rounding) fails the depth test: no need to divide for its depth and test it.
    auto behind = [](double inverseW, float stored) {
        return inverseW > 0.0 && inverseW * double(stored) < 1.0 - 1e-9;
    };

    auto draw = [&](size_t t) {
        ++stats.trianglesIn;
        const auto& tri = scene.triangles[t];
        ClipPolygon polygon;
        for (int k = 0; k < 3; ++k) {
            glm::dvec3 weights(0.0);
            weights[k] = 1.0;
            polygon.add({work == VertexWork::OncePerVertex ? buffers.clipPositions[tri[size_t(k)]]
                                                           : transform(tri[size_t(k)]),
                         weights});
        }
        // Trivially outside one plane: nothing to draw. Inside every plane: no clipping.
        bool outside = false, inside = true;
        for (const Vec4d& plane : planes) {
            int in = 0;
            for (int k = 0; k < 3; ++k)
                in += glm::dot(plane, polygon.vertices[size_t(k)].position) >= 0.0;
            outside = outside || in == 0;
            inside = inside && in == 3;
        }
        if (outside) {
            ++stats.culledOutside;
            return;
        }
        if (!inside) {
            ++stats.clipped;
            for (const Vec4d& plane : planes) {
                polygon = clipAgainstPlane(polygon, plane);
                if (polygon.count < 3) break;
            }
            if (polygon.count < 3) {
                ++stats.culledOutside;
                return;
            }
        }
        // Per pixel, an unclipped triangle's corners are transformed again for every pixel
        // (a clipped one keeps the clipper's new vertices).
        const bool perPixel = work == VertexWork::PerPixel && inside;
        // The convex polygon as a fan; every piece keeps the triangle's winding.
        bool drawn = false;
        for (int k = 1; k + 1 < polygon.count; ++k) {
            const ClipVertex* v[3] = {&polygon.vertices[0], &polygon.vertices[size_t(k)],
                                      &polygon.vertices[size_t(k + 1)]};
            const Vec4d* clip[3] = {&v[0]->position, &v[1]->position, &v[2]->position};
            Corners corners;
            setUp(clip, corners);
            FixedPoint2 s[3];
            for (int i = 0; i < 3; ++i)
                s[i] = snapToSubpixel(corners.exact[i].x, corners.exact[i].y);
            const AffineInPixel<double> plane = inversePlane(corners);
            const uint32_t piece = uint32_t(drawnPieces.size());
            bool won = false;  // a fragment passed the depth test: the piece is kept
            // A fragment's work: the depth test, then for the resolve the triangle and the
            // piece. What it reads is copied in, so that the compiler keeps it in registers.
            const size_t stride = size_t(width);
            const uint32_t id = uint32_t(t);
            // None in a depth-only frame (the buffers may keep an earlier frame's memory).
            uint32_t* const pieceBuffer = settings.depthOnly ? nullptr : buffers.piece.data();
            auto fragment = [=, &won](size_t i, double inverseW) {
                if (!depthTest(depthBuffer[i], float(1.0 / inverseW)) || !pieceBuffer) return;
                triangleBuffer[i] = id;
                pieceBuffer[i] = piece;
                won = true;
            };
            // A run of pixels in a row: first 1/w for all of them and which are certainly
            // behind (loops without calls, so the compiler can use SIMD), then the rest.
            auto run = [=](int y, int x0, int x1) {
                double inverseW[kRasterBlock];
                bool test[kRasterBlock];
                const int n = x1 - x0 + 1;
                const size_t i = size_t(y) * stride + size_t(x0);
                for (int j = 0; j < n; ++j) inverseW[j] = plane(x0 + j, y);
                for (int j = 0; j < n; ++j) test[j] = !behind(inverseW[j], depthBuffer[i + j]);
                for (int j = 0; j < n; ++j)
                    if (test[j]) fragment(i + size_t(j), inverseW[j]);
            };
            // Per pixel, the corners again (the vertex work's lesson).
            auto again = [&](int y, int x0, int x1) {
                for (int x = x0; x <= x1; ++x) {
                    Vec4d p[3] = {transform(tri[0]), transform(tri[1]), transform(tri[2])};
                    const Vec4d* q[3] = {&p[0], &p[1], &p[2]};
                    Corners c;
                    setUp(q, c);
                    const double inverseW = inversePlane(c)(x, y);
                    const size_t i = size_t(y) * stride + size_t(x);
                    if (!behind(inverseW, depthBuffer[i])) fragment(i, inverseW);
                }
            };
            // Coverage from the snapped (exact integer) edge functions, depth from the
            // unsnapped corners.
            const int64_t area =
                perPixel ? rasterizeTriangleBlocks(s[0], s[1], s[2], width, height,
                                                   settings.backfaceCulling, fragments, again)
                         : rasterizeTriangleBlocks(s[0], s[1], s[2], width, height,
                                                   settings.backfaceCulling, fragments, run);
            drawn = drawn || area < 0 || (area > 0 && !settings.backfaceCulling);
            if (won) {
                uint32_t weights = kWholeTriangle;
                if (!inside || work != VertexWork::OncePerVertex) {
                    weights = uint32_t(cornerWeights.size());
                    cornerWeights.push_back({v[0]->weights, v[1]->weights, v[2]->weights});
                }
                drawnPieces.push_back({corners.screen, corners.w, weights});
            }
        }
        if (drawn)
            ++stats.trianglesDrawn;
        else
            ++stats.culledBackface;
    };
    if (meshSubset) {
        // The kept mesh triangles in file order, then everything else: the same order as
        // the full frame, so z-buffer ties fall the same way.
        for (uint32_t t : *meshSubset) draw(t);
        for (size_t t = scene.meshTriangles; t < scene.triangles.size(); ++t) draw(t);
    } else {
        for (size_t t = 0; t < scene.triangles.size(); ++t) draw(t);
    }
    stats.fragments = fragments;

    // The resolve: per visible pixel its perspective-correct weights (Heckbert, Moreton
    // 1991), blended from the piece's corners to the original triangle's vertices.
    if (!settings.depthOnly) {
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                const size_t i = buffers.index(x, y);
                if (triangleBuffer[i] == kNoPrimitive) continue;
                const Drawn& d = drawnPieces[buffers.piece[i]];
                const glm::dvec3 screen = d.screen(x, y);
                glm::dvec3 l =
                    settings.perspectiveCorrect ? perspectiveCorrectWeights(screen, d.w) : screen;
                if (d.weights != kWholeTriangle) {
                    const auto& q = cornerWeights[d.weights];
                    l = l.x * q[0] + l.y * q[1] + l.z * q[2];
                }
                buffers.weight1[i] = float(l.y);
                buffers.weight2[i] = float(l.z);
            }
    }
    for (float d : buffers.depth) stats.pixelsCovered += d != kInfinity<float>;
    stats.milliseconds = watch.milliseconds();
    return stats;
}

ShadowMap buildShadowMap(const RasterScene& scene, const PointLight& light, int size) {
    ShadowMap map;
    map.size = size;
    Vec3 centre = 0.5f * (scene.boundsMin + scene.boundsMax);
    float radius = 0.5f * scene.diagonal();
    Camera& c = map.lightCamera;
    c.eye = light.position;
    c.view = centre - light.position;
    if (isZero(c.view)) c.view = Vec3(0, -1, 0);
    c.up = Vec3(0, 1, 0);
    float distance = glm::length(centre - light.position);
    float halfAngle =
        distance > radius * 1.01f ? std::asin(radius / distance) * 1.05f : glm::radians(85.0f);
    c.fovYDegrees = std::min(170.0f, glm::degrees(2.0f * halfAngle));
    c.aspect = 1.0f;
    RasterSettings settings;
    settings.width = settings.height = size;
    settings.depthOnly = true;
    FrameBuffers buffers;
    rasterizeFrame(scene, c, settings, buffers);
    auto [near, far] = nearFarFor(scene, c, settings);
    map.viewProjection = projectionMatrix(c, near, far) * viewMatrix(c);
    map.depth = std::move(buffers.depth);
    return map;
}

// EXERCISE 6.8: shadow map lookup with a depth bias (2 points)
bool litByShadowMap(const ShadowMap& map, const Vec3& point, double bias) {
    // BEGIN SOLUTION
    Vec4d clip = map.viewProjection * Vec4d(glm::dvec3(point), 1.0);
    if (!(clip.w > 0.0)) return true;  // behind the light's view
    // The map's texel: divide by w, then the viewport (row 0 at the top).
    double x = (clip.x / clip.w + 1.0) * 0.5 * map.size,
           y = (1.0 - clip.y / clip.w) * 0.5 * map.size;
    if (!(x >= 0.0 && x < map.size && y >= 0.0 && y < map.size)) return true;
    size_t texel = size_t(y) * size_t(map.size) + size_t(x);
    return clip.w - bias <= double(map.depth[texel]);
    // END SOLUTION
}

// EXERCISE 6.9: the hybrid: a shadow ray from the rasterized position (1 point)
bool litByShadowRay(const Scene& scene, const Vec3& point, const Vec3& geometricNormal,
                    const PointLight& light) {
    // BEGIN SOLUTION
    Vec3 toLight = light.position - point;
    Ray ray(offsetOrigin(point, geometricNormal, toLight), toLight, 0.0f, 1.0f - 1e-5f);
    return !scene.occluded(ray);
    // END SOLUTION
}

const char* vertexWorkName(VertexWork work) {
    switch (work) {
        case VertexWork::OncePerVertex:
            return "once per vertex (vertex shader)";
        case VertexWork::PerCorner:
            return "per triangle corner";
        case VertexWork::PerPixel:
            return "per pixel";
    }
    return "?";
}

const char* shadowModeName(ShadowMode mode) {
    switch (mode) {
        case ShadowMode::None:
            return "none";
        case ShadowMode::Map:
            return "shadow map";
        case ShadowMode::Rays:
            return "shadow rays (hybrid)";
    }
    return "?";
}

bool surfaceAt(const RasterScene& scene, const FrameBuffers& buffers, int x, int y,
               SurfaceHit& hit) {
    size_t i = buffers.index(x, y);
    uint32_t id = buffers.triangle[i];
    if (id == kNoPrimitive) return false;
    hit = triangleSurface(scene.positions, scene.normals, scene.triangles[id], buffers.weight1[i],
                          buffers.weight2[i]);
    hit.t = buffers.depth[i];
    hit.material = scene.material[id];
    hit.object = scene.object[id];
    hit.primitive = id;
    return true;
}

bool texcoordAt(const RasterScene& scene, const FrameBuffers& buffers, int x, int y, Vec2& uv) {
    size_t i = buffers.index(x, y);
    uint32_t id = buffers.triangle[i];
    if (id == kNoPrimitive || scene.texcoords.empty()) return false;
    const auto& tri = scene.triangles[id];
    const float w1 = buffers.weight1[i], w2 = buffers.weight2[i];
    uv = (1.0f - w1 - w2) * scene.texcoords[tri[0]] + w1 * scene.texcoords[tri[1]] +
         w2 * scene.texcoords[tri[2]];
    return true;
}

float checkerTexel(Vec2 uv, float dark) {
    glm::ivec2 cell = glm::ivec2(glm::floor(uv));
    return ((cell.x + cell.y) & 1) ? dark : 1.0f;
}

ShadedFrame shadeFrame(const Scene& scene, const RasterScene& raster, const Camera& camera,
                       const FrameBuffers& buffers, const ShadeSettings& settings,
                       const std::vector<ShadowMap>* maps) {
    Stopwatch watch;
    ShadedFrame frame;
    std::vector<ShadowMap> ownMaps;
    if (settings.shadows == ShadowMode::Map && !maps) {
        for (const PointLight& light : scene.lights)
            ownMaps.push_back(buildShadowMap(raster, light, settings.mapSize));
        maps = &ownMaps;
    }
    const double bias =
        settings.mapBias > 0.0 ? settings.mapBias : 2e-3 * double(raster.diagonal());
    const int width = buffers.width, height = buffers.height;
    frame.image = Image(width, height, scene.background);
    frame.litByFirstLight.assign(size_t(width) * size_t(height), -1);
    const CameraBasisT<float> basis = camera.basis();
    const float checkerSize = std::max(raster.diagonal(), 1e-6f) / 24.0f;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            SurfaceHit hit;
            if (!surfaceAt(raster, buffers, x, y, hit)) continue;
            const Vec3 direction =
                camera.directionThrough(basis, float(x) + 0.5f, float(y) + 0.5f, width, height);
            FacingNormals normals = facingNormals(direction, hit);
            // Every material shaded as diffuse: mirrors and glass need rays (global data).
            Material m = Material::diffuse(scene.materials[size_t(hit.material)].albedo);
            if (settings.checker) {
                glm::ivec3 cell = glm::ivec3(glm::floor(hit.point / checkerSize));
                if ((cell.x + cell.y + cell.z) & 1) m.albedo *= 0.3f;
            }
            Vec2 uv;
            if (settings.texture && texcoordAt(raster, buffers, x, y, uv))
                m.albedo *= checkerTexel(uv);
            Vec3 colour = scene.ambient * m.albedo;
            for (size_t l = 0; l < scene.lights.size(); ++l) {
                const PointLight& light = scene.lights[l];
                DirectLight d = directLight(m, light, hit.point, normals);
                if (!d.contributes()) continue;
                bool lit = true;
                if (settings.shadows == ShadowMode::Map)
                    lit = litByShadowMap((*maps)[l], hit.point, bias);
                else if (settings.shadows == ShadowMode::Rays) {
                    ++frame.shadowRays;
                    lit = litByShadowRay(scene, hit.point, hit.geometricNormal, light);
                }
                if (l == 0) frame.litByFirstLight[buffers.index(x, y)] = lit ? 1 : 0;
                if (lit) colour += d.radiance;
            }
            frame.image.at(x, y) = colour;
        }
    frame.milliseconds = watch.milliseconds();
    return frame;
}

std::vector<uint32_t> meshIds(const RasterScene& scene, const FrameBuffers& buffers) {
    std::vector<uint32_t> ids(buffers.triangle);
    for (uint32_t& id : ids)
        if (id != kNoPrimitive && id >= scene.meshTriangles) id = kNoPrimitive;
    return ids;
}

std::vector<float> meshDepths(const RasterScene& scene, const FrameBuffers& buffers) {
    std::vector<float> depth(buffers.depth);
    for (size_t i = 0; i < depth.size(); ++i)
        if (buffers.triangle[i] == kNoPrimitive || buffers.triangle[i] >= scene.meshTriangles)
            depth[i] = kInfinity<float>;
    return depth;
}

}  // namespace boxes
