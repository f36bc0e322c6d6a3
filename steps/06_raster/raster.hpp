// Step 06: the rasterizer's building blocks, the exercises. A point goes from world space
// through the camera's view space and clip space to the screen; triangles are clipped in
// homogeneous clip space, covered pixels found with edge functions and a top-left fill
// rule, hidden surfaces removed by a z-buffer, and attributes interpolated with 1/w.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <glm/mat4x4.hpp>

#include "core/scene.hpp"

namespace boxes {

using Vec4d = glm::dvec4;
using Mat4d = glm::dmat4;

// Exercise 6.1: the view matrix (world -> camera space, glm::lookAt: right-handed, the
// camera looks down -z) and the projection (camera -> clip space, glm::perspective with
// GLM's default clip depth: the near plane maps to z/w = -1, the far plane to +1). Built
// from the core's one camera model (eye, view direction, up, vertical field of view,
// aspect ratio), so pixel centres match the ray tracer's primary rays.
struct SpaceMatrices {
    Mat4d view{1.0}, projection{1.0};
};
SpaceMatrices spaceMatrices(const Camera& camera, double near, double far);
// The two parts of spaceMatrices.
Mat4d viewMatrix(const Camera& camera);
Mat4d projectionMatrix(const Camera& camera, double near, double far);

// Exercise 6.2: clip space -> screen: divide by w (normalized device coordinates in
// [-1, 1]), then the viewport: x from [-1, 1] to [0, width], y flipped so that row 0 is
// the top, [1, -1] to [0, height]; z stays the NDC depth. Pixel (x, y) has its centre at
// (x + 0.5, y + 0.5), as in Camera::directionThrough.
glm::dvec3 clipToScreen(const Vec4d& clip, int width, int height);

// A vertex of a clipped polygon: its clip-space position and its weights with respect to
// the original triangle's three vertices (so any attribute can be interpolated later).
struct ClipVertex {
    Vec4d position{0.0};
    glm::dvec3 weights{0.0};
};

// A convex polygon during clipping: a triangle, clipped by up to six planes, has at most
// 3 + 6 vertices.
struct ClipPolygon {
    std::array<ClipVertex, 12> vertices;
    int count = 0;
    void add(const ClipVertex& v) { vertices[size_t(count++)] = v; }
};

// A plane in homogeneous clip space: a point p is inside when dot(plane, p) >= 0.
// The near plane with GLM's default depth is z + w >= 0; the far plane is w - z >= 0.
constexpr Vec4d kClipNearPlane{0.0, 0.0, 1.0, 1.0};
constexpr Vec4d kClipFarPlane{0.0, 0.0, -1.0, 1.0};
// The guard band: |x| <= g w and |y| <= g w, so screen coordinates stay within g times the
// image and fit the fixed-point edge functions; triangles inside the band are not clipped.
inline std::array<Vec4d, 4> guardBandPlanes(double g) {
    return {Vec4d(-1, 0, 0, g), Vec4d(1, 0, 0, g), Vec4d(0, -1, 0, g), Vec4d(0, 1, 0, g)};
}

// Exercise 6.3: one Sutherland-Hodgman step (Sutherland, Hodgman 1974): the part of the
// convex polygon on the inside of `plane`. A new vertex is placed where an edge crosses
// the plane, interpolated linearly in clip space (weights too); computed from the inside
// end towards the outside end so that two triangles sharing the edge get the same point.
ClipPolygon clipAgainstPlane(const ClipPolygon& polygon, const Vec4d& plane);

// Screen positions in fixed point, 1/256 pixel: edge functions on integers are exact, so
// two triangles sharing an edge see exactly opposite values (no gap, no double draw).
constexpr int kSubpixelBits = 8;
constexpr int64_t kSubpixelOne = int64_t(1) << kSubpixelBits;
struct FixedPoint2 {
    int64_t x = 0, y = 0;
};
inline FixedPoint2 snapToSubpixel(double x, double y) {
    return {int64_t(std::llround(x * double(kSubpixelOne))),
            int64_t(std::llround(y * double(kSubpixelOne)))};
}
// The centre of pixel (x, y) in fixed point.
inline FixedPoint2 pixelCentre(int x, int y) {
    return {int64_t(x) * kSubpixelOne + kSubpixelOne / 2,
            int64_t(y) * kSubpixelOne + kSubpixelOne / 2};
}

// Exercise 6.4: the edge function E(a, b, p) = (b - a) x (p - a) (the z of the 2D cross
// product, screen y pointing down): zero on the line through a and b, its sign tells the
// side, and E(v0, v1, v2) is twice the triangle's signed area. Exact on fixed point.
int64_t edgeFunction(const FixedPoint2& a, const FixedPoint2& b, const FixedPoint2& p);

// Exercise 6.5: the top-left fill rule (as in Direct3D and OpenGL): a pixel centre exactly
// on an edge belongs to the triangle only when the edge is a top edge (horizontal, the
// triangle below it) or a left edge. For a triangle with positive area E(v0, v1, v2) > 0
// (clockwise on a screen with y down), the edge a -> b is a top edge when it is horizontal
// and runs to +x, a left edge when it runs up (to -y).
bool isTopLeftEdge(const FixedPoint2& a, const FixedPoint2& b);

// Exercise 6.6: the z-buffer test: draw when the incoming depth is nearer than the stored
// one (and store it). On a tie the triangle drawn first keeps the pixel, so the result
// does not flicker and matches the ray tracer's "first hit found wins".
bool depthTest(float& stored, float incoming);

// Exercise 6.7: perspective-correct interpolation weights. `screen` are the barycentric
// weights of the pixel centre in screen space (affine, from the edge functions), `w` the
// clip w of the three vertices (their depth along the view). An attribute that is linear
// on the triangle in 3D is linear in screen space only after dividing by w: weight_i =
// (screen_i / w_i) / sum_j (screen_j / w_j) (Heckbert, Moreton 1991).
glm::dvec3 perspectiveCorrectWeights(const glm::dvec3& screen, const glm::dvec3& w);

// The pixels whose centres lie in the triangle's bounding box, clipped to the image:
// columns x0..x1 and rows y0..y1 (empty when x0 > x1 or y0 > y1).
struct PixelBounds {
    int64_t x0, y0, x1, y1;
};
inline PixelBounds pixelBounds(const FixedPoint2& v0, const FixedPoint2& v1, const FixedPoint2& v2,
                               int width, int height) {
    auto first = [](int64_t a, int64_t b, int64_t c) {  // ceil(min - 1/2)
        return (std::min(a, std::min(b, c)) - kSubpixelOne / 2 + kSubpixelOne - 1) >> kSubpixelBits;
    };
    auto last = [](int64_t a, int64_t b, int64_t c) {  // floor(max - 1/2)
        return (std::max(a, std::max(b, c)) - kSubpixelOne / 2) >> kSubpixelBits;
    };
    return {std::max<int64_t>(0, first(v0.x, v1.x, v2.x)),
            std::max<int64_t>(0, first(v0.y, v1.y, v2.y)),
            std::min<int64_t>(width - 1, last(v0.x, v1.x, v2.x)),
            std::min<int64_t>(height - 1, last(v0.y, v1.y, v2.y))};
}

// The pixels a triangle covers: calls covered(x, y, screenWeights) for every pixel centre
// inside the triangle under the top-left rule, within [0, width) x [0, height). The
// vertices may come in either winding; zero area draws nothing. Returns the signed area
// (twice, in fixed point); with cullBackFaces a back face (E > 0, see below) draws nothing.
template <typename Covered>
int64_t rasterizeTriangle(FixedPoint2 v0, FixedPoint2 v1, FixedPoint2 v2, int width, int height,
                          bool cullBackFaces, Covered&& covered) {
    int64_t area = edgeFunction(v0, v1, v2);
    // A front face (counter-clockwise seen by the camera, the OBJ convention) turns clockwise
    // on the y-down screen: E(v0, v1, v2) < 0. A back face has E > 0.
    if (area == 0 || (cullBackFaces && area > 0)) return area;
    // Work on the positive winding; remember to swap the weights of vertices 1 and 2 back.
    bool swapped = area < 0;
    if (swapped) std::swap(v1, v2);
    int64_t positive = swapped ? -area : area;
    // Edge i is opposite vertex i; a non-top-left edge needs E > 0, i.e. E - 1 >= 0.
    const int64_t bias0 = isTopLeftEdge(v1, v2) ? 0 : -1;
    const int64_t bias1 = isTopLeftEdge(v2, v0) ? 0 : -1;
    const int64_t bias2 = isTopLeftEdge(v0, v1) ? 0 : -1;
    const auto [x0, y0, x1, y1] = pixelBounds(v0, v1, v2, width, height);
    const double inverseArea = 1.0 / double(positive);
    // An edge function is affine in p: a step of one pixel to the right adds the same
    // amount everywhere, a step down another (Pineda 1988). In integers the sums are exact,
    // so stepping gives the values edgeFunction gives at every pixel, for three calls per
    // edge instead of one per pixel.
    const FixedPoint2 start = pixelCentre(int(x0), int(y0));
    const FixedPoint2 right{start.x + kSubpixelOne, start.y},
        below{start.x, start.y + kSubpixelOne};
    const int64_t first0 = edgeFunction(v1, v2, start), first1 = edgeFunction(v2, v0, start),
                  first2 = edgeFunction(v0, v1, start);
    const int64_t dx0 = edgeFunction(v1, v2, right) - first0,
                  dx1 = edgeFunction(v2, v0, right) - first1,
                  dx2 = edgeFunction(v0, v1, right) - first2;
    const int64_t dy0 = edgeFunction(v1, v2, below) - first0,
                  dy1 = edgeFunction(v2, v0, below) - first1,
                  dy2 = edgeFunction(v0, v1, below) - first2;
    int64_t row0 = first0, row1 = first1, row2 = first2;
    for (int64_t y = y0; y <= y1; ++y, row0 += dy0, row1 += dy1, row2 += dy2) {
        int64_t e0 = row0, e1 = row1, e2 = row2;
        for (int64_t x = x0; x <= x1; ++x, e0 += dx0, e1 += dx1, e2 += dx2) {
            if (e0 + bias0 < 0 || e1 + bias1 < 0 || e2 + bias2 < 0) continue;
            glm::dvec3 l(double(e0) * inverseArea, double(e1) * inverseArea,
                         double(e2) * inverseArea);
            if (swapped) std::swap(l.y, l.z);
            covered(int(x), int(y), l);
        }
    }
    return area;
}

// The pixels rasterizeTriangle covers (the same edge functions, bias and bounding box, so
// the same bits), found block by block on the screen's grid of kRasterBlock x kRasterBlock
// pixels, as hardware and llvmpipe do. An edge function is affine, so over a block it is
// smallest and largest at the block's corners: a block with all corners outside one edge is
// skipped, one with all corners inside every edge is covered without a test per pixel
// (trivial reject and accept: McCool, Wales, Moule 2001; Abrash 2009), exact in integers.
// Calls covered(y, x0, x1) for every run of covered pixel centres x0..x1 in a block's row
// (a row meets the convex triangle in one run), block by block: each pixel once, in no
// fixed order. `fragments` grows by their number. Returns the signed area as
// rasterizeTriangle does.
constexpr int kRasterBlock = 8;
template <typename Covered>
int64_t rasterizeTriangleBlocks(FixedPoint2 v0, FixedPoint2 v1, FixedPoint2 v2, int width,
                                int height, bool cullBackFaces, size_t& fragments,
                                Covered&& covered) {
    const int64_t area = edgeFunction(v0, v1, v2);
    if (area == 0 || (cullBackFaces && area > 0)) return area;
    if (area < 0) std::swap(v1, v2);
    const FixedPoint2 a[3] = {v1, v2, v0}, b[3] = {v2, v0, v1};  // edge k is opposite vertex k
    const auto [x0, y0, x1, y1] = pixelBounds(v0, v1, v2, width, height);
    if (x0 > x1 || y0 > y1) return area;
    // Per edge: its value at the first pixel centre (with the top-left bias: covered when
    // >= 0) and its steps (Pineda 1988).
    int64_t first[3], dx[3], dy[3];
    const FixedPoint2 start = pixelCentre(int(x0), int(y0));
    for (int k = 0; k < 3; ++k) {
        first[k] = edgeFunction(a[k], b[k], start) + (isTopLeftEdge(a[k], b[k]) ? 0 : -1);
        dx[k] = edgeFunction(a[k], b[k], {start.x + kSubpixelOne, start.y}) -
                edgeFunction(a[k], b[k], start);
        dy[k] = edgeFunction(a[k], b[k], {start.x, start.y + kSubpixelOne}) -
                edgeFunction(a[k], b[k], start);
    }
    constexpr int64_t kBlock = kRasterBlock;
    size_t count = 0;
    for (int64_t by = y0 - y0 % kBlock; by <= y1; by += kBlock) {
        const int64_t py0 = std::max(by, y0), py1 = std::min(by + kBlock - 1, y1);
        for (int64_t bx = x0 - x0 % kBlock; bx <= x1; bx += kBlock) {
            const int64_t px0 = std::max(bx, x0), px1 = std::min(bx + kBlock - 1, x1);
            int64_t e[3];
            bool outside = false, inside = true;
            for (int k = 0; k < 3; ++k) {
                e[k] = first[k] + dx[k] * (px0 - x0) + dy[k] * (py0 - y0);
                const int64_t sx = dx[k] * (px1 - px0), sy = dy[k] * (py1 - py0);
                const int64_t low = e[k] + std::min<int64_t>(0, sx) + std::min<int64_t>(0, sy);
                const int64_t high = e[k] + std::max<int64_t>(0, sx) + std::max<int64_t>(0, sy);
                outside = outside || high < 0;
                inside = inside && low >= 0;
            }
            if (outside) continue;
            if (inside) {
                count += size_t((px1 - px0 + 1) * (py1 - py0 + 1));
                for (int64_t y = py0; y <= py1; ++y) covered(int(y), int(px0), int(px1));
                continue;
            }
            for (int64_t y = py0; y <= py1; ++y, e[0] += dy[0], e[1] += dy[1], e[2] += dy[2]) {
                int64_t e0 = e[0], e1 = e[1], e2 = e[2], runFirst = -1, runLast = -2;
                for (int64_t x = px0; x <= px1; ++x, e0 += dx[0], e1 += dx[1], e2 += dx[2]) {
                    if ((e0 | e1 | e2) < 0) continue;  // a sign bit: outside an edge
                    if (runFirst < 0) runFirst = x;
                    runLast = x;
                }
                if (runFirst < 0) continue;
                count += size_t(runLast - runFirst + 1);
                covered(int(y), int(runFirst), int(runLast));
            }
        }
    }
    fragments += count;
    return area;
}

}  // namespace boxes
