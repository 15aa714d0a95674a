// The haze's per-pixel loops (far_field_haze.cpp), written once and compiled
// twice: for the baseline x86-64 the binary targets (far_field_haze.cpp) and,
// on x86-64, for AVX2 (haze_kernels_avx2.cpp, built with -mavx2: eight float
// lanes instead of four); hazeKernels() picks the second when the CPU has
// AVX2 (detected once). Both compute the same bytes: no fused multiply-adds
// (-ffp-contract=off on both files) and the same operations in the same order.
//
// Everything defined in this header has internal linkage (an unnamed
// namespace) and calls no out-of-line template, so code compiled for AVX2
// never stands in for the baseline's.
//
// Kernels (PixelWord: an RGBA8 pixel as a 32-bit word, red in byte 0):
//   window(px, depth, n, na, b, p): every pixel of a span hazed at eye depth
//     a / (b - depth) (window depth; na = -beta a). Writes those n pixels only,
//     so spans of covered pixels can be hazed while other threads write the
//     pixels between them.
//   depth(px, depth, n, p): pixels hazed at eye depth depth[k] (+inf = sky, kept).
//   transmittances(depth, n, beta, t): t[k] = exp(-beta depth[k]).
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace vista {

// A 32-bit view of an RGBA8 pixel that may alias the image's bytes.
typedef uint32_t __attribute__((may_alias)) PixelWord;

struct HazeParams {
    float beta = 0;               // extinction, 1/m
    float colour[3] = {0, 0, 0};  // haze colour, 0..255
};

struct HazeKernels {
    void (*window)(PixelWord* px, const float* depth, size_t n, float na, float b, const HazeParams& p);
    void (*depth)(PixelWord* px, const float* depth, size_t n, const HazeParams& p);
    void (*transmittances)(const float* depth, size_t n, float beta, float* t);
};

// The kernels for this CPU.
const HazeKernels& hazeKernels();
// The covered pixels of rows [y0, y1) of a frame `width` pixels wide, hazed by
// k.window: the runs of window depth < 1 (the opacity stage's rule) less the
// pixels listed in skip (ascending indices y * width + x). No other pixel is
// read or written.
void hazeCoveredRows(const HazeKernels& k, PixelWord* px, const float* depth, size_t width, size_t y0, size_t y1,
                     const uint32_t* skip, size_t nSkip, float na, float b, const HazeParams& h);
// The baseline kernels and, where built and supported by the CPU, the AVX2 ones (else null).
const HazeKernels& hazeKernelsBaseline();
const HazeKernels* hazeKernelsAvx2();

#ifdef VISTA_HAZE_KERNELS_DEFINE
namespace {

// exp(x) for x <= 0 in plain arithmetic the compiler vectorises (no call, no
// table): x = n ln2 + r, 2^n from the exponent bits, e^r by its Taylor
// polynomial to r^7 on |r| < ln2 (relative error < 2e-6, far below an 8-bit
// step). x below -87 gives about 1e-38, x above 0 gives 1.
inline float expNonPositive(float x) {
    x = x < -87.0f ? -87.0f : x;  // selects, not branches: loops over pixels vectorise
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

// FrameEffects::applyHaze for transmittance t on a packed pixel: colour * t +
// haze * (1 - t), rounded half up; alpha kept. Signed conversions only (int
// <-> float have vector forms on every x86 level).
inline uint32_t hazeBlend(uint32_t p, float t, const HazeParams& h) {
    const float s = 1.0f - t;
    const int r = int(float(int(p & 255u)) * t + h.colour[0] * s + 0.5f);
    const int g = int(float(int((p >> 8) & 255u)) * t + h.colour[1] * s + 0.5f);
    const int b = int(float(int((p >> 16) & 255u)) * t + h.colour[2] * s + 0.5f);
    return uint32_t(r | (g << 8) | (b << 16)) | (p & 0xff000000u);
}

void hazeWindowKernel(PixelWord* px, const float* depth, size_t n, float na, float b, const HazeParams& h) {
    for (size_t i = 0; i < n; ++i) {
        float w = b - depth[i];
        w = w > 1e-30f ? w : 1e-30f;
        px[i] = hazeBlend(px[i], expNonPositive(na / w), h);
    }
}

void hazeDepthKernel(PixelWord* px, const float* depth, size_t n, const HazeParams& h) {
    for (size_t k = 0; k < n; ++k) {
        const float z = depth[k];
        const uint32_t p = px[k];
        const uint32_t q = hazeBlend(p, expNonPositive(-h.beta * z), h);
        const uint32_t keep = uint32_t(z < __builtin_inff()) - 1u;  // all ones = sky: unchanged
        px[k] = (q & ~keep) | (p & keep);
    }
}

void transmittanceKernel(const float* depth, size_t n, float beta, float* t) {
    for (size_t k = 0; k < n; ++k) t[k] = expNonPositive(-beta * depth[k]);
}

}  // namespace
#endif

}  // namespace vista
