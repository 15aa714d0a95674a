// Composite stage (far_field_stages.h): traced colours
// into the panoramic cache, the frame kept for the next cache frame.
#include <algorithm>
#include <cmath>

#include "foundation/timing.h"
#include "runtime/engine/far_field_stages.h"

namespace vista {

const Image& skyImage(FarFieldMemory& m, const FarFrame& f) {
    // Elevations depend on pitch, roll, fov and size only: heading rotates the
    // world around the vertical axis.
    const Camera& c = f.camera;
    const double key[5] = {c.pitch, c.roll, c.fovY, double(f.width) * 65536.0 + f.height, f.fx->night ? 1.0 : 0.0};
    if (!std::equal(key, key + 5, m.skyKey)) {
        m.sky = Image(f.width, f.height);
        for (int y = 0; y < f.height; ++y)
            for (int x = 0; x < f.width; ++x) m.sky.set(x, y, f.fx->sky(f.rays.dir(x, y)));
        std::copy(key, key + 5, m.skyKey);
    }
    return m.sky;
}

void compositeStage(FarFrame& f, FarFieldMemory& m, bool cacheMode, FrameStats& stats, bool keepFrame) {
    Stopwatch sw;
    if (cacheMode) {
        if (m.cache && !f.trace.empty() && f.farDepth.size() == f.pixelCount) {
            // Nearest far surface around every traced pixel: minimum over the 3 x 3 blocks of
            // kCacheWindowPx pixels around its block (a window of radius >= kCacheWindowPx).
            // Only pending pixels (cached or traced) have a far depth this frame; all others count
            // as +inf, so the blocks are the minima over the pending list.
            const int B = int(kCacheWindowPx), bw = (f.width + B - 1) / B, bh = (f.height + B - 1) / B;
            std::vector<float> block(size_t(bw) * size_t(bh), INFINITY);
            const uint32_t W = uint32_t(f.width);
            for (const uint32_t i : f.pending) {
                float& b = block[size_t(i / W) / size_t(B) * size_t(bw) + size_t(i % W) / size_t(B)];
                b = std::min(b, f.farDepth[i]);
            }
            float lowest = INFINITY;
            for (float v : block) lowest = std::min(lowest, v);
            if (std::isfinite(lowest)) m.lastMinDepth = lowest;
            std::vector<glm::u8vec4> traced(f.trace.size());
            std::vector<float> nearest(f.trace.size());
            for (size_t j = 0; j < f.trace.size(); ++j) {
                const uint32_t i = f.trace[j];
                std::copy_n(&f.out.rgba[size_t(i) * 4], 4, &traced[j][0]);
                const int bx = int(i % W) / B, by = int(i / W) / B;
                float v = INFINITY;
                for (int yy = std::max(0, by - 1); yy <= std::min(bh - 1, by + 1); ++yy)
                    for (int xx = std::max(0, bx - 1); xx <= std::min(bw - 1, bx + 1); ++xx)
                        v = std::min(v, block[size_t(yy) * size_t(bw) + size_t(xx)]);
                nearest[j] = v;
            }
            m.cache->store(f.traceCells, f.traceSubs, traced, nearest);
            if (!f.moverMask.empty()) {
                // A moving object may be in these cells: they are traced again while it is there.
                std::vector<int64_t> moving;
                for (size_t j = 0; j < f.trace.size(); ++j)
                    if (f.moverMask[f.trace[j]] & kFootprintMover) moving.push_back(f.traceCells[j]);
                m.cache->forget(moving);
            }
        }
        if (keepFrame) m.prev = f.out;  // fallback for never-traced cache cells next frame
        else m.prev = Image();
    }
    stats.stages.add(Stage::Composite, sw.ms());
}

}  // namespace vista
