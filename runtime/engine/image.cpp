// PNG I/O for Image (libpng). See image.h for the contract.
#include "runtime/engine/image.h"

#include <algorithm>

#include "foundation/atomic_file.h"

#include <png.h>

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <memory>

namespace vista {

namespace {

struct FileCloser {
    void operator()(FILE* f) const {
        if (f) std::fclose(f);
    }
};

// libpng reports errors through longjmp; we keep the message for the Status.
struct PngErr {
    char message[256] = {0};
};

void pngErrorFn(png_structp png, png_const_charp msg) {
    auto* e = static_cast<PngErr*>(png_get_error_ptr(png));
    if (e) std::snprintf(e->message, sizeof(e->message), "%s", msg ? msg : "unknown libpng error");
    png_longjmp(png, 1);
}
void pngWarnFn(png_structp, png_const_charp) {}

// libpng writes into a string; the file is then written atomically.
void pngWriteToString(png_structp png, png_bytep data, png_size_t n) {
    static_cast<std::string*>(png_get_io_ptr(png))->append(reinterpret_cast<const char*>(data), n);
}
void pngFlushNothing(png_structp) {}

}  // namespace

namespace {

// PNG bytes of 8-bit rows (`channels` 1 = gray, 3 = RGB, 4 = RGBA); `what`
// names the output in an error.
Result<std::string> encodePngRows(const uint8_t* data, int width, int height, int channels, const std::string& what) {
    PngErr err;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &err, pngErrorFn, pngWarnFn);
    if (!png) return Status::error("writePng '" + what + "': libpng init failed");
    png_infop info = png_create_info_struct(png);
    std::vector<png_bytep> rows(static_cast<size_t>(height));
    for (int y = 0; y < height; ++y)
        rows[size_t(y)] = const_cast<png_bytep>(data + size_t(y) * size_t(width) * size_t(channels));
    std::string bytes;
    volatile bool failed = false;
    if (setjmp(png_jmpbuf(png))) {
        failed = true;
    } else {
        png_set_write_fn(png, &bytes, pngWriteToString, pngFlushNothing);
        // Fast settings (zlib level 1, one filter for every row): a 640x480 frame encodes in a
        // third of the time of adaptive filtering at level 3, for files a few percent larger.
        png_set_compression_level(png, 1);
        png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_UP);
        png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), 8,
                     channels == 1   ? PNG_COLOR_TYPE_GRAY
                     : channels == 3 ? PNG_COLOR_TYPE_RGB
                                     : PNG_COLOR_TYPE_RGBA,
                     PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
        png_write_info(png, info);
        png_write_image(png, rows.data());
        png_write_end(png, nullptr);
    }
    png_destroy_write_struct(&png, &info);
    if (failed) return Status::error("writePng '" + what + "': encoding failed: " + err.message);
    return bytes;
}

Status writeBytes(const Result<std::string>& bytes, const std::string& path) {
    if (!bytes) return bytes.status();
    return writeFileAtomic(path, bytes.value());
}

}  // namespace

Status writePng(const Image& img, const std::string& path) {
    if (!img.valid())
        return Status::error("writePng '" + path + "': invalid image " + std::to_string(img.width) + "x" +
                             std::to_string(img.height));
    return writeBytes(encodePngRows(img.rgba.data(), img.width, img.height, 4, path), path);
}

Result<std::string> pngRgbBytes(const Image& img, const std::string& what) {
    if (!img.valid())
        return Status::error("writePngRgb '" + what + "': invalid image " + std::to_string(img.width) + "x" +
                             std::to_string(img.height));
    std::vector<uint8_t> rgb(size_t(img.width) * size_t(img.height) * 3);
    for (size_t i = 0, n = rgb.size() / 3; i < n; ++i) std::copy_n(&img.rgba[4 * i], 3, &rgb[3 * i]);
    return encodePngRows(rgb.data(), img.width, img.height, 3, what);
}

Status writePngRgb(const Image& img, const std::string& path) { return writeBytes(pngRgbBytes(img, path), path); }

Result<std::string> pngGray8Bytes(const std::vector<uint8_t>& pixels, int width, int height, const std::string& what) {
    if (width < 1 || height < 1 || pixels.size() != size_t(width) * size_t(height))
        return Status::error("writePngGray8 '" + what + "': " + std::to_string(pixels.size()) + " pixels for " +
                             std::to_string(width) + "x" + std::to_string(height));
    return encodePngRows(pixels.data(), width, height, 1, what);
}

Status writePngGray8(const std::vector<uint8_t>& pixels, int width, int height, const std::string& path) {
    return writeBytes(pngGray8Bytes(pixels, width, height, path), path);
}

Result<Image> readPng(const std::string& path) {
    std::unique_ptr<FILE, FileCloser> f(std::fopen(path.c_str(), "rb"));
    if (!f) return Status::error("readPng '" + path + "': cannot open: " + std::strerror(errno));
    unsigned char sig[8];
    if (std::fread(sig, 1, 8, f.get()) != 8 || png_sig_cmp(sig, 0, 8) != 0)
        return Status::error("readPng '" + path + "': not a PNG file");
    PngErr err;
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &err, pngErrorFn, pngWarnFn);
    if (!png) return Status::error("readPng '" + path + "': libpng init failed");
    png_infop info = png_create_info_struct(png);
    Image img;
    std::vector<png_bytep> rows;
    volatile bool failed = false;
    if (setjmp(png_jmpbuf(png))) {
        failed = true;
    } else {
        png_init_io(png, f.get());
        png_set_sig_bytes(png, 8);
        png_set_user_limits(png, 1u << 16, 1u << 16);
        png_read_info(png, info);
        png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
        int ct = png_get_color_type(png, info), bd = png_get_bit_depth(png, info);
        if (bd == 16) png_set_strip_16(png);
        if (ct == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
        if (ct == PNG_COLOR_TYPE_GRAY && bd < 8) png_set_expand_gray_1_2_4_to_8(png);
        if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
        if (ct == PNG_COLOR_TYPE_GRAY || ct == PNG_COLOR_TYPE_GRAY_ALPHA) png_set_gray_to_rgb(png);
        if (!(ct & PNG_COLOR_MASK_ALPHA) && !png_get_valid(png, info, PNG_INFO_tRNS))
            png_set_filler(png, 0xFF, PNG_FILLER_AFTER);
        png_read_update_info(png, info);
        if (png_get_rowbytes(png, info) != size_t(w) * 4) png_error(png, "unsupported pixel format");
        img = Image(int(w), int(h));
        rows.resize(h);
        for (png_uint_32 y = 0; y < h; ++y) rows[y] = &img.rgba[size_t(y) * size_t(w) * 4];
        png_read_image(png, rows.data());
        png_read_end(png, nullptr);
    }
    png_destroy_read_struct(&png, &info, nullptr);
    if (failed) return Status::error("readPng '" + path + "': corrupt or truncated PNG: " + err.message);
    if (!img.valid()) return Status::error("readPng '" + path + "': empty image");
    return img;
}

}  // namespace vista
