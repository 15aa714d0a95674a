// Far-field stages (internal to runtime/engine): the frame of FarField::render
// as named stage functions on plain arrays, one file each
// (far_field_<stage>.cpp), sharing one FarFrame. Pixel classes as in
// far_field.h; kFarPending marks a pixel no stage has classified yet. Each
// stage adds its pixel counts to FrameStats::pixels, its rays to raysCast and
// its wall time to FrameStats::stages. Not thread-safe (one frame, one writer);
// nothing throws.
#pragma once
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <future>
#include <memory>
#include <thread>
#include <utility>
#include <vector>

#include <glm/glm.hpp>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include "runtime/engine/far_field.h"
#include "runtime/engine/far_field_rays.h"
#include "runtime/engine/panorama_cache.h"
#include "runtime/engine/ray_scene.h"

namespace vista {

constexpr uint8_t kFarPending = 5;

// Runs body() in a task arena of `threads` workers (0 = the caller's arena).
template <class F>
void inArena(int threads, const F& body) {
    if (threads > 0) {
        tbb::task_arena arena(threads);
        arena.execute(body);
    } else {
        body();
    }
}

// Eye-plane depth (metres) of an OpenGL window depth d in [0, 1) rendered with
// near plane n > 0 and far plane zf (<= 0: infinite far plane).
inline double eyeDepthOfWindowDepth(double d, double n, double zf) {
    const double zn = 2.0 * d - 1.0;
    return zf > 0 ? 2.0 * zf * n / ((zf + n) - zn * (zf - n)) : 2.0 * n / (1.0 - zn);
}

// Where the far field's rays start (metres): just short of the near distance
// when the near field is one (FarFieldOptions::nearIsDistance), else the eye.
inline float farRayStart(const FarFieldOptions& o) {
    return o.nearIsDistance && o.nearDistance > 0 && std::isfinite(o.nearDistance) ? float(o.nearDistance * 0.999)
                                                                                   : 0.0f;
}

// Rays cast ahead of the ray stage, on another thread while the near field
// is drawn (FarField::beginFrame; far_field_speculate.cpp): last frame's
// traced pixels, cast for this frame's camera in chunks. stop() ends the work
// after the chunk in hand and joins; the chunks done by then hold exact
// results (the same rays the ray stage would cast).
struct SpeculativeRays {
    Camera camera;
    float tnear = 0.0f;
    FrameEffects effects;
    std::vector<uint32_t> pixels;                  // ascending
    Image colors;                                  // camera-sized: the colours of cast pixels
    std::vector<float> depth;                      // per entry of pixels (eye-plane depth, +inf = sky)
    std::vector<uint8_t> hit;                      // per entry: 1 = showed geometry
    std::unique_ptr<std::atomic<uint8_t>[]> done;  // per chunk
    size_t chunks = 0;
    std::atomic<size_t> next{0};
    std::atomic<bool> stopFlag{false};
    std::atomic<uint64_t> rays{0};  // rays cast so far
    std::thread worker;
    bool active() const { return worker.joinable() || chunks > 0; }
    void stop();    // ends the work after the chunk in hand and joins (no-op when idle)
    void finish();  // joins once every chunk is cast (no-op when idle)
    void discard() {
        stop();
        chunks = 0;
    }  // stops and forgets (not counted anywhere)
    ~SpeculativeRays() { stop(); }
};
constexpr size_t kSpeculativeChunk = 512;  // rays per chunk of SpeculativeRays

// What a FarField keeps from frame to frame.
struct FarFieldMemory {
    std::unique_ptr<PanoramaCache> cache;
    double cacheKey[4] = {0, 0, 0, 0};  // fovY, width, height, oversample of the cache
    double cacheReach = 0;              // PanoramaCache::reuseReach of the last cache frame's policy
    Image prev;                         // last composited frame (cache mode)
    Image sky;                          // sky colours (depend on pitch, roll, fov, size only)
    double skyKey[5] = {1e300, 0, 0, 0, 0};
    Camera last;
    bool haveLast = false;
    std::future<HorizonResult> earlyHorizon;  // FarField::beginFrame
    Camera earlyCamera;
    double lastMinDepth = 0;  // nearest far surface of the last cache frame (m; 0 = none yet)
    double msPerRay = 0;      // ray stage ms per ray (moving average; 0 = not measured)
    double compositeMs = 0;   // composite stage ms (moving average)
    // Cache duty cycle (FarFieldOptions::cacheAdaptive).
    int cachePaused = 0;                       // moving frames left to trace without the cache
    int cachePauseLength = kCachePauseFrames;  // the next pause (doubles while verdicts say it does not pay)
    int horizonPaused = 0;                     // moving frames left to trace without the horizon
    int horizonStrikes = 0;                    // judged frames in a row in which the horizon did not pay
    bool lastFrameCached = false;              // the last frame ran the cache stage (its stores are fresh)
    // Scratch of the cache stage, kept so that a frame does not fault in fresh pages.
    std::vector<CacheCandidate> cand;
    std::vector<uint8_t> traceMarks;
    std::vector<float> farDepth;    // swapped into FarFrame::farDepth for the frame
    std::vector<uint32_t> raySlot;  // ray stage (rayStep 2): per pixel, ~0 between frames
    SpeculativeRays spec;           // FarField::beginFrame (o.speculate)
    // Still objects (RayScene::stillObjects): per slot, the state the cache last accounted for,
    // and the scene's stillSerial() then.
    std::vector<StillState> stillSeen;
    uint64_t stillSerial = 0;
};

// Radius (pixels) of the screen window whose nearest far surface a cached cell records.
constexpr double kCacheWindowPx = 8.0;

// Working state of one frame, filled stage by stage.
struct FarFrame {
    FarFrame(const Camera& camera, const float* depth, Image& out, std::vector<uint8_t>& cls);
    const Camera& camera;
    const PixelRays rays;  // pixel-centre directions
    const int width, height;
    const size_t pixelCount;
    const float* depth;                    // near-field window depth (1 = nothing drawn), or null
    Image& out;                            // the frame (camera size)
    std::vector<uint8_t>& cls;             // per pixel: a FarPixelClass or kFarPending
    bool moving = false;                   // camera differs from the last frame's
    const Image* sky = nullptr;            // sky colour per pixel (set before the horizon stage)
    const FrameEffects* fx = nullptr;      // run-time effects (haze, night sky); never null during render()
    std::vector<uint8_t> columnNeeded;     // per column: has a pending pixel (opacity)
    uint64_t covered = 0;                  // pixels of class covered (opacity, seam)
    std::vector<uint32_t> seamCandidates;  // covered pixels the seam check examines (opacity)
    // The seam's hits and their hazed colours, written by writeSeamHits (the covered haze may
    // still be reading and writing those pixels while the seam casts).
    std::vector<std::pair<uint32_t, glm::u8vec4>> seamHits;
    std::vector<uint32_t> pending;       // pending pixels after the horizon, ascending
    std::vector<uint32_t> trace;         // pixels to trace this frame, ascending (cache)
    std::vector<int64_t> traceCells;     // their panorama cells (cache stage only)
    std::vector<glm::u8vec2> traceSubs;  // where their rays fall in those cells (cache stage only)
    // Per pixel: kFootprintMover inside a moving object's screen footprint, kFootprintStill inside
    // that of a still object that changed this frame (moverFootprint); empty = none.
    std::vector<uint8_t> moverMask;
    // World bounding spheres of the still objects that changed since the last frame, where they
    // were and where they are (stillChanges).
    std::vector<glm::dvec4> changedStills;
    std::vector<float>
        farDepth;  // cache mode: per pending pixel, eye-plane depth of its far colour (+inf = sky/none); others unset
};

// Opacity (far_field_opacity.cpp). In: depth (null = nothing covered). Out:
// cls (every pixel covered or pending), covered, columnNeeded, and
// seamCandidates: the covered pixels with window depth >= listAbove (> 1 =
// none), ascending. Records Opacity.
void opacityStage(FarFrame& f, FrameStats& stats, float listAbove = 2.0f);

// The window depth below which no covered pixel can lie beyond the near
// distance (the seam's candidates are the covered pixels at or above it).
float seamListDepth(const FarFrame& f, const FarFieldOptions& o);
// Seam check (far_field_seam.cpp) applies when o.verifySeam, the near field
// is a distance > 0, depth exists and the scene has triangles (it runs when,
// after the opacity stage, something is covered).
bool seamCheckApplies(const FarFrame& f, const RayScene& rays, const FarFieldOptions& o);
// In: seamCandidates, depth, o.nearDistance, o.depthZFar, camera.zNear. Every candidate
// pixel whose surface lies beyond the near distance casts one ray with tfar =
// that distance: a hit turns it rayHit (covered decremented, pixels.rayHit
// counted, its hazed colour listed in seamHits), a miss leaves it covered.
// Every such ray, hit or miss, is added to raysCast. Records Seam.
void seamStage(FarFrame& f, const RayScene& rays, const FarFieldOptions& o, FrameStats& stats);
// Writes the seam's hits (seamHits) into out; after the covered haze is done.
void writeSeamHits(FarFrame& f);

// Haze of the covered pixels (far_field_haze.cpp), run when o.hazeCovered,
// haze is on and depth exists: every pixel the near field drew (window depth
// < 1) gets the haze of its eye-plane depth (from depth, camera.zNear,
// o.depthZFar), the blend of FrameEffects::applyHaze. start(), before the
// opacity stage, runs it as a task beside the stages up to the ray stage:
// they write only pixels that are not covered (the seam's hits wait in
// seamHits), it writes only covered ones, and it reads the depth buffer,
// which nothing writes, so the work fills the core the serial stages
// (opacity, seam, horizon, the cache's lookups) leave idle. finish() waits
// for it (before anything reads a covered pixel's colour or writes a seam
// hit) and records Haze (stage and effect: the task's own wall time). With
// o.threads > 0 (each stage in an arena of its own) it runs within start().
// The destructor waits.
class CoveredHaze {
public:
    CoveredHaze() = default;
    CoveredHaze(const CoveredHaze&) = delete;
    CoveredHaze& operator=(const CoveredHaze&) = delete;
    ~CoveredHaze() { _group.wait(); }
    void start(const FarFrame& f, const FarFieldOptions& o);
    void finish(FrameStats& stats);

private:
    tbb::task_group _group;
    double _ms = 0;
    bool _started = false;
};

// Horizon (far_field_horizon.cpp), run when o.horizon. In: grid,
// columnNeeded, moving, camera. When horizon tracing applies, pending pixels
// above their column's row become horizonCulled with their sky colour (f.sky)
// written to out, and Horizon is recorded; when
// it does not (no grid, camera rolled, zenith/nadir in view) a note says why,
// nothing is culled and no time is recorded.
// early (optional): the horizon of this very camera traced ahead of the
// frame (FarField::beginFrame, all columns); then the stage waits for it
// (the wait is the recorded time) and notes "horizon overlapped".
// Returns the number of pixels culled (0 when it does not apply).
uint64_t horizonStage(FarFrame& f, const HeightGrid* grid, const FarFieldOptions& o, FrameStats& stats,
                      std::future<HorizonResult>* early = nullptr);
// What the rays of the `culled` pixels the horizon culled this frame (class
// kFarHorizon) would have cost the ray stage, in wall ms: a sample of at most
// `sample` of them, spread over the frame, cast from farRayStart(o) and timed
// on this thread with the far limit the ray stage would give them (haze),
// scaled to all of them and divided among the stage's workers (o.threads, or
// TBB's concurrency). Nearly all are sky misses, far cheaper than the frame's
// mean traced ray. 0 when none was culled.
double culledRaysMs(const FarFrame& f, const RayScene& rays, const FarFieldOptions& o, uint64_t culled,
                    size_t sample = 512);
// Far limit of a ray (unit direction d) that stops at eye-plane depth zMax
// (haze: nothing beyond the visibility is traced). In float, with a margin of
// 4e-6 of itself over float's rounding: a hit short of zMax is never cut
// (the caller compares the hit's depth with zMax in double).
inline float hazeTfar(const glm::vec3& d, const glm::vec3& fwd, float zMax) {
    return zMax / std::max(glm::dot(d, fwd), 1e-6f) * (1.0f + 4e-6f);
}
// The horizon options of a frame (near distance, haze depth, subsampling while moving).
HorizonOptions horizonOptions(const FarFieldOptions& o, bool moving);
// No far geometry: every pending pixel becomes horizonCulled, sky colour written. No time.
void cullAllPending(FarFrame& f, FrameStats& stats);

// Lists the pending pixels in f.pending (ascending). No time.
void listPending(FarFrame& f);
// Cache (far_field_cache.cpp), run when the cache is on and f.pending is not
// empty. In: f.pending, o.cacheErrorPx, o.pixelBudget, o.frameMsTarget,
// o.cacheOversample, m.prev, f.sky; the stage times already in `stats`.
// (Re)creates the panorama for the camera, selects the pixels to trace under
// the quality-bounded policy (f.trace, f.traceCells); the others become cache
// and get their cell's colour (never traced: last frame's pixel, else sky).
// Sizes f.farDepth to the frame and sets it for the cache pixels (their cell's
// nearest surface; the ray stage fills the traced ones; other pixels are left
// as they were and never read). Records Cache; with
// a frame-time target, a note gives the budget.
// Pixels traced (trace) include every pending pixel of f.moverMask.
void cacheStage(FarFrame& f, FarFieldMemory& m, const FarFieldOptions& o, FrameStats& stats);
// f.moverMask: the pixels whose centre ray passes within kMoverMarginPx
// pixels (at the image centre's pixel angle) of a moving object's bounding
// sphere (RayScene::moverSpheres: kFootprintMover) or of a sphere of
// f.changedStills (kFootprintStill); empty when there is none. Exact per
// pixel inside each sphere's bounding square on screen; a sphere holding the
// eye or crossing the eye plane marks every pixel. The cache stage traces
// every marked pixel; the composite forgets the cells of kFootprintMover
// pixels only (a still object's new look is kept).
constexpr double kMoverMarginPx = 1.5;
constexpr uint8_t kFootprintMover = 1, kFootprintStill = 2;
void moverFootprint(FarFrame& f, const RayScene& rays);
// Still objects (RayScene::stillObjects; FarFieldOptions::cacheMovers): every
// slot whose version differs from m.stillSeen's changed since the last
// frame. Its old sphere (if it was shown) and new one (if it is) go to
// f.changedStills, and the cache (if any) forgets the cells whose rays could
// pass through their bounding boxes (PanoramaCache::invalidateBox with
// m.cacheReach); m.stillSeen takes the new states. Nothing when
// stillSerial() is unchanged. Returns the number of cells forgotten.
uint64_t stillChanges(FarFrame& f, FarFieldMemory& m, const RayScene& rays);
// The panorama for `camera` (resolution and oversample as o.cacheOversample
// asks): kept when it fits, else made anew (its cells zero pages, not yet
// resident).
PanoramaCache& ensureCache(FarFieldMemory& m, const Camera& camera, const FarFieldOptions& o);
// The pixel budget of this frame: o.pixelBudget, capped with a frame-time
// target by what is left of it after spentMs at m.msPerRay (at least 1 % of
// the pixels); < 0 = no cap.
int64_t cacheBudget(const FarFrame& f, const FarFieldMemory& m, const FarFieldOptions& o, double spentMs);
// Cache off: f.trace = f.pending. No class, no time.
void bypassCache(FarFrame& f);

// Rays (far_field_rays.cpp). In: f.trace, o.rayStep, o.threads. Casts them
// with castPrimaryRays (rayStep 2: the even lattice first, the pixels between
// lattice pixels that showed one triangle blended, see FarFieldOptions); each
// becomes rayHit or rayMiss class, its colour (prelit or sky) written to out,
// its eye-plane depth to f.farDepth when that is set; raysCast += rays cast,
// pixels.rayHit / rayMiss count cast rays, pixels.interpolated the blended
// ones. Records Rays.
void raysStage(FarFrame& f, FarFieldMemory& m, const RayScene& rays, const FarFieldOptions& o, FrameStats& stats);

// Same pixel rays: eye, orientation, field of view and size (far_field.cpp).
bool sameCamera(const Camera& a, const Camera& b);
// Same colours for the same ray: the effects that shade rays (haze, its visibility, night sky).
inline bool sameRayShading(const FrameEffects& a, const FrameEffects& b) {
    return a.haze == b.haze && a.visibility == b.visibility && a.night == b.night;
}

// Speculative rays (far_field_speculate.cpp). Starts casting `pixels`
// (ascending, e.g. last frame's traced pixels) for `camera` with the ray
// stage's start distance and effects (o), on one other thread, chunk by
// chunk, into m.spec; any earlier speculation is stopped first. Nothing
// starts for an empty list or o.rayStep != 1.
void startSpeculation(FarFieldMemory& m, const RayScene& rays, const Camera& camera, const FarFieldOptions& o,
                      std::vector<uint32_t> pixels);
// Stops m.spec and takes its results for the ray stage: when it was cast for
// f.camera with farRayStart(o) and o's effects, every entry j of f.trace whose
// pixel a finished chunk cast gets its colour in f.out, hit[j] and depth[j]
// (depth may be null); the other entries' indices j are returned (ascending),
// all of them when nothing applies. Adds the speculative rays cast to
// raysCast and a note with how many were used. m.spec is idle afterwards.
std::vector<uint32_t> takeSpeculation(FarFrame& f, FarFieldMemory& m, const FarFieldOptions& o, uint8_t* hit,
                                      float* depth, FrameStats& stats);
// A frame without a ray stage: stops m.spec and counts its rays as cast and none used.
void discardSpeculation(FarFieldMemory& m, FrameStats& stats);

// Sky colours of the camera (far_field_composite.cpp), cached in m.sky.
const Image& skyImage(FarFieldMemory& m, const FarFrame& f);
// Composite (far_field_composite.cpp). In cache mode, stores the traced pixels' colours (now in out) into
// m.cache with the nearest far surface of their window (f.farDepth), sets
// m.lastMinDepth and keeps the frame in m.prev (when keepFrame). Assigns no
// class. Records Composite.
// keepFrame: keep the frame in m.prev (else m.prev is emptied; then never-traced cells left out show the sky).
void compositeStage(FarFrame& f, FarFieldMemory& m, bool cacheMode, FrameStats& stats, bool keepFrame = true);

}  // namespace vista
