// RegionPager: the streaming pager of a paged city (paged_load.h). It keeps
// the regions near a moving camera resident, loading them on worker threads
// ahead of the camera and dropping them behind it; the caller (the frame
// thread) owns what was loaded and mirrors it into its own structures (a
// RayScene's regions, a scene graph) between frames.
//
// The desired set, from the last update(eye, velocity): the lookahead's reach
// is every point the camera can get to within the lookahead at its speed,
// whichever way it turns: the disc of radius |velocity| * lookahead around the
// eye (xy only). A reach along the heading alone misses a turn: a camera that
// leaves a region's radius by a few metres and turns back at a corner needs
// the region again sooner than a load takes. The lookahead is
// prefetchS, or longer where loading is slower: outside wait mode it is at
// least kLookaheadLoads times the longest of the last kLoadTimesKept full-level
// loads (read and prepare, wall time on the worker), so a region comes within
// reach of the lookahead while there is still time to load it and the one
// queued before it (stats().lookaheadS). Wait mode keeps prefetchS, so its
// frames do not depend on load timing. Every non-empty
// region whose bounds (manifest `bounds`, 2D) come within `radius` of that
// reach is desired at full detail; every other region within `far` of it at
// its coarse level (far <= radius: none). With prefetchS = 0 and a resting
// eye this is exactly what loadPagedNear() loads for a path of one sample
// (selectPagedRegions / selectCoarseRegions of the eye). A region whose full
// file failed to load is desired at its coarse level instead; one whose coarse
// file failed too, not at all (each failure is reported once, never retried).
//
// Budget (budgetBytes > 0): the desired set's cost (a load's file bytes,
// manifest sizes, times its kind's weight in options.cost: the resident bytes
// the caller's prepare makes of one file byte) is held at or under it, less
// room for what the workers' loads pass through while they are prepared
// (options.cost.loading times the largest full file, per worker): coarse regions go first, farthest
// first, then full regions farthest first (the radius shrinks), each keeping
// its coarse level if that fits; then regions left out get their coarse level
// back, nearest first, while it fits (a budget below every full region keeps
// the coarse levels near the eye). The resident
// bytes (levels held by the caller plus loads in flight or not yet collected)
// (their cost) never exceed the budget either: a region changing level keeps its old level
// until the new one arrives only when both fit, else the old level is dropped
// first.
//
// Chunk parts (chunkRadius >= 0): a full level then loads without its
// near-field chunks (RegionLoad::chunks false), and the chunks come as a part
// of their own (RegionLoad::level false: the full file read again, prepared
// for its chunks only) for the full regions within chunkRadius of the
// lookahead's reach: a near field that reaches a few hundred metres keeps
// chunks for the few regions around the camera, not for every full region.
// A part is dropped when its region leaves the band or its full level goes;
// it counts in the resident bytes (its file's bytes) and in the cost at its
// own weight. Under a budget the parts of the full regions in the band are
// counted before any level is cut (the near field around the camera
// outranks the far city; a full region cut from the radius takes its part
// with it), then given nearest first while they fit. chunkRadius < 0:
// every level comes with its chunks (one load, RegionLoad::chunks true).
//
// Load order: by urgency, then by the mean of the region's distance to the
// eye and to the end of the lookahead along the heading (eye + velocity *
// lookahead; so regions ahead of the heading come
// before those behind at the same distance): full regions within reach of the
// eye, coarse regions within reach of the eye, then regions wanted only for the
// lookahead. Only loads not yet started are re-ordered or cancelled; a load in
// flight whose region is no longer wanted is discarded when it arrives.
//
// Threads: update(), collect() and stats() are called from one thread (the
// frame thread); loads (loadPagedRegion) run on `workers` worker threads and
// never on the caller's. The destructor cancels queued loads and joins the
// workers (a load in flight finishes first).
//
// collect(): what changed since the last call: regions that arrived (each
// with its SceneModel, handed over: the pager keeps no copy) and levels to
// drop (the caller frees them). Apply the drops before the arrivals: a region
// changing level comes as a drop of one level and an arrival of the other.
// Arrivals and drops are sorted (drops by region; arrivals full before coarse,
// by region), so a run that waits (below) hands the same lists in the same
// order whatever the timing. In wait mode (options.wait) collect() first
// blocks until every desired level is resident or failed (a failed full file
// then waits for its coarse fallback): the caller then holds exactly the
// desired set, the same regions as a synchronous load of the same reach.
// collect(true) waits so once without wait mode (a viewer's first frame).
//
// The regions at the camera: the non-empty regions whose bounds hold the eye
// (2D), else the nearest non-empty one when it is within reach (radius or
// far) of the eye. cameraShortfall(): after update(), whether the budget
// left one of them out altogether (not even its coarse level fits: frames
// there would draw nothing), with what they need (cost, as the budget counts
// it, plus the loading reserve) at their coarse and at their full level.
// belowDetail(): after collect(), the regions that the caller holds below
// the detail their distance from the last eye asks for (full within radius,
// at least coarse within far; a failed file counts).
//
// Contract (VISTA_CHECK): radius and far finite and >= 0, prefetchS finite
// and >= 0, budgetBytes >= 0, cost weights finite and > 0 (loading >= 0), workers 1 .. 16,
// eye and velocity finite.
#pragma once
#include <algorithm>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <glm/glm.hpp>

#include "runtime/scene/paged_load.h"
#include "runtime/scene/scene_model.h"

namespace vista {

// Default lookahead of --paged-prefetch, seconds along the velocity.
constexpr double kDefaultPagedPrefetchS = 4.0;
constexpr double kMaxPagedPrefetchS = 600.0;
// The adaptive lookahead (above): loads of time it covers, and how many recent full loads it remembers.
constexpr double kLookaheadLoads = 2.0;
constexpr int kLoadTimesKept = 8;

// What one load makes of a region's file (RegionPagerOptions::prepare).
struct RegionLoad {
    int region = 0;
    bool coarse = false;
    bool level = true;   // the level itself (false: a chunk part, see above)
    bool chunks = true;  // its near-field chunks
};

// Resident bytes per file byte of each kind of load, as the caller's prepare
// makes them (the budget's weights; 1 everywhere: the budget counts file bytes).
struct RegionCost {
    double full = 1.0, coarse = 1.0, chunks = 1.0;  // full level, coarse level, chunk part
    // The passing peak of decoding and preparing a load, beyond what it keeps, per file byte:
    // under a budget, room for each worker's largest load (the largest full file) is held back.
    double loading = 0.0;
};

struct RegionPagerOptions {
    double radius = kDefaultPagedRadiusM;  // metres: full detail within
    double chunkRadius = -1;               // metres: chunk parts within (< 0: chunks come with every level)
    double far = kDefaultPagedFarM;        // metres: coarse level within (<= radius: none)
    double prefetchS = kDefaultPagedPrefetchS;
    uint64_t budgetBytes = 0;  // the resident loads' cost (bytes); 0 = no budget
    RegionCost cost;           // the budget's weights
    bool wait = false;         // collect() blocks until the desired set is resident
    int workers = 1;
    // Optional: run on the worker thread right after a level loads (e.g. the
    // near-field chunks of its graph, its Embree scene); it may complete the
    // model in place, and its result travels in RegionArrival::prepared.
    // Must be thread-safe and must not throw.
    std::function<std::shared_ptr<void>(SceneModel& model, const RegionLoad& load)> prepare;
};

// One region level loaded on a worker thread.
struct RegionArrival {
    int region = 0;  // index into the manifest's regions
    bool coarse = false;
    bool chunks = false;  // a chunk part (of the full level), not a level
    SceneModel model;
    uint64_t bytes = 0;              // its file bytes (manifest)
    std::thread::id loader;          // the worker thread that read it
    uint64_t sequence = 0;           // 1, 2, ...: the order in which the pager's loads finished
    std::shared_ptr<void> prepared;  // what options.prepare made of it (null without one)
};

struct RegionDrop {
    int region = 0;
    bool coarse = false;
    bool chunks = false;  // a chunk part, not a level
};

struct RegionPagerDelta {
    std::vector<RegionDrop> dropped;
    std::vector<RegionArrival> arrived;
    std::vector<std::string> damaged;  // one message per file that failed to load (it names the file)
    bool waited = false;               // wait mode: collect() blocked for a load
};

struct RegionPagerStats {
    uint64_t residentBytes = 0;      // levels held by the caller, in flight or not yet collected
    uint64_t peakResidentBytes = 0;  // the most residentBytes has been
    uint64_t residentCost = 0;       // the same loads' cost (options.cost): what the budget holds
    uint64_t heldCost = 0;           // ... of the loads held by the caller alone
    uint64_t peakResidentCost = 0;   // the most residentCost has been
    uint64_t loadingReserve = 0;     // of the budget, held back for the loads being prepared
    uint64_t processOverhead = 0;    // set by CityStream::holdProcessUnder: the process's memory beside its loads
    uint64_t bytesRead = 0;          // file bytes of the successful loads
    int loads = 0;                   // successful loads (discarded ones included)
    int chunkLoads = 0;              // ... of which chunk parts
    int unloads = 0;                 // levels handed out as drops
    int discarded = 0;               // loads that arrived unwanted and were freed here
    int failed = 0;                  // loads that failed (damaged or missing files)
    int framesWaited = 0;            // collect() calls that blocked (wait mode)
    double waitMs = 0;               // total time blocked in collect()
    int budgetLimited = 0;           // updates whose desired set the budget cut
    int residentFull = 0, residentCoarse = 0;  // levels held by the caller now
    int residentChunks = 0;                    // chunk parts held by the caller now
    double lookaheadS = 0;                     // the last update()'s lookahead (seconds)
    double peakLookaheadS = 0;                 // the longest lookahead of any update()
    double fullLoadSMax = 0;                   // the longest full-level load (read and prepare), seconds
};

// RegionPager::cameraShortfall(): the budget cannot hold the regions at the camera.
struct RegionShortfall {
    bool starved = false;
    std::vector<int> regions;  // the regions at the camera (manifest indices)
    uint64_t needCoarse = 0;   // their coarse levels' cost + the loading reserve
    uint64_t needFull = 0;     // their full levels' (and chunk parts') cost + the loading reserve
};

class RegionPager {
public:
    // `manifest` must outlive the pager.
    RegionPager(const PagedManifest& manifest, const RegionPagerOptions& options);
    ~RegionPager();
    RegionPager(const RegionPager&) = delete;
    RegionPager& operator=(const RegionPager&) = delete;

    // Decides the desired set for the eye (world metres) moving at `velocity`
    // (metres per second), drops what is no longer wanted and queues the loads.
    void update(const glm::dvec3& eye, const glm::dvec3& velocity);
    RegionPagerDelta collect(bool wait = false);
    RegionPagerStats stats() const;
    // Replaces the budget (options.budgetBytes; 0 = none) from the next update() on: for a
    // caller that follows the process's measured memory (CityStream::holdProcessUnder).
    void setBudget(uint64_t bytes);
    // True when no load is queued, being prepared or waiting to be collected.
    bool idle() const;
    RegionShortfall cameraShortfall() const { return _shortfall; }
    int belowDetail() const;

    // The desired set of the last update(): per manifest region 0 (none), 1
    // (coarse) or 2 (full).
    const std::vector<uint8_t>& desired() const { return _desired; }
    // What the caller holds now (after the last collect()): same coding.
    std::vector<uint8_t> held() const;

private:
    struct Job {
        int region = 0;
        bool coarse = false;
        bool chunks = false;  // a chunk part
    };
    struct Done {
        Job job;
        Result<SceneModel> model = Status::error("not loaded");
        std::thread::id loader;
        uint64_t sequence = 0;
        std::shared_ptr<void> prepared;
    };
    enum Level : uint8_t { kNone = 0, kCoarse = 1, kFull = 2 };

    void workerLoop();
    void schedule(RegionPagerDelta* delta);
    void computeDesired();
    void drop(int region, bool coarse, RegionPagerDelta* delta, bool chunks = false);
    void computeChunks(uint64_t total);
    int urgency(const Job& j) const;
    std::vector<uint8_t>& hold(const Job& j) { return j.chunks ? _holdChunks : (j.coarse ? _holdCoarse : _holdFull); }
    std::vector<uint8_t>& flight(const Job& j) {
        return j.chunks ? _flightChunks : (j.coarse ? _flightCoarse : _flightFull);
    }
    bool wanted(const Job& j) const {
        return j.chunks ? _desiredChunks[size_t(j.region)] != 0
                        : _desired[size_t(j.region)] == (j.coarse ? kCoarse : kFull);
    }
    void takeArrivals(std::deque<Done>& done, RegionPagerDelta* delta);
    uint64_t levelBytes(int region, bool coarse) const;
    uint64_t cost(int region, bool coarse, bool chunks = false) const;  // levelBytes times the kind's weight
    uint64_t _reserve = 0;  // workers x the largest load's passing peak (cost.loading)
    uint64_t _budget = 0;   // budgetBytes less _reserve: what the held and queued loads' cost may reach
    double regionKey(int region) const;

    const PagedManifest& _m;
    RegionPagerOptions _o;
    glm::dvec2 _eye{0.0}, _ahead{0.0};
    double _reach = 0;  // metres the camera covers in the lookahead at its speed
    // The distance from the lookahead's reach (the disc of radius _reach around the eye) to a
    // region at `eyeDistance` metres from the eye.
    double reachDistance(double eyeDistance) const { return std::max(0.0, eyeDistance - _reach); }
    bool _haveEye = false;

    // Frame-thread state.
    std::vector<uint8_t> _desired;
    std::vector<uint8_t> _nearEye;                    // 1: wanted within reach of the eye itself
    std::vector<uint8_t> _holdFull, _holdCoarse;      // held by the caller (or arrived, not yet collected)
    std::vector<uint8_t> _flightFull, _flightCoarse;  // queued or loading
    std::vector<uint8_t> _failedFull, _failedCoarse;
    // Chunk parts (chunkRadius >= 0): wanted, near the eye itself, held, queued or loading.
    std::vector<uint8_t> _desiredChunks, _nearEyeChunks, _holdChunks, _flightChunks;
    std::vector<double> _key;    // load order within an urgency (lower first)
    RegionPagerDelta _pending;   // drops decided by update(), handed out by the next collect()
    RegionShortfall _shortfall;  // of the last update()
    void computeShortfall();
    RegionPagerStats _stats;

    // Shared with the workers (under _mutex).
    mutable std::mutex _mutex;
    std::condition_variable _work, _arrived;
    std::deque<Job> _queue;
    std::deque<Done> _done;
    std::deque<double> _fullLoadS;  // the last kLoadTimesKept full-level loads, seconds
    double _fullLoadSMax = 0;
    int _busy = 0;
    uint64_t _finished = 0;
    bool _stop = false;
    std::vector<std::thread> _threads;
};

}  // namespace vista
