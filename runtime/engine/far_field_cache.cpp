// Cache stage (far_field_stages.h): pending pixels looked up in the panoramic
// cache; the confidence records and the pixel budget pick the ones to trace.
#include <algorithm>

#include "foundation/timing.h"
#include "runtime/engine/far_field_stages.h"

namespace vista {

void listPending(FarFrame& f) {
    f.pending.clear();
    for (size_t i = 0; i < f.pixelCount; ++i)
        if (f.cls[i] == kFarPending) f.pending.push_back(uint32_t(i));
}

void bypassCache(FarFrame& f, const FarFieldOptions& o, FrameStats& stats) {
    f.trace = f.pending;
    f.traceCells.clear();
    if (o.cache && !f.pending.empty()) stats.notes.push_back("cache bypassed: unlimited pixel budget");
}

void cacheStage(FarFrame& f, FarFieldMemory& m, const FarFieldOptions& o, FrameStats& stats) {
    Stopwatch sw;
    const double key[4] = {f.camera.fovY, double(f.width), double(f.height), o.cacheOversample};
    if (!m.cache || !std::equal(key, key + 4, m.cacheKey)) {
        m.cache = std::make_unique<PanoramaCache>(PanoramaCache::forCamera(f.camera, o.cacheOversample));
        std::copy(key, key + 4, m.cacheKey);
    }
    PanoramaCache& cache = *m.cache;
    cache.beginFrame(f.camera);
    const uint32_t W = uint32_t(f.width);
    std::vector<CacheCandidate> cand(f.pending.size());
    for (size_t k = 0; k < f.pending.size(); ++k) {
        const uint32_t i = f.pending[k];
        cand[k].pixel = i;
        cand[k].cell = cache.index(f.rays.dir(int(i % W), int(i / W)));
    }
    std::vector<uint8_t> trace;
    cache.selectForTracing(cand, o.pixelBudget, trace);
    f.trace.clear();
    f.traceCells.clear();
    const bool havePrev = m.prev.width == f.width && m.prev.height == f.height;
    uint64_t fromCache = 0;
    for (size_t k = 0; k < f.pending.size(); ++k) {
        const uint32_t i = f.pending[k];
        if (trace[k]) {
            f.trace.push_back(i);
            f.traceCells.push_back(cand[k].cell);
            continue;
        }
        f.cls[i] = kFarCache;
        glm::u8vec4 c = cache.color(cand[k].cell);
        if (c.w == 0) {  // never traced (budget short): last frame's pixel, else sky, until refined
            const uint8_t* s = havePrev ? &m.prev.rgba[size_t(i) * 4] : &f.sky->rgba[size_t(i) * 4];
            c = glm::u8vec4(s[0], s[1], s[2], 255);
        }
        std::copy_n(&c[0], 4, &f.out.rgba[size_t(i) * 4]);
        ++fromCache;
    }
    stats.pixels.cache += fromCache;
    stats.stages.add(Stage::Cache, sw.ms());
}

}  // namespace vista
