// FarField: the far-field frame as a sequence of stages (see far_field.h; the
// stages are in far_field_<stage>.cpp, declared in far_field_stages.h).
#include "runtime/engine/far_field.h"

#include <algorithm>
#include <cmath>

#include "runtime/engine/far_field_stages.h"
#include "runtime/engine/ray_scene.h"

namespace vista {

namespace {

// False when no geometry lies beyond the near distance: an empty city, or the
// eye's farthest corner of the city's bounding box within the near distance.
bool farGeometryExists(const RayScene& rays, const HeightGrid* grid, const Camera& camera, const FarFieldOptions& o) {
    if (!grid) return rays.triangleCount() > 0;
    if (grid->empty()) return false;
    if (!o.nearIsDistance || o.nearDistance <= 0) return true;
    const glm::dvec3 e = camera.eye - grid->frameOrigin(), lo = grid->boundsMin(), hi = grid->boundsMax();
    double far2 = 0;
    for (int k = 0; k < 3; ++k) {
        const double a = std::max(std::abs(e[k] - lo[k]), std::abs(e[k] - hi[k]));
        far2 += a * a;
    }
    return far2 >= o.nearDistance * o.nearDistance;
}

// A stage that pauses while it does not pay (the cache, the horizon): true,
// with the note, while `framesLeft` paused frames remain (counted down here);
// only frames where the pause applies (`applies`) count.
bool pausedThisFrame(int& framesLeft, bool applies, FrameStats& stats, const char* note) {
    if (!applies || framesLeft <= 0) return false;
    --framesLeft;
    stats.notes.push_back(note);
    return true;
}

}  // namespace

bool sameCamera(const Camera& a, const Camera& b) {
    return a.eye == b.eye && a.heading == b.heading && a.pitch == b.pitch && a.roll == b.roll && a.fovY == b.fovY &&
           a.width == b.width && a.height == b.height;
}

FarField::FarField(const RayScene& rays, const HeightGrid* grid, const FarFieldOptions& options)
    : _rays(rays), _grid(grid), _options(options), _mem(std::make_unique<FarFieldMemory>()) {}
FarField::~FarField() = default;

void FarField::setOptions(const FarFieldOptions& o) {
    const bool cacheChanged = o.cache != _options.cache || o.cacheOversample != _options.cacheOversample ||
                              !sameRayShading(o.effects, _options.effects);
    _options = o;
    if (cacheChanged) _mem->cache.reset();
}

void FarField::beginFrame(const Camera& camera) {
    // Dropping an std::async future waits for its task: never two at once.
    _mem->earlyHorizon = std::future<HorizonResult>();
    if (_options.speculate && !_traced.empty() && _traced.back() < uint32_t(camera.width * camera.height) &&
        farGeometryExists(_rays, _grid, camera, _options))
        startSpeculation(*_mem, _rays, camera, _options, _traced);
    else _mem->spec.stop();
    if (!_grid || !_options.horizon || !farGeometryExists(_rays, _grid, camera, _options) || !horizonApplies(camera))
        return;
    const bool moving = _mem->haveLast && !sameCamera(_mem->last, camera);
    if (moving && _mem->horizonPaused > 0) return;  // the horizon is paused (renderStages)
    const HorizonOptions ho = horizonOptions(_options, moving);
    const HeightGrid* grid = _grid;
    _mem->earlyCamera = camera;
    _mem->earlyHorizon = std::async(std::launch::async, [grid, camera, ho] { return traceHorizon(*grid, camera, ho); });
}

void FarField::awaitSpeculation() { _mem->spec.finish(); }

void FarField::reset() {
    _mem->spec.discard();
    // A restart after a frame (the bench's warm-up) makes the panorama for that camera if no
    // stage did yet: clear() then zeroes its cells in place, so they are resident before the
    // first timed frame instead of faulting in inside a cache stage (a 73 MB panorama's first
    // cache frame took 40 ms on a streamed drive whose warm-up frame had not made it).
    if (_options.cache && _mem->haveLast) ensureCache(*_mem, _mem->last, _options);
    if (_mem->cache) _mem->cache->clear();
    _mem->prev = Image();
    _mem->haveLast = false;
    _mem->cachePaused = 0;
    _mem->cachePauseLength = kCachePauseFrames;
    _mem->horizonPaused = 0;
    _mem->horizonStrikes = 0;
    _mem->lastFrameCached = false;
}

uint64_t FarField::sceneChanged(const SceneBoxes& boxes) {
    _mem->spec.discard();
    _mem->prev = Image();
    _mem->lastFrameCached = false;  // the next frame's reuse is no verdict on the cache
    uint64_t forgotten = 0;
    if (_mem->cache)
        for (const auto& [lo, hi] : boxes) forgotten += _mem->cache->invalidateBox(lo, hi, _mem->cacheReach);
    return forgotten;
}

void FarField::render(const Camera& camera, const float* depth, Image& out, FrameStats& stats) {
    VISTA_CHECK(camera.width >= 1 && camera.height >= 1);
    if (out.width != camera.width || out.height != camera.height || !out.valid())
        out = Image(camera.width, camera.height);
    FarFrame f(camera, depth, out, _class);
    f.fx = &_options.effects;
    f.moving = _mem->haveLast && !sameCamera(_mem->last, camera);
    _mem->last = camera;
    _mem->haveLast = true;
    _rayStart = farRayStart(_options);
    renderStages(f, depth, stats);
    if (_mem->spec.active()) discardSpeculation(*_mem, stats);  // the ray stage did not run
    _traced = std::move(f.trace);
}

void FarField::renderStages(FarFrame& f, const float* depth, FrameStats& stats) {
    const Camera& camera = f.camera;
    // The horizon beginFrame started is this frame's, used or not: consumed here (its
    // destructor waits for the task if no stage took it).
    std::future<HorizonResult> early = std::move(_mem->earlyHorizon);
    // Still objects that changed since the last frame: their cells are forgotten now, whichever
    // stages run, and their pixels traced in this frame's cache stage.
    if (_options.cacheMovers) stillChanges(f, *_mem, _rays);
    CoveredHaze haze;  // beside the stages below, until the ray stage
    haze.start(f, _options);
    auto finishHaze = [&] {
        haze.finish(stats);
        writeSeamHits(f);
    };
    // The seam check applies when something is covered: its candidates are listed by the opacity pass.
    const bool seam = seamCheckApplies(f, _rays, _options);
    opacityStage(f, stats, seam ? seamListDepth(f, _options) : 2.0f);
    if (seam && f.covered > 0) seamStage(f, _rays, _options, stats);
    stats.pixels.covered += f.covered;
    if (f.covered == f.pixelCount) {  // no sky, no far field visible: nothing else runs
        finishHaze();
        return;
    }

    f.sky = &skyImage(*_mem, f);
    if (!farGeometryExists(_rays, _grid, camera, _options)) {
        stats.notes.push_back("rays off: no far geometry beyond the near distance");
        cullAllPending(f, stats);
        finishHaze();
        compositeStage(f, *_mem, false, stats);
        return;
    }
    const bool useEarly = early.valid() && sameCamera(_mem->earlyCamera, camera);
    const bool budgeted = _options.pixelBudget >= 0 || _options.frameMsTarget > 0;
    // The horizon pauses while it does not pay (FarFieldOptions::horizonAdaptive).
    const bool horizonAdaptive = _options.horizonAdaptive && !budgeted && f.moving;
    const bool useHorizon =
        _options.horizon && !pausedThisFrame(_mem->horizonPaused, horizonAdaptive, stats,
                                             "horizon paused: tracing it cost more than the rays it saved");
    if (useHorizon) {
        const double before = stats.stages.ms(Stage::Horizon);
        const uint64_t culled = horizonStage(f, _grid, _options, stats, useEarly ? &early : nullptr);
        // What the horizon cost this frame: its stage time (the trace, or only the wait for a
        // trace that overlapped the near-field draw). Judged once a ray stage has run (frame 1
        // on), against a timed sample of the culled pixels' own rays (mostly sky misses: the
        // mean traced ray prices them 5 to 10 times too high).
        const double costMs = stats.stages.ms(Stage::Horizon) - before;
        if (horizonAdaptive && _mem->msPerRay > 0) {
            // One slow frame (the trace's thread descheduled) is not a verdict: it takes kHorizonStrikes in a row.
            const bool pays = costMs <= culledRaysMs(f, _rays, _options, culled);
            _mem->horizonStrikes = pays ? 0 : _mem->horizonStrikes + 1;
            if (_mem->horizonStrikes >= kHorizonStrikes) {
                _mem->horizonPaused = kHorizonPauseFrames;
                _mem->horizonStrikes = 0;
            }
        }
    }
    listPending(f);
    const bool adaptive = _options.cacheAdaptive && !budgeted && f.moving;
    const bool useCache = _options.cache && !pausedThisFrame(_mem->cachePaused, adaptive, stats,
                                                             "cache paused: its reuse did not pay for its lookups");
    f.farDepth.swap(_mem->farDepth);  // reuse last frame's buffer (cacheStage refills it)
    const bool cacheRan = useCache && !f.pending.empty();
    if (cacheRan) {
        const double before = stats.stages.ms(Stage::Cache);
        if (_options.cacheMovers) moverFootprint(f, _rays);
        const uint64_t reusedBefore = stats.pixels.cache;
        cacheStage(f, *_mem, _options, stats);
        const double lookupMs = stats.stages.ms(Stage::Cache) - before;
        const double reuse = double(stats.pixels.cache - reusedBefore) / double(f.pending.size());
        // Judged only when last frame's stores are fresh (two cache frames in a row).
        if (adaptive && _mem->lastFrameCached && _mem->msPerRay > 0) {
            if (reuse * _mem->msPerRay < lookupMs / double(f.pending.size())) {
                _mem->cachePaused = _mem->cachePauseLength;
                _mem->cachePauseLength = std::min(2 * _mem->cachePauseLength, kCacheMaxPauseFrames);
            } else {
                _mem->cachePauseLength = kCachePauseFrames;
            }
        }
    } else {
        f.farDepth.clear();
        bypassCache(f);
    }
    _mem->lastFrameCached = cacheRan;
    finishHaze();  // the rays have both cores, and their timing prices a far pixel
    if (!f.trace.empty()) {
        const double before = stats.stages.ms(Stage::Rays);
        raysStage(f, *_mem, _rays, _options, stats);
        const double perRay = (stats.stages.ms(Stage::Rays) - before) / double(f.trace.size());
        _mem->msPerRay = _mem->msPerRay > 0 ? 0.8 * _mem->msPerRay + 0.2 * perRay : perRay;
    }
    const double before = stats.stages.ms(Stage::Composite);
    // The last frame is the fallback of never-traced cells left out by a budget: kept only under one.
    compositeStage(f, *_mem, cacheRan, stats, cacheRan && budgeted);
    const double composite = stats.stages.ms(Stage::Composite) - before;
    _mem->compositeMs = _mem->compositeMs > 0 ? 0.8 * _mem->compositeMs + 0.2 * composite : composite;
    f.farDepth.swap(_mem->farDepth);
}

}  // namespace vista
