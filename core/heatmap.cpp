#include "core/heatmap.hpp"

// A public-domain header of static functions, not all of which are used here.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#include <stb/stb_easy_font.h>
#pragma GCC diagnostic pop

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace boxes {
namespace {

// viridis, sampled at 17 evenly spaced points from matplotlib's table (CC0), in sRGB.
constexpr float kViridis[17][3] = {
    {0.2670f, 0.0049f, 0.3294f}, {0.2823f, 0.0950f, 0.4173f}, {0.2788f, 0.1755f, 0.4834f},
    {0.2590f, 0.2515f, 0.5247f}, {0.2297f, 0.3224f, 0.5457f}, {0.1994f, 0.3876f, 0.5546f},
    {0.1727f, 0.4488f, 0.5579f}, {0.1490f, 0.5081f, 0.5573f}, {0.1276f, 0.5669f, 0.5506f},
    {0.1206f, 0.6258f, 0.5335f}, {0.1579f, 0.6838f, 0.5017f}, {0.2461f, 0.7389f, 0.4520f},
    {0.3692f, 0.7889f, 0.3829f}, {0.5160f, 0.8312f, 0.2943f}, {0.6785f, 0.8637f, 0.1895f},
    {0.8456f, 0.8873f, 0.0997f}, {0.9932f, 0.9062f, 0.1439f}};

float toLinear(float srgb) {
    return srgb <= 0.04045f ? srgb / 12.92f : std::pow((srgb + 0.055f) / 1.055f, 2.4f);
}

// Where a count sits on the log scale, 0 to 1.
double position(double count, double top) {
    return std::log1p(std::max(0.0, count)) / std::log1p(top);
}

std::string tickText(double v) {
    char buf[32];
    if (v >= 10000.0)
        std::snprintf(buf, sizeof buf, "%.0fk", v / 1000.0);
    else
        std::snprintf(buf, sizeof buf, "%.0f", v);
    return buf;
}

}  // namespace

Vec3 viridis(double t) {
    t = std::clamp(std::isnan(t) ? 0.0 : t, 0.0, 1.0) * 16.0;
    int i = std::min(15, int(t));
    float f = float(t - i);
    Vec3 c;
    for (int k = 0; k < 3; ++k)
        c[k] = toLinear(kViridis[i][k] + f * (kViridis[i + 1][k] - kViridis[i][k]));
    return c;
}

double scaleTop(double largest) {
    if (!(largest < 1e300))
        throw std::invalid_argument("scaleTop: the largest count is not finite");
    for (double decade = 1.0;; decade *= 10.0)
        for (double m : {1.0, 2.0, 5.0})
            if (m * decade >= largest) return m * decade;
}

int textWidth(const std::string& text, int scale) {
    std::string copy = text;
    return stb_easy_font_width(copy.data()) * scale;
}

void drawText(Image& image, int x, int y, const std::string& text, Vec3 colour, int scale) {
    std::string copy = text;
    std::vector<char> buffer(copy.size() * 1024 + 1024);  // 270 bytes a character on average
    int quads =
        stb_easy_font_print(0.0f, 0.0f, copy.data(), nullptr, buffer.data(), int(buffer.size()));
    // Each quad: four vertices of (x, y, z float, colour 4 bytes), an axis-aligned box.
    struct Vertex {
        float x, y, z;
        unsigned char rgba[4];
    };
    const Vertex* v = reinterpret_cast<const Vertex*>(buffer.data());
    for (int q = 0; q < quads; ++q, v += 4) {
        // The box's corners, whatever order the quad lists them in.
        float left = std::min({v[0].x, v[1].x, v[2].x, v[3].x});
        float right = std::max({v[0].x, v[1].x, v[2].x, v[3].x});
        float upper = std::min({v[0].y, v[1].y, v[2].y, v[3].y});
        float lower = std::max({v[0].y, v[1].y, v[2].y, v[3].y});
        int x0 = x + int(std::lround(left * scale)), y0 = y + int(std::lround(upper * scale));
        int x1 = x + int(std::lround(right * scale)), y1 = y + int(std::lround(lower * scale));
        for (int py = std::max(0, y0); py < std::min(image.height(), y1); ++py)
            for (int px = std::max(0, x0); px < std::min(image.width(), x1); ++px)
                image.at(px, py) = colour;
    }
}

Image heatMapImage(const std::vector<double>& counts, int width, int height, double top,
                   const std::string& title) {
    if (counts.size() != size_t(width) * size_t(height))
        throw std::invalid_argument("heatMapImage: one count per pixel");
    if (!(top > 0.0)) throw std::invalid_argument("heatMapImage: the scale's top must be > 0");
    const int scale = width >= 480 ? 2 : 1;  // letters readable on a large picture
    std::vector<double> ticks = {0.0};
    for (double t = 1.0; t < top * 0.999; t *= 10.0) ticks.push_back(t);
    ticks.push_back(top);
    int labelWidth = 0;
    for (double t : ticks) labelWidth = std::max(labelWidth, textWidth(tickText(t), scale));
    const int titleHeight = 12 * scale, barWidth = 14 * scale, margin = 6 * scale;
    const int bottom = 8 * scale;  // room for the 0 under the bar's end
    Image out(std::max(width + margin + barWidth + labelWidth + 8 * scale,
                       textWidth(title, scale) + 4 * scale),
              height + titleHeight + bottom, Vec3(1.0f));
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            out.at(x, y + titleHeight) =
                viridis(position(counts[size_t(y) * size_t(width) + size_t(x)], top));
    drawText(out, 2 * scale, 2 * scale, title, Vec3(0.0f), scale);
    // The bar: top at the top of the map, 0 at its bottom.
    const int barX = width + margin;
    for (int y = 0; y < height; ++y) {
        Vec3 c = viridis(1.0 - double(y) / double(std::max(1, height - 1)));
        for (int x = barX; x < barX + barWidth; ++x) out.at(x, y + titleHeight) = c;
    }
    for (double t : ticks) {
        int y = titleHeight + int(std::lround((1.0 - position(t, top)) * (height - 1)));
        for (int x = barX + barWidth; x < barX + barWidth + 3 * scale; ++x)
            if (y >= 0 && y < out.height()) out.at(x, y) = Vec3(0.0f);
        drawText(out, barX + barWidth + 4 * scale,
                 std::clamp(y - 3 * scale, titleHeight, out.height() - 11 * scale), tickText(t),
                 Vec3(0.0f), scale);
    }
    return out;
}

}  // namespace boxes
