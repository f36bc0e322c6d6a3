// A cost per pixel as a picture: how many box or triangle tests each pixel's rays made,
// coloured with viridis (van der Walt and Smith 2015: perceptually uniform, and read in
// order by readers with the common colour blindnesses), beside a colour bar with its
// scale, under a title line. Labels drawn with stb_easy_font, so a headless PNG says what
// it shows without a window.
#pragma once

#include <string>
#include <vector>

#include "core/image.hpp"

namespace boxes {

// viridis at t in [0, 1] (clamped), in linear RGB (the Image's space).
Vec3 viridis(double t);

// The top of a logarithmic scale for counts up to `largest`: 1, 2 or 5 times a power of 10,
// at least `largest` (and at least 1).
double scaleTop(double largest);

// The heat map of `counts` (width x height, rows top to bottom): each count on a log scale,
// log(1 + count) / log(1 + top), so 0 is the darkest and `top` the brightest; a colour
// bar on the right with its ticks (0, 1, 10, 100, ... and top), and `title` above. The
// picture is wider and taller than the counts by its margins.
Image heatMapImage(const std::vector<double>& counts, int width, int height, double top,
                   const std::string& title);

// Text in the image's pixels, its top-left corner at (x, y), each font pixel `scale`
// pixels wide (stb_easy_font's 5-pixel-high letters); clipped to the image.
void drawText(Image& image, int x, int y, const std::string& text, Vec3 colour, int scale = 1);
// The width of that text in pixels.
int textWidth(const std::string& text, int scale = 1);

}  // namespace boxes
