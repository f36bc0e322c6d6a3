// Helpers every experiment of step 05's lab shares: image sizes and sample counts (smaller
// for a quick run), units, single-thread render settings, and image comparisons.
#pragma once

#include <algorithm>
#include <cstdlib>
#include <cstring>

#include "05_efficiency/measure.hpp"

namespace boxes::lab {

// Image sizes and sample counts, reduced for a quick run.
inline int sized(const LabOptions& o, int full) {
    return o.quick ? std::max(4, full / 4) : full;
}
inline int samples(const LabOptions& o, int full) {
    return o.quick ? std::max(100, full / 50) : full;
}
inline double batchSeconds(const LabOptions& o) {
    return o.quick ? 0.001 : 0.01;
}

inline double ns(double seconds) {
    return seconds * 1e9;
}
inline double ms(double seconds) {
    return seconds * 1e3;
}

// Largest difference of two images in 8-bit sRGB steps (what a PNG shows).
inline long long maxStep8(const Image& a, const Image& b) {
    auto x = a.toRgb8(), y = b.toRgb8();
    int worst = 0;
    for (size_t i = 0; i < x.size(); ++i) worst = std::max(worst, std::abs(int(x[i]) - int(y[i])));
    return worst;
}
inline bool identical(const Image& a, const Image& b) {
    return a.width() == b.width() && a.height() == b.height() &&
           std::memcmp(a.pixels().data(), b.pixels().data(), a.pixels().size() * sizeof(Vec3)) == 0;
}

inline RenderSettings oneThread(int w, int h) {
    RenderSettings s;
    s.width = w;
    s.height = h;
    s.threads = 1;
    return s;
}

}  // namespace boxes::lab
