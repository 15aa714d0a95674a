// Haze stage: FrameEffects::applyHaze over pixels whose eye-plane depth is
// known (the far field's lattice of traced pixels), with the transmittance
// read from a table over the reciprocal depth (HazeTableView: within one
// level of applyHaze) and blended in fixed point.
//
// hazeStage(): hazes the n listed pixels (indices y * width + x) at their
// eye-plane depth (depth[k] for entry k, metres; +inf = sky, left alone) on
// the calling thread. Records Stage::Haze and the haze effect when fx.haze
// and n > 0; else does nothing. Contract: every listed index < out's pixel
// count. Thread-safe for distinct outputs.
#pragma once
#include <cstddef>
#include <cstdint>

#include "runtime/engine/frame_effects.h"
#include "runtime/engine/frame_stats.h"
#include "runtime/engine/haze_kernels.h"
#include "runtime/engine/image.h"

namespace vista {

void hazeStage(const FrameEffects& fx, const uint32_t* pixels, size_t n, const float* depth, Image& out,
               FrameStats& stats);

// The haze of fx for a caller that hazes pixels as it writes them (the ray
// casts with RayShading::haze): (px, depth, n) hazes the n RGBA8 words px[k]
// at eye depth depth[k] (+inf: left alone) on the calling thread, as
// hazeStage would (bench_far_field's BM_HazeAtDepth times it over a frame).
// Made once per frame (it looks up the table); does nothing without fx.haze.
class DepthHaze {
public:
    explicit DepthHaze(const FrameEffects& fx);
    void operator()(uint32_t* px, const float* depth, size_t n) const;

private:
    bool _on;
    HazeParams _h;
    HazeTableView _table;
    const HazeKernels* _kernels;
};

}  // namespace vista
