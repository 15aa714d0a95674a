// Per-mode summaries of a bench run (bench.h): frame-time statistics,
// same-frame speedups, quality, pixel classes, rays and stage times. The
// far-field sweep (tests/bench/far_field_sweep.cpp) reads these summaries
// instead of computing its own.
#include "cmd/bench.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vista {

double medianOfSameFrameRatios(const std::vector<double>& baseMs, const std::vector<double>& modeMs) {
    std::vector<double> ratios;
    for (size_t f = 0; f < std::min(baseMs.size(), modeMs.size()); ++f)
        if (baseMs[f] > 0 && modeMs[f] > 0) ratios.push_back(baseMs[f] / modeMs[f]);
    return percentile(std::move(ratios), 0.5);
}

std::vector<double> modeFrameTimes(const BenchResult& r, const std::string& mode) {
    std::vector<double> ms;
    for (const auto& f : r.frames)
        if (f.mode == mode) ms.push_back(f.stats.frameMs);
    return ms;
}

const std::vector<std::string>& speedupBases() {
    static const std::vector<std::string> kBases = {"full", "near", "raycast"};
    return kBases;
}

std::string clearTwinName(const std::string& mode) { return mode + "+clear"; }

namespace {

// Pixel classes (min / mean / max percent, mean count) over the frames of a mode.
void summarisePixels(const std::vector<const BenchFrameRecord*>& frames, double npx, ModeSummary& s) {
    PixelClassSummary* cls[6] = {&s.covered, &s.horizonCulled, &s.cache, &s.rayHit, &s.rayMiss, &s.interpolated};
    for (auto* c : cls) c->minPct = std::numeric_limits<double>::infinity();
    for (const BenchFrameRecord* r : frames) {
        const PixelCounts& p = r->stats.pixels;
        const uint64_t c[6] = {p.covered, p.horizonCulled, p.cache, p.rayHit, p.rayMiss, p.interpolated};
        for (int k = 0; k < 6; ++k) {
            const double pct = 100.0 * double(c[k]) / npx;
            cls[k]->minPct = std::min(cls[k]->minPct, pct);
            cls[k]->maxPct = std::max(cls[k]->maxPct, pct);
            cls[k]->meanPct += pct / double(frames.size());
            cls[k]->meanCount += double(c[k]) / double(frames.size());
            s.hasPixels = s.hasPixels || c[k] > 0;
        }
    }
}

void summariseStagesAndNotes(const std::vector<const BenchFrameRecord*>& frames, ModeSummary& s) {
    std::map<std::string, double> sum;
    for (const BenchFrameRecord* r : frames) {
        r->stats.stages.forEach([&](Stage stage, double ms) {
            sum[stageName(stage)] += ms;
            ++s.stageRuns[stageName(stage)];
        });
        for (const auto& n : r->stats.notes) ++s.noteCounts[n];
    }
    for (const auto& kv : sum) s.stagesMsMean[kv.first] = kv.second / double(s.stageRuns[kv.first]);
    // Effects: mean ms over the frames it ran in; frames it ran in.
    std::map<std::string, double> fx;
    for (const BenchFrameRecord* r : frames) {
        r->stats.effects.forEach([&](EffectId e, double ms) {
            fx[effectName(e)] += ms;
            ++s.effectRuns[effectName(e)];
        });
        s.glassPixelsMean += double(r->stats.glassPixels) / double(frames.size());
        s.reflectionRaysMean += double(r->stats.reflectionRays) / double(frames.size());
    }
    for (const auto& kv : fx) s.effectsMsMean[kv.first] = kv.second / double(s.effectRuns[kv.first]);
}

}  // namespace

ModeSummary summariseMode(const BenchResult& r, const std::string& mode, const std::vector<std::string>& bases,
                          double npx) {
    ModeSummary s;
    s.mode = mode;
    std::vector<const BenchFrameRecord*> frames;
    for (const auto& f : r.frames)
        if (f.mode == mode) frames.push_back(&f);
    if (frames.empty()) return s;
    std::vector<double> ms, psnr, diff, tri, calls, cull, draw, rays;
    for (const BenchFrameRecord* f : frames) {
        ms.push_back(f->stats.frameMs);
        psnr.push_back(f->psnrDb);
        diff.push_back(f->diffFraction);
        tri.push_back(double(f->stats.triangles));
        calls.push_back(double(f->stats.drawCalls));
        cull.push_back(f->stats.cullMs);
        draw.push_back(f->stats.drawMs);
        rays.push_back(double(f->stats.raysCast));
    }
    s.frameMsMedian = percentile(ms, 0.5);
    s.frameMsP95 = percentile(ms, 0.95);
    s.frameMsP99 = percentile(ms, 0.99);
    s.frameMsMax = *std::max_element(ms.begin(), ms.end());
    if (r.streamed) {
        s.streamed = true;
        std::vector<double> with, without;
        for (const BenchFrameRecord* f : frames) (f->regionsArrived > 0 ? with : without).push_back(f->stats.frameMs);
        auto times = [](const std::vector<double>& v) {
            ModeSummary::FrameTimes t;
            t.frames = int(v.size());
            if (v.empty()) return t;
            t.medianMs = percentile(v, 0.5);
            t.p99Ms = percentile(v, 0.99);
            t.maxMs = *std::max_element(v.begin(), v.end());
            return t;
        };
        s.withArrivals = times(with);
        s.withoutArrivals = times(without);
    }
    double sum = 0;
    for (double v : ms) sum += v;
    s.frameMsMean = sum / double(ms.size());
    for (const auto& base : bases) {
        const std::vector<double> baseMs = modeFrameTimes(r, base);
        if (baseMs.size() == ms.size()) s.speedupMedianOfRatios[base] = medianOfSameFrameRatios(baseMs, ms);
    }
    if (std::isnan(psnr.front())) {  // no reference (BenchConfig::referenceSsaa)
        s.psnrDbMedian = s.psnrDbMin = s.diffFractionMedian = NAN;
    } else {
        s.psnrDbMedian = percentile(psnr, 0.5);
        s.psnrDbMin = *std::min_element(psnr.begin(), psnr.end());
        s.diffFractionMedian = percentile(diff, 0.5);
    }
    s.trianglesMedian = percentile(tri, 0.5);
    s.drawCallsMedian = percentile(calls, 0.5);
    s.cullMsMedian = percentile(cull, 0.5);
    s.drawMsMedian = percentile(draw, 0.5);
    s.raysMedian = percentile(rays, 0.5);
    summarisePixels(frames, npx, s);
    summariseStagesAndNotes(frames, s);
    return s;
}

}  // namespace vista
