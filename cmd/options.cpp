// Command-line value parsers (options.h).
#include "cmd/options.h"

#include "foundation/input_file.h"
#include "foundation/number_text.h"

#include <algorithm>
#include <cstdio>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <unistd.h>

namespace vista {

namespace {

// A whole string as a signed integer; false on anything else (sign, spaces, overflow).
bool toInteger(const std::string& s, long long& v) {
    if (s.empty()) return false;
    char* end = nullptr;
    errno = 0;
    v = std::strtoll(s.c_str(), &end, 10);
    return end && *end == 0 && errno != ERANGE;
}

bool toNumber(const std::string& s, double& v) {
    if (s.empty()) return false;
    char* end = nullptr;
    v = std::strtod(s.c_str(), &end);
    return end && *end == 0 && std::isfinite(v);
}

// "AsepB" with decimal digits only on both sides (at most 9 each); false otherwise.
bool splitPair(const std::string& s, const char* seps, long& a, long& b) {
    const size_t k = s.find_first_of(seps);
    auto digits = [](const std::string& t) {
        return !t.empty() && t.size() <= 9 &&
               std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; });
    };
    if (k == std::string::npos || !digits(s.substr(0, k)) || !digits(s.substr(k + 1))) return false;
    a = std::stol(s.substr(0, k));
    b = std::stol(s.substr(k + 1));
    return true;
}

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
    long w = 0, h = 0;
    if (!splitPair(s, "xX", w, h))
        return Status::error("--size '" + s + "': expected WIDTHxHEIGHT, e.g. 640x480 (each 1 .. 8192 pixels)");
    if (w < 1 || h < 1 || w > kMaxImageSide || h > kMaxImageSide)
        return Status::error("--size " + s + " out of range 1x1 .. 8192x8192 pixels");
    return ImageSize{int(w), int(h)};
}

Status parseTexels(const std::string& s, int& x, int& y) {
    if (s == "1") {
        x = y = 1;
        return Status::ok();
    }
    long a = 0, b = 0;
    if (!splitPair(s, "xX", a, b) || a < 1 || b < 1 || a > 32 || b > 32)
        return Status::error("--texels '" + s + "': expected 1 or AxB with 1 <= A, B <= 32 (e.g. 8x2, 4x1)");
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
    double v = 0;
    if (!toNumber(s, v))
        return Status::error("--near '" + s + "': expected a distance in metres (1 .. 100000) or 'auto'");
    if (v < kMinNearDistance || v > kMaxNearDistance)
        return Status::error("--near " + s + " out of range 1 .. 100000 metres (or 'auto')");
    return v;
}

Status checkPixelBudget(int64_t v) {
    if (v >= -1 && v <= kMaxPixelBudget) return Status::ok();
    return Status::error("--budget " + std::to_string(v) + " out of range 0 .. " + std::to_string(kMaxPixelBudget) +
                         " rays per frame (or 'unlimited' / -1)");
}

Result<int64_t> parsePixelBudget(const std::string& s) {
    const std::string range = " rays per frame, or 'unlimited' / -1";
    if (s == "unlimited" || s == "-1") return int64_t(-1);
    long long v = 0;
    if (!toInteger(s, v))
        return Status::error("--budget '" + s + "': expected an integer 0 .. " + std::to_string(kMaxPixelBudget) +
                             range);
    if (v < 0 || v > kMaxPixelBudget)
        return Status::error("--budget " + s + " out of range 0 .. " + std::to_string(kMaxPixelBudget) + range);
    return int64_t(v);
}

Result<uint64_t> parseTriangleBudget(const std::string& s) {
    long long v = 0;
    if (!toInteger(s, v) || v < 0 || uint64_t(v) > kMaxTriangleBudget)
        return Status::error("--triangle-budget '" + s + "' out of range 0 .. " + std::to_string(kMaxTriangleBudget) +
                             " triangles (0 = near field by distance)");
    return uint64_t(v);
}

Status checkFov(double deg) {
    if (deg > kMinFovDeg && deg < kMaxFovDeg) return Status::ok();
    return Status::error("--fov " + num(deg) + " out of range (1, 179) degrees");
}

Result<double> parseFov(const std::string& s) {
    double v = 0;
    if (!toNumber(s, v)) return Status::error("--fov '" + s + "': expected degrees in (1, 179)");
    VISTA_RETURN_IF_ERROR(checkFov(v));
    return v;
}

Result<double> parseStorageBudget(const std::string& s) {
    if (s == "auto") return -1.0;
    if (s == "off") return 0.0;
    double v = 0;
    if (!toNumber(s, v) || !(v >= kMinStorageBudgetMb && v <= kMaxStorageBudgetMb))
        return Status::error("--storage-budget '" + s + "': expected auto, off or megabytes in 0.01 .. 1000000");
    return v;
}

Status checkSplatSigma(double sigma) {
    if (sigma == 0 || (sigma >= kMinSplatSigma && sigma <= kMaxSplatSigma)) return Status::ok();
    return Status::error("--point-splat " + num(sigma) + " out of range 0.05 .. 4 pixels (or off)");
}

Result<double> parseSplatSigma(const std::string& s) {
    if (s == "off" || s == "0") return 0.0;
    double v = 0;
    if (!toNumber(s, v) || !checkSplatSigma(v) || v == 0)
        return Status::error("--point-splat '" + s +
                             "': expected a Gaussian sigma in output pixels, 0.05 .. 4, or 'off' (1-pixel points)");
    return v;
}

std::string formatSplatSigma(double sigma) {
    if (!(sigma > 0)) return "off";
    char b[32];
    std::snprintf(b, sizeof b, "%g", sigma);
    return b;
}

Result<int> parseReference(const std::string& s) {
    if (s == "full") return 0;
    long long k = 0;
    if (s.rfind("ssaa:", 0) == 0 && toInteger(s.substr(5), k) && k >= 2 && k <= kMaxReferenceSsaa) return int(k);
    return Status::error("--reference '" + s + "': expected 'full' or 'ssaa:K' with K in 2 .. 8");
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
        const std::string k = s.substr(prefix.size());
        char* end = nullptr;
        errno = 0;
        const long v = std::strtol(k.c_str(), &end, 10);
        if (!k.empty() && *end == 0 && errno == 0 && v >= 1 && v <= 100000) return int(v);
        return Status::error("--sampling '" + s + "': K out of range 1 .. 100000 (runs:K)");
    }
    return Status::error("--sampling '" + s + "': expected spread, consecutive or runs:K (K in 1 .. 100000)");
}

std::string samplingName(int runs) {
    return runs <= 0 ? "spread" : runs == 1 ? "consecutive" : "runs:" + std::to_string(runs);
}

Result<std::vector<int>> parseSweep(const std::string& s) {
    const std::string prefix = "sizes=";
    if (s.rfind(prefix, 0) != 0) return Status::error("--sweep '" + s + "': expected sizes=S1,S2,... (metres)");
    std::vector<int> out;
    std::stringstream ss(s.substr(prefix.size()));
    std::string item;
    while (std::getline(ss, item, ',')) {
        char* end = nullptr;
        long v = std::strtol(item.c_str(), &end, 10);
        if (item.empty() || *end || v < 100 || v > 16000)
            return Status::error("--sweep: size '" + item + "' out of range 100 .. 16000 metres");
        out.push_back(int(v));
    }
    if (out.empty()) return Status::error("--sweep '" + s + "': no sizes");
    return out;
}

void addModeFlags(CLI::App& app, ModeFlags& f) {
    app.add_option("--near", f.near,
                   "near-field distance in metres, 1 .. 100000, or 'auto' (hybrid: adaptive split per frame among 0 = "
                   "ray casting, 15 .. 800 m and everything; the other "
                   "modes then use 100) (default " +
                       f.near + ")");
    app.add_option("--triangle-budget", f.triangleBudget,
                   "hybrid: near field = the nearest 40 m chunks up to N triangles instead of --near, 0 .. 10000000000 "
                   "(default " +
                       f.triangleBudget + " = off)");
    app.add_option(
        "--budget", f.budget,
        "hybrid: most far-field rays per frame (the cache re-traces its worst pixels first), 0 .. 1000000000, "
        "or 'unlimited' / -1 = no cap: every pixel over --cache-error is re-traced (default " +
            f.budget + ")");
    app.add_option(
        "--horizon-grid", f.horizonGrid,
        "hybrid: horizon height-grid resolution, cells per side, 1 .. 8192, or 0 = auto: cells of about 4 m, "
        "512 .. 2048 a side (default 0)");
    app.add_flag("--no-cache", f.noCache, "hybrid: panoramic image cache off (every far pixel traced)");
    app.add_flag("--cache-always", f.cacheAlways,
                 "hybrid: look up the cache in every frame, also while its measured reuse does not pay for its lookups "
                 "(by default it then pauses for 8 moving frames and measures again)");
    app.add_flag("--no-overlap", f.noOverlap,
                 "hybrid: trace the horizon and last frame's far pixels after the near field is drawn instead of on "
                 "other threads "
                 "during the draw");
    app.add_option("--cache-error", f.cacheError,
                   "hybrid: reuse a cached far pixel while its estimated reprojection error is below this many pixels, "
                   "0 .. 100 (0 = only pixels traced by this very camera) (default 0.25)");
    app.add_option(
        "--frame-ms", f.frameMs,
        "hybrid: frame-time target in ms, 0 .. 10000: the far-field ray budget adapts to what the target leaves "
        "after the near field (0 = no target) (default 0)");
    app.add_option(
        "--far-step", f.farStep,
        "hybrid: far-field ray spacing, 1 or 2: 2 = rays on every other pixel and row first, pixels between "
        "lattice pixels that showed one triangle (or sky) blended from them (lossy: PSNR in the bench) (default 1)");
    app.add_option("--baked", f.baked, "impostor: the baked file of this city (from `vista bake`)");
    app.add_option(
        "--baked-mesh", f.bakedMesh,
        "lodmesh: the mesh bake of this city (from `vista bake --representation mesh`), unless the city file is one");
    app.add_option(
        "--point-splat", f.pointSplat,
        "impostor: points drawn as Gaussian splats of SIGMA output pixels with normalised accumulation, 0.05 .. 4, "
        "or off = 1-pixel points (default " +
            formatSplatSigma(ModeOptions().splatSigma) + ")");
    app.add_option("--threads", f.threads, "worker threads for ray casting, 0 .. 1024 (0 = all cores)");
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
    if (o.threads < 0 || o.threads > 1024)
        return Status::error("--threads " + std::to_string(o.threads) + " out of range 0 .. 1024 (0 = all cores)");
    return checkSplatSigma(o.splatSigma);
}

Status parseModeFlags(const ModeFlags& f, ModeOptions& o) {
    auto nd = parseNearDistance(f.near);
    if (!nd) return nd.status();
    auto tb = parseTriangleBudget(f.triangleBudget);
    if (!tb) return tb.status();
    auto pb = parsePixelBudget(f.budget);
    if (!pb) return pb.status();
    if (!f.baked.empty() && access(f.baked.c_str(), R_OK) != 0)
        return Status::error("--baked '" + f.baked + "': cannot read the file");
    if (!f.bakedMesh.empty() && access(f.bakedMesh.c_str(), R_OK) != 0)
        return Status::error("--baked-mesh '" + f.bakedMesh + "': cannot read the file");
    o.nearDistance = nd.value();
    o.triangleBudget = tb.value();
    o.pixelBudget = pb.value();
    o.horizonGrid = f.horizonGrid;
    o.cache = !f.noCache;
    o.cacheAdaptive = !f.cacheAlways;
    o.cacheErrorPx = f.cacheError;
    o.overlap = !f.noOverlap;
    o.frameMsTarget = f.frameMs;
    o.farStep = f.farStep;
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

CLI::Option* addSeedOption(CLI::App& app, const std::string& name, uint64_t& seed, const std::string& help) {
    return app
        .add_option_function<std::string>(
            name,
            [&seed, name](const std::string& text) {
                auto v = parseUnsignedText("option " + name, text, 0, UINT64_MAX);
                if (!v) throw CLI::ValidationError(v.status().message());
                seed = *v;
            },
            help)
        ->type_name("UINT");
}

void addPathFlags(CLI::App& app, PathFlags& f, bool timing) {
    auto* path = app.add_option("--path", f.file, "walkthrough path CSV (from `vista path`)");
    addSeedOption(app, "--seed", f.seed,
                  "make the path from this seed instead of --path (default " + std::to_string(f.seed) + ")")
        ->excludes(path);
    app.add_option("--kind", f.kind, "path kind when made from --seed: walk, car, fly (default " + f.kind + ")");
    app.add_flag("--lht", f.lht, "car path made from --seed: left-hand traffic (lanes driven mirrored)");
    if (!timing) return;
    app.add_option("--duration", f.duration, "path duration in seconds when made from --seed (default 60)");
    app.add_option(
        "--run-up", f.runUp,
        "seconds driven before the path starts and dropped, so it starts at cruising speed, 0 .. 600 (default 8)");
}

Result<PathOptions> parsePathFlags(const PathFlags& f) {
    auto k = parsePathKind(f.kind);
    if (!k) return Status::error("--kind: " + k.status().message());
    PathOptions po;
    po.seed = f.seed;
    po.kind = k.value();
    po.maxSpeed = defaultSpeed(po.kind);
    po.duration = f.duration;
    po.runUp = f.runUp;
    po.leftHandTraffic = f.lht;
    VISTA_RETURN_IF_ERROR(validatePathOptions(po));
    return po;
}

Status checkRunFiles(CommandFiles files, const std::string& city, const PathFlags& path, const ModeFlags& mode) {
    VISTA_RETURN_IF_ERROR(files.input("city", city)
                              .input("--path", path.file)
                              .input("--baked", mode.baked)
                              .input("--baked-mesh", mode.bakedMesh)
                              .check());
    if (!path.file.empty())
        if (Status s = checkInputFile("path file", path.file, kMaxPathCsvBytes); !s)
            return Status::error("option --path: " + s.message());
    return Status::ok();
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
    help << "with a paged city (a DIR.paged directory from `vista gen`): load only the regions within this many metres "
            "of the walkthrough at full detail, "
         << kMinPagedRadiusM << " .. " << kMaxPagedRadiusM << " (default " << kDefaultPagedRadiusM << ")";
    app.add_option("--paged-radius", reach.radius, help.str());
    std::ostringstream far;
    far << "with a paged city: load the other regions within this many metres of the walkthrough at their coarse level "
           "(detail 0, no trees) for the far field, "
        << kMinPagedRadiusM << " .. " << kMaxPagedRadiusM << " (default " << kDefaultPagedFarM
        << " = the whole city; 0 = none: the city ends at --paged-radius)";
    app.add_option("--paged-far", reach.far, far.str());
}

Status validatePagedReach(const PagedReach& reach) {
    VISTA_RETURN_IF_ERROR(validatePagedRadius("--paged-radius", reach.radius));
    return validatePagedRadius("--paged-far", reach.far);
}

}  // namespace vista
