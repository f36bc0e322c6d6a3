#include "04_bvh/culling_map.hpp"

#include <SDL2/SDL_keycode.h>

#include <algorithm>
#include <cstdio>

#include "core/image.hpp"

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

void plot(Image& image, int x0, int width, int x, int y, Vec3 colour, float alpha = 1.0f) {
    if (x < 0 || x >= width || y < 0 || y >= image.height()) return;
    Vec3& p = image.at(x0 + x, y);
    p = alpha * colour + (1.0f - alpha) * p;
}

// A line `thickness` pixels wide (1 or 2: the second row or column below or to the right).
void line(Image& image, int x0, int width, Vec2 a, Vec2 b, Vec3 colour, int thickness = 1) {
    float length = std::max(std::abs(b.x - a.x), std::abs(b.y - a.y));
    int steps = int(std::min(4096.0f, std::ceil(length))) + 1;
    bool steep = std::abs(b.y - a.y) > std::abs(b.x - a.x);
    for (int i = 0; i <= steps; ++i) {
        Vec2 p = a + (b - a) * (float(i) / float(steps));
        int x = int(std::floor(p.x)), y = int(std::floor(p.y));
        for (int k = 0; k < thickness; ++k)
            plot(image, x0, width, steep ? x + k : x, steep ? y : y + k, colour);
    }
}

void fillRect(Image& image, int x0, int width, Vec2 lo, Vec2 hi, Vec3 colour, float alpha) {
    for (int y = int(std::ceil(lo.y)); y < int(std::ceil(hi.y)); ++y)
        for (int x = int(std::ceil(lo.x)); x < int(std::ceil(hi.x)); ++x)
            plot(image, x0, width, x, y, colour, alpha);
}

// The legend's letters, 5 x 7 pixels each (one string per row, '#' set): only those of
// "culled", "kept", "wrongly kept" and "frustum". The core draws no text outside the
// window's panel, and the headless map needs its legend in the picture.
struct Glyph {
    char letter;
    const char* rows[7];
};
constexpr Glyph kGlyphs[] = {
    {'c', {".....", ".....", ".###.", "#....", "#....", "#....", ".###."}},
    {'d', {"....#", "....#", ".####", "#...#", "#...#", "#...#", ".####"}},
    {'e', {".....", ".....", ".###.", "#...#", "#####", "#....", ".###."}},
    {'f', {"..##.", ".#..#", ".#...", "###..", ".#...", ".#...", ".#..."}},
    {'g', {".....", ".....", ".####", "#...#", ".####", "....#", ".###."}},
    {'k', {"#....", "#....", "#..#.", "#.#..", "##...", "#.#..", "#..#."}},
    {'l', {".##..", "..#..", "..#..", "..#..", "..#..", "..#..", ".###."}},
    {'m', {".....", ".....", "##.#.", "#.#.#", "#.#.#", "#.#.#", "#...#"}},
    {'n', {".....", ".....", "#.##.", "##..#", "#...#", "#...#", "#...#"}},
    {'o', {".....", ".....", ".###.", "#...#", "#...#", "#...#", ".###."}},
    {'p', {".....", ".....", "####.", "#...#", "####.", "#....", "#...."}},
    {'r', {".....", ".....", "#.##.", "##..#", "#....", "#....", "#...."}},
    {'s', {".....", ".....", ".####", "#....", ".###.", "....#", "####."}},
    {'t', {".#...", ".#...", "###..", ".#...", ".#...", ".#..#", "..##."}},
    {'u', {".....", ".....", "#...#", "#...#", "#...#", "#..##", ".##.#"}},
    {'w', {".....", ".....", "#...#", "#...#", "#.#.#", "#.#.#", ".#.#."}},
    {'y', {".....", ".....", "#...#", "#...#", ".####", "....#", ".###."}},
};

// Draws `text` with its top left at (x, y), each font pixel `scale` pixels; returns the
// x after it. Letters the font lacks (and spaces) advance without drawing.
int drawText(Image& image, int x0, int width, int x, int y, const char* text, int scale,
             Vec3 colour) {
    for (; *text; ++text, x += 6 * scale) {
        for (const Glyph& g : kGlyphs) {
            if (g.letter != *text) continue;
            for (int row = 0; row < 7; ++row)
                for (int col = 0; col < 5; ++col)
                    if (g.rows[row][col] == '#')
                        for (int k = 0; k < scale * scale; ++k)
                            plot(image, x0, width, x + col * scale + k % scale,
                                 y + row * scale + k / scale, colour);
        }
    }
    return x;
}

// The legend: a strip of two lines at the bottom, a colour sample and its meaning each.
// Font pixels per image pixel: about a 20th of the height, and the widest line (162 font
// pixels) within the width; 0 (no legend) on maps too small for it.
int legendScale(int width, int height) {
    return width < 170 || height < 100 ? 0 : std::max(1, std::min(height / 150, width / 170));
}
int legendHeight(int width, int height) {
    return 22 * legendScale(width, height);
}
void drawLegend(Image& image, int x0, int width, const Vec3 colours[4], Vec3 frustumColour) {
    int scale = legendScale(width, image.height());
    if (scale == 0) return;
    int lineHeight = 9 * scale, top = image.height() - legendHeight(width, image.height());
    for (int y = top; y < image.height(); ++y)
        for (int x = 0; x < width; ++x) image.at(x0 + x, y) = Vec3(0.0f);
    struct Entry {
        Vec3 colour;
        const char* text;
        bool filled;
    };
    const Entry entries[2][2] = {
        {{colours[1], "culled", false}, {colours[2], "kept", false}},
        {{colours[3], "wrongly kept", true}, {frustumColour, "frustum", false}}};
    for (int r = 0; r < 2; ++r) {
        int x = 4 * scale, y = top + 2 * scale + r * lineHeight;
        for (const Entry& e : entries[r]) {
            Vec2 lo{float(x), float(y)}, hi{float(x + 7 * scale), float(y + 7 * scale)};
            if (e.filled) fillRect(image, x0, width, lo, hi, e.colour, 0.35f);
            line(image, x0, width, lo, Vec2(hi.x, lo.y), e.colour, scale);
            line(image, x0, width, Vec2(hi.x, lo.y), hi, e.colour, scale);
            line(image, x0, width, hi, Vec2(lo.x, hi.y), e.colour, scale);
            line(image, x0, width, Vec2(lo.x, hi.y), lo, e.colour, scale);
            x = drawText(image, x0, width, x + 10 * scale, y, e.text, scale, Vec3(0.8f));
            x += 10 * scale;
        }
    }
}
}  // namespace

void drawCullingMap(Image& image, int x0, int width, const Bvh& bvh, const Frustum& frustum,
                    CullTest test, int level, Vec3 up) {
    for (int y = 0; y < image.height(); ++y)
        for (int x = 0; x < width; ++x) image.at(x0 + x, y) = Vec3(0.004f);
    if (bvh.empty()) return;
    // Map axes: two directions perpendicular to up.
    up = glm::normalize(up);
    Vec3 across = std::abs(up.x) < 0.9f ? Vec3(1, 0, 0) : Vec3(0, 0, 1);
    Vec3 mapX = glm::normalize(across - glm::dot(across, up) * up);
    Vec3 mapY = glm::cross(up, mapX);
    auto project = [&](Vec3 p) { return Vec2(glm::dot(p, mapX), glm::dot(p, mapY)); };
    // The view fits what the map is about: the hierarchy's box and the frustum, with a
    // margin of 4% on each side, the same scale on both axes.
    Vec2 regionLo(kInfinity<float>), regionHi(-kInfinity<float>);
    const BvhNode& root = bvh.nodes[0];
    for (int i = 0; i < 8; ++i) {
        Vec3 p(i & 1 ? root.boundsMax.x : root.boundsMin.x,
               i & 2 ? root.boundsMax.y : root.boundsMin.y,
               i & 4 ? root.boundsMax.z : root.boundsMin.z);
        regionLo = glm::min(regionLo, project(p));
        regionHi = glm::max(regionHi, project(p));
        regionLo = glm::min(regionLo, project(frustum.corners[size_t(i)]));
        regionHi = glm::max(regionHi, project(frustum.corners[size_t(i)]));
    }
    Vec2 centre = 0.5f * (regionLo + regionHi), size = glm::max(regionHi - regionLo, Vec2(1e-30f));
    float mapHeight = float(image.height() - legendHeight(width, image.height()));
    float scale = 0.92f * std::min(float(width) / size.x, mapHeight / size.y);
    auto toMap = [&](Vec3 p) {
        Vec2 d = project(p) - centre;
        return Vec2(0.5f * float(width) + d.x * scale, 0.5f * mapHeight - d.y * scale);
    };
    // The frustum's footprint (the convex hull of its corners on the map), tinted first:
    // what lies inside it on the map, and what does not, at a glance.
    {
        std::vector<Vec2> hull;  // Andrew's monotone chain, counter-clockwise
        std::vector<Vec2> points;
        for (const Vec3& c : frustum.corners) points.push_back(toMap(c));
        std::sort(points.begin(), points.end(),
                  [](Vec2 a, Vec2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
        auto cross = [](Vec2 o, Vec2 a, Vec2 b) {
            return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
        };
        for (int pass = 0; pass < 2; ++pass) {
            size_t start = hull.size();
            for (Vec2 q : points) {
                while (hull.size() >= start + 2 &&
                       cross(hull[hull.size() - 2], hull.back(), q) <= 0)
                    hull.pop_back();
                hull.push_back(q);
            }
            hull.pop_back();
            std::reverse(points.begin(), points.end());
        }
        for (int y = 0; y < image.height(); ++y)
            for (int x = 0; x < width; ++x) {
                Vec2 q(float(x) + 0.5f, float(y) + 0.5f);
                bool inside = hull.size() >= 3;
                for (size_t i = 0; i < hull.size() && inside; ++i)
                    inside = cross(hull[i], hull[(i + 1) % hull.size()], q) >= 0;
                if (inside) plot(image, x0, width, x, y, Vec3(0.02f, 0.05f, 0.12f));
            }
    }
    std::vector<NodeVisibility> verdict = classifyNodes(bvh, frustum, test);
    // Not visited (below a culled box) and culled are both grey: culled, as far as the
    // renderer is concerned. Wrongly kept boxes are filled, so they read among the rest.
    const Vec3 colours[] = {Vec3(0.12f), Vec3(0.12f), Vec3(0.1f, 0.75f, 0.15f),
                            Vec3(1.0f, 0.08f, 0.05f)};
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
    int thickness = std::min(width, image.height()) >= 250 ? 2 : 1;
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
        if (kind == int(NodeVisibility::WronglyKept)) fillRect(image, x0, width, lo, hi, c, 0.2f);
        int t = kind == int(NodeVisibility::WronglyKept) ? thickness : 1;
        line(image, x0, width, lo, Vec2(hi.x, lo.y), c, t);
        line(image, x0, width, Vec2(hi.x, lo.y), hi, c, t);
        line(image, x0, width, hi, Vec2(lo.x, hi.y), c, t);
        line(image, x0, width, Vec2(lo.x, hi.y), lo, c, t);
    }
    // The frustum's twelve edges, in light blue; on larger maps they and the wrongly kept
    // boxes are two pixels wide.
    const auto& k = frustum.corners;
    const int edges[12][2] = {{0, 1}, {1, 3}, {3, 2}, {2, 0}, {4, 5}, {5, 7},
                              {7, 6}, {6, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
    const Vec3 frustumColour(0.25f, 0.55f, 1.0f);
    for (const auto& e : edges)
        line(image, x0, width, toMap(k[size_t(e[0])]), toMap(k[size_t(e[1])]), frustumColour,
             thickness);
    drawLegend(image, x0, width, colours, frustumColour);
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
                             "the hierarchy from above (depth 6) coloured by the plane test, and "
                             "a camera's frustum; a red box over the frustum's tinted footprint "
                             "passes above or below it"});
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

void addTreeReport(Report& report, const Scene& scene, const MeshBvhGeometry& geometry,
                   const std::string& png, const CommonOptions& options) {
    report.facts["build_ms"] = geometry.stats().buildMs;
    report.facts["nodes"] = geometry.stats().nodes;
    report.facts["sah_cost"] = geometry.stats().sahCost;
    addCullingMap(report, geometry.bvh(), png, options.width, options.height, scene.camera.up);
}

}  // namespace boxes
