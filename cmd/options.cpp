// Command-line value parsers (options.h).
#include "cmd/options.h"

#include "foundation/input_file.h"
#include "foundation/number_text.h"
#include "runtime/traffic/signal_states.h"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <unistd.h>

namespace vista {

namespace {

// "AsepB" (sep one of `seps`): A and B decimal integers in [lo, hi]
// (number_text.h). An error names "option WHAT", the whole text and the part
// (`nameA`, `nameB`), and ends in `shape`.
Status parsePair(const std::string& s, const char* seps, const std::string& what, const char* nameA, const char* nameB,
                 uint64_t lo, uint64_t hi, const std::string& shape, uint64_t& a, uint64_t& b) {
    const std::string head = "option " + what + " = '" + echoText(s) + "': ";
    const size_t k = s.find_first_of(seps);
    if (k == std::string::npos) return Status::error(head + "no '" + seps[0] + "'" + shape);
    auto first = parseUnsignedText(nameA, s.substr(0, k), lo, hi);
    if (!first) return Status::error(head + first.status().message() + shape);
    auto second = parseUnsignedText(nameB, s.substr(k + 1), lo, hi);
    if (!second) return Status::error(head + second.status().message() + shape);
    a = *first;
    b = *second;
    return Status::ok();
}

// number_text's error for an option that also takes words ("auto", "off").
Status orWords(const Status& s, const std::string& words) { return Status::error(s.message() + " (or " + words + ")"); }

std::string num(double v) {
    std::ostringstream o;
    o << v;
    return o.str();
}

}  // namespace

Status checkImageSize(int w, int h) {
    if (w < 1 || h < 1 || w > kMaxImageSide || h > kMaxImageSide)
        return Status::error("--size " + std::to_string(w) + "x" + std::to_string(h) +
                             " out of range 1x1 .. 8192x8192 pixels");
    return Status::ok();
}

Result<ImageSize> parseImageSize(const std::string& s) {
    uint64_t w = 0, h = 0;
    VISTA_RETURN_IF_ERROR(parsePair(s, "xX", "--size", "width", "height", 1, kMaxImageSide,
                                    " (expected WIDTHxHEIGHT, e.g. 640x480, each 1 .. 8192 pixels)", w, h));
    return ImageSize{int(w), int(h)};
}

Status parseTexels(const std::string& s, int& x, int& y) {
    if (s == "1") {
        x = y = 1;
        return Status::ok();
    }
    uint64_t a = 0, b = 0;
    VISTA_RETURN_IF_ERROR(parsePair(s, "xX", "--texels", "A", "B", 1, 32,
                                    " (expected 1 or AxB with A, B in [1, 32], e.g. 8x2, 4x1)", a, b));
    x = int(a);
    y = int(b);
    return Status::ok();
}

Result<std::vector<uint32_t>> parseCellList(const std::string& s) {
    const std::string shape = " (expected ids or ranges like 3,7,10-20)";
    if (s.empty()) return Status::error("--cells '': no cell id given" + shape);
    std::vector<uint32_t> out;
    std::stringstream ss(s);
    std::string item;
    while (std::getline(ss, item, ',')) {
        if (item.empty()) continue;
        const size_t dash = item.find('-', 1);
        const std::string what = "--cells item '" + echoText(item) + "'";
        auto a = parseUnsignedText(what, item.substr(0, dash), 0, 100000000);
        if (!a) return Status::error(a.status().message() + shape);
        uint64_t b = *a;
        if (dash != std::string::npos) {
            auto r = parseUnsignedText(what, item.substr(dash + 1), *a, 100000000);
            if (!r) return Status::error(r.status().message() + shape);
            b = *r;
        }
        for (uint64_t v = *a; v <= b; ++v) out.push_back(uint32_t(v));
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    if (out.empty()) return Status::error("--cells '" + echoText(s) + "': no cell id given" + shape);
    return out;
}

Status checkNearDistance(double v) {
    if (v < 0 || (v >= kMinNearDistance && v <= kMaxNearDistance)) return Status::ok();
    return Status::error("--near " + num(v) + " out of range 1 .. 100000 metres (or 'auto')");
}

Result<double> parseNearDistance(const std::string& s) {
    if (s == "auto") return -1.0;
    auto v = parseRealText("option --near", s, kMinNearDistance, kMaxNearDistance);
    if (!v) return orWords(v.status(), "'auto'");
    return v;
}

Status checkPixelBudget(int64_t v) {
    if (v >= -1 && v <= kMaxPixelBudget) return Status::ok();
    return Status::error("--budget " + std::to_string(v) + " out of range 0 .. " + std::to_string(kMaxPixelBudget) +
                         " rays per frame (or 'unlimited' / -1)");
}

Result<int64_t> parsePixelBudget(const std::string& s) {
    if (s == "unlimited") return int64_t(-1);
    auto v = parseSignedText("option --budget", s, -1, kMaxPixelBudget);  // -1 = unlimited
    if (!v) return orWords(v.status(), "'unlimited'");
    return v;
}

Status checkFov(double deg) {
    if (deg > kMinFovDeg && deg < kMaxFovDeg) return Status::ok();
    return Status::error("--fov " + num(deg) + " out of range (1, 179) degrees");
}

Result<double> parseStorageBudget(const std::string& s) {
    if (s == "auto") return -1.0;
    if (s == "off") return 0.0;
    auto v = parseRealText("option --storage-budget", s, kMinStorageBudgetMb, kMaxStorageBudgetMb);
    if (!v) return orWords(v.status(), "'auto', 'off'");
    return v;
}

Status checkSplatSigma(double sigma) {
    if (sigma == 0 || (sigma >= kMinSplatSigma && sigma <= kMaxSplatSigma)) return Status::ok();
    return Status::error("--point-splat " + num(sigma) + " out of range 0.05 .. 4 pixels (or off)");
}

Result<double> parseSplatSigma(const std::string& s) {
    if (s == "off" || s == "0") return 0.0;
    auto v = parseRealText("option --point-splat", s, kMinSplatSigma, kMaxSplatSigma);
    if (!v) return orWords(v.status(), "'off' = 1-pixel points");
    return v;
}

std::string formatSplatSigma(double sigma) {
    if (!(sigma > 0)) return "off";
    char b[32];
    std::snprintf(b, sizeof b, "%g", sigma);
    return b;
}

Result<int> parseReference(const std::string& s) {
    const std::string shape = " (expected 'full', 'ssaa:K' or 'none')";
    if (s == "full") return 0;
    if (s == "none") return kNoReference;
    if (s.rfind("ssaa:", 0) != 0)
        return Status::error("option --reference = '" + echoText(s) + "': expected 'full', 'ssaa:K' with K in [2, " +
                             std::to_string(kMaxReferenceSsaa) + "] or 'none'");
    auto k = parseUnsignedText("K", s.substr(5), 2, kMaxReferenceSsaa);
    if (!k) return Status::error("option --reference = '" + echoText(s) + "': " + k.status().message() + shape);
    return int(*k);
}

Result<std::string> parseModeName(const std::string& s) {
    if (!findRenderMode(s))
        return Status::error("--mode '" + s + "': unknown mode; available modes: " + renderModeNames());
    return s;
}

Result<std::vector<std::string>> parseModeList(const std::string& list) {
    std::vector<std::string> out;
    std::stringstream ss(list);
    std::string item;
    while (std::getline(ss, item, ',')) {
        item.erase(0, item.find_first_not_of(" \t"));
        if (!item.empty()) item.erase(item.find_last_not_of(" \t") + 1);
        if (item.empty()) continue;
        if (!findRenderMode(item))
            return Status::error("--modes: unknown mode '" + item + "'; available modes: " + renderModeNames());
        if (std::find(out.begin(), out.end(), item) != out.end())
            return Status::error("--modes: mode '" + item + "' listed twice");
        out.push_back(item);
    }
    if (out.empty())
        return Status::error("--modes '" + list + "': no mode given; available modes: " + renderModeNames());
    return out;
}

Result<int> parseSampling(const std::string& s) {
    if (s == "spread") return 0;
    if (s == "consecutive") return 1;
    const std::string prefix = "runs:";
    if (s.rfind(prefix, 0) == 0) {
        auto k = parseUnsignedText("K", s.substr(prefix.size()), 1, 100000);
        if (!k)
            return Status::error("option --sampling = '" + echoText(s) + "': " + k.status().message() +
                                 " (expected spread, consecutive or runs:K)");
        return int(*k);
    }
    return Status::error("option --sampling = '" + echoText(s) +
                         "': expected spread, consecutive or runs:K (K in [1, 100000])");
}

std::string samplingName(int runs) {
    return runs <= 0 ? "spread" : runs == 1 ? "consecutive" : "runs:" + std::to_string(runs);
}

Result<std::vector<int>> parseSweep(const std::string& s) {
    const std::string prefix = "sizes=";
    if (s.rfind(prefix, 0) != 0)
        return Status::error("option --sweep = '" + echoText(s) + "': expected sizes=S1,S2,... (metres)");
    std::vector<int> out;
    std::stringstream ss(s.substr(prefix.size()));
    std::string item;
    while (std::getline(ss, item, ',')) {
        auto v = parseUnsignedText("size", item, 100, 16000);  // metres
        if (!v) return Status::error("option --sweep = '" + echoText(s) + "': " + v.status().message());
        out.push_back(int(*v));
    }
    if (out.empty()) return Status::error("option --sweep = '" + echoText(s) + "': no sizes");
    return out;
}

void addModeFlags(CLI::App& app, ModeFlags& f) {
    app.add_option("--traffic", f.traffic,
                   "a traffic directory (`vista traffic`): its vehicles and pedestrians move through every mode, "
                   "placed at each frame's path time (near field drawn, far field ray-cast)");
    app.add_option("--near", f.near,
                   "near-field distance in metres, 1 .. 100000, or 'auto' (hybrid: adaptive split per frame among 0 = "
                   "ray casting, 15 .. 800 m and everything; the other "
                   "modes then use 100) (default " +
                       f.near + ")");
    addNumberOption(app, "--triangle-budget", f.triangleBudget, 0, kMaxTriangleBudget,
                    "hybrid: near field = the nearest 40 m chunks up to N triangles instead of --near, 0 .. "
                    "10000000000 (default " +
                        std::to_string(f.triangleBudget) + " = off)");
    app.add_option(
        "--budget", f.budget,
        "hybrid: most far-field rays per frame (the cache re-traces its worst pixels first), 0 .. 1000000000, "
        "or 'unlimited' / -1 = no cap: every pixel over --cache-error is re-traced (default " +
            f.budget + ")");
    addNumberOption(
        app, "--horizon-grid", f.horizonGrid, 0, 8192,
        "hybrid: horizon height-grid resolution, cells per side, 1 .. 8192, or 0 = auto: cells of about 4 m, "
        "512 .. 2048 a side (default 0)");
    app.add_flag("--no-cache", f.noCache, "hybrid: panoramic image cache off (every far pixel traced)");
    app.add_flag("--cache-always", f.cacheAlways,
                 "hybrid: look up the cache in every frame, also while its measured reuse does not pay for its lookups "
                 "(by default it then pauses for 8 moving frames and measures again), and trace the horizon in every "
                 "frame too: no pause follows measured times");
    app.add_flag("--no-overlap", f.noOverlap,
                 "hybrid: trace the horizon and last frame's far pixels after the near field is drawn instead of on "
                 "other threads "
                 "during the draw");
    addNumberOption(
        app, "--cache-error", f.cacheError, RealRange::closed(0, 100),
        "hybrid: reuse a cached far pixel while its estimated reprojection error is below this many pixels, "
        "0 .. 100 (0 = only pixels traced by this very camera) (default 0.25)");
    addNumberOption(
        app, "--frame-ms", f.frameMs, RealRange::closed(0, 10000),
        "hybrid: frame-time target in ms, 0 .. 10000: the far-field ray budget adapts to what the target leaves "
        "after the near field (0 = no target) (default 0)");
    addNumberOption(
        app, "--far-step", f.farStep, 1, 2,
        "hybrid: far-field ray spacing, 1 or 2: 2 = rays on every other pixel and row first, pixels between "
        "lattice pixels that showed one triangle (or sky) blended from them (lossy: PSNR in the bench) (default 1)");
    addNumberOption(
        app, "--near-detail", f.nearDetail, RealRange::closed(0, 100),
        "hybrid: draw a near-field chunk with its window recesses flattened where that moves its surface by at most "
        "this many pixels on screen, 0 .. 100 (0 = off: every chunk at full detail) (default " +
            formatSplatSigma(f.nearDetail) + ")");
    app.add_flag("--no-front-to-back", f.noFrontToBack,
                 "hybrid: draw the near field's chunks in the city's order instead of nearest first");
    app.add_option("--baked", f.baked, "impostor: the baked file of this city (from `vista bake`)");
    app.add_option(
        "--baked-mesh", f.bakedMesh,
        "lodmesh: the mesh bake of this city (from `vista bake --representation mesh`), unless the city file is one");
    app.add_option(
        "--point-splat", f.pointSplat,
        "impostor: points drawn as Gaussian splats of SIGMA output pixels with normalised accumulation, 0.05 .. 4, "
        "or off = 1-pixel points (default " +
            formatSplatSigma(ModeOptions().splatSigma) + ")");
    addNumberOption(app, "--threads", f.threads, 0, 1024, "worker threads for ray casting, 0 .. 1024 (0 = all cores)");
}

Status checkModeOptions(const ModeOptions& o) {
    VISTA_RETURN_IF_ERROR(checkNearDistance(o.nearDistance));
    VISTA_RETURN_IF_ERROR(checkPixelBudget(o.pixelBudget));
    if (o.triangleBudget > kMaxTriangleBudget)
        return Status::error("--triangle-budget " + std::to_string(o.triangleBudget) + " out of range 0 .. " +
                             std::to_string(kMaxTriangleBudget) + " triangles");
    if (o.horizonGrid < 0 || o.horizonGrid > 8192)
        return Status::error("--horizon-grid " + std::to_string(o.horizonGrid) +
                             " out of range 1 .. 8192 cells per side, or 0 = auto");
    if (!(o.cacheErrorPx >= 0 && o.cacheErrorPx <= 100))
        return Status::error("--cache-error " + std::to_string(o.cacheErrorPx) + " out of range 0 .. 100 pixels");
    if (!(o.frameMsTarget >= 0 && o.frameMsTarget <= 10000))
        return Status::error("--frame-ms " + std::to_string(o.frameMsTarget) +
                             " out of range 0 .. 10000 ms (0 = no target)");
    if (o.farStep < 1 || o.farStep > 2)
        return Status::error("--far-step " + std::to_string(o.farStep) + " out of range 1 .. 2 pixels");
    if (!(o.nearDetailPx >= 0 && o.nearDetailPx <= 100))
        return Status::error("--near-detail " + std::to_string(o.nearDetailPx) +
                             " out of range 0 .. 100 pixels (0 = off)");
    if (o.threads < 0 || o.threads > 1024)
        return Status::error("--threads " + std::to_string(o.threads) + " out of range 0 .. 1024 (0 = all cores)");
    return checkSplatSigma(o.splatSigma);
}

Status parseModeFlags(const ModeFlags& f, ModeOptions& o) {
    auto nd = parseNearDistance(f.near);
    if (!nd) return nd.status();
    auto pb = parsePixelBudget(f.budget);
    if (!pb) return pb.status();
    if (!f.baked.empty() && access(f.baked.c_str(), R_OK) != 0)
        return Status::error("--baked '" + f.baked + "': cannot read the file");
    if (!f.bakedMesh.empty() && access(f.bakedMesh.c_str(), R_OK) != 0)
        return Status::error("--baked-mesh '" + f.bakedMesh + "': cannot read the file");
    o.nearDistance = nd.value();
    o.triangleBudget = f.triangleBudget;
    o.pixelBudget = pb.value();
    o.horizonGrid = f.horizonGrid;
    o.cache = !f.noCache;
    o.cacheAdaptive = !f.cacheAlways;
    o.horizonAdaptive = !f.cacheAlways;
    o.cacheErrorPx = f.cacheError;
    o.overlap = !f.noOverlap;
    o.frameMsTarget = f.frameMs;
    o.farStep = f.farStep;
    o.nearDetailPx = f.nearDetail;
    o.nearFrontToBack = !f.noFrontToBack;
    o.bakedFile = f.baked;
    o.bakedMeshFile = f.bakedMesh;
    o.threads = f.threads;
    if (!f.pointSplat.empty()) {
        auto sg = parseSplatSigma(f.pointSplat);
        if (!sg) return sg.status();
        o.splatSigma = *sg;
    }
    return checkModeOptions(o);
}

namespace option_detail {

CLI::Option* addConvertedOption(CLI::App& app, const std::string& name, const std::string& help,
                                const std::string& typeName, std::function<Status(const std::string&)> set,
                                std::function<std::string()> shown) {
    auto convert = [set](const CLI::results_t& res) {
        if (res.empty()) return false;
        if (Status s = set(res.back()); !s) throw CLI::ValidationError(s.message());
        return true;
    };
    CLI::Option* opt = app.add_option(name, convert, help, false, std::move(shown));
    opt->type_name(typeName);
    opt->type_size(1, 1);
    opt->expected(1);
    return opt;
}

}  // namespace option_detail

namespace {

CLI::Option* addReal(CLI::App& app, const std::string& name, const RealRange& range, const std::string& help,
                     std::function<void(double)> store, std::function<std::string()> shown) {
    return option_detail::addConvertedOption(
        app, name, help, CLI::detail::type_name<double>(),
        [name, range, store](const std::string& text) -> Status {
            auto v = parseRealText("option " + name, text, range);
            if (!v) return v.status();
            store(*v);
            return Status::ok();
        },
        std::move(shown));
}

}  // namespace

CLI::Option* addNumberOption(CLI::App& app, const std::string& name, double& value, const RealRange& range,
                             const std::string& help) {
    return addReal(
        app, name, range, help, [&value](double v) { value = v; },
        [&value] { return CLI::detail::checked_to_string<double, double>(value); });
}

CLI::Option* addNumberOption(CLI::App& app, const std::string& name, std::optional<double>& value,
                             const RealRange& range, const std::string& help) {
    return addReal(
        app, name, range, help, [&value](double v) { value = v; }, [] { return std::string(); });
}

CLI::Option* addSeedOption(CLI::App& app, const std::string& name, uint64_t& seed, const std::string& help) {
    return addNumberOption(app, name, seed, 0, UINT64_MAX, help);
}

void addPathFlags(CLI::App& app, PathFlags& f, bool timing) {
    auto* path = app.add_option("--path", f.file, "walkthrough path CSV (from `vista path`)");
    addSeedOption(app, "--seed", f.seed,
                  "make the path from this seed instead of --path (default " + std::to_string(f.seed) + ")")
        ->excludes(path);
    app.add_option("--kind", f.kind, "path kind when made from --seed: walk, car, fly (default " + f.kind + ")");
    app.add_flag("--lht", f.lht, "car path made from --seed: left-hand traffic (lanes driven mirrored)");
    app.add_option("--route", f.route,
                   "path made from --seed: tour (default: toward far goals along shortest paths, a long drive keeps "
                   "going across the city) or wander (a seeded random walk that prefers going straight on)");
    if (!timing) return;
    addNumberOption(app, "--duration", f.duration, path_range::duration,
                    "path duration in seconds when made from --seed, (0, 86400] (default 60)");
    addNumberOption(
        app, "--run-up", f.runUp, path_range::runUp,
        "seconds driven before the path starts and dropped, so it starts at cruising speed, 0 .. 600 (default 8)");
}

Status checkLeftHandTraffic(bool lht, PathKind kind) {
    if (!lht || kind == PathKind::Car) return Status::ok();
    return Status::error(std::string("option --lht: applies to car paths (lanes driven on the left), not to --kind ") +
                         pathKindName(kind) + " (a " + pathKindName(kind) + " path does not drive in lanes)");
}

Status checkFrameCount(int frames, size_t samples, bool repeats) {
    if (repeats || frames < 0 || size_t(frames) <= samples) return Status::ok();
    return Status::error("option --frames = " + std::to_string(frames) + ": the path has " + std::to_string(samples) +
                         (samples == 1 ? " sample" : " samples") + ", so frames would repeat samples (allowed: 1 .. " +
                         std::to_string(samples) +
                         "; give --allow-repeated-frames to render repeated samples on purpose)");
}

void addRepeatedFramesFlag(CLI::App& app, bool& repeats) {
    app.add_flag("--allow-repeated-frames", repeats,
                 "allow --frames above the path's sample count: samples are then rendered more than once (by "
                 "default such a run is refused, naming the sample count)");
}

Status refuseEmptyValues(const CLI::App& app) {
    for (const CLI::Option* opt : app.get_options()) {
        if (opt->get_type_size() == 0 || opt->count() == 0) continue;  // a flag, or not given
        for (const std::string& v : opt->results())
            if (v.empty()) {
                const std::string name = opt->get_name();
                return Status::error((name.rfind("-", 0) == 0 ? "option " : "argument ") + name +
                                     " = '': empty (give a " + opt->get_type_name() +
                                     " value, or leave the option out for its default)");
            }
    }
    return Status::ok();
}

Result<PathOptions> parsePathFlags(const PathFlags& f) {
    auto k = parsePathKind(f.kind);
    if (!k) return Status::error("--kind: " + k.status().message());
    if (f.lht && !f.file.empty())
        return Status::error(
            "option --lht: applies to car paths made from --seed (lanes driven on the left), not to "
            "the recorded path of --path '" +
            echoText(f.file) + "'");
    VISTA_RETURN_IF_ERROR(checkLeftHandTraffic(f.lht, *k));
    PathOptions po;
    po.seed = f.seed;
    po.kind = k.value();
    po.maxSpeed = defaultSpeed(po.kind);
    po.duration = f.duration;
    po.runUp = f.runUp;
    po.leftHandTraffic = f.lht;
    auto r = parseRouteStyle(f.route);
    if (!r) return Status::error("--route: " + r.status().message());
    po.route = r.value();
    VISTA_RETURN_IF_ERROR(validatePathOptions(po));
    return po;
}

Status checkRunFiles(CommandFiles& files, const std::string& city, const PathFlags& path, const ModeFlags& mode) {
    VISTA_RETURN_IF_ERROR(files.input("city", city)
                              .input("--path", path.file)
                              .input("--baked", mode.baked)
                              .input("--baked-mesh", mode.bakedMesh)
                              .input("--traffic", mode.traffic)
                              .check());
    if (!path.file.empty())
        if (Status s = checkInputFile("path file", path.file, kMaxPathCsvBytes); !s)
            return Status::error("option --path: " + s.message());
    return Status::ok();
}

Result<std::shared_ptr<const TrafficTracks>> loadTrafficFlag(const std::string& dir) {
    if (dir.empty()) return std::shared_ptr<const TrafficTracks>();
    auto t = loadTrafficTracks(dir);
    if (!t) {
        const std::string& m = t.status().message();
        return Status::error(m.rfind("--traffic", 0) == 0 ? m : "--traffic = '" + dir + "': " + m);
    }
    if (t->frames() == 0) return Status::error("--traffic = '" + dir + "': the floating-car data has no time step");
    auto tracks = std::make_shared<TrafficTracks>(std::move(*t));
    // The heads' lamps: SUMO's signal states, when the run recorded them.
    if (std::filesystem::exists(std::filesystem::path(dir) / "signals.xml")) {
        auto s = loadSignalStates(dir);
        if (!s) return Status::error("--traffic = '" + dir + "': " + s.status().message());
        tracks->signals = std::make_shared<SignalStates>(std::move(*s));
    }
    return std::shared_ptr<const TrafficTracks>(std::move(tracks));
}

Result<Effects> parseEffectsOption(const std::string& s, const Effects& base) {
    if (s.empty())
        return Status::error(
            "option --effects = '': empty (give 'none', effect names such as haze,glass, or a JSON "
            "object)");
    if (s.size() > kMaxEffectsTextBytes)
        return Status::error("option --effects: " + std::to_string(s.size()) + " bytes, more than the limit of " +
                             byteLimitText(kMaxEffectsTextBytes));
    if (s == "none") return Effects();
    if (s[0] == '{') return parseEffectsJson(s, "option --effects");
    if (s.back() == ',') return Status::error("option --effects = '" + echoText(s) + "': empty effect name");
    Effects out;
    std::stringstream ss(s);
    std::string name;
    while (std::getline(ss, name, ',')) {
        EffectId id;
        if (name.empty()) return Status::error("option --effects = '" + echoText(s) + "': empty effect name");
        if (!findEffect(name, id))
            return Status::error("option --effects: unknown effect '" + echoText(name) + "' (known: " + effectNames() +
                                 "; or 'none', or a JSON object)");
        if (out.has(id)) return Status::error("option --effects: effect '" + name + "' is named twice");
        if (base.has(id)) {
            switch (id) {
                case EffectId::SunShadows: out.sun_shadows = base.sun_shadows; break;
                case EffectId::AmbientOcclusion: out.ambient_occlusion = base.ambient_occlusion; break;
                case EffectId::Haze: out.haze = base.haze; break;
                case EffectId::Glass: out.glass = base.glass; break;
                case EffectId::Night: out.night = base.night; break;
                case EffectId::Materials: out.materials = base.materials; break;
                case EffectId::Count: break;
            }
        } else {
            out.enable(id);
        }
    }
    return out;
}

Result<FrameEffects> runTimeEffects(const std::optional<std::string>& option, const Effects& declared, bool quiet,
                                    const char* cmd) {
    if (!option) return FrameEffects::fromScene(declared);
    auto e = parseEffectsOption(*option, declared);
    if (!e) return e.status();
    // A baked effect cannot change per run: asking for it is an error, not a silent no-op.
    for (int i = 0; i < kEffectCount; ++i) {
        const EffectId id = EffectId(i);
        if (id != EffectId::Night && effectIsBaked(id) && e->has(id))
            return Status::error(std::string("option --effects: '") + effectName(id) +
                                 "' is baked into the scene's colours at generation and cannot change per run "
                                 "(give it to `vista gen --effects`); run-time effects: haze, glass, night");
    }
    FrameEffects fx = FrameEffects::fromScene(*e);
    fx.glassMarked = declared.glass.has_value();
    if (!fx.glassMarked) fx.glass = false;
    if (!quiet) {
        for (int i = 0; i < kEffectCount; ++i) {
            const EffectId id = EffectId(i);
            if (id == EffectId::Night || !effectIsBaked(id) || e->has(id) == declared.has(id)) continue;
            std::fprintf(stderr,
                         "%s: note: %s is baked into the scene's colours at generation; it stays %s (regenerate with "
                         "`vista gen --effects` to change it)\n",
                         cmd, effectName(id), declared.has(id) ? "on" : "off");
        }
        if (e->glass && !declared.glass)
            std::fprintf(stderr, "%s: note: the scene declares no glass, so no window is marked: no reflections\n",
                         cmd);
    }
    return fx;
}

void addPagedFlags(CLI::App& app, PagedReach& reach) {
    std::ostringstream help;
    help << "with a paged city (a DIR.paged directory from `vista gen`): the regions within this many metres of the "
            "camera (streamed; of the walkthrough with --paged-preload) at full detail, "
         << kMinPagedRadiusM << " .. " << kMaxPagedRadiusM << " (default " << kDefaultPagedRadiusM << ")";
    const RealRange range = RealRange::closed(kMinPagedRadiusM, kMaxPagedRadiusM);
    addNumberOption(app, "--paged-radius", reach.radius, range, help.str());
    std::ostringstream far;
    far << "with a paged city: the other regions within this many metres of the camera (of the walkthrough with "
           "--paged-preload) at their coarse level "
           "(detail 0, trees as impostors) for the far field, "
        << kMinPagedRadiusM << " .. " << kMaxPagedRadiusM << " (default " << kDefaultPagedFarM
        << " = the whole city; 0 = none: the city ends at --paged-radius)";
    addNumberOption(app, "--paged-far", reach.far, range, far.str());
}

Status validatePagedReach(const PagedReach& reach) {
    VISTA_RETURN_IF_ERROR(validatePagedRadius("--paged-radius", reach.radius));
    return validatePagedRadius("--paged-far", reach.far);
}

void addPagedStreamFlags(CLI::App& app, PagedStreamFlags& f) {
    app.add_flag("--paged-stream", f.stream,
                 "with a paged city: stream it (the default): regions load on a worker thread as the camera "
                 "approaches and unload when it leaves (--paged-radius at full detail and --paged-far at the coarse "
                 "level, around the camera), the first frame waits for the regions at its camera; --memory-budget "
                 "bounds what is resident. Given explicitly, a run that cannot stream is an error instead of "
                 "preloading; modes " +
                     streamingModeNames());
    app.add_flag("--paged-preload", f.preload,
                 "with a paged city: load the regions near the whole walkthrough before the first frame instead of "
                 "streaming (the city ends at --paged-far from the path)");
    app.add_flag("--paged-wait", f.wait,
                 "with a streamed paged city: every frame waits until the regions within reach of its camera are "
                 "resident, so frames do not depend on load timing");
    std::ostringstream help;
    help << "with a streamed paged city: also load the regions within reach of anywhere the camera can get to in "
            "this many seconds at its speed, those ahead first (at least: longer where loading is slower), 0 .. "
         << kMaxPagedPrefetchS << " (default " << kDefaultPagedPrefetchS << ")";
    addNumberOption(app, "--paged-prefetch", f.prefetchS, RealRange::closed(0, kMaxPagedPrefetchS), help.str());
}

Status validatePagedStream(PagedStreamFlags& f) {
    if (!f.preload) return Status::ok();
    for (const auto& [given, flag] : {std::pair<bool, const char*>{f.stream, "--paged-stream"},
                                      {f.wait, "--paged-wait"},
                                      {f.prefetchS.has_value(), "--paged-prefetch"}})
        if (given)
            return Status::error(std::string("--paged-preload: not with ") + flag +
                                 " (the preloaded city does not stream)");
    return Status::ok();
}

}  // namespace vista
