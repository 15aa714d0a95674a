#include "runtime/engine/metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "foundation/status.h"

namespace vista {

double lumaOf(const uint8_t* p) { return 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2]; }

double lumaMse(const Image& a, const Image& b) {
    VISTA_CHECK(a.valid() && b.valid() && a.width == b.width && a.height == b.height);
    size_t n = size_t(a.width) * size_t(a.height);
    double sum = 0;
    for (size_t i = 0; i < n; ++i) {
        double d = lumaOf(&a.rgba[i * 4]) - lumaOf(&b.rgba[i * 4]);
        sum += d * d;
    }
    return sum / double(n);
}

double lumaPsnr(const Image& a, const Image& b) {
    double mse = lumaMse(a, b);
    if (mse <= 0) return kPsnrCapDb;
    return std::min(kPsnrCapDb, 10.0 * std::log10(255.0 * 255.0 / mse));
}

double fractionDiffering(const Image& a, const Image& b, int threshold) {
    VISTA_CHECK(a.valid() && b.valid() && a.width == b.width && a.height == b.height);
    size_t n = size_t(a.width) * size_t(a.height), count = 0;
    for (size_t i = 0; i < n; ++i) {
        const uint8_t* p = &a.rgba[i * 4];
        const uint8_t* q = &b.rgba[i * 4];
        int d = std::max({std::abs(p[0] - q[0]), std::abs(p[1] - q[1]), std::abs(p[2] - q[2])});
        if (d > threshold) ++count;
    }
    return double(count) / double(n);
}

Image differenceImage(const Image& a, const Image& b, double gain) {
    VISTA_CHECK(a.valid() && b.valid() && a.width == b.width && a.height == b.height);
    Image out(a.width, a.height);
    size_t n = size_t(a.width) * size_t(a.height);
    for (size_t i = 0; i < n; ++i) {
        double ya = lumaOf(&a.rgba[i * 4]), yb = lumaOf(&b.rgba[i * 4]);
        double d = std::min(255.0, std::abs(ya - yb) * gain);
        uint8_t grey = uint8_t(std::lround(yb * 0.35));
        uint8_t* o = &out.rgba[i * 4];
        if (d >= 1.0) {
            o[0] = uint8_t(std::max<double>(grey, d));
            o[1] = uint8_t(grey * (1.0 - d / 255.0));
            o[2] = o[1];
        } else {
            o[0] = o[1] = o[2] = grey;
        }
        o[3] = 255;
    }
    return out;
}

Image downsampleBox(const Image& src, int k) {
    VISTA_CHECK(src.valid() && k >= 1 && src.width % k == 0 && src.height % k == 0);
    Image out(src.width / k, src.height / k);
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x) {
            unsigned sum[4] = {0, 0, 0, 0};
            for (int j = 0; j < k; ++j)
                for (int i = 0; i < k; ++i) {
                    const uint8_t* p = &src.rgba[(size_t(y * k + j) * size_t(src.width) + size_t(x * k + i)) * 4];
                    for (int c = 0; c < 4; ++c) sum[c] += p[c];
                }
            unsigned kk = unsigned(k * k);
            uint8_t* o = &out.rgba[(size_t(y) * size_t(out.width) + size_t(x)) * 4];
            for (int c = 0; c < 4; ++c) o[c] = uint8_t((sum[c] + kk / 2) / kk);
        }
    return out;
}

Image averageImages(const std::vector<Image>& images) {
    VISTA_CHECK(!images.empty());
    const Image& f = images.front();
    for (const auto& im : images) VISTA_CHECK(im.valid() && im.width == f.width && im.height == f.height);
    Image out(f.width, f.height);
    size_t n = f.rgba.size(), cnt = images.size();
    for (size_t i = 0; i < n; ++i) {
        size_t s = 0;
        for (const auto& im : images) s += im.rgba[i];
        out.rgba[i] = uint8_t((s + cnt / 2) / cnt);
    }
    return out;
}

}  // namespace vista
