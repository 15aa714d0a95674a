// Opacity stage (far_field_stages.h): near-field depth -> covered / pending.
#include <algorithm>

#include "foundation/timing.h"
#include "runtime/engine/far_field_stages.h"

namespace vista {

FarFrame::FarFrame(const Camera& c, const float* d, Image& o, std::vector<uint8_t>& classes)
    : camera(c),
      rays(c),
      width(c.width),
      height(c.height),
      pixelCount(size_t(c.width) * size_t(c.height)),
      depth(d),
      out(o),
      cls(classes) {}

static_assert(kFarCovered == 0, "the opacity loop writes open * kFarPending");

void opacityStage(FarFrame& f, FrameStats& stats, float listAbove) {
    Stopwatch sw;
    const size_t W = size_t(f.width);
    f.cls.resize(f.pixelCount);
    f.columnNeeded.assign(W, 0);
    f.seamCandidates.clear();
    f.covered = 0;
    if (f.depth) {
        // Branch-free per row (the compiler vectorises it); a row with a
        // covered pixel at or beyond listAbove (rare: chunks straddling the
        // near distance) is scanned again for the seam candidates.
        uint8_t* need = f.columnNeeded.data();
        for (size_t y = 0; y < size_t(f.height); ++y) {
            const float* d = f.depth + y * W;
            uint8_t* c = &f.cls[y * W];
            uint32_t covered = 0, seam = 0;
            for (size_t x = 0; x < W; ++x) {
                const uint32_t open = d[x] < 1.0f ? 0u : 1u;
                c[x] = uint8_t(open * kFarPending);  // kFarCovered = 0
                need[x] |= uint8_t(open);
                covered += 1u - open;
                seam |= uint32_t(d[x] >= listAbove) & (1u - open);
            }
            f.covered += covered;
            if (seam)
                for (size_t x = 0; x < W; ++x)
                    if (d[x] < 1.0f && d[x] >= listAbove) f.seamCandidates.push_back(uint32_t(y * W + x));
        }
    } else {
        std::fill(f.cls.begin(), f.cls.end(), kFarPending);
        std::fill(f.columnNeeded.begin(), f.columnNeeded.end(), uint8_t(1));
    }
    stats.stages.add(Stage::Opacity, sw.ms());
}

}  // namespace vista
