#include "04_bvh/culling_map.hpp"

#include <SDL2/SDL_keycode.h>

#include <algorithm>
#include <cstdio>

#include "core/app.hpp"

namespace boxes {

CullingView cullingView(const Bounds3f& bounds, int index, int count, float aspect) {
    Vec3 centre = bounds.centroid();
    float radius = 0.5f * glm::length(bounds.diagonal());
    float angle = 2.0f * kPi * float(index) / float(std::max(1, count));
    Vec3 offset(std::sin(angle), 0.35f, std::cos(angle));
    CullingView v;
    v.camera.eye = centre + 1.3f * radius * glm::normalize(offset);
    v.camera.view = centre - v.camera.eye;
    v.camera.fovYDegrees = 40.0f;
    v.camera.aspect = aspect;
    v.nearDistance = 0.01f * radius;
    v.farDistance = glm::length(v.camera.view);  // the far plane cuts the mesh in two
    return v;
}

namespace {

void plot(Image& image, int x0, int width, int x, int y, Vec3 colour) {
    if (x < 0 || x >= width || y < 0 || y >= image.height()) return;
    image.at(x0 + x, y) = colour;
}

void line(Image& image, int x0, int width, Vec2 a, Vec2 b, Vec3 colour) {
    float length = std::max(std::abs(b.x - a.x), std::abs(b.y - a.y));
    int steps = int(std::min(4096.0f, std::ceil(length))) + 1;
    for (int i = 0; i <= steps; ++i) {
        Vec2 p = a + (b - a) * (float(i) / float(steps));
        plot(image, x0, width, int(std::floor(p.x)), int(std::floor(p.y)), colour);
    }
}

}  // namespace

void drawCullingMap(Image& image, int x0, int width, const Bvh& bvh, const Frustum& frustum,
                    CullTest test, int level, Vec3 up) {
    for (int y = 0; y < image.height(); ++y)
        for (int x = 0; x < width; ++x) image.at(x0 + x, y) = Vec3(0.08f);
    if (bvh.empty()) return;
    // Map axes: two directions perpendicular to up.
    up = glm::normalize(up);
    Vec3 across = std::abs(up.x) < 0.9f ? Vec3(1, 0, 0) : Vec3(0, 0, 1);
    Vec3 mapX = glm::normalize(across - glm::dot(across, up) * up);
    Vec3 mapY = glm::cross(up, mapX);
    Bounds3f region = bvh.bounds();
    region.extend(frustum.corners[0]);  // the eye's neighbourhood
    Vec3 centre = region.centroid();
    float extent = 0.6f * glm::length(region.diagonal());
    float scale = 0.5f * float(std::min(width, image.height())) / extent;
    auto toMap = [&](Vec3 p) {
        Vec3 d = p - centre;
        return Vec2(0.5f * float(width) + glm::dot(d, mapX) * scale,
                    0.5f * float(image.height()) - glm::dot(d, mapY) * scale);
    };
    std::vector<NodeVisibility> verdict = classifyNodes(bvh, frustum, test);
    const Vec3 colours[] = {Vec3(0.25f), Vec3(0.35f), Vec3(0.2f, 0.85f, 0.3f),
                            Vec3(1.0f, 0.2f, 0.2f)};
    // Boxes at the level, drawn culled first so kept and wrongly kept stay on top.
    std::vector<std::pair<uint32_t, int>> stack = {{0, 0}}, drawn;
    while (!stack.empty()) {
        auto [index, depth] = stack.back();
        stack.pop_back();
        const BvhNode& node = bvh.nodes[index];
        if (node.isLeaf() || depth == level) {
            drawn.push_back({index, int(verdict[index])});
            continue;
        }
        stack.push_back({node.leftFirst, depth + 1});
        stack.push_back({node.leftFirst + 1, depth + 1});
    }
    std::stable_sort(drawn.begin(), drawn.end(),
                     [](const auto& a, const auto& b) { return a.second < b.second; });
    for (auto [index, kind] : drawn) {
        const BvhNode& node = bvh.nodes[index];
        Vec2 lo(kInfinity<float>), hi(-kInfinity<float>);
        for (int i = 0; i < 8; ++i) {
            Vec3 p(i & 1 ? node.boundsMax.x : node.boundsMin.x,
                   i & 2 ? node.boundsMax.y : node.boundsMin.y,
                   i & 4 ? node.boundsMax.z : node.boundsMin.z);
            Vec2 m = toMap(p);
            lo = glm::min(lo, m);
            hi = glm::max(hi, m);
        }
        Vec3 c = colours[kind];
        line(image, x0, width, lo, Vec2(hi.x, lo.y), c);
        line(image, x0, width, Vec2(hi.x, lo.y), hi, c);
        line(image, x0, width, hi, Vec2(lo.x, hi.y), c);
        line(image, x0, width, Vec2(lo.x, hi.y), lo, c);
    }
    // The frustum's twelve edges, in light blue.
    const auto& k = frustum.corners;
    const int edges[12][2] = {{0, 1}, {1, 3}, {3, 2}, {2, 0}, {4, 5}, {5, 7},
                              {7, 6}, {6, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
    for (const auto& e : edges)
        line(image, x0, width, toMap(k[size_t(e[0])]), toMap(k[size_t(e[1])]),
             Vec3(0.4f, 0.7f, 1.0f));
}

void addCullingMap(Report& report, const Bvh& bvh, const std::string& png, int width, int height,
                   Vec3 up) {
    CullingView v = cullingView(bvh.bounds(), 1, 8, float(width) / float(height));
    Frustum f = makeFrustum(v.camera, v.nearDistance, v.farDistance);
    Image map(width, height);
    drawCullingMap(map, 0, width, bvh, f, CullTest::Planes, 6, up);
    std::string path = pngWithSuffix(png, "-cull");
    map.writePng(path);
    report.images.push_back({path,
                             "the hierarchy from above (depth 6): grey culled, green kept, red "
                             "wrongly kept by the plane test; the frustum in blue"});
}

std::vector<KeyBinding> CullingMapWindow::keys() {
    return {{SDLK_c, "culling test: planes / planes + frustum corners"},
            {SDLK_l, "show deeper boxes in the map"},
            {SDLK_k, "show shallower boxes in the map"},
            {SDLK_f, "far plane: through the target / 3x further"}};
}

bool CullingMapWindow::onKey(int key) {
    if (key == SDLK_c)
        test_ = test_ == CullTest::Planes ? CullTest::PlanesAndCorners : CullTest::Planes;
    else if (key == SDLK_l || key == SDLK_k)
        level_ = std::clamp(level_ + (key == SDLK_l ? 1 : -1), 0, 64);
    else if (key == SDLK_f)
        farScale_ = farScale_ == 1.0f ? 3.0f : 1.0f;
    else
        return false;
    return true;
}

void CullingMapWindow::draw(Image& image, int x0, const Bvh& bvh, const Camera& camera, Vec3 up) {
    // Far plane through the mesh's centre (or 3x as far): it cuts the mesh.
    Bounds3f bounds = bvh.bounds();
    float radius = 0.5f * glm::length(bounds.diagonal());
    float centre = glm::dot(bounds.centroid() - camera.eye, glm::normalize(camera.view));
    Frustum f = makeFrustum(camera, 0.01f * radius, std::max(0.02f * radius, farScale_ * centre));
    cullHierarchy(bvh, f, CullTest::Planes, &counts_[0]);
    cullHierarchy(bvh, f, CullTest::PlanesAndCorners, &counts_[1]);
    drawCullingMap(image, x0, image.width() - x0, bvh, f, test_, level_, up);
}

std::vector<std::string> CullingMapWindow::status() const {
    char line[160];
    std::vector<std::string> lines;
    std::snprintf(line, sizeof line, "map (right): %s, depth %d",
                  test_ == CullTest::Planes ? "planes (p-vertex)" : "planes + frustum corners",
                  level_);
    lines.push_back(line);
    lines.push_back("grey culled, green kept, red wrongly kept; blue: frustum");
    for (int i = 0; i < 2; ++i) {
        const CullCounts& c = counts_[i];
        std::snprintf(line, sizeof line, "%-9s visited %zu culled %zu kept %zu wrongly kept %zu",
                      i == 0 ? "planes" : "+corners", c.visited, c.culled, c.kept, c.wronglyKept);
        lines.push_back(line);
    }
    return lines;
}

}  // namespace boxes
