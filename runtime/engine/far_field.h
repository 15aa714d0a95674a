// FarField: the per-frame far-field pipeline of thesis ch. 4 on plain arrays
// (no OSG, no GL): opacity from the near field's depth, horizon tracing,
// panoramic cache, Embree ray casting, composite, pixel counts, stage times.
//
// Per frame, every pixel is classified exactly once (thesis Table 4.1);
// classification() holds the class per pixel, FrameStats::pixels the counts:
//   covered        the near field drew it (depth < 1) and the frame leaves its
//                  colour as is. This includes seam-checked pixels whose ray
//                  missed (nothing far lies in front of the drawn surface).
//   horizonCulled  sky colour without a ray: above the horizon row of its
//                  column, or no far geometry exists beyond the near distance.
//   cache          colour taken from the panoramic cache (no ray this frame).
//   rayHit         a ray cast this frame hit geometry; the pixel shows its
//                  prelit colour. Either an uncovered pixel traced by the ray
//                  stage, or a covered pixel whose seam-check ray hit far
//                  geometry in front of the near field's surface (replaced).
//   rayMiss        an uncovered pixel traced this frame that hit nothing: sky.
// FrameStats::raysCast += every Embree ray of the frame, hit or miss: the ray
// stage's (rayHit + rayMiss of uncovered pixels) plus every seam-check ray
// (those that hit are also rayHit; those that missed are counted only here).
// So raysCast >= rayHit + rayMiss, with equality when no seam ray missed.
// Sky colour = lighting.h skyColor(elevation of the pixel-centre ray), the same
// as the OffscreenRenderer's background, so sky pixels agree across modes.
//
// The frame runs as named stages, one file each (far_field_<stage>.cpp, see
// far_field_stages.h and docs/reference/far-field.md): opacity, seam, horizon, cache,
// rays, composite. Stages run only when called for: no uncovered pixel ->
// nothing after opacity; no far geometry (city bounds within the near
// distance, or an empty city) -> no horizon/cache/ray stage (note "rays off:
// no far geometry"); camera rolled / zenith or nadir in view -> no horizon
// stage (note says why); horizon not paying -> paused (horizonAdaptive, a
// note); cache off -> every remaining pixel traced. stats.stages records the time of
// every stage that ran (Stage::Opacity, Seam, Horizon, Cache, Rays,
// Composite); stats.notes explains skipped stages.
//
// Determinism: the image, classes and counts do not depend on thread count.
// The pauses (cacheAdaptive, horizonAdaptive; default on) follow measured
// times, so with them the classes and counts of a moving frame can differ
// between runs, and its image within the cache's error bound: the cache's
// pause changes which pixels it serves, and so does the horizon's with the
// cache on (a culled pixel is neither looked up nor stored; a traced miss is
// both). Without the cache the horizon's pause leaves the image as it is.
// Ray casting runs in a tbb::task_arena with `threads` workers (0 = all cores);
// FTZ/DAZ are set in every casting thread (RayScene). Not thread-safe itself;
// nothing throws. Contract: depth (if not null) has width*height entries.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "runtime/engine/frame_effects.h"
#include "runtime/engine/frame_stats.h"
#include "runtime/scene/camera.h"
#include "runtime/engine/horizon.h"
#include "runtime/engine/image.h"
#include "runtime/engine/panorama_cache.h"

namespace vista {

class RayScene;
struct FarFieldMemory;
struct FarFrame;

// Pixel classes of classification() (see above).
enum FarPixelClass : uint8_t { kFarCovered = 0, kFarHorizon = 1, kFarCache = 2, kFarRayHit = 3, kFarRayMiss = 4 };

// Moving frames the cache pauses for when it did not pay (FarFieldOptions::cacheAdaptive);
// each further verdict in a row that it does not pay doubles the pause, up to kCacheMaxPauseFrames.
constexpr int kCachePauseFrames = 8;
constexpr int kCacheMaxPauseFrames = 64;
// Moving frames the horizon pauses for when it did not pay (FarFieldOptions::horizonAdaptive).
constexpr int kHorizonPauseFrames = 8;
// Judged frames in a row in which the horizon must not pay before it pauses.
constexpr int kHorizonStrikes = 2;

struct FarFieldOptions {
    double nearDistance = 100.0;  // metres (>= 0): horizon skips geometry the near field draws; 0 = skip nothing
    // true: the near field draws every object whose bounding box comes within nearDistance of
    // the eye (selectNearField), so no surface nearer than nearDistance is missing from it: far
    // and seam rays start at nearDistance. false when the near field is a triangle budget (then
    // rays start at the eye and the horizon skips nothing).
    bool nearIsDistance = true;
    // The tallest moving object standing on the far geometry (metres, >= 0; a
    // traffic run's agents, 0 = none): the horizon bounds every cell that much
    // higher (HorizonOptions::lift), so no moving object is cut off as sky.
    double movingHeight = 0;
    // Panoramic cache (panorama_cache.h): a cached far pixel is reused while
    // its estimated reprojection error is below cacheErrorPx (0 = only
    // pixels traced by this very camera), else re-traced, the worst first, up
    // to pixelBudget rays (< 0 = no cap) and, with frameMsTarget > 0, up to
    // what the target leaves after the stages before the cache stage (ms per
    // ray measured as the frames go; at least 1 % of the pixels).
    int64_t pixelBudget = -1;
    double cacheErrorPx = 0.25;
    double frameMsTarget = 0.0;
    bool cache = true;
    bool horizon = true;
    // Pause the horizon while it does not pay: when a moving frame's horizon
    // stage (the trace, or the wait for a trace that overlapped the near
    // field) took longer than the rays of the pixels it culled would have
    // (culledRaysMs: a timed sample of those rays, far_field_stages.h) on
    // kHorizonStrikes judged frames in a row, the next kHorizonPauseFrames
    // moving frames trace those pixels instead (they miss and show the same
    // sky; a note says so); then it is traced and judged again. On an elevated view over a 64 km² city the trace over
    // the 2048-cell grid cost 80 to 120 ms a frame for a few ms of sky rays. Never paused for a still camera or under a
    // pixel budget or frame-time target (the culled pixels would eat the budget).
    bool horizonAdaptive = true;
    // Speculative rays: beginFrame also casts last frame's traced pixels for
    // the new camera, on one other thread while the near field is drawn (on
    // this machine the draw keeps 1.1 of 2 cores busy); the ray stage takes
    // the results of the pixels it traces (the same rays, so the same
    // image) and casts only the rest. Rays for pixels not traced this frame
    // are wasted, and counted in raysCast (a note says how many were used).
    // Only with rayStep 1 and only after beginFrame.
    bool speculate = true;
    // The caller begins each frame before drawing the near field (FarField::beginFrame):
    // the bench's hybrid and the viewer's FarFieldNode (at cull time) do so while set
    // (`--no-overlap` clears it). FarField itself does not read it.
    bool overlap = true;
    int horizonSubsampleMoving = 1;  // >= 1: subsample factor of the horizon while the camera moves
    double cacheOversample = 1.5;
    // Moving objects of the ray scene (RayScene::placeMovers, a traffic run's
    // agents): every pending pixel within the screen footprint of one's
    // bounding sphere now (plus kMoverMarginPx) is traced, never served from
    // the cache, and its cell is not kept (PanoramaCache::forget), so no
    // cached colour ever shows a moving object where it was, nor hides one
    // where it is. Still objects of the ray scene (placeMovers' `still` list, a
    // traffic run's lamp overlays) are cached as the city is: on a frame where
    // one changed (its StillState::version differs from the one the cache last
    // saw: another lamp, shown or hidden), the cells whose rays could pass
    // through its old and new bounding boxes are forgotten
    // (PanoramaCache::invalidateBox) and its screen footprint is traced that
    // frame, so the change shows on that very frame; on the other frames its
    // pixels are served from the cache. false: the naive cache (measurements
    // of its error only).
    bool cacheMovers = true;
    // Pause the cache while it does not pay: after two consecutive cache
    // frames of a moving camera, if the share r of pending pixels the second
    // reused, times the measured ms per ray, is below the measured ms per
    // lookup (the cache stage per pending pixel), the next
    // kCachePauseFrames moving frames trace every far pixel without lookups
    // (a note says so); then two cache frames measure again, and a second
    // verdict in a row doubles the pause (16, 32, at most kCacheMaxPauseFrames:
    // on a fly-over the two measuring frames cost 12 to 17 ms of lookups
    // each); a verdict that it pays resets it. Never paused for
    // a still camera or under a pixel budget or frame-time target. false =
    // always look up (the cache Pareto front of docs/measurements/far-field.md measures that).
    bool cacheAdaptive = true;
    int threads = 0;
    // Ray spacing of the far field: 1 = a ray per far pixel (exact); 2 = rays
    // on the even pixel lattice first, and a pixel between lattice pixels
    // that were all cast this frame and all showed the same triangle (or all
    // the sky) takes their perspective-correct blend instead of a ray (its
    // own sky colour when they showed sky). Lossy: a feature narrower than
    // two pixels between lattice pixels on one triangle is missed.
    int rayStep = 1;
    // Far plane of the projection the near-field depth was rendered with
    // (camera.zNear is the near plane); <= 0 = infinite. Used to turn depth into
    // distance for the seam check below.
    double depthZFar = 0.0;
    // Seam check: a near-field object straddling the near distance is drawn,
    // but its parts beyond the near distance may lie behind far geometry the
    // rasteriser never saw. Covered pixels whose surface is farther than
    // nearDistance are re-cast with tfar = that distance; a hit replaces the
    // pixel (counted as rayHit instead of covered); every such ray, hit or
    // miss, counts in raysCast. Off = trust coverage.
    bool verifySeam = true;
    // Run-time effects: haze (rays, horizon and seam stop at hazeFar; haze
    // stage after the rays), night sky. Glass marks pass through untouched
    // (the reflection stage after the frame handles them).
    FrameEffects effects;
    // Haze of the near field done here instead of in the rasteriser: the
    // covered pixels of `out` arrive unhazed and are hazed from the depth
    // buffer (hybrid: the colour is read back anyway, and a per-fragment
    // haze program costs more on a CPU rasteriser than one pass over the
    // pixels). No effect without haze or without depth.
    bool hazeCovered = false;
};

class FarField {
public:
    // `grid` may be null (no horizon stage). Both must outlive the FarField.
    FarField(const RayScene& rays, const HeightGrid* grid, const FarFieldOptions& options);
    ~FarField();
    void setOptions(const FarFieldOptions& options);
    const FarFieldOptions& options() const { return _options; }
    // Fills every uncovered pixel of `out` (resized to the camera if needed;
    // covered pixels keep their colour). depth: near-field window depth, 1 =
    // nothing drawn; null = nothing covered. Adds pixel counts, raysCast,
    // stage times and notes to `stats`.
    void render(const Camera& camera, const float* depth, Image& out, FrameStats& stats);
    // Optional, before the near field of a frame is drawn: starts the horizon
    // of `camera` on another thread (all columns), so that it overlaps the
    // draw; render() of the same camera then waits for it instead of tracing
    // (the Horizon stage time is the wait; a note says so). A render() of
    // another camera discards it. No horizon without a grid or with the
    // horizon off or not applicable to the camera. With o.speculate, also
    // starts the speculative rays of last frame's traced pixels
    // (FarFieldOptions::speculate), which render() stops and takes.
    void beginFrame(const Camera& camera);
    // Waits until the speculative rays beginFrame started are all cast (tests:
    // makes what render() takes from them deterministic; a frame never waits).
    void awaitSpeculation();
    // Drops the cache (walkthrough jump).
    void reset();
    // Parts of the scene inside these world boxes arrived or left (a streamed
    // city): the cache forgets the cells whose rays could pass through one
    // (PanoramaCache::invalidateBox), the speculative rays cast into the old
    // scene and the kept frame go; every other cell is served as before.
    // Returns the number of cells forgotten.
    uint64_t sceneChanged(const SceneBoxes& boxes);
    // Per pixel of the last frame: a FarPixelClass (0 covered, 1 horizon, 2 cache, 3 hit, 4 miss).
    const std::vector<uint8_t>& classification() const { return _class; }
    // The pixels the ray stage of the last frame cast (ascending indices
    // y * width + x; empty when it did not run): rayHit/rayMiss pixels that
    // were not covered. Seam-check rays are not in it. RaySet files record it.
    const std::vector<uint32_t>& lastTraced() const { return _traced; }
    // Where the last frame's far-field rays started (metres; FarFieldOptions::nearIsDistance).
    float lastRayStart() const { return _rayStart; }

private:
    void renderStages(FarFrame& f, const float* depth, FrameStats& stats);
    const RayScene& _rays;
    const HeightGrid* _grid;
    FarFieldOptions _options;
    std::unique_ptr<FarFieldMemory> _mem;  // cache, last frame, sky, early horizon (far_field_stages.h)
    std::vector<uint8_t> _class;
    std::vector<uint32_t> _traced;
    float _rayStart = 0.0f;
};

}  // namespace vista
