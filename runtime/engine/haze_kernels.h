// The haze's per-pixel loops, written once (haze_kernels_impl.h) and
// compiled twice: for the baseline x86-64 the binary targets
// (far_field_haze.cpp) and, on x86-64, for AVX2 (haze_kernels_avx2.cpp, built
// with -mavx2: eight pixels a step in AVX2 intrinsics: gathers from the
// table, masked loads and stores); hazeKernels() picks the second when the
// CPU has it (detected once). Both compute the same bytes: no fused
// multiply-adds (-ffp-contract=off on both files), correctly rounded
// divisions, and the same integer blend.
//
// Kernels (PixelWord: an RGBA8 pixel as a 32-bit word, red in byte 0). Both
// read the transmittance from a table over the reciprocal eye depth
// (HazeTableView) and blend in fixed point (hazeBlendFixed):
//   window(px, depth, n, invA, b, table, p): the pixels of a span whose window
//     depth is < 1 (the opacity stage's covered rule) hazed at eye depth
//     a / (b - depth). Pixels of window depth 1 are neither read nor written,
//     so a span may hold pixels other threads write.
//   depth(px, depth, n, table, p): pixels hazed at eye depth depth[k]
//     (+inf = sky, kept: neither the table nor the blend touches it).
#pragma once
#include <cstddef>
#include <cstdint>

namespace vista {

// A 32-bit view of an RGBA8 pixel that may alias the image's bytes.
typedef uint32_t __attribute__((may_alias)) PixelWord;

struct HazeParams {
    float beta = 0;               // extinction, 1/m
    float colour[3] = {0, 0, 0};  // haze colour, 0..255
};

// The transmittance of a hazed pixel as a table over the reciprocal eye
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
    void (*depth)(PixelWord* px, const float* depth, size_t n, const HazeTableView& table, const HazeParams& p);
};

// The kernels for this CPU.
const HazeKernels& hazeKernels();
// The covered pixels of rows [y0, y1) of a frame `width` pixels wide, hazed by
// k.window: the pixels of window depth < 1 (the opacity stage's rule). No
// other pixel is read or written. Eye depth of window depth d: a / (b - d),
// invA = 1 / a.
void hazeCoveredRows(const HazeKernels& k, PixelWord* px, const float* depth, size_t width, size_t y0, size_t y1,
                     float invA, float b, const HazeTableView& table, const HazeParams& h);
// The table for extinction beta > 0 (1/m): made once per extinction and kept
// (the last few); thread-safe.
HazeTableView hazeTable(float beta);
// The baseline kernels and, where built and supported by the CPU, the AVX2 ones (else null).
const HazeKernels& hazeKernelsBaseline();
const HazeKernels* hazeKernelsAvx2();

}  // namespace vista
