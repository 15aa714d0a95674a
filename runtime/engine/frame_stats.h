// FrameStats: what one rendered frame cost and what its pixels hold, typed,
// shared by every render mode, the bench, the viewer's HUD and the nodes.
//
// PixelCounts classify every pixel of a frame exactly once (thesis Table 4.1;
// counts, not percentages): covered by rasterised geometry; above the horizon
// (sky without tracing); taken from the panoramic cache; traced this frame and
// hit geometry; traced this frame and missed (sky). Modes that do not
// classify pixels leave them all 0. raysCast counts every Embree ray of the
// frame (including seam-check rays, hit or miss), so rays per frame can be
// compared between modes.
// StageTimes: wall milliseconds per named stage of the frame, and whether the
// stage ran at all (a stage that did not run is absent, not 0 ms). The stage
// list is fixed (Stage); stageName() gives the names used in CSV/JSON.
// Plain data; no OSG, no GL; not thread-safe (one frame, one writer).
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "citygen/effects.h"

namespace vista {

struct PixelCounts {
    uint64_t covered = 0;        // drawn by the near field (or rasterised geometry)
    uint64_t horizonCulled = 0;  // above the horizon: sky without tracing
    uint64_t cache = 0;          // taken from the panoramic cache
    uint64_t rayHit = 0;         // traced this frame, hit geometry
    uint64_t rayMiss = 0;        // traced this frame, hit nothing (sky)
    uint64_t interpolated = 0;   // blended from ray-cast neighbours (FarFieldOptions::rayStep 2)
    uint64_t total() const { return covered + horizonCulled + cache + rayHit + rayMiss + interpolated; }
};

enum class Stage : uint8_t {
    Cull,       // choosing the near field (split, adaptive choice)
    Near,       // rasterising the near field (GL draw + read back)
    Readback,   // reading colour/depth back from GL (part of Near when both run)
    Opacity,    // near-field depth -> coverage mask
    Seam,       // re-casting covered pixels beyond the near distance
    Horizon,    // horizon tracing through the height grid
    Cache,      // panoramic cache lookup and selection
    Rays,       // Embree ray casting of the far field
    Composite,  // far-field image written behind the near field
    Haze,       // haze applied to ray-cast pixels (the rasteriser fogs inside its draw)
    Reflect,    // glass reflections: reflection rays for marked pixels, blended in
    Count
};
constexpr size_t kStageCount = size_t(Stage::Count);
// "cull", "near", "readback", "opacity", "seam", "horizon", "cache", "rays", "composite", "haze", "reflect".
const char* stageName(Stage s);

class StageTimes {
public:
    void add(Stage s, double ms) {
        _ms[size_t(s)] += ms;
        _ran[size_t(s)] = true;
    }
    void set(Stage s, double ms) {
        _ms[size_t(s)] = ms;
        _ran[size_t(s)] = true;
    }
    bool ran(Stage s) const { return _ran[size_t(s)]; }
    double ms(Stage s) const { return _ms[size_t(s)]; }
    size_t count() const {
        size_t n = 0;
        for (bool r : _ran) n += r ? 1 : 0;
        return n;
    }
    // f(Stage, ms) for every stage that ran, in Stage order.
    template <class F>
    void forEach(F&& f) const {
        for (size_t i = 0; i < kStageCount; ++i)
            if (_ran[i]) f(Stage(i), _ms[i]);
    }

private:
    std::array<double, kStageCount> _ms{};
    std::array<bool, kStageCount> _ran{};
};

// Which effects ran in a frame and their time (ms), indexed by EffectId. An
// effect that did not run (not declared, switched off, or nothing of it on
// screen) is absent. Baked effects never run per frame.
class EffectTimes {
public:
    void add(EffectId e, double ms) {
        _ms[size_t(e)] += ms;
        _ran[size_t(e)] = true;
    }
    bool ran(EffectId e) const { return _ran[size_t(e)]; }
    double ms(EffectId e) const { return _ms[size_t(e)]; }
    template <class F>
    void forEach(F&& f) const {
        for (size_t i = 0; i < size_t(kEffectCount); ++i)
            if (_ran[i]) f(EffectId(i), _ms[i]);
    }

private:
    std::array<double, size_t(kEffectCount)> _ms{};
    std::array<bool, size_t(kEffectCount)> _ran{};
};

struct FrameStats {
    double frameMs = 0, cullMs = 0, drawMs = 0;
    uint64_t triangles = 0, drawCalls = 0;
    uint64_t raysCast = 0;  // every ray cast this frame (far field, seam check, probes)
    // Speculative rays (FarFieldOptions::speculate): cast while the near field was drawn (in
    // raysCast), and how many of them gave a traced pixel its colour (rayHit/rayMiss pixels
    // the ray stage did not cast itself).
    uint64_t speculativeRays = 0, speculativeUsed = 0;
    PixelCounts pixels;
    StageTimes stages;
    EffectTimes effects;
    uint64_t glassPixels = 0;        // pixels marked as glass on screen
    uint64_t reflectionRays = 0;     // reflection rays (also counted in raysCast)
    std::vector<std::string> notes;  // e.g. "horizon off: camera rolled"
};

}  // namespace vista
