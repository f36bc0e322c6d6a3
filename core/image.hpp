// Linear float RGB images, tone mapping to 8-bit sRGB, PNG files (stb), and image
// differences. Pixel (0,0) is the top-left corner.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/math.hpp"

namespace boxes {

class Image {
public:
    Image() = default;
    Image(int width, int height, Vec3 fill = Vec3(0.0f));

    int width() const { return width_; }
    int height() const { return height_; }
    bool empty() const { return pixels_.empty(); }
    Vec3& at(int x, int y) { return pixels_[size_t(y) * size_t(width_) + size_t(x)]; }
    const Vec3& at(int x, int y) const { return pixels_[size_t(y) * size_t(width_) + size_t(x)]; }
    std::vector<Vec3>& pixels() { return pixels_; }
    const std::vector<Vec3>& pixels() const { return pixels_; }

    // Clamp to [0,1] and encode with the sRGB curve; 3 bytes per pixel, rows top to bottom.
    std::vector<uint8_t> toRgb8() const;
    static Image fromRgb8(int width, int height, const uint8_t* rgb);

    // Writes a PNG through a temporary file and a rename, so a failed or interrupted
    // write never leaves a partial image behind. Throws std::runtime_error on failure.
    void writePng(const std::string& path) const;
    static Image readPng(const std::string& path);

private:
    int width_ = 0;
    int height_ = 0;
    std::vector<Vec3> pixels_;
};

uint8_t encodeSrgb8(float linear);
float decodeSrgb8(uint8_t value);

struct ImageDifference {
    double rmse = 0.0;           // over all channels, in linear units
    double maxError = 0.0;       // largest absolute channel difference
    size_t pixelsDiffering = 0;  // pixels with any channel difference above the threshold
};
// Throws std::invalid_argument when the sizes differ.
ImageDifference compareImages(const Image& a, const Image& b, float threshold = 0.0f);

// Marks pixels so a reader sees even one of them: the picture dimmed to grey, every
// marked pixel in `colour` with a ring of that colour around it (radius: 1/100 of the
// width, at least 3 pixels). `marked` holds one flag per pixel, rows top to bottom.
// Returns the number of marked pixels.
size_t markPixels(Image& image, const std::vector<uint8_t>& marked, Vec3 colour);

// A PNG's companions: pngStem("a.png") is "a", pngWithSuffix("a.png", "-cull") is
// "a-cull.png".
std::string pngStem(const std::string& png);
std::string pngWithSuffix(const std::string& png, const std::string& suffix);

// Writes a file through a temporary name and a rename (no partial files).
void writeFileAtomically(const std::string& path, const void* data, size_t size);

}  // namespace boxes
