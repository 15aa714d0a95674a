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
#define VISTA_HAZE_KERNELS_DEFINE
#include "runtime/engine/haze_kernels.h"

namespace vista {

const HazeKernels& hazeKernelsBaseline() {
    static constexpr HazeKernels k{hazeCoveredKernel, hazeDepthKernel, transmittanceKernel};
    return k;
}

#ifdef VISTA_HAZE_AVX2
const HazeKernels* hazeKernelsAvx2Table();  // haze_kernels_avx2.cpp
const HazeKernels* hazeKernelsAvx2() {
    static const bool has = __builtin_cpu_supports("avx2");
    return has ? hazeKernelsAvx2Table() : nullptr;
}
#else
const HazeKernels* hazeKernelsAvx2() { return nullptr; }
#endif

const HazeKernels& hazeKernels() {
    static const HazeKernels& k = hazeKernelsAvx2() ? *hazeKernelsAvx2() : hazeKernelsBaseline();
    return k;
}

namespace {

HazeParams hazeParams(const FrameEffects& fx) {
    HazeParams h;
    h.beta = float(fx.extinction());
    const glm::u8vec4 c = fx.hazeColor();
    for (int k = 0; k < 3; ++k) h.colour[k] = float(c[k]);
    return h;
}

void recordHaze(double ms, FrameStats& stats) {
    stats.stages.add(Stage::Haze, ms);
    stats.effects.add(EffectId::Haze, ms);
}

}  // namespace

void hazeStage(const FrameEffects& fx, const uint32_t* pixels, size_t n, const float* depth, Image& out,
               FrameStats& stats, int threads) {
    if (!fx.haze || n == 0) return;
    Stopwatch sw;
    const HazeParams h = hazeParams(fx);
    const HazeKernels& kernels = hazeKernels();
    PixelWord* px = reinterpret_cast<PixelWord*>(out.rgba.data());
    if (!pixels) {
        // The whole frame in order (the `raycast` mode): vectorised spans on the arena's threads.
        inArena(threads, [&] {
            tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 16384), [&](const tbb::blocked_range<size_t>& r) {
                kernels.depth(px + r.begin(), depth + r.begin(), r.end() - r.begin(), h);
            });
        });
    } else {
        // A pixel list: the transmittances in one vectorised pass, then the blend per pixel.
        constexpr float kInf = std::numeric_limits<float>::infinity();
        std::vector<float> t(n);
        kernels.transmittances(depth, n, h.beta, t.data());
        for (size_t k = 0; k < n; ++k) {
            if (!(depth[k] < kInf)) continue;
            PixelWord& p = px[pixels[k]];
            p = hazeBlend(p, t[k], h);
        }
    }
    recordHaze(sw.ms(), stats);
}

void hazeCoveredStage(FarFrame& f, const FarFieldOptions& o, FrameStats& stats) {
    if (!o.effects.haze || !f.depth) return;
    Stopwatch sw;
    const HazeParams h = hazeParams(o.effects);
    const HazeKernels& kernels = hazeKernels();
    // Eye depth of window depth d: z = a / (b - d) (eyeDepthOfWindowDepth
    // rearranged; infinite far plane: a = n, b = 1), in float: its relative
    // error (1e-7) is far below an 8-bit step.
    const double zn = f.camera.zNear, zf = o.depthZFar;
    const float a = float(zf > 0 ? zn * zf / (zf - zn) : zn), b = float(zf > 0 ? zf / (zf - zn) : 1.0);
    const float na = -h.beta * a;
    const size_t W = size_t(f.width);
    PixelWord* px = reinterpret_cast<PixelWord*>(f.out.rgba.data());
    const uint8_t* cls = f.cls.data();
    const float* depth = f.depth;
    inArena(o.threads, [&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, size_t(f.height), 32),
                          [&](const tbb::blocked_range<size_t>& r) {
                              kernels.covered(px + r.begin() * W, cls + r.begin() * W, depth + r.begin() * W,
                                              (r.end() - r.begin()) * W, na, b, h);
                          });
    });
    recordHaze(sw.ms(), stats);
}

}  // namespace vista
