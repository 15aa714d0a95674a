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
#include <tbb/task_group.h>

#include "foundation/timing.h"
#include "runtime/engine/far_field_stages.h"
#define VISTA_HAZE_KERNELS_DEFINE
#include "runtime/engine/haze_kernels.h"

namespace vista {

const HazeKernels& hazeKernelsBaseline() {
    static constexpr HazeKernels k{hazeWindowKernel, hazeDepthKernel, transmittanceKernel};
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
        hazeListed(fx, pixels, n, depth, out);
    }
    recordHaze(sw.ms(), stats);
}

void hazeListed(const FrameEffects& fx, const uint32_t* pixels, size_t n, const float* depth, Image& out) {
    if (!fx.haze || n == 0) return;
    // The transmittances in one vectorised pass, then the blend per pixel.
    const HazeParams h = hazeParams(fx);
    PixelWord* px = reinterpret_cast<PixelWord*>(out.rgba.data());
    constexpr float kInf = std::numeric_limits<float>::infinity();
    std::vector<float> t(n);
    hazeKernels().transmittances(depth, n, h.beta, t.data());
    for (size_t k = 0; k < n; ++k) {
        if (!(depth[k] < kInf)) continue;
        PixelWord& p = px[pixels[k]];
        p = hazeBlend(p, t[k], h);
    }
}

void hazeCoveredRows(const HazeKernels& k, PixelWord* px, const float* depth, size_t width, size_t y0, size_t y1,
                     const uint32_t* skip, size_t nSkip, float na, float b, const HazeParams& h) {
    const uint32_t* skipEnd = skip + nSkip;
    const uint32_t* next = std::lower_bound(skip, skipEnd, uint32_t(y0 * width));
    for (size_t y = y0; y < y1; ++y) {
        const size_t row = y * width;
        const float* d = depth + row;
        PixelWord* p = px + row;
        size_t covered = 0;
        for (size_t x = 0; x < width; ++x) covered += d[x] < 1.0f ? 1u : 0u;  // vectorised count
        const bool skipsHere = next != skipEnd && *next < row + width;
        if (covered == 0) {
            while (next != skipEnd && *next < row + width) ++next;
            continue;
        }
        if (covered == width && !skipsHere) {
            k.window(p, d, width, na, b, h);
            continue;
        }
        // A row the skyline, a far object or a seam hit crosses: its covered runs one by one.
        size_t x = 0;
        while (x < width) {
            while (x < width && !(d[x] < 1.0f && !(next != skipEnd && *next == row + x))) {
                if (next != skipEnd && *next == row + x) ++next;
                ++x;
            }
            const size_t start = x;
            while (x < width && d[x] < 1.0f && !(next != skipEnd && *next == row + x)) ++x;
            if (x > start) k.window(p + start, d + start, x - start, na, b, h);
        }
    }
}

void CoveredHaze::start(const FarFrame& f, const FarFieldOptions& o) {
    if (!o.hazeCovered || !o.effects.haze || !f.depth || f.covered == 0) return;
    _started = true;
    _seamHits.clear();
    for (const uint32_t i : f.seamCandidates)
        if (f.cls[i] != kFarCovered) _seamHits.push_back(i);
    // Eye depth of window depth d: z = a / (b - d) (eyeDepthOfWindowDepth
    // rearranged; infinite far plane: a = n, b = 1), in float: its relative
    // error (1e-7) is far below an 8-bit step.
    const double zn = f.camera.zNear, zf = o.depthZFar;
    const float a = float(zf > 0 ? zn * zf / (zf - zn) : zn), b = float(zf > 0 ? zf / (zf - zn) : 1.0);
    const HazeParams h = hazeParams(o.effects);
    const float na = -h.beta * a;
    const size_t W = size_t(f.width), H = size_t(f.height);
    PixelWord* px = reinterpret_cast<PixelWord*>(f.out.rgba.data());
    const float* depth = f.depth;
    auto body = [this, px, depth, W, H, na, b, h] {
        Stopwatch sw;
        const HazeKernels& kernels = hazeKernels();
        tbb::parallel_for(tbb::blocked_range<size_t>(0, H, 16), [&](const tbb::blocked_range<size_t>& r) {
            hazeCoveredRows(kernels, px, depth, W, r.begin(), r.end(), _seamHits.data(), _seamHits.size(), na, b, h);
        });
        _ms = sw.ms();
    };
    if (o.threads > 0) inArena(o.threads, body);
    else _group.run(body);
}

void CoveredHaze::finish(FrameStats& stats) {
    if (!_started) return;
    _group.wait();
    _started = false;
    recordHaze(_ms, stats);
}

}  // namespace vista
