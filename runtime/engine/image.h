// Image: 8-bit RGBA raster (row 0 at the top) plus PNG I/O.
//
// Contract: rgba.size() == width * height * 4 for a valid image. writePng is
// atomic (temp + rename) and returns an error naming the path; readPng
// rejects missing/corrupt/truncated files with an error, never crashes.
// pngRgbBytes and pngGray8Bytes are the bytes writePngRgb and writePngGray8
// write (for a caller that writes them itself); `what` names the output in
// an error.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "foundation/status.h"

namespace vista {

struct Image {
    int width = 0, height = 0;
    std::vector<uint8_t> rgba;

    Image() = default;
    Image(int w, int h) : width(w), height(h), rgba(size_t(w) * size_t(h) * 4, 0) {}
    bool valid() const { return width > 0 && height > 0 && rgba.size() == size_t(width) * size_t(height) * 4; }
    glm::u8vec4 at(int x, int y) const {
        const uint8_t* p = &rgba[(size_t(y) * size_t(width) + size_t(x)) * 4];
        return {p[0], p[1], p[2], p[3]};
    }
    void set(int x, int y, const glm::u8vec4& c) {
        uint8_t* p = &rgba[(size_t(y) * size_t(width) + size_t(x)) * 4];
        p[0] = c.x;
        p[1] = c.y;
        p[2] = c.z;
        p[3] = c.w;
    }
};

Status writePng(const Image& img, const std::string& path);
// RGB PNG (alpha dropped); atomic.
Status writePngRgb(const Image& img, const std::string& path);
// 8-bit grayscale PNG of width x height pixels (row 0 at the top); atomic.
Status writePngGray8(const std::vector<uint8_t>& pixels, int width, int height, const std::string& path);
Result<std::string> pngRgbBytes(const Image& img, const std::string& what);
Result<std::string> pngGray8Bytes(const std::vector<uint8_t>& pixels, int width, int height, const std::string& what);
Result<Image> readPng(const std::string& path);

}  // namespace vista
