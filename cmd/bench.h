// The bench: renders a walkthrough path in several render modes side by side
// (interleaved frame by frame in one process, one GL context), scores every
// frame against a reference and writes frames.csv, summary.json, plots and
// difference images (bench_output.cpp). Modes come from the registry
// (nodes/render/render_mode.h); nothing here is specific to one mode.
//
// Steps of runBenchmark(): set up (renderer, ray scene if a mode needs it,
// the modes; every set-up cost timed), warm up (one frame per mode,
// discarded, then reset), the frame loop, summarise (summariseMode), write.
// Reference: every frame is compared with the `full` image of the same
// camera (or, with referenceSsaa = k > 1, with the average of k x k
// sub-pixel-jittered `full` renders = a box-filtered supersampled image).
// With no reference (kNoReference: a long drive measured for its time and
// memory alone) `full` runs only when listed, PSNR and differing fractions
// are NaN (empty in frames.csv, null in summary.json), no worst frames or
// quality plot are written, and speedups are against the bases that ran.
// Metrics: luma PSNR (metrics.h, capped at 99 dB for identical images) and
// the fraction of pixels differing by more than diffThreshold.
// Timing: frame_ms per mode as reported by the mode (glFinish included).
// Speedups: the median over frames of same-frame ratios base_ms[f] /
// mode_ms[f] (never a ratio of medians), against `full`, `near` and
// `raycast` when they ran (`full` always runs but with no reference).
// Errors: bad configuration or setup failures (no display, unknown mode,
// Embree failure) return a Status; nothing throws.
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "cmd/memory.h"
#include "cmd/paged_stream.h"
#include "foundation/atomic_file.h"
#include "foundation/statistics.h"
#include "foundation/status.h"
#include "nodes/render/render_mode.h"
#include "runtime/scene/paths.h"
#include "runtime/scene/region_pager.h"
#include "runtime/traffic/traffic_tracks.h"

namespace vista {

struct BenchConfig {
    int width = 640, height = 480;
    int frames = 120;
    int sampleRuns = kDefaultSampleRuns;  // 0 = frames spread over the path; k = k runs of consecutive samples
    double fovYDeg = 60.0;
    double zNear = 0.3;
    std::vector<std::string> modes{"full", "near"};
    std::string outDir;           // created if missing; empty = write nothing
    int referenceSsaa = 0;        // 0/1 = `full` image; k >= 2 = k x k supersampled full; kNoReference = none
    int diffThreshold = 8;        // for the differing-pixel fraction (0..255)
    int worstFrames = 2;          // difference images for the N worst frames per mode
    bool countFragments = false;  // notes each GL frame's fragments that pass the depth test (setCountFragments)
    bool saveFrames = false;      // every frame of every mode as frames/f<NNNN>_<mode>.png
    // Non-empty: every dumpRaysEvery-th frame (0, N, 2N, ...) of every mode
    // with a far-field ray stage (RenderMode::lastTracedPixels: hybrid) is
    // written as <dir>/<mode>_f<NNNN>.rays (RaySet, runtime/engine/ray_set.h),
    // outside the timed frame. No such mode among `modes` is an error.
    std::string dumpRaysDir;
    int dumpRaysEvery = 1;  // 1 .. 1000000
    bool warmup = true;
    bool quiet = false;  // no progress on stderr
    // Paced (--pace): frame f starts no earlier than its path time after the first frame's
    // (t[f] - t[0] seconds of wall time): a drive at the path's own speed.
    bool pace = false;
    // Every mode also runs without the run-time effects, on the same frames,
    // as "MODE+clear" (the two alternate which goes first from frame to
    // frame); its speedup against MODE is the effects' same-frame cost ratio.
    bool alsoClear = false;
    ModeOptions options;
    std::string command;                              // recorded in summary.json
    std::string cityLabel;                            // recorded in summary.json
    std::vector<MemoryPhase> memoryPhases;            // phases measured by the caller before the run (load)
    double memoryBudgetGb = 0, memoryEstimateMb = 0;  // --memory-budget (0 = none) and the up-front estimate
    double loadMs = -1;                  // city load time measured by the caller (set-up "load"); < 0 = not reported
    double runUpS = -1;                  // the path's run-up (PathOptions::runUp) when the bench made it; < 0 = unknown
    std::string effectsDeclared = "{}";  // the scene's effects (JSON, effects.h), recorded in summary.json
    // A paged city's load (summary.json "paged": regions_loaded, regions_total,
    // radius_m, bytes_loaded): JSON object, empty = a city file.
    std::string pagedJson;
    // A paged city streamed (the default, cmd/paged_stream.h): its manifest (outlives the run)
    // and the pager's options; the chunked city graph and the ray scene of
    // the modes are then a CityStream (nodes/render/city_stream.h) advanced
    // to every frame's camera (and its velocity along the path) before the
    // frame, and `city` / `scene` are not drawn (only the modes of
    // modeStreams(); hybrid's near field, split index and horizon grid are
    // the stream's too, and the modes drop what they cached of the old scene
    // whenever regions arrive or leave: RenderMode::sceneChanged). Null: the
    // modes draw `scene` and cast into `city`.
    const PagedManifest* streamManifest = nullptr;
    RegionPagerOptions stream;
    // A paged city, loaded or streamed: its manifest (ModeContext::paged; outlives the run).
    const PagedManifest* pagedManifest = nullptr;
    // --traffic: the agents every mode draws at each frame's path time
    // (ModeContext::traffic); null = no traffic (nothing of it runs).
    std::shared_ptr<const TrafficTracks> traffic;
};
// Checks sizes, frame count, fov, reference, modes and the mode options
// (options.h ranges); messages name the command-line flag.
Status validateBenchConfig(const BenchConfig& c);

struct BenchFrameRecord {
    int frame = 0;
    size_t pathIndex = 0;
    double t = 0;
    std::string mode;
    FrameStats stats;
    double psnrDb = 0, diffFraction = 0;
    int regionsArrived = 0;  // streamed: region levels that finished loading and joined the scene before this frame
    int runOrder = 0;        // 0, 1, ...: when the mode ran within the frame (the order rotates frame by frame)
};

// One pixel class over the frames of a mode: percent of the frame's pixels
// (min / mean / max over frames) and the mean count per frame.
struct PixelClassSummary {
    double minPct = 0, meanPct = 0, maxPct = 0, meanCount = 0;
};

struct ModeSummary {
    std::string mode;
    double frameMsMedian = 0, frameMsP95 = 0, frameMsMean = 0, frameMsP99 = 0, frameMsMax = 0;
    // Streamed runs: frame times of the frames before which a region level
    // arrived (and was spliced in) against those of the other frames.
    struct FrameTimes {
        int frames = 0;
        double medianMs = 0, p99Ms = 0, maxMs = 0;
    };
    bool streamed = false;
    FrameTimes withArrivals, withoutArrivals;
    // Base mode -> median over frames f of base_ms[f] / mode_ms[f].
    std::map<std::string, double> speedupMedianOfRatios;
    double psnrDbMedian = 0, psnrDbMin = 0;
    double diffFractionMedian = 0;
    double trianglesMedian = 0, drawCallsMedian = 0, cullMsMedian = 0, drawMsMedian = 0;
    double raysMedian = 0;  // FrameStats::raysCast per frame
    // Pixel classes (thesis Table 4.1); hasPixels = false when the mode
    // classified no pixel in any frame (full, near, osgimpostor, osglod).
    bool hasPixels = false;
    PixelClassSummary covered, horizonCulled, cache, rayHit, rayMiss, interpolated;
    // Per stage: mean ms over the frames in which it ran, and in how many it ran.
    std::map<std::string, double> stagesMsMean;
    std::map<std::string, int> stageRuns;
    // Run-time effects: mean ms over the frames each ran in, and in how many frames it ran.
    std::map<std::string, double> effectsMsMean;
    std::map<std::string, int> effectRuns;
    double glassPixelsMean = 0, reflectionRaysMean = 0;
    std::map<std::string, int> noteCounts;  // frame notes and in how many frames each appeared
    SetupTimes setupMs;                     // load, bvh, then the mode's own
};

struct BenchResult {
    std::vector<BenchFrameRecord> frames;  // frame-major: all modes of frame 0, then frame 1, ...
    std::vector<ModeSummary> modes;        // `full` first
    std::string glRenderer;
    PathMotion motion;  // of the rendered frames
    double loadAvgStart = -1, loadAvgEnd = -1;
    std::vector<MemoryPhase> memory;  // load, setup (ray scene, modes), frames
    // Streamed runs (BenchConfig::streamManifest): the pager's totals, the
    // frames before which a region arrived, the damaged files (each once).
    bool streamed = false;
    RegionPagerStats stream;
    RegionPagerOptions streamOptions;  // the stream's own (its chunk radius)
    int framesWithArrivals = 0;
    // Per frame: the frame thread's time in the stream's advance() before it
    // (pager update, collect, splicing arrivals into the graph and the ray
    // scene; with --paged-wait the wait too), outside the frame's own time.
    std::vector<double> advanceMs;
    std::vector<std::string> streamDamaged;
    StreamDetail streamDetail;  // frames that drew a region below the detail its distance asks for
};

// The config with `full` moved to the front of the modes (the reference of
// every frame is rendered before the others; summaries list it first).
BenchConfig withFullFirst(BenchConfig cfg);

// Runs the bench. `city` may be null (hand-built graph: then ray modes fail
// with an error); `scene` is the scene graph the GL modes draw.
Result<BenchResult> runBenchmark(const SceneModel* city, osg::Node* scene, const Path& path, const BenchConfig& config);

// Median over frames of baseMs[f] / modeMs[f]; frames where either time is
// not positive are skipped; NaN when none is left. Sizes must match.
double medianOfSameFrameRatios(const std::vector<double>& baseMs, const std::vector<double>& modeMs);
// Frame times of one mode in frame order (empty if it did not run).
std::vector<double> modeFrameTimes(const BenchResult& r, const std::string& mode);
// The summary of one mode over r.frames (pixels = width * height); speedups
// against every mode of `bases` that ran (itself included).
ModeSummary summariseMode(const BenchResult& r, const std::string& mode, const std::vector<std::string>& bases,
                          double pixels);
// The bases of speedups in summaries: full, near, raycast.
const std::vector<std::string>& speedupBases();
// The name of a mode's twin without run-time effects (BenchConfig::alsoClear).
std::string clearTwinName(const std::string& mode);

// frames.csv, summary.json, frame_time.png, quality.png (bench_output.cpp),
// each staged into `batch` (the caller commits).
Status writeBenchOutputs(const BenchResult& r, const BenchConfig& cfg, const SceneModel* city, const Path& path,
                         OutputBatch& batch);

}  // namespace vista
