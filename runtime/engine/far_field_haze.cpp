// The haze stage (far_field_haze.h) and the haze of covered pixels
// (far_field_stages.h): the transmittance evaluated per pixel in arithmetic
// the compiler vectorises, blended on packed pixels.
#include "runtime/engine/far_field_haze.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include <tbb/parallel_for.h>

#include "foundation/timing.h"
#include "runtime/engine/far_field_stages.h"

namespace vista {

namespace {

// A 32-bit view of an RGBA8 pixel (byte 0 = red on the little-endian
// machines vista builds for) that may alias the image's bytes.
typedef uint32_t __attribute__((may_alias)) PixelWord;

// exp(x) for x <= 0 in plain arithmetic the compiler vectorises (no call, no
// table): x = n ln2 + r, 2^n from the exponent bits, e^r by its Taylor
// polynomial to r^7 on |r| < ln2 (relative error < 2e-6, far below an 8-bit
// step). x below -87 gives about 1e-38, x above 0 gives 1.
inline float expNonPositive(float x) {
    x = x < -87.0f ? -87.0f : x;  // branch-free forms, so loops over pixels vectorise
    x = x > 0.0f ? 0.0f : x;
    const float t = x * 1.44269504f;  // x / ln2, in (-126, 0]
    const int n = int(t);             // truncation: n = ceil(t) for t <= 0
    const float r = x - float(n) * 0.693147181f;
    float p = 1.0f / 5040.0f;
    p = p * r + 1.0f / 720.0f;
    p = p * r + 1.0f / 120.0f;
    p = p * r + 1.0f / 24.0f;
    p = p * r + 1.0f / 6.0f;
    p = p * r + 0.5f;
    p = p * r + 1.0f;
    p = p * r + 1.0f;
    const uint32_t bits = uint32_t(n + 127) << 23;
    float scale;
    std::memcpy(&scale, &bits, sizeof scale);
    return p * scale;
}

// The haze blend of FrameEffects::applyHaze for transmittance t, on a packed
// pixel: colour * t + haze * (1 - t), rounded half up; alpha kept.
struct HazeBlend {
    explicit HazeBlend(const FrameEffects& fx) : beta(float(fx.extinction())) {
        const glm::u8vec4 h = fx.hazeColor();
        for (int c = 0; c < 3; ++c) colour[c] = float(h[c]);
    }
    uint32_t apply(uint32_t p, float t) const {
        const float s = 1.0f - t;
        const uint32_t r = uint32_t(int(float(p & 255u) * t + colour[0] * s + 0.5f));
        const uint32_t g = uint32_t(int(float((p >> 8) & 255u) * t + colour[1] * s + 0.5f));
        const uint32_t b = uint32_t(int(float((p >> 16) & 255u) * t + colour[2] * s + 0.5f));
        return r | (g << 8) | (b << 16) | (p & 0xff000000u);
    }
    float beta;
    float colour[3];
};

// The covered pixels of a span hazed for window depths d (eye depth a / (b - d), na = -beta a);
// every pixel is computed and the covered ones kept: a select, so the loop vectorises.
void hazeCoveredSpan(PixelWord* px, const uint8_t* cls, const float* depth, size_t n, float na, float b,
                     const HazeBlend& blend) {
    for (size_t i = 0; i < n; ++i) {
        const uint32_t p = px[i];
        const float w = b - depth[i];
        const uint32_t q = blend.apply(p, expNonPositive(na / (w > 1e-30f ? w : 1e-30f)));
        px[i] = cls[i] == kFarCovered ? q : p;
    }
}

void recordHaze(double ms, FrameStats& stats) {
    stats.stages.add(Stage::Haze, ms);
    stats.effects.add(EffectId::Haze, ms);
}

}  // namespace

void hazeStage(const FrameEffects& fx, const uint32_t* pixels, size_t n, const float* depth, Image& out,
               FrameStats& stats) {
    if (!fx.haze || n == 0) return;
    Stopwatch sw;
    const HazeBlend blend(fx);
    PixelWord* px = reinterpret_cast<PixelWord*>(out.rgba.data());
    constexpr float kInf = std::numeric_limits<float>::infinity();
    if (!pixels) {
        // The whole frame in order (the `raycast` mode): one vectorised pass; sky (+inf) kept.
        for (size_t k = 0; k < n; ++k) {
            const float z = depth[k];
            const uint32_t p = px[k];
            const uint32_t q = blend.apply(p, expNonPositive(-blend.beta * z));
            px[k] = z < kInf ? q : p;
        }
    } else {
        // A pixel list: the transmittances in one vectorised pass, then the blend per pixel.
        std::vector<float> t(n);
        for (size_t k = 0; k < n; ++k) t[k] = expNonPositive(-blend.beta * depth[k]);
        for (size_t k = 0; k < n; ++k) {
            if (!(depth[k] < kInf)) continue;
            PixelWord& p = px[pixels[k]];
            p = blend.apply(p, t[k]);
        }
    }
    recordHaze(sw.ms(), stats);
}

void hazeCoveredStage(FarFrame& f, const FarFieldOptions& o, FrameStats& stats) {
    if (!o.effects.haze || !f.depth) return;
    Stopwatch sw;
    const HazeBlend blend(o.effects);
    // Eye depth of window depth d: z = a / (b - d) (eyeDepthOfWindowDepth
    // rearranged; infinite far plane: a = n, b = 1), in float: its relative
    // error (1e-7) is far below an 8-bit step.
    const double zn = f.camera.zNear, zf = o.depthZFar;
    const float a = float(zf > 0 ? zn * zf / (zf - zn) : zn), b = float(zf > 0 ? zf / (zf - zn) : 1.0);
    const float na = -blend.beta * a;
    const size_t W = size_t(f.width);
    PixelWord* px = reinterpret_cast<PixelWord*>(f.out.rgba.data());
    const uint8_t* cls = f.cls.data();
    const float* depth = f.depth;
    inArena(o.threads, [&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, size_t(f.height), 32),
                          [&](const tbb::blocked_range<size_t>& r) {
                              hazeCoveredSpan(px + r.begin() * W, cls + r.begin() * W, depth + r.begin() * W,
                                              (r.end() - r.begin()) * W, na, b, blend);
                          });
    });
    recordHaze(sw.ms(), stats);
}

}  // namespace vista
