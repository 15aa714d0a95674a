// The haze stage (far_field_haze.h) and the haze of covered pixels
// (far_field_stages.h): one transmittance table per frame, applied per pixel.
#include "runtime/engine/far_field_haze.h"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "foundation/timing.h"
#include "runtime/engine/far_field_stages.h"

namespace vista {

namespace {

// Transmittance per 1/1024 of the haze range (linear interpolation: error
// < 1e-6, far below an 8-bit step), then the same blend as applyHaze.
class HazeTable {
public:
    explicit HazeTable(const FrameEffects& fx) : _beta(float(fx.extinction())) {
        const glm::u8vec4 h = fx.hazeColor();
        for (int c = 0; c < 3; ++c) _h[c] = float(h[c]);
        const double step = fx.hazeFar() / kSteps;
        _invStep = float(1.0 / step);
        for (int i = 0; i <= kSteps + 1; ++i) _t[i] = fx.transmittance(i * step);
    }
    // p: an RGBA pixel hazed in place for eye-plane depth z (metres).
    void apply(uint8_t* p, float z) const {
        const float u = std::max(z * _invStep, 0.0f);
        float t;
        if (u < float(kSteps)) {
            const int i = int(u);
            t = _t[i] + (_t[i + 1] - _t[i]) * (u - float(i));
        } else {
            t = std::exp(-_beta * z);  // beyond the visibility (callers normally stop there)
        }
        const float s = 1.0f - t;
        // Round half up; the blend of two values in [0, 255] stays in range.
        for (int c = 0; c < 3; ++c) p[c] = uint8_t(float(p[c]) * t + _h[c] * s + 0.5f);
    }

private:
    static constexpr int kSteps = 1024;
    float _t[kSteps + 2];
    float _beta = 0;
    float _invStep = 1;
    float _h[3];
};

void recordHaze(double ms, FrameStats& stats) {
    stats.stages.add(Stage::Haze, ms);
    stats.effects.add(EffectId::Haze, ms);
}

}  // namespace

void hazeStage(const FrameEffects& fx, const uint32_t* pixels, size_t n, const float* depth, Image& out,
               FrameStats& stats) {
    if (!fx.haze || n == 0) return;
    Stopwatch sw;
    const HazeTable table(fx);
    for (size_t k = 0; k < n; ++k) {
        if (!std::isfinite(depth[k])) continue;
        table.apply(&out.rgba[size_t(pixels ? pixels[k] : uint32_t(k)) * 4], depth[k]);
    }
    recordHaze(sw.ms(), stats);
}

void hazeCoveredStage(FarFrame& f, const FarFieldOptions& o, FrameStats& stats) {
    if (!o.effects.haze || !f.depth) return;
    Stopwatch sw;
    const HazeTable table(o.effects);
    // Eye depth of window depth d: z = a / (b - d) (eyeDepthOfWindowDepth
    // rearranged; infinite far plane: a = n, b = 1), in float: its relative
    // error (1e-7) is far below the table's step.
    const double n = f.camera.zNear, zf = o.depthZFar;
    const float a = float(zf > 0 ? n * zf / (zf - n) : n), b = float(zf > 0 ? zf / (zf - n) : 1.0);
    const size_t W = size_t(f.width);
    inArena(o.threads, [&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, size_t(f.height), 16),
                          [&](const tbb::blocked_range<size_t>& r) {
                              for (size_t y = r.begin(); y != r.end(); ++y)
                                  for (size_t i = y * W, e = i + W; i < e; ++i)
                                      if (f.cls[i] == kFarCovered)
                                          table.apply(&f.out.rgba[i * 4], a / std::max(b - f.depth[i], 1e-30f));
                          });
    });
    recordHaze(sw.ms(), stats);
}

}  // namespace vista
