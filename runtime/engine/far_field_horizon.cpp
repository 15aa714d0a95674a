// Horizon stage (far_field_stages.h): pending pixels above the horizon row of
// their column become sky without a ray.
#include <algorithm>

#include "foundation/timing.h"
#include "runtime/engine/far_field_stages.h"

namespace vista {

HorizonOptions horizonOptions(const FarFieldOptions& o, bool moving) {
    HorizonOptions ho;
    ho.nearDistance = o.nearIsDistance ? o.nearDistance : 0.0;
    ho.subsample = moving ? std::max(1, o.horizonSubsampleMoving) : 1;
    if (o.effects.haze) ho.maxEyeDepth = o.effects.hazeFar();  // nothing beyond is traced
    return ho;
}

void horizonStage(FarFrame& f, const HeightGrid* grid, const FarFieldOptions& o, FrameStats& stats,
                  std::future<HorizonResult>* early) {
    if (!grid) {
        stats.notes.push_back("horizon off: no height grid");
        return;
    }
    Stopwatch sw;
    HorizonResult hr;
    if (early && early->valid()) {
        hr = early->get();  // traced while the near field was drawn; the stage time is the wait
        stats.notes.push_back("horizon overlapped with the near field");
    } else {
        HorizonOptions ho = horizonOptions(o, f.moving);
        ho.columnNeeded = &f.columnNeeded;
        hr = traceHorizon(*grid, f.camera, ho);
    }
    if (!hr.active) {
        stats.notes.push_back(hr.reason);
        return;
    }
    uint64_t culled = 0;
    for (int x = 0; x < f.width; ++x) {
        const int r = std::min(hr.row[size_t(x)], f.height);
        for (int y = 0; y < r; ++y) {
            uint8_t& c = f.cls[size_t(y) * size_t(f.width) + size_t(x)];
            if (c == kFarPending) {
                c = kFarHorizon;
                ++culled;
            }
        }
    }
    stats.pixels.horizonCulled += culled;
    stats.stages.add(Stage::Horizon, sw.ms());
}

void cullAllPending(FarFrame& f, FrameStats& stats) {
    uint64_t sky = 0;
    for (uint8_t& c : f.cls)
        if (c == kFarPending) {
            c = kFarHorizon;
            ++sky;
        }
    stats.pixels.horizonCulled += sky;
}

}  // namespace vista
