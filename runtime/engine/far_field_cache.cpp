// Cache stage (far_field_stages.h): pending pixels looked up in the panoramic
// cache; the quality-bounded policy (panorama_cache.h) and the per-frame
// budget pick the ones to trace.
#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "foundation/timing.h"
#include "foundation/units.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/engine/far_field_stages.h"

namespace vista {

void listPending(FarFrame& f) {
    f.pending.clear();
    for (size_t i = 0; i < f.pixelCount; ++i)
        if (f.cls[i] == kFarPending) f.pending.push_back(uint32_t(i));
}

void bypassCache(FarFrame& f) {
    f.trace = f.pending;
    f.traceCells.clear();
    f.traceSubs.clear();
}

int64_t cacheBudget(const FarFrame& f, const FarFieldMemory& m, const FarFieldOptions& o, double spentMs) {
    int64_t budget = o.pixelBudget;
    if (o.frameMsTarget > 0 && m.msPerRay > 0) {
        // What is left of the target after the stages so far and the composite, in rays;
        // never below 1 % of the frame, so that a late frame still converges.
        const double left = o.frameMsTarget - spentMs - m.compositeMs;
        const int64_t floor = std::max<int64_t>(64, int64_t(f.pixelCount / 100));
        const int64_t byTime = std::max<int64_t>(floor, int64_t(std::max(0.0, left) / m.msPerRay));
        budget = budget < 0 ? byTime : std::min(budget, byTime);
    }
    return budget;
}

PanoramaCache& ensureCache(FarFieldMemory& m, const Camera& camera, const FarFieldOptions& o) {
    const double key[4] = {camera.fovY, double(camera.width), double(camera.height), o.cacheOversample};
    if (!m.cache || !std::equal(key, key + 4, m.cacheKey)) {
        m.cache = std::make_unique<PanoramaCache>(PanoramaCache::forCamera(camera, o.cacheOversample));
        std::copy(key, key + 4, m.cacheKey);
    }
    return *m.cache;
}

uint64_t stillChanges(FarFrame& f, FarFieldMemory& m, const RayScene& rays) {
    f.changedStills.clear();
    const uint64_t serial = rays.stillSerial();
    if (serial == m.stillSerial) return 0;
    m.stillSerial = serial;
    const std::vector<StillState>& now = rays.stillObjects();
    if (m.stillSeen.size() < now.size()) m.stillSeen.resize(now.size());  // new slots: hidden so far
    uint64_t forgotten = 0;
    for (size_t i = 0; i < now.size(); ++i) {
        if (now[i].version == m.stillSeen[i].version) continue;
        const StillState* states[2] = {&m.stillSeen[i], &now[i]};
        for (const StillState* s : states) {
            if (!s->shown) continue;
            f.changedStills.push_back(s->sphere);
            if (!m.cache) continue;
            const glm::dvec3 c(s->sphere), r(s->sphere.w);
            forgotten += m.cache->invalidateBox(c - r, c + r, m.cacheReach);
        }
        m.stillSeen[i] = now[i];
    }
    return forgotten;
}

void moverFootprint(FarFrame& f, const RayScene& rays) {
    const std::vector<glm::dvec4>& spheres = rays.moverSpheres();
    f.moverMask.clear();
    if (spheres.empty() && f.changedStills.empty()) return;
    f.moverMask.assign(f.pixelCount, 0);
    const Camera& cam = f.camera;
    const glm::dvec3 fwd = cam.forward(), right = cam.right(), up = cam.up();
    const double focal = 0.5 * f.height / std::tan(0.5 * cam.fovY);
    const double margin = kMoverMarginPx / focal;  // radians
    auto mark = [&](const glm::dvec4& s, uint8_t bit) {
        const glm::dvec3 v = glm::dvec3(s) - cam.eye;
        const double d = glm::length(v), r = s.w, z = glm::dot(v, fwd);
        if (z < -r) return;  // behind the eye
        int x0 = 0, x1 = f.width - 1, y0 = 0, y1 = f.height - 1;
        if (d > r && z - r > 1e-3) {
            // The sphere's image lies within this square around its centre's (each axis: |d x| <= r d / (z (z - r))).
            const double cx = 0.5 * f.width + focal * glm::dot(v, right) / z;
            const double cy = 0.5 * f.height - focal * glm::dot(v, up) / z;
            const double half = focal * r * d / (z * (z - r)) + kMoverMarginPx + 1.0;
            x0 = std::max(0, int(std::floor(cx - half)));
            x1 = std::min(f.width - 1, int(std::ceil(cx + half)));
            y0 = std::max(0, int(std::floor(cy - half)));
            y1 = std::min(f.height - 1, int(std::ceil(cy + half)));
        }
        const double cosLimit = d > r ? std::cos(std::min(kPi, std::asin(r / d) + margin)) : -2.0;
        const glm::dvec3 axis = d > 0 ? v / d : fwd;
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x)
                if (glm::dot(f.rays.dir(x, y), axis) >= cosLimit)
                    f.moverMask[size_t(y) * size_t(f.width) + size_t(x)] |= bit;
    };
    for (const glm::dvec4& s : spheres) mark(s, kFootprintMover);
    for (const glm::dvec4& s : f.changedStills) mark(s, kFootprintStill);
}

void cacheStage(FarFrame& f, FarFieldMemory& m, const FarFieldOptions& o, FrameStats& stats) {
    double spentMs = 0;
    stats.stages.forEach([&](Stage s, double ms) {
        if (s != Stage::Readback) spentMs += ms;  // readback is part of Near when both are set
    });
    Stopwatch sw;
    PanoramaCache& cache = ensureCache(m, f.camera, o);
    cache.beginFrame(f.camera);
    const uint32_t W = uint32_t(f.width);
    std::vector<CacheCandidate>& cand = m.cand;  // scratch kept across frames (no fresh pages per frame)
    cand.resize(f.pending.size());
    inArena(o.threads, [&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, cand.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t k = r.begin(); k != r.end(); ++k) {
                const uint32_t i = f.pending[k];
                cand[k].pixel = i;
                cand[k].cell = cache.index(f.rays.dir(int(i % W), int(i / W)), &cand[k].sub);
            }
        });
    });
    CachePolicy policy;
    policy.maxErrorPx = o.cacheErrorPx;
    policy.radPerPixel = 2.0 * std::tan(0.5 * f.camera.fovY) / std::max(1, f.height);
    policy.lowerDepth = o.nearIsDistance && o.nearDistance > 0 ? o.nearDistance : m.lastMinDepth;
    policy.windowPx = kCacheWindowPx;
    policy.budget = cacheBudget(f, m, o, spentMs);
    m.cacheReach = PanoramaCache::reuseReach(policy);
    if (o.frameMsTarget > 0) stats.notes.push_back("cache budget " + std::to_string(policy.budget) + " rays");
    f.farDepth.resize(f.pixelCount);  // only pending pixels are read: cache ones below, traced ones by the ray stage
    std::vector<uint8_t>& trace = m.traceMarks;
    inArena(o.threads, [&] { cache.selectForTracing(cand, policy, trace); });
    f.trace.clear();
    f.traceCells.clear();
    f.traceSubs.clear();
    const bool havePrev = m.prev.width == f.width && m.prev.height == f.height;
    uint64_t fromCache = 0;
    const bool movers = !f.moverMask.empty();
    for (size_t k = 0; k < f.pending.size(); ++k) {
        const uint32_t i = f.pending[k];
        if (trace[k] || (movers && f.moverMask[i])) {
            f.trace.push_back(i);
            f.traceCells.push_back(cand[k].cell);
            f.traceSubs.push_back(cand[k].sub);
            continue;
        }
        f.cls[i] = kFarCache;
        glm::u8vec4 c = cache.color(cand[k].cell);
        if (c.w == 0) {  // never traced (budget short): last frame's pixel, else sky, until refined
            const uint8_t* s = havePrev ? &m.prev.rgba[size_t(i) * 4] : &f.sky->rgba[size_t(i) * 4];
            c = glm::u8vec4(s[0], s[1], s[2], 255);
        }
        std::copy_n(&c[0], 4, &f.out.rgba[size_t(i) * 4]);
        f.farDepth[i] = cache.nearDistance(cand[k].cell);
        ++fromCache;
    }
    stats.pixels.cache += fromCache;
    stats.stages.add(Stage::Cache, sw.ms());
}

}  // namespace vista
