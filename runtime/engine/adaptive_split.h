// The near/far split (thesis §4.3.1) and its automatic choice (§6.4.3).
//
// selectNearField(): which objects the rasteriser draws. By distance: every
// object whose axis-aligned bounding box comes within `nearDistance` of the
// eye (objects straddling the boundary are drawn whole: no popping, and every
// geometry point closer than nearDistance is drawn). By triangle budget: the
// nearest objects (by box distance) until the budget would be exceeded (the
// first object is always drawn). Pure; thread-safe.
//
// AdaptiveSplit: picks the near distance per frame from the measured cost of
// this machine. Four kinds of choice, each priced with its own fixed costs:
//   0 (ray casting): the hybrid draws the `raycast` frame (no GL pass, no
//     read-back, no far-field stage): every pixel cast. Priced by the probe's
//     timed ms per ray over the whole view (one thread, divided among the
//     cores) times the pixels, or, without probe timing, b * rays(0).
//   a middle distance d: c + a * triangles(d) (c only if triangles(d) > 0:
//     an empty near field needs no GL pass) + b * rays(d) + F.
//   +infinity (everything): the `full` frame, c + a * all triangles.
//   the fixed distance (AdaptiveSplitOptions::fixedDistance, `hybrid-fixed`'s
//     choice): priced as a middle distance, corrected by its own frames (until
//     they ran, by the middle frames like it, as a middle distance), so that
//     the split falls back to it where the model's middle does not pay.
// Triangles are counted in view: an object whose box lies wholly outside one
// of the view's four side planes is culled by the renderer and costs no
// raster time (for everything, counted at each probe, and every triangle on
// a city of more than 200,000 objects; with haze, only objects within it).
// Each kind's price is corrected by what its own frames measured (an end point's or the fixed
// distance's frames drawn by a guard instead of the choice count too: recordFrame()): the lower quartile over
// its last 8 frames
// (recordFrame()) of (whole frame ms, the decision included) minus (the current model's price of what that frame
// drew and traced); a middle distance by those middle frames nearest to its triangles in view and far pixels (log
// scale, within 1.1x of the nearest: one offset for every middle distance priced the model's favourite below every
// frame where its slope over the distance is wrong, on fly-overs). Re-priced as the model learns, so a residual taken
// against the first frames' priors does not outlive them, and frames slowed by other work (which only slows) do not
// price a kind out of reach. So costs the model does not see (the probe, the cull, the
// sky layer, haze in the rasteriser, the ray stage's task start-up) are
// learned online for each alternative instead of tuned. Until a kind has run
// its correction is 0; each kind is tried now and then (its cheapest
// candidate, when the kind has not run for `endTryEvery` frames and its price
// is within `endTryRatio` of the best) so that a wrong price does not keep
// the split from it. Everything is offered before the raster cost is
// measured only to be tried, never as the best on the priors alone (a frame
// of a large city drawn whole can cost a quarter second). F skips the far
// field's first frame (one-time costs).
// raster ms = c + a * triangles and far ms = c' + b * far pixels are robust
// line fits (Theil-Sen) over the last `window` frames, whose near distances
// differ as the walk goes on; priors until a fit is well conditioned; b falls
// back to the mean ms per far pixel, and a fitted b is kept within [1/5, 1] of
// that mean; b is capped by the probe's bulk ms per far ray (the probe rays
// that need the far field at the current near distance, cast again from it
// and timed on one thread; timing all probe rays priced far rays like the
// short ones into nearby facades, and the split then shrank the near field
// into ever more rays): a fixed cost per frame (thread start, packet set-up)
// divided by a few hundred rays would otherwise make rays look dearer than
// they are, push the near field out, and so starve the fit), the far field's
// fixed cost F (opacity, seam, horizon, composite: exponential moving
// average), the raster's fixed cost c (the fit's median residual: clear,
// read-back), predicted triangles(d) from the objects' boxes (exact) and
// predicted rays(d) from a sparse probe of the view (every `probeStride`-th
// pixel, sparser so that a large image gets about `probeRays` probe rays,
// fewer on frames so cheap that the probe would cost more than 2.5 % of one,
// cast once per `probeInterval` frames and at once when the view jumped (eye
// moved more than minDistance, heading or pitch more than 0.1 rad since the
// probe): a pixel whose first hit lies beyond d, or that misses below the
// horizon, needs a ray; with haze (setHazeFar) the probe stops at the haze
// and a surface beyond it counts as a miss: sky above the horizon costs no
// ray). rays(d) is not capped by the pixel budget: the aim is the lowest
// frame time at full accuracy (a budget-capped model would always pick the
// smallest near field and let the cache's error grow). The last choice is
// kept unless another is priced lower by more than `switchMargin` (a change
// of distance costs the frames after it: the band between the two distances
// is in neither the cache nor the last frame's traced pixels). While the two
// fits are not both well conditioned, every `exploreEvery`-th choice steps
// one candidate up or down from the optimum so that the fit sees varied
// triangle counts, when that neighbour's price is within `exploreRatio` of
// the best (else only every fourth time); once they are, the walk's views
// vary the counts.
// Not thread-safe; deterministic for given measurements (timeProbe off).
#pragma once
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <unordered_map>
#include <vector>

#include <glm/glm.hpp>

#include "runtime/scene/camera.h"

namespace vista {

class RayScene;

struct SplitObject {
    glm::dvec3 lo{0.0}, hi{0.0};  // world bounding box
    uint64_t triangles = 0;
};

double boxDistance(const SplitObject& o, const glm::dvec3& p);

// SplitIndex: the objects bucketed on a uniform xy grid (cells of `cell`
// metres, each object in the cell of its box's low corner; objects wider
// than a cell in x or y in a list visited by every query), so that the
// objects near a point are found by visiting the cells within reach, not
// every object: a paged 32 km city has half a million 40 m chunks, and a
// linear scan per frame cost 20 ms. Keeps a reference to `objects` (they must
// outlive it). within() returns exactly what the linear selectNearField()
// returns (tested).
//
// Blocks (a streamed city): the index is a set of blocks, each a run of
// objects[first, first + count) bucketed on its own grid (makeBlock(), built
// from the run's objects alone on any thread, e.g. a pager's worker), added
// and removed by key between queries (addBlock / removeBlock: no other block
// is touched). A static index is one block of every object (key 0). A
// streamed index (SplitIndex(objects, blockCell)) starts empty and finds the
// blocks within reach through a grid of blockCell-metre cells (each block in
// the cell of its low corner), so a query visits the blocks and cells near
// the point, whatever the number of blocks resident. Objects outside every
// block (free slots of a streamed list) are never visited. Queries order
// their results by block key, then by index (for a static index: ascending).
// Queries are const and thread-safe; addBlock/removeBlock are not (call them
// between queries). The objects of a block must not change while it is in
// the index.
class SplitIndex {
public:
    // A run of objects bucketed on its own grid (local indices 0 .. count-1).
    struct Block {
        double cell = 64.0, x0 = 0, y0 = 0;
        int nx = 0, ny = 0;
        std::vector<uint32_t> start, items, wide;  // CSR cells: items[start[c] .. start[c+1])
        glm::dvec2 lo{0.0}, hi{0.0};               // xy bounds of the run's boxes (lo > hi: empty)
        uint32_t count = 0;
        uint64_t triangles = 0;
    };
    static std::shared_ptr<const Block> makeBlock(const SplitObject* objects, size_t count, double cell = 64.0);

    explicit SplitIndex(const std::vector<SplitObject>& objects, double cell = 64.0);
    // A streamed index: no block yet; blockCell (> 0, metres) = the cells that find blocks (a region's size).
    SplitIndex(const std::vector<SplitObject>& objects, double blockCell, std::nullptr_t);
    // objects[first, first + block->count) must hold the objects the block was made of. Contract:
    // a streamed index, a key not in the index.
    void addBlock(uint64_t key, uint32_t first, std::shared_ptr<const Block> block);
    void removeBlock(uint64_t key);  // no such key: nothing

    // Every object whose box comes within d of p (boxDistance <= d), in block order; all for d = +inf.
    std::vector<uint32_t> within(const glm::dvec3& p, double d) const;
    // (boxDistance, triangles) of every object within d of p, unsorted.
    void distances(const glm::dvec3& p, double d, std::vector<std::pair<double, uint64_t>>& out) const;
    // f(index, boxDistance) for every object within d of p, unordered.
    template <class F>
    void visitWithin(const glm::dvec3& p, double d, F&& f) const {
        visit(p, d, [&](uint64_t, uint32_t i) {
            const double t = boxDistance(_objects[i], p);
            if (t <= d) f(i, t);
        });
    }
    // f(block key, index, boxDistance) for every object within d of p, unordered.
    template <class F>
    void visitKeyed(const glm::dvec3& p, double d, F&& f) const {
        visit(p, d, [&](uint64_t key, uint32_t i) {
            const double t = boxDistance(_objects[i], p);
            if (t <= d) f(key, i, t);
        });
    }
    // The work of a query within d of p: blocks whose bounds were tested, objects whose boxes were.
    struct VisitCost {
        size_t blocks = 0, objects = 0;
    };
    VisitCost cost(const glm::dvec3& p, double d) const;
    uint64_t totalTriangles() const { return _total; }
    size_t size() const { return _count; }  // objects in the blocks
    size_t blockCount() const { return _blocks.size(); }
    const std::vector<SplitObject>& objects() const { return _objects; }

private:
    struct Entry {
        uint32_t first = 0;
        std::shared_ptr<const Block> block;
    };
    // f(block key, index) for every object of the blocks whose bounds come within d of p.
    template <class F>
    void visit(const glm::dvec3& p, double d, F&& f, VisitCost* cost = nullptr) const;
    int64_t blockCellOf(const Block& b) const;
    const std::vector<SplitObject>& _objects;
    std::map<uint64_t, Entry> _blocks;
    double _blockCell = 0;                                           // 0: every block is tested (a static index)
    double _maxExtent = 0;                                           // widest block (x or y) ever added
    std::unordered_map<int64_t, std::vector<uint64_t>> _blockCells;  // block cell -> keys
    uint64_t _total = 0;
    size_t _count = 0;
};

// Returns the indices of the near-field objects (ascending).
std::vector<uint32_t> selectNearField(const std::vector<SplitObject>& objects, const glm::dvec3& eye,
                                      double nearDistance);
std::vector<uint32_t> selectNearField(const SplitIndex& index, const glm::dvec3& eye, double nearDistance);
std::vector<uint32_t> selectNearFieldByBudget(const std::vector<SplitObject>& objects, const glm::dvec3& eye,
                                              uint64_t triangleBudget);
// The same through the index (only its blocks' objects; ordered as within()): the nearest
// objects are found within a reach doubled from 64 m until the budget is reached or every
// object is in reach, so a frame visits the objects near the eye, not every one.
std::vector<uint32_t> selectNearFieldByBudget(const SplitIndex& index, const glm::dvec3& eye, uint64_t triangleBudget);

struct AdaptiveSplitOptions {
    double minDistance = 15.0, maxDistance = 800.0;
    int candidates = 16;     // geometric steps between min and max
    int probeStride = 8;     // probe every 8th pixel in x and y, at least
    int probeRays = 2400;    // ... and sparser on larger images: about this many rays (640x480 / 128)
    int probeInterval = 10;  // frames between probes
    double smoothing = 0.2;  // EMA weight of a new measurement
    double initialDistance = 100.0;
    int window = 60;             // frames in the raster-cost fit
    int exploreEvery = 7;        // every n-th choice explores a neighbouring candidate while the fits are not
                                 // both well conditioned (0 = never)
    double exploreRatio = 1.2;   // ... when its price is within this factor of the best (else every 4th time)
    double switchMargin = 0.05;  // the last choice is kept unless another is priced lower by more than this share
    int endTryEvery = 40;        // a kind (0, middle, everything) not chosen for this many frames is tried ...
    double endTryRatio = 1.3;    // ... when its price is within this factor of the best (0 = never)
    // Two more candidates at the ends: 0 (ray casting: the `raycast` frame) and
    // +infinity (everything rasterised: the `full` frame). Ray casting is
    // offered once both costs have been measured or the probe is timed (its
    // price is the probe's rate); everything once both are measured, and
    // before that, from the same point as ray casting, only to be tried.
    bool rayCastOnly = true, everythingNear = true;
    // The fixed near distance (`hybrid-fixed`) as a candidate of its own kind (0 = none): priced
    // like a middle distance, corrected by its own frames.
    double fixedDistance = 0;
    // Time the probe: its bulk ms per ray caps b (off: b from the frames alone, deterministic).
    bool timeProbe = true;
};

class AdaptiveSplit {
public:
    AdaptiveSplit(const std::vector<SplitObject>& objects, const RayScene* rays, const AdaptiveSplitOptions& o = {});
    // Over an index the caller keeps (a streamed near field: its blocks change between frames).
    AdaptiveSplit(const SplitIndex& index, const RayScene* rays, const AdaptiveSplitOptions& o = {});
    // Near distance to use for this frame (0 and +infinity possible, see the options).
    double choose(const Camera& camera, int64_t pixelBudget);
    // Measurements of the frame just rendered: the near field's triangles and
    // raster ms; the far pixels filled (cached or traced; the hybrid leaves out
    // those its speculative rays filled during the draw) and the ms of the
    // stages that scale with them (cache + rays); the far field's other
    // stages' ms (fixedMs; 0 when the frame had no far field).
    void record(uint64_t triangles, double rasterMs, uint64_t farPixels, double farMs, double fixedMs = 0);
    // The whole frame's ms (decision included) of a frame rendered at nearD: the distance
    // choose() returned last, or an end point (0, +infinity) or the fixed distance drawn instead
    // of it (a guard held or measured it, split_guard.h; the fixed distance's frame is priced with
    // its triangles in view and far pixels at the last choice); other values are ignored.
    // Corrects that kind's price: a reference's price rests on every frame drawn at it, not only
    // on the split's rare tries (one or two frames in 24, whose noise then priced it against
    // eight frames of the middle). The first frame of the middle or the fixed distance, whichever
    // runs first, is not counted (the far field's one-time costs); the other's first frame is.
    void recordFrame(double nearD, double frameMs);
    // Haze: nothing beyond this eye-plane depth (metres) is traced; 0 = no haze.
    void setHazeFar(double zMax) { _hazeFar = zMax; }
    // The learned correction of a kind's price (0 = ray casting, 1 = middle, 2 = everything,
    // 3 = the fixed distance), ms.
    // The lower quartile over the kind's last 8 counted frames of (frame ms - the current
    // model's price of what that frame drew and traced); 0 before its first counted frame.
    double correctionMs(int kind) const;
    double msPerTriangle() const { return _a; }
    double rasterFixedMs() const { return _c; }  // the raster fit's intercept (0 until a is fitted)
    double msPerRay() const;                     // per far pixel: the frames' model, capped by the probe's bulk rate
    double farFixedMs() const { return _f; }
    double current() const { return _current; }
    // The triangles in view of the last choice (0 for ray casting): what the raster fit is
    // fed (record()'s triangles) by a caller that drew that choice.
    uint64_t chosenTriangles() const { return _chosenTris; }
    // Predictions (exposed for tests/docs).
    uint64_t predictedTriangles(const glm::dvec3& eye, double d) const;
    double predictedRays(double d) const;
    const SplitIndex& index() const { return _index; }

private:
    void probe(const Camera& camera);
    const std::vector<SplitObject>& _objects;
    std::unique_ptr<SplitIndex> _ownIndex;  // over a static object list (null: the caller's index)
    const SplitIndex& _index;
    const RayScene* _rays;
    AdaptiveSplitOptions _o;
    double _a = 2e-5, _b = 5e-4, _f = 0, _bProbe = 0;       // priors: ms per triangle, ms per far pixel, fixed far ms
    double _c = 0;                                          // fixed raster ms (fitted with a)
    bool _haveA = false, _haveB = false, _haveF = false;    // measured (not the priors)
    bool _bFitted = false;                                  // _b is the frames' well-conditioned slope (not the mean)
    std::vector<std::pair<double, double>> _rasterSamples;  // (triangles, ms), last `window` frames
    std::vector<std::pair<double, double>> _farSamples;     // (far pixels, ms), last `window` frames
    double _current;
    int _frame = 0;
    std::vector<float> _probeT;            // per probe pixel: first hit distance (inf = miss), sorted ascending
    double _probeScale = 1;                // screen pixels per probe pixel
    double _probeAllMs = 0;                // one-thread ms per probe ray over the whole view (EMA; 0 = not timed)
    double _hazeFar = 0;                   // setHazeFar
    double _frameMs = 0;                   // EMA of the recorded frames' ms
    double _probeMsPerRay = 0;             // the last probe's whole ms per probe ray
    static constexpr int kSplitKinds = 4;  // ray casting, middle, everything, the fixed distance
    int kindOf(double d) const;
    // The model's price of a choice of `kind` that draws `tris` triangles in view and traces
    // `rays` far pixels in a frame of `pixels` pixels.
    double priceOf(int kind, double tris, double rays, double pixels) const;
    // A frame the split chose, as its kind's correction needs it.
    struct KindFrame {
        double tris = 0, rays = 0, pixels = 0, frameMs = 0;
    };
    std::vector<KindFrame> _kindFrames[kSplitKinds];             // per kind: its last counted frames
    bool _kindSeen[kSplitKinds] = {false, false, false, false};  // per kind: its first (uncounted) frame ran
    uint64_t _chosenTris = 0;                                    // the last choice's triangles in view
    double _chosenRays = 0;                                      // ... and its predicted far rays
    uint64_t _everythingTris = 0;                                // every object's triangles in view at the last probe
    uint64_t _fixedTris = 0;                                     // the fixed distance's triangles in view ...
    double _fixedRays = 0;                                       // ... and predicted far rays, at the last choice
    int _lastKindFrame[kSplitKinds] = {0, 0, 0, 0};              // per kind: the frame it was last chosen or tried
    int _farFrames = 0;                                          // frames recorded with a far field
    int64_t _pixels = 0;                                         // the camera's pixel count at the last choice
    glm::dvec3 _probeEye{0.0};                                   // the camera of the last probe
    double _probeHeading = 0, _probePitch = 0;
};

}  // namespace vista
