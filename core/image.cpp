#include "core/image.hpp"

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace boxes {

Image::Image(int width, int height, Vec3 fill) : width_(width), height_(height) {
    if (width <= 0 || height <= 0)
        throw std::invalid_argument("image size must be positive, got " + std::to_string(width) +
                                    "x" + std::to_string(height));
    if (size_t(width) * size_t(height) > size_t(1) << 28)
        throw std::invalid_argument("image size " + std::to_string(width) + "x" +
                                    std::to_string(height) + " is too large");
    pixels_.assign(size_t(width) * size_t(height), fill);
}

uint8_t encodeSrgb8(float linear) {
    if (!(linear > 0.0f)) return 0;  // also maps NaN to black
    if (linear >= 1.0f) return 255;
    float s =
        linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
    return uint8_t(std::lround(s * 255.0f));
}

float decodeSrgb8(uint8_t value) {
    float s = value / 255.0f;
    return s <= 0.04045f ? s / 12.92f : std::pow((s + 0.055f) / 1.055f, 2.4f);
}

std::vector<uint8_t> Image::toRgb8() const {
    std::vector<uint8_t> out(pixels_.size() * 3);
    for (size_t i = 0; i < pixels_.size(); ++i) {
        out[3 * i + 0] = encodeSrgb8(pixels_[i].r);
        out[3 * i + 1] = encodeSrgb8(pixels_[i].g);
        out[3 * i + 2] = encodeSrgb8(pixels_[i].b);
    }
    return out;
}

Image Image::fromRgb8(int width, int height, const uint8_t* rgb) {
    Image image(width, height);
    for (size_t i = 0; i < image.pixels_.size(); ++i)
        image.pixels_[i] =
            Vec3(decodeSrgb8(rgb[3 * i]), decodeSrgb8(rgb[3 * i + 1]), decodeSrgb8(rgb[3 * i + 2]));
    return image;
}

namespace {
std::string temporaryNameFor(const std::string& path) {
    return path + ".tmp" + std::to_string(::getpid());
}

void appendToVector(void* context, void* data, int size) {
    auto* bytes = static_cast<std::vector<uint8_t>*>(context);
    bytes->insert(bytes->end(), static_cast<uint8_t*>(data), static_cast<uint8_t*>(data) + size);
}
}  // namespace

std::string pngStem(const std::string& png) {
    return png.size() > 4 && png.ends_with(".png") ? png.substr(0, png.size() - 4) : png;
}

std::string pngWithSuffix(const std::string& png, const std::string& suffix) {
    return pngStem(png) + suffix + ".png";
}

void writeFileAtomically(const std::string& path, const void* data, size_t size) {
    std::string tmp = temporaryNameFor(path);
    {
        std::ofstream file(tmp, std::ios::binary);
        if (!file) throw std::runtime_error("cannot write '" + path + "'");
        file.write(static_cast<const char*>(data), std::streamsize(size));
        if (!file) {
            std::remove(tmp.c_str());
            throw std::runtime_error("writing '" + path + "' failed");
        }
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) {
        std::remove(tmp.c_str());
        throw std::runtime_error("cannot write '" + path + "': " + ec.message());
    }
}

void Image::writePng(const std::string& path) const {
    if (empty()) throw std::runtime_error("cannot write an empty image to '" + path + "'");
    std::vector<uint8_t> rgb = toRgb8();
    std::vector<uint8_t> png;
    if (!stbi_write_png_to_func(appendToVector, &png, width_, height_, 3, rgb.data(), width_ * 3))
        throw std::runtime_error("PNG encoding failed for '" + path + "'");
    writeFileAtomically(path, png.data(), png.size());
}

Image Image::readPng(const std::string& path) {
    int w = 0, h = 0, channels = 0;
    uint8_t* data = stbi_load(path.c_str(), &w, &h, &channels, 3);
    if (!data) throw std::runtime_error("cannot read image '" + path + "'");
    Image image = fromRgb8(w, h, data);
    stbi_image_free(data);
    return image;
}

size_t markPixels(Image& image, const std::vector<uint8_t>& marked, Vec3 colour) {
    const int w = image.width(), h = image.height();
    if (marked.size() != size_t(w) * size_t(h))
        throw std::invalid_argument("markPixels: one flag per pixel");
    for (Vec3& p : image.pixels()) {  // grey, darker: the marks stand out on any picture
        float grey = 0.2126f * p.x + 0.7152f * p.y + 0.0722f * p.z;
        p = Vec3(0.35f * grey);
    }
    const int r = std::max(3, w / 100);
    size_t count = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (!marked[size_t(y) * size_t(w) + size_t(x)]) continue;
            ++count;
            image.at(x, y) = colour;
            // A ring one pixel thick: the pixels whose distance rounds to r.
            for (int dy = -r - 1; dy <= r + 1; ++dy)
                for (int dx = -r - 1; dx <= r + 1; ++dx) {
                    int d2 = dx * dx + dy * dy, px = x + dx, py = y + dy;
                    if (d2 < r * r - r || d2 > r * r + r) continue;
                    if (px >= 0 && py >= 0 && px < w && py < h) image.at(px, py) = colour;
                }
        }
    return count;
}

ImageDifference compareImages(const Image& a, const Image& b, float threshold) {
    if (a.width() != b.width() || a.height() != b.height())
        throw std::invalid_argument("images differ in size");
    ImageDifference diff;
    double sum = 0.0;
    for (size_t i = 0; i < a.pixels().size(); ++i) {
        bool differs = false;
        for (int c = 0; c < 3; ++c) {
            double e = std::abs(double(a.pixels()[i][c]) - double(b.pixels()[i][c]));
            sum += e * e;
            diff.maxError = std::max(diff.maxError, e);
            differs |= e > threshold;
        }
        diff.pixelsDiffering += differs;
    }
    diff.rmse = a.pixels().empty() ? 0.0 : std::sqrt(sum / (3.0 * double(a.pixels().size())));
    return diff;
}

}  // namespace boxes
