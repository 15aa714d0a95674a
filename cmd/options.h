// Command-line values of the `vista` commands: one parser per option kind,
// used by every command that takes the option (bench, view, bake_report).
// Every number in an option's value is read by foundation/number_text.h:
// plain numeric options through addNumberOption (at parse time), and the
// numbers inside the other kinds (WxH, K/N, runs:K, lists, "auto" or a
// number) by their parsers below. Each parser returns the value or an error
// whose message names the flag, the value and the allowed range; the
// command prints it and exits with code 2 (reportBadInput, parseOrExit).
// The check* functions apply the same ranges to values set in code
// (BenchConfig), so a range is written once.
//
// PathFlags: the walkthrough options (--path, --seed, --kind, --duration,
// --run-up) of bench and view. ModeFlags: the render-mode options both `vista bench` and `vista view`
// accept (--near, --triangle-budget, --budget, --horizon-grid, --no-cache,
// --cache-error, --frame-ms, --no-overlap, --baked, --baked-mesh, --threads, --traffic), declared once by
// addModeFlags() and turned into ModeOptions by parseModeFlags().
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include <CLI/CLI.hpp>

#include "citygen/effects.h"
#include "foundation/number_text.h"
#include "foundation/output_paths.h"
#include "foundation/status.h"
#include "nodes/render/render_mode.h"
#include "runtime/scene/paged_walkthrough.h"
#include "runtime/scene/paths.h"
#include "runtime/scene/region_pager.h"
#include "runtime/traffic/traffic_tracks.h"

namespace vista {

struct ImageSize {
    int width = 0, height = 0;
};
constexpr int kMaxImageSide = 8192;
constexpr double kMinNearDistance = 1.0, kMaxNearDistance = 100000.0;
constexpr int64_t kMaxPixelBudget = 1000000000;
constexpr uint64_t kMaxTriangleBudget = 10000000000ull;
constexpr double kMinFovDeg = 1.0, kMaxFovDeg = 179.0;
constexpr int kMaxReferenceSsaa = 8;
constexpr int kNoReference = -1;  // --reference none

// --size WxH (x or X): each side 1 .. 8192 pixels.
Result<ImageSize> parseImageSize(const std::string& s);
Status checkImageSize(int width, int height);
// --near M|auto: metres in 1 .. 100000, or "auto" -> -1.
Result<double> parseNearDistance(const std::string& s);
Status checkNearDistance(double metres);  // < 0 = auto
// --budget N|unlimited: rays per frame 0 .. 1e9, or "unlimited" / "-1" -> -1.
Result<int64_t> parsePixelBudget(const std::string& s);
Status checkPixelBudget(int64_t rays);
// --fov D: vertical field of view in degrees, strictly between 1 and 179
// (bench, render, view: addNumberOption with kFovRange).
constexpr RealRange kFovRange = RealRange::open(kMinFovDeg, kMaxFovDeg);
Status checkFov(double degrees);
// --reference full|ssaa:K|none: 0 for `full`, K in 2 .. 8, kNoReference for `none`.
Result<int> parseReference(const std::string& s);
// --modes a,b,c: registered modes (render_mode.h), comma-separated, no duplicates.
Result<std::vector<std::string>> parseModeList(const std::string& s);
// --sampling spread|consecutive|runs:K (K in 1 .. 100000): 0 = spread, 1 =
// consecutive, K = runs (Path::frames).
Result<int> parseSampling(const std::string& s);
// The --sampling text of a value of parseSampling (its inverse).
std::string samplingName(int runs);
// --mode NAME: one registered mode.
Result<std::string> parseModeName(const std::string& s);
// vista bake: --cells "3,7,10-20" -> sorted unique ids (0 .. 1e8); --shard K/N
// with 1 <= K <= N; --texels 1 or AxB with A, B in 1 .. 32.
Result<std::vector<uint32_t>> parseCellList(const std::string& s);
Status parseTexels(const std::string& s, int& x, int& y);
// --point-splat SIGMA|off: Gaussian sigma of the impostor splats in output
// pixels, 0.05 .. 4, or "off" / "0" -> 0 (1-pixel points).
constexpr double kMinSplatSigma = 0.05, kMaxSplatSigma = 4.0;
Result<double> parseSplatSigma(const std::string& s);
Status checkSplatSigma(double sigma);        // 0 (off) or within the range
std::string formatSplatSigma(double sigma);  // "off" or the number
// --storage-budget auto|off|MB: -1 for auto, 0 for off, else MB in 0.01 .. 1e6.
constexpr double kMinStorageBudgetMb = 0.01, kMaxStorageBudgetMb = 1e6;
Result<double> parseStorageBudget(const std::string& s);
// --sweep sizes=S1,S2,...: city sizes in metres, each 100 .. 16000.
Result<std::vector<int>> parseSweep(const std::string& s);

// --effects: "none", a comma list of effect names (each keeps the parameters
// `base` declares for it, else its defaults), or a JSON object as in the
// parameter file's "effects". Unknown names / fields / values out of range ->
// error naming them and the known effects.
Result<Effects> parseEffectsOption(const std::string& s, const Effects& base);
// The run-time effects of a run (bench, viewer): the scene's `declared`
// ones, or --effects over them. Glass marks exist only where the scene
// declared glass at generation; baked effects follow the scene file (a note
// on stderr says so unless quiet; `cmd` prefixes it).
// `option` unset = the scene's; set = parsed (an empty value is an error; a
// baked effect other than night is refused: it cannot change per run).
Result<FrameEffects> runTimeEffects(const std::optional<std::string>& option, const Effects& declared, bool quiet,
                                    const char* cmd);

struct ModeFlags {
    std::string near = "auto", budget = "unlimited";
    uint64_t triangleBudget = 0;  // 0 = off (the near field by distance) .. kMaxTriangleBudget
    int horizonGrid = 0;          // 0 = auto (HeightGrid::autoCells)
    bool noCache = false, noOverlap = false, cacheAlways = false;
    double cacheError = 0.25, frameMs = 0.0;
    int farStep = 1;
    double nearDetail = kDefaultNearDetailPx;  // --near-detail: pixels, 0 = off
    bool noFrontToBack = false;
    std::string baked;
    std::string bakedMesh;
    std::string pointSplat;  // "" = the default (ModeOptions::splatSigma)
    int threads = 0;
    std::string traffic;  // --traffic DIR: a `vista traffic` directory drawn in every mode ("" = none)
};
// Declares the flags on `app`; the defaults shown are the values in `flags`.
void addModeFlags(CLI::App& app, ModeFlags& flags);
// Parses and range-checks the flags into `out`.
Status parseModeFlags(const ModeFlags& flags, ModeOptions& out);

// --traffic DIR: the agents' tracks (loadTrafficTracks), null for ""; errors
// name --traffic and the directory.
Result<std::shared_ptr<const TrafficTracks>> loadTrafficFlag(const std::string& dir);

// Range checks of ModeOptions (for options set in code).
Status checkModeOptions(const ModeOptions& o);

// Numeric options: one value, read by number_text.h when CLI11 parses the
// command line (decimal only: no hex, octal or binary prefix, no fraction for
// an integer, no '-' where the range has no negatives, never wrapped or
// truncated). A value outside the range or malformed throws
// CLI::ValidationError with number_text's message, which names the option,
// the text as written and the range ("option --frames = '0x10' is not a whole
// number (expected a decimal integer in [1, 1000000])"); parseOrExit prints it
// and returns exit code 2. The help shows CLI11's own type name (INT, UINT,
// FLOAT); capture_default_str() shows the variable's value as CLI11 would.
// A std::optional variable stays unset unless the option is given.
template <class T>
struct NumberOptionType {
    using type = T;
};
template <class T>
using NumberOptionBound = typename NumberOptionType<T>::type;  // a bound never deduces T

namespace option_detail {
// Registers `name` as a one-value option whose text goes to `set`; a failed
// Status becomes CLI::ValidationError. `shown` gives the default for the help.
CLI::Option* addConvertedOption(CLI::App& app, const std::string& name, const std::string& help,
                                const std::string& typeName, std::function<Status(const std::string&)> set,
                                std::function<std::string()> shown);
template <class T>
Result<T> parseInteger(const std::string& name, const std::string& text, T min, T max) {
    static_assert(std::is_integral_v<T> && !std::is_same_v<T, bool>, "an integer option");
    if constexpr (std::is_signed_v<T>) {
        auto v = parseSignedText("option " + name, text, int64_t(min), int64_t(max));
        if (!v) return v.status();
        return T(*v);
    } else {
        auto v = parseUnsignedText("option " + name, text, uint64_t(min), uint64_t(max));
        if (!v) return v.status();
        return T(*v);
    }
}
template <class T, class Store>
CLI::Option* addInteger(CLI::App& app, const std::string& name, T min, T max, const std::string& help, Store store,
                        std::function<std::string()> shown) {
    return addConvertedOption(
        app, name, help, CLI::detail::type_name<T>(),
        [name, min, max, store](const std::string& text) -> Status {
            auto v = parseInteger<T>(name, text, min, max);
            if (!v) return v.status();
            store(*v);
            return Status::ok();
        },
        std::move(shown));
}
}  // namespace option_detail

// Integers: [min, max], both included.
template <class T>
CLI::Option* addNumberOption(CLI::App& app, const std::string& name, T& value, NumberOptionBound<T> min,
                             NumberOptionBound<T> max, const std::string& help) {
    return option_detail::addInteger<T>(
        app, name, min, max, help, [&value](T v) { value = v; },
        [&value] { return CLI::detail::checked_to_string<T, T>(value); });
}
template <class T>
CLI::Option* addNumberOption(CLI::App& app, const std::string& name, std::optional<T>& value, NumberOptionBound<T> min,
                             NumberOptionBound<T> max, const std::string& help) {
    return option_detail::addInteger<T>(
        app, name, min, max, help, [&value](T v) { value = v; }, [] { return std::string(); });
}
// Reals: within `range` (RealRange: closed, open or half-open).
CLI::Option* addNumberOption(CLI::App& app, const std::string& name, double& value, const RealRange& range,
                             const std::string& help);
CLI::Option* addNumberOption(CLI::App& app, const std::string& name, std::optional<double>& value,
                             const RealRange& range, const std::string& help);

// A seed option (0 .. 2^64-1, decimal; addNumberOption): "-1" or 2^64 is a
// parse error naming the option and the range, never a wrapped value.
CLI::Option* addSeedOption(CLI::App& app, const std::string& name, uint64_t& seed, const std::string& help);

struct PathFlags {
    std::string file, kind = "car", route = routeStyleName(PathOptions().route);
    uint64_t seed = 1;
    double duration = 60.0, runUp = PathOptions().runUp;
    bool lht = false;
};
// Declares --path, --seed, --kind, --lht, --route and, with `timing`, --duration and --run-up.
void addPathFlags(CLI::App& app, PathFlags& flags, bool timing);
// The path options of the flags (kind and ranges checked; messages name the
// flag). --lht applies to car paths driven in lanes: with --kind walk or fly,
// or with a --path file (a recorded path, not driven here), it is an error.
Result<PathOptions> parsePathFlags(const PathFlags& flags);
// --lht for a path of `kind`: an error unless the path is a car path (walk
// and fly paths do not drive in lanes). `option` names the flag.
Status checkLeftHandTraffic(bool lht, PathKind kind);

// --frames N against a path of `samples` samples: more frames than samples
// would render samples more than once (spread and runs sampling repeat them),
// so N > samples is an error naming both unless `repeats`
// (--allow-repeated-frames) says the repeats are wanted.
Status checkFrameCount(int frames, size_t samples, bool repeats);
// Declares --allow-repeated-frames on `app` (bench, render).
void addRepeatedFramesFlag(CLI::App& app, bool& repeats);

// Every value given on the command line for an option that takes a value
// (flags excluded) must be non-empty: `--rig ""` or `--xodr-positions ""`
// would otherwise read as "option not given" and run without it. The error
// names the option and says to give a value or leave the option out.
// parseOrExit() applies it to every command.
Status refuseEmptyValues(const CLI::App& app);

// The file rule of a walkthrough run (bench, render, view): `files` holds the
// command's outputs; adds its inputs (the city, --path, --baked, --baked-mesh)
// and checks the rule (output_paths.h: paths resolved, no aliasing, the
// outputs locked while `files` lives), and that a --path file is a regular
// file within kMaxPathCsvBytes, before anything is read or created.
Status checkRunFiles(CommandFiles& files, const std::string& city, const PathFlags& path, const ModeFlags& mode);

// The paged-city reach (PagedReach, paged_walkthrough.h) of bench, view and render:
// --paged-radius M = metres around the walkthrough within which regions are
// loaded at full detail (default kDefaultPagedRadiusM); --paged-far M =
// metres within which the other regions are loaded at their coarse level,
// for the far field (default kDefaultPagedFarM = the whole city; 0 or <=
// radius: none).
void addPagedFlags(CLI::App& app, PagedReach& reach);
// Both values within [kMinPagedRadiusM, kMaxPagedRadiusM]; errors name the option.
Status validatePagedReach(const PagedReach& reach);

// Streaming a paged city (bench, view, render; cmd/paged_stream.h): a paged
// city streams by default: the chunked city and the ray scene follow the
// camera of each frame (nodes/render/city_stream.h, the region pager of
// runtime/scene/region_pager.h), the first frame waiting for the regions at
// its camera. --paged-preload = the preloading loader instead: the regions
// around the whole path are loaded before the first frame (and the city ends
// there); --paged-stream = ask for the stream explicitly (an error where the
// run cannot stream, instead of preloading); --paged-wait = each frame waits
// until the regions within reach of its camera are resident (deterministic
// frames); --paged-prefetch S = seconds of lookahead along the camera's
// velocity, 0 .. kMaxPagedPrefetchS (default kDefaultPagedPrefetchS).
struct PagedStreamFlags {
    bool stream = false;
    bool preload = false;
    bool wait = false;
    std::optional<double> prefetchS;
};
void addPagedStreamFlags(CLI::App& app, PagedStreamFlags& flags);
// Errors name the option: --paged-preload with --paged-stream, --paged-wait or --paged-prefetch.
Status validatePagedStream(PagedStreamFlags& flags);

}  // namespace vista
