// Speculative rays (far_field_stages.h): last frame's traced pixels cast for
// this frame's camera while the near field is drawn.
#include <algorithm>
#include <string>

#include <pthread.h>
#include <sched.h>

#include <tbb/task_arena.h>

#include "foundation/status.h"
#include "runtime/engine/far_field_stages.h"

namespace vista {

void SpeculativeRays::stop() {
    stopFlag.store(true, std::memory_order_relaxed);
    finish();
}

void SpeculativeRays::finish() {
    if (worker.joinable()) worker.join();
}

void startSpeculation(FarFieldMemory& m, const RayScene& rays, const Camera& camera, const FarFieldOptions& o,
                      std::vector<uint32_t> pixels) {
    SpeculativeRays& s = m.spec;
    s.stop();
    s.chunks = 0;
    if (pixels.empty() || o.rayStep != 1) return;
    const size_t n = pixels.size(), N = size_t(camera.width) * size_t(camera.height);
    VISTA_CHECK(pixels.back() < N);
    s.camera = camera;
    s.tnear = farRayStart(o);
    s.effects = o.effects;
    s.pixels = std::move(pixels);
    if (s.colors.width != camera.width || s.colors.height != camera.height || !s.colors.valid())
        s.colors = Image(camera.width, camera.height);
    s.depth.resize(n);
    s.hit.resize(n);
    s.chunks = (n + kSpeculativeChunk - 1) / kSpeculativeChunk;
    s.done.reset(new std::atomic<uint8_t>[s.chunks]);
    for (size_t c = 0; c < s.chunks; ++c) s.done[c].store(0, std::memory_order_relaxed);
    s.next.store(0, std::memory_order_relaxed);
    s.rays.store(0, std::memory_order_relaxed);
    s.stopFlag.store(false, std::memory_order_relaxed);
    s.worker = std::thread([&s, &rays] {
        // One worker at the idle priority: it runs on what the draw leaves of the cores and
        // does not slow the draw (its rasteriser's threads) down.
        sched_param sp{};
        pthread_setschedparam(pthread_self(), SCHED_IDLE, &sp);  // best effort: a failure leaves it at normal priority
        tbb::task_arena arena(1);
        arena.execute([&] {
            RayShading sh;
            sh.effects = &s.effects;
            sh.tnear = s.tnear;
            sh.haze = true;  // hazed here, on the cores the draw leaves idle
            while (!s.stopFlag.load(std::memory_order_relaxed)) {
                const size_t c = s.next.fetch_add(1, std::memory_order_relaxed);
                if (c >= s.chunks) break;
                const size_t b = c * kSpeculativeChunk, e = std::min(s.pixels.size(), b + kSpeculativeChunk);
                RayCounts counts;
                sh.depth = &s.depth[b];
                castPrimaryRays(rays, s.camera, &s.pixels[b], e - b, s.colors, counts, 0, &s.hit[b], sh);
                s.rays.fetch_add(counts.rays, std::memory_order_relaxed);
                s.done[c].store(1, std::memory_order_release);
            }
        });
    });
}

namespace {

// Counts a stopped worker's rays (cast, used), notes them and marks it idle.
void recordSpeculation(SpeculativeRays& s, uint64_t used, FrameStats& stats) {
    const uint64_t cast = s.rays.load(std::memory_order_relaxed);
    stats.raysCast += cast;
    stats.speculativeRays += cast;
    stats.speculativeUsed += used;
    stats.notes.push_back("speculative rays: " + std::to_string(cast) + " cast during the draw, " +
                          std::to_string(used) + " used");
    s.chunks = 0;
}

}  // namespace

void discardSpeculation(FarFieldMemory& m, FrameStats& stats) {
    const bool had = m.spec.chunks > 0;
    m.spec.stop();
    if (had) recordSpeculation(m.spec, 0, stats);
}

std::vector<uint32_t> takeSpeculation(FarFrame& f, FarFieldMemory& m, const FarFieldOptions& o, uint8_t* hit,
                                      float* depth, FrameStats& stats) {
    SpeculativeRays& s = m.spec;
    const size_t n = f.trace.size();
    std::vector<uint32_t> left;
    left.reserve(n);
    const bool had = s.chunks > 0;
    s.stop();
    const bool applies = had && sameCamera(s.camera, f.camera) && s.tnear == farRayStart(o) && o.rayStep == 1 &&
                         sameRayShading(s.effects, o.effects);
    uint64_t used = 0;
    if (applies) {
        // Both lists ascend: one merge walk.
        size_t k = 0;
        for (size_t j = 0; j < n; ++j) {
            const uint32_t p = f.trace[j];
            while (k < s.pixels.size() && s.pixels[k] < p) ++k;
            if (k < s.pixels.size() && s.pixels[k] == p &&
                s.done[k / kSpeculativeChunk].load(std::memory_order_acquire)) {
                std::copy_n(&s.colors.rgba[size_t(p) * 4], 4, &f.out.rgba[size_t(p) * 4]);
                hit[j] = s.hit[k];
                if (depth) depth[j] = s.depth[k];
                ++used;
            } else {
                left.push_back(uint32_t(j));
            }
        }
    } else {
        for (size_t j = 0; j < n; ++j) left.push_back(uint32_t(j));
    }
    if (had) recordSpeculation(s, used, stats);
    s.chunks = 0;
    return left;
}

}  // namespace vista
