// The bench: renders a walkthrough path in several modes side by side
// (interleaved frame by frame in one process) and writes frames.csv,
// summary.json, plots and difference images.
//
// Modes are created through makeMode() from a table (kModeTable in
// bench.cpp). Other modules add theirs there: `hybrid` (runtime/mode_hybrid.h)
// and `impostor` (bake/mode_impostor.h, registered by the `vista` tool's main).
//
// Reference: every frame is compared with the `full` image of the same
// camera (or, with referenceSsaa = k > 1, with the average of k x k
// sub-pixel-jittered `full` renders = a box-filtered supersampled image).
// Metrics: luma PSNR (metrics.h, capped at 99 dB for identical images) and
// the fraction of pixels differing by more than diffThreshold.
// Timing: frame_ms per mode as reported by the mode (glFinish included);
// one warm-up frame per mode is rendered and discarded before frame 0.
// summary.json per mode: frame-time, quality and triangle statistics, plus
// `pixels` (Table 4.1 classes as min/mean/max percent of the frame and mean
// count; only for modes that classify pixels: hybrid, raycast, impostor),
// `stages_ms` (mean ms per stage over the frames it ran in) and `stage_runs`;
// top level `options` records the BenchOptions used (docs/user-guide.md).
// Errors: bad configuration or setup failures (no display, unknown mode,
// Embree failure) return a Status; nothing throws.
#pragma once
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "foundation/status.h"
#include "nodes/render/render_mode.h"
#include "runtime/scene/paths.h"

namespace vista {

// ---- Mode factory -----------------------------------------------------------
using ModeFactory = Result<std::unique_ptr<BenchMode>> (*)(BenchContext& ctx);
struct ModeInfo {
    const char* name;
    const char* summary;
    bool needsRays;     // the bench builds ctx.rays (RayScene) before creating it
    ModeFactory make;
};
// All registered modes, in display order.
const std::vector<ModeInfo>& modeTable();
// Adds a mode (or replaces one of the same name). Call at start-up, before
// any bench runs; not thread-safe. Used for modes of libraries that depend on
// runtime, such as the bake's `impostor`.
void registerBenchMode(const ModeInfo& mode);
std::vector<std::string> availableModes();
const ModeInfo* findMode(const std::string& name);
// Creates a mode. Unknown name -> error listing the available modes. The
// caller must have built ctx.rays when the mode needs rays.
Result<std::unique_ptr<BenchMode>> makeMode(const std::string& name, BenchContext& ctx);
// Parses "full,near,raycast" (comma-separated, no duplicates, known names).
Result<std::vector<std::string>> parseModeList(const std::string& list);

// ---- The bench loop ---------------------------------------------------------
struct BenchConfig {
    int width = 640, height = 480;
    int frames = 120;
    double fovYDeg = 60.0;
    double zNear = 0.3;
    std::vector<std::string> modes{"full", "near"};
    std::string outDir;            // created if missing; empty = write nothing
    int referenceSsaa = 0;         // 0/1 = `full` image; k >= 2 = k x k supersampled full
    int diffThreshold = 8;         // for the differing-pixel fraction (0..255)
    int worstFrames = 2;           // difference images for the N worst frames per mode
    bool warmup = true;
    bool quiet = false;            // no progress on stderr
    BenchOptions options;
    std::string command;           // recorded in summary.json
    std::string cityLabel;         // recorded in summary.json
};
// Also checks the far-field options: nearDistance < 0 (auto) or 1 .. 100000
// metres; pixelBudget < 0 (unlimited) or 0 .. kMaxPixelBudget; horizonGrid
// 1 .. 8192; threads 0 .. 1024. Messages name the command-line flag.
Status validateBenchConfig(const BenchConfig& c);

// Command-line values of the far-field options (messages name the flag, the
// value and the allowed range):
//   --near M|auto      -> metres in 1 .. 100000, or -1 for "auto"
//   --budget N|unlimited -> 0 .. kMaxPixelBudget, or -1 (also "-1") for unlimited
constexpr double kMinNearDistance = 1.0, kMaxNearDistance = 100000.0;
constexpr int64_t kMaxPixelBudget = 1000000000;
Result<double> parseNearDistance(const std::string& s);
Result<int64_t> parsePixelBudget(const std::string& s);

struct BenchFrameRecord {
    int frame = 0;
    size_t pathIndex = 0;
    double t = 0;
    std::string mode;
    FrameStats stats;
    double psnrDb = 0, diffFraction = 0;
};

// One pixel class over the frames of a mode: percent of the frame's pixels
// (min / mean / max over frames) and the mean count per frame.
struct PixelClassSummary {
    double minPct = 0, meanPct = 0, maxPct = 0, meanCount = 0;
};

struct ModeSummary {
    std::string mode;
    double frameMsMedian = 0, frameMsP95 = 0, frameMsMean = 0;
    double speedupVsFullMedian = 0;
    double psnrDbMedian = 0, psnrDbMin = 0;
    double diffFractionMedian = 0;
    double trianglesMedian = 0, drawCallsMedian = 0, cullMsMedian = 0, drawMsMedian = 0;
    // Pixel classes (thesis Table 4.1); hasPixels = false when the mode
    // classified no pixel in any frame (full, near, osgimpostor).
    bool hasPixels = false;
    PixelClassSummary covered, horizonCulled, cache, rayHit, rayMiss;
    // Per stage: mean ms over the frames in which it ran, and in how many it ran.
    std::map<std::string, double> stagesMsMean;
    std::map<std::string, int> stageRuns;
};

struct BenchResult {
    std::vector<BenchFrameRecord> frames;
    std::vector<ModeSummary> modes;
    std::string glRenderer;
};

// Runs the bench. `city` may be null (synthetic scene: then ray modes fail
// with an error); `scene` is the scene graph rendered by the GL modes.
Result<BenchResult> runBenchmark(const SceneModel* city, osg::Node* scene, const Path& path, const BenchConfig& config);

// Median / percentile (linear interpolation) of a copy of v; NaN if empty.
double percentile(std::vector<double> v, double p);

}  // namespace vista
