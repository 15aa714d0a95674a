// Opacity stage (far_field_stages.h): near-field depth -> covered / pending.
#include <algorithm>

#include "foundation/timing.h"
#include "runtime/engine/far_field_stages.h"

namespace vista {

FarFrame::FarFrame(const Camera& c, const float* d, Image& o, std::vector<uint8_t>& classes)
    : camera(c), rays(c), width(c.width), height(c.height), pixelCount(size_t(c.width) * size_t(c.height)), depth(d),
      out(o), cls(classes) {}

void opacityStage(FarFrame& f, FrameStats& stats, float listAbove) {
    Stopwatch sw;
    const size_t W = size_t(f.width);
    f.cls.assign(f.pixelCount, kFarPending);
    f.columnNeeded.assign(W, 0);
    f.seamCandidates.clear();
    f.covered = 0;
    if (f.depth) {
        for (size_t y = 0; y < size_t(f.height); ++y) {
            const float* d = f.depth + y * W;
            uint8_t* c = &f.cls[y * W];
            for (size_t x = 0; x < W; ++x) {
                if (d[x] < 1.0f) {
                    c[x] = kFarCovered;
                    ++f.covered;
                    if (d[x] >= listAbove) f.seamCandidates.push_back(uint32_t(y * W + x));
                } else {
                    f.columnNeeded[x] = 1;
                }
            }
        }
    } else {
        std::fill(f.columnNeeded.begin(), f.columnNeeded.end(), uint8_t(1));
    }
    stats.stages.add(Stage::Opacity, sw.ms());
}

}  // namespace vista
