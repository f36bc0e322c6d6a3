// png_compare A.png B.png: one JSON line comparing two 8-bit images of the same size:
// width, height, differing (the fraction of pixels with a channel more than one 8-bit step
// apart), max_step (the largest channel difference in 8-bit steps) and distinct_colours
// (of A). For tests that compare pictures written by programs (tests/windows_x11.py).
// Bad input: one line on stderr, exit 1.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <set>
#include <stdexcept>
#include <vector>

#include "core/image.hpp"

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: png_compare A.png B.png\n");
        return 2;
    }
    try {
        boxes::Image a = boxes::Image::readPng(argv[1]), b = boxes::Image::readPng(argv[2]);
        if (a.width() != b.width() || a.height() != b.height())
            throw std::runtime_error("the images differ in size");
        // 8-bit sRGB round-trips exactly through readPng and toRgb8 (test_core).
        std::vector<uint8_t> pa = a.toRgb8(), pb = b.toRgb8();
        size_t differing = 0;
        int maxStep = 0;
        std::set<uint32_t> colours;
        for (size_t i = 0; i < pa.size(); i += 3) {
            int step = 0;
            for (size_t c = 0; c < 3; ++c) step = std::max(step, std::abs(pa[i + c] - pb[i + c]));
            differing += step > 1;
            maxStep = std::max(maxStep, step);
            colours.insert(uint32_t(pa[i]) << 16 | uint32_t(pa[i + 1]) << 8 | pa[i + 2]);
        }
        std::printf(
            "{\"width\": %d, \"height\": %d, \"differing\": %.6g, \"max_step\": %d, "
            "\"distinct_colours\": %zu}\n",
            a.width(), a.height(), double(differing) / double(pa.size() / 3), maxStep,
            colours.size());
    } catch (const std::exception& e) {
        std::fprintf(stderr, "png_compare: %s\n", e.what());
        return 1;
    }
}
