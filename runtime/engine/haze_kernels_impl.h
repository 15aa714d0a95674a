// The haze kernels' definitions (declared in haze_kernels.h), included by the
// two files that compile them: far_field_haze.cpp (the baseline) and
// haze_kernels_avx2.cpp (-mavx2). Everything here has internal linkage (an
// unnamed namespace) and calls no out-of-line template, so code compiled for
// AVX2 never stands in for the baseline's. No include guard: each of the two
// files includes it once.
#include <cstddef>
#include <cstdint>
#include <cstring>
#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include "runtime/engine/haze_kernels.h"

namespace vista {
namespace {

// The table entry of reciprocal eye depth u: its float bits select the bucket.
inline int32_t hazeTableIndexOfU(float u, const HazeTableView& table) {
    uint32_t bits;
    std::memcpy(&bits, &u, sizeof bits);
    int32_t i = int32_t(bits >> HazeTableView::kShift) - table.base;  // a negative u: past the end
    i = i < 0 ? 0 : i;
    return i > table.last ? table.last : i;
}

// The table entry of window depth d: u = (b - d) invA is the reciprocal eye depth.
inline int32_t hazeTableIndex(float d, float invA, float b, const HazeTableView& table) {
    return hazeTableIndexOfU((b - d) * invA, table);
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

#if defined(__AVX2__)
// The AVX2 blend of eight pixels at reciprocal eye depths u: the table's T
// gathered, then h + (c - h) T / 32768 per channel by pmulhrsw (hazeBlendFixed's bytes).
struct HazeBlend8 {
    __m256i base, last, zero, low16, alpha, hc;
    const uint16_t* t;
    HazeBlend8(const HazeTableView& table, const int32_t* h)
        : base(_mm256_set1_epi32(table.base)),
          last(_mm256_set1_epi32(table.last)),
          zero(_mm256_setzero_si256()),
          low16(_mm256_set1_epi32(0xffff)),
          alpha(_mm256_set1_epi32(int32_t(0xff000000u))),
          // The haze colour as 16-bit channels of two pixels (alpha 0: restored from the source).
          hc(_mm256_set_epi16(0, int16_t(h[2]), int16_t(h[1]), int16_t(h[0]), 0, int16_t(h[2]), int16_t(h[1]),
                              int16_t(h[0]), 0, int16_t(h[2]), int16_t(h[1]), int16_t(h[0]), 0, int16_t(h[2]),
                              int16_t(h[1]), int16_t(h[0]))),
          t(table.t) {}
    __m256i operator()(__m256i p8, __m256 u) const {
        __m256i idx = _mm256_sub_epi32(_mm256_srli_epi32(_mm256_castps_si256(u), HazeTableView::kShift), base);
        idx = _mm256_min_epi32(_mm256_max_epi32(idx, zero), last);
        // T per pixel (16 bits of a 32-bit gather at 2-byte steps), then in each 16-bit half.
        __m256i T = _mm256_and_si256(_mm256_i32gather_epi32(reinterpret_cast<const int*>(t), idx, 2), low16);
        T = _mm256_or_si256(T, _mm256_slli_epi32(T, 16));
        // Channels as 16-bit lanes: pixels 0, 1 | 4, 5 in lo, 2, 3 | 6, 7 in hi; T likewise.
        const __m256i lo = _mm256_unpacklo_epi8(p8, zero), hi = _mm256_unpackhi_epi8(p8, zero);
        const __m256i tLo = _mm256_unpacklo_epi32(T, T), tHi = _mm256_unpackhi_epi32(T, T);
        const __m256i rLo = _mm256_add_epi16(hc, _mm256_mulhrs_epi16(_mm256_sub_epi16(lo, hc), tLo));
        const __m256i rHi = _mm256_add_epi16(hc, _mm256_mulhrs_epi16(_mm256_sub_epi16(hi, hc), tHi));
        return _mm256_or_si256(_mm256_andnot_si256(alpha, _mm256_packus_epi16(rLo, rHi)), _mm256_and_si256(alpha, p8));
    }
};
#endif

void hazeWindowKernel(PixelWord* px, const float* depth, size_t n, float invA, float b, const HazeTableView& table,
                      const HazeParams& p) {
    const int32_t h[3] = {int32_t(p.colour[0]), int32_t(p.colour[1]), int32_t(p.colour[2])};
    size_t i = 0;
#if defined(__AVX2__)
    const HazeBlend8 blend(table, h);
    const __m256 vb = _mm256_set1_ps(b), vInvA = _mm256_set1_ps(invA), one = _mm256_set1_ps(1.0f);
    for (; i + 8 <= n; i += 8) {
        const __m256 d = _mm256_loadu_ps(depth + i);
        const __m256i covered = _mm256_castps_si256(_mm256_cmp_ps(d, one, _CMP_LT_OQ));
        const int coveredBits = _mm256_movemask_ps(_mm256_castsi256_ps(covered));
        if (coveredBits == 0) continue;
        const bool all = coveredBits == 0xff;  // plain loads and stores (masked ones cost more)
        const __m256i p8 = all ? _mm256_loadu_si256(reinterpret_cast<const __m256i*>(px + i))
                               : _mm256_maskload_epi32(reinterpret_cast<const int*>(px + i), covered);
        const __m256i q = blend(p8, _mm256_mul_ps(_mm256_sub_ps(vb, d), vInvA));
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

void hazeDepthKernel(PixelWord* px, const float* depth, size_t n, const HazeTableView& table, const HazeParams& p) {
    const int32_t h[3] = {int32_t(p.colour[0]), int32_t(p.colour[1]), int32_t(p.colour[2])};
    size_t i = 0;
#if defined(__AVX2__)
    const HazeBlend8 blend(table, h);
    const __m256 one = _mm256_set1_ps(1.0f), inf = _mm256_set1_ps(__builtin_inff());
    for (; i + 8 <= n; i += 8) {
        const __m256 z = _mm256_loadu_ps(depth + i);
        const __m256 shown = _mm256_cmp_ps(z, inf, _CMP_LT_OQ);
        if (_mm256_movemask_ps(shown) == 0) continue;
        const __m256i p8 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(px + i));
        const __m256i q = blend(p8, _mm256_div_ps(one, z));
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(px + i), _mm256_blendv_epi8(p8, q, _mm256_castps_si256(shown)));
    }
#endif
    for (; i < n; ++i)
        if (depth[i] < __builtin_inff())
            px[i] = hazeBlendFixed(px[i], table.t[hazeTableIndexOfU(1.0f / depth[i], table)], h);
}

}  // namespace
}  // namespace vista
