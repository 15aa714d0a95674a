// Composite stage (far_field_stages.h): sky behind the horizon, traced colours
// into the panoramic cache, the frame kept for the next cache frame.
#include <algorithm>

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

void compositeStage(FarFrame& f, FarFieldMemory& m, bool cacheMode, FrameStats& stats) {
    Stopwatch sw;
    for (size_t i = 0; i < f.pixelCount; ++i)
        if (f.cls[i] == kFarHorizon) std::copy_n(&f.sky->rgba[i * 4], 4, &f.out.rgba[i * 4]);
    if (cacheMode) {
        if (m.cache && !f.trace.empty()) {
            std::vector<glm::u8vec4> traced(f.trace.size());
            for (size_t j = 0; j < f.trace.size(); ++j) std::copy_n(&f.out.rgba[size_t(f.trace[j]) * 4], 4, &traced[j][0]);
            m.cache->store(f.traceCells, traced);
        }
        m.prev = f.out;  // fallback for never-traced cache cells next frame
    }
    stats.stages.add(Stage::Composite, sw.ms());
}

}  // namespace vista
