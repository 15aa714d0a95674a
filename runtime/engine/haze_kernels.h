// The haze's per-pixel loops (far_field_haze.cpp), written once and compiled
// twice: for the baseline x86-64 the binary targets (far_field_haze.cpp) and,
// on x86-64, for AVX2 (haze_kernels_avx2.cpp, built with -mavx2: eight float
// lanes instead of four, and the covered pixels' kernel in AVX2 intrinsics:
// gathers from the table, masked loads and stores); hazeKernels() picks the
// second when the CPU has it (detected once). Both compute the same bytes: no
// fused multiply-adds (-ffp-contract=off on both files) and the same
// operations in the same order.
//
// Everything defined in this header has internal linkage (an unnamed
// namespace) and calls no out-of-line template, so code compiled for AVX2
// never stands in for the baseline's.
//
// Kernels (PixelWord: an RGBA8 pixel as a 32-bit word, red in byte 0):
//   window(px, depth, n, invA, b, table, p): the pixels of a span whose window
//     depth is < 1 (the opacity stage's covered rule) hazed at eye depth
//     a / (b - depth), by the transmittance table (HazeTableView) and the
//     fixed-point blend of hazeBlendFixed. Pixels of window depth 1 are
//     neither read nor written, so a span may hold pixels other threads write.
//   depth(px, depth, n, p): pixels hazed at eye depth depth[k] (+inf = sky, kept).
//   transmittances(depth, n, beta, t): t[k] = exp(-beta depth[k]).
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstring>
#if defined(VISTA_HAZE_KERNELS_DEFINE) && defined(__AVX2__)
#include <immintrin.h>
#endif

namespace vista {

// A 32-bit view of an RGBA8 pixel that may alias the image's bytes.
typedef uint32_t __attribute__((may_alias)) PixelWord;

struct HazeParams {
    float beta = 0;               // extinction, 1/m
    float colour[3] = {0, 0, 0};  // haze colour, 0..255
};

// The transmittance of the covered pixels as a table over the reciprocal eye
// depth u = 1 / z: entry i holds T = round(32768 exp(-beta / u)) (at most
// 32767) at the middle of the bucket of floats u whose bits >> kShift are
// base + i; u beyond the table takes its end entries (u below it: T = 0 to
// within 2^-16; above it: T = 32767). Nine mantissa bits a bucket: z is known
// to 2^-10 of itself, so T is within 0.1 of an 8-bit level of the exact
// blend (HazeKernels test), from 20 KB of entries for any extinction.
struct HazeTableView {
    static constexpr int kShift = 14;  // 23 - 9 mantissa bits
    const uint16_t* t = nullptr;       // last + 2 entries (one of padding for 32-bit gathers)
    int32_t base = 0;
    int32_t last = 0;
};

struct HazeKernels {
    void (*window)(PixelWord* px, const float* depth, size_t n, float invA, float b, const HazeTableView& table,
                   const HazeParams& p);
    void (*depth)(PixelWord* px, const float* depth, size_t n, const HazeParams& p);
    void (*transmittances)(const float* depth, size_t n, float beta, float* t);
};

// The kernels for this CPU.
const HazeKernels& hazeKernels();
// The covered pixels of rows [y0, y1) of a frame `width` pixels wide, hazed by
// k.window: the pixels of window depth < 1 (the opacity stage's rule) less the
// pixels listed in skip (ascending indices y * width + x). No other pixel is
// read or written. Eye depth of window depth d: a / (b - d), invA = 1 / a.
void hazeCoveredRows(const HazeKernels& k, PixelWord* px, const float* depth, size_t width, size_t y0, size_t y1,
                     const uint32_t* skip, size_t nSkip, float invA, float b, const HazeTableView& table,
                     const HazeParams& h);
// The table for extinction beta > 0 (1/m): made once per extinction and kept
// (the last few); thread-safe.
HazeTableView hazeTable(float beta);
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

// The table's transmittance for window depth d: u = (b - d) invA is the
// reciprocal eye depth; its float bits select the bucket.
inline int32_t hazeTableIndex(float d, float invA, float b, const HazeTableView& table) {
    const float u = (b - d) * invA;
    uint32_t bits;
    std::memcpy(&bits, &u, sizeof bits);
    int32_t i = int32_t(bits >> HazeTableView::kShift) - table.base;  // a negative u: past the end
    i = i < 0 ? 0 : i;
    return i > table.last ? table.last : i;
}

// colour + (haze - colour) (1 - T / 32768) in fixed point, rounded half up:
// h + floor(((c - h) T + 2^14) / 2^15) per channel (the AVX2 kernel's
// pmulhrsw), the floor taken on a non-negative sum (255 2^15 added, 255 taken
// off after the shift) so that no negative number is shifted; alpha kept.
inline uint32_t hazeBlendFixed(uint32_t p, int32_t T, const int32_t* h) {
    uint32_t q = p & 0xff000000u;
    for (int k = 0; k < 3; ++k) {
        const int32_t c = int32_t((p >> (8 * k)) & 255u);
        const int32_t step = int32_t(uint32_t((c - h[k]) * T + 16384 + 255 * 32768) >> 15) - 255;
        q |= uint32_t(h[k] + step) << (8 * k);
    }
    return q;
}

void hazeWindowKernel(PixelWord* px, const float* depth, size_t n, float invA, float b, const HazeTableView& table,
                      const HazeParams& p) {
    const int32_t h[3] = {int32_t(p.colour[0]), int32_t(p.colour[1]), int32_t(p.colour[2])};
    size_t i = 0;
#if defined(__AVX2__)
    const __m256 vb = _mm256_set1_ps(b), vInvA = _mm256_set1_ps(invA), one = _mm256_set1_ps(1.0f);
    const __m256i base = _mm256_set1_epi32(table.base), last = _mm256_set1_epi32(table.last),
                  zero = _mm256_setzero_si256(), low16 = _mm256_set1_epi32(0xffff),
                  alpha = _mm256_set1_epi32(int32_t(0xff000000u));
    // The haze colour as 16-bit channels of two pixels (alpha 0: restored from the source).
    const __m256i hc = _mm256_set_epi16(0, int16_t(h[2]), int16_t(h[1]), int16_t(h[0]), 0, int16_t(h[2]), int16_t(h[1]),
                                        int16_t(h[0]), 0, int16_t(h[2]), int16_t(h[1]), int16_t(h[0]), 0, int16_t(h[2]),
                                        int16_t(h[1]), int16_t(h[0]));
    for (; i + 8 <= n; i += 8) {
        const __m256 d = _mm256_loadu_ps(depth + i);
        const __m256i covered = _mm256_castps_si256(_mm256_cmp_ps(d, one, _CMP_LT_OQ));
        const int coveredBits = _mm256_movemask_ps(_mm256_castsi256_ps(covered));
        if (coveredBits == 0) continue;
        const bool all = coveredBits == 0xff;  // plain loads and stores (masked ones cost more)
        const __m256 u = _mm256_mul_ps(_mm256_sub_ps(vb, d), vInvA);
        __m256i idx = _mm256_sub_epi32(_mm256_srli_epi32(_mm256_castps_si256(u), HazeTableView::kShift), base);
        idx = _mm256_min_epi32(_mm256_max_epi32(idx, zero), last);
        // T per pixel (16 bits of a 32-bit gather at 2-byte steps), then in each 16-bit half.
        __m256i T = _mm256_and_si256(_mm256_i32gather_epi32(reinterpret_cast<const int*>(table.t), idx, 2), low16);
        T = _mm256_or_si256(T, _mm256_slli_epi32(T, 16));
        const __m256i p8 = all ? _mm256_loadu_si256(reinterpret_cast<const __m256i*>(px + i))
                               : _mm256_maskload_epi32(reinterpret_cast<const int*>(px + i), covered);
        // Channels as 16-bit lanes: pixels 0, 1 | 4, 5 in lo, 2, 3 | 6, 7 in hi; T likewise.
        const __m256i lo = _mm256_unpacklo_epi8(p8, zero), hi = _mm256_unpackhi_epi8(p8, zero);
        const __m256i tLo = _mm256_unpacklo_epi32(T, T), tHi = _mm256_unpackhi_epi32(T, T);
        const __m256i rLo = _mm256_add_epi16(hc, _mm256_mulhrs_epi16(_mm256_sub_epi16(lo, hc), tLo));
        const __m256i rHi = _mm256_add_epi16(hc, _mm256_mulhrs_epi16(_mm256_sub_epi16(hi, hc), tHi));
        const __m256i q =
            _mm256_or_si256(_mm256_andnot_si256(alpha, _mm256_packus_epi16(rLo, rHi)), _mm256_and_si256(alpha, p8));
        if (all) _mm256_storeu_si256(reinterpret_cast<__m256i*>(px + i), q);
        else _mm256_maskstore_epi32(reinterpret_cast<int*>(px + i), covered, q);
    }
#endif
    while (i < n) {  // runs of covered pixels (the baseline's whole span, the AVX2 kernel's tail)
        while (i < n && !(depth[i] < 1.0f)) ++i;
        const size_t end = [&] {
            size_t e = i;
            while (e < n && depth[e] < 1.0f) ++e;
            return e;
        }();
        for (; i < end; ++i) px[i] = hazeBlendFixed(px[i], table.t[hazeTableIndex(depth[i], invA, b, table)], h);
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
