// vista bench: headless walkthrough, modes side by side -> frames.csv,
// summary.json, plots, difference images. Also the size sweep (--sweep).
// Every mode comes from the registry (nodes/render/render_mode.h); the
// options are parsed by cmd/options.h.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cmd/bench.h"
#include "cmd/cli.h"
#include "cmd/commands.h"
#include "cmd/options.h"
#include "cmd/paged_stream.h"
#include "cmd/plot.h"
#include "foundation/atomic_file.h"
#include "foundation/timing.h"
#include "nodes/render/walkthrough.h"
#include "runtime/scene/scene_graph.h"

namespace vista {

namespace {

namespace fs = std::filesystem;
const char* const kCmd = "vista bench";

struct BenchArgs {
    std::string city, size = "640x480", modes = "full,near", out, reference = "full", sweep;
    std::optional<std::string> effects;  // unset: the scene's
    std::string sampling = samplingName(kDefaultSampleRuns);
    std::vector<fs::path> createdOut;  // directories of --out made by this run, deepest first
    bool quiet = false;
    bool repeats = false;  // --allow-repeated-frames
    PathFlags path;
    ModeFlags mode;
    BenchConfig cfg;
    PathOptions pathOptions;
    PagedReach paged;
    PagedStreamFlags stream;
    bool streamed = false;  // a paged city that streams (choosePagedStream)
    CommandFiles files;     // checked by configure; holds the outputs' locks for the run
};

void declareFlags(CLI::App& app, BenchArgs& a) {
    std::string modeHelp = "comma-separated modes (default full,near); available:";
    for (const auto& m : renderModes()) modeHelp += std::string("\n    ") + m.name + ": " + m.summary;
    app.add_option("city", a.city,
                   "city scene file (.osgb), or a paged city directory (DIR.paged); not needed with --sweep");
    addPathFlags(app, a.path, true);
    addPagedFlags(app, a.paged);
    addPagedStreamFlags(app, a.stream);
    addNumberOption(app, "--frames", a.cfg.frames, 1, 1000000,
                    "frames rendered, sampled from the path as --sampling says, 1 .. 1000000 and at most the path's "
                    "sample count (default 120)");
    addRepeatedFramesFlag(app, a.repeats);
    app.add_option("--sampling", a.sampling,
                   "which path samples are the frames: 'spread' (evenly over the whole path), 'consecutive' (the first "
                   "N samples, as a simulator renders them) or 'runs:K' (K runs of consecutive samples, their starts "
                   "spread over the path) (default " +
                       samplingName(kDefaultSampleRuns) + ")");
    app.add_option("--size", a.size, "image size WIDTHxHEIGHT, 1x1 .. 8192x8192 (default 640x480)");
    app.add_option("--modes", a.modes, modeHelp);
    addModeFlags(app, a.mode);
    addNumberOption(app, "--fov", a.cfg.fovYDeg, kFovRange, "vertical field of view in degrees, (1, 179) (default 60)");
    app.add_option("--reference", a.reference,
                   "reference for the quality metrics: full (default), ssaa:K (K x K supersampled full) or none "
                   "(no quality metrics, `full` runs only when listed: a long drive timed alone)");
    addNumberOption(app, "--diff-threshold", a.cfg.diffThreshold, 0, 255,
                    "per-channel difference counted as a differing pixel, 0 .. 255 (default 8)");
    addNumberOption(app, "--worst", a.cfg.worstFrames, 0, 100,
                    "difference images for the N worst frames per mode, 0 .. 100 (default 2)");
    app.add_flag("--pace", a.cfg.pace,
                 "with --sampling consecutive: pace the frames at the path's own speed (frame f starts no earlier "
                 "than its path time after the first frame's), a real-time drive");
    app.add_flag("--count-fragments", a.cfg.countFragments,
                 "count every frame's fragments that pass the depth test (a GL query; costs time) into the notes of "
                 "frames.csv: 'fragments: N (F per pixel)'");
    app.add_flag("--save-frames", a.cfg.saveFrames,
                 "also write every frame of every mode as OUT/frames/fNNNN_MODE.png");
    app.add_option(
        "--dump-rays", a.cfg.dumpRaysDir,
        "write the far-field rays each hybrid frame traced as DIR/MODE_fNNNN.rays (ray sets for bench_raw_rays)");
    addNumberOption(app, "--dump-rays-every", a.cfg.dumpRaysEvery, 1, 1000000,
                    "with --dump-rays: only every N-th frame, 1 .. 1000000 (default 1)");
    app.add_option("--out", a.out, "output directory (created if missing)")->required();
    addNumberOption(
        app, "--memory-budget", a.cfg.memoryBudgetGb, kMemoryBudgetGbRange,
        "GB, (0, 65536]: refuse up front a run whose estimated peak memory (from the city file's size) exceeds it; a "
        "streamed paged city's regions are held within it, and a budget that cannot hold the regions at the camera "
        "is an error naming the budget they need; summary.json reports the estimate and the measured peak per phase "
        "(default: no budget)");
    app.add_option("--effects", a.effects,
                   "run-time effects for this run instead of the scene's: 'none', names (haze, glass, night) or a JSON "
                   "object as in the params file; baked effects (sun_shadows, ambient_occlusion, materials, night's "
                   "lights) follow the scene file, and naming one here is an error (give it to `vista gen --effects`)");
    app.add_flag("--also-clear", a.cfg.alsoClear,
                 "also run every mode without the run-time effects on the same frames, as MODE+clear (alternating "
                 "which goes first); its speedup_vs_MODE in summary.json is the effects' same-frame cost ratio; "
                 "without effects it is an A/A run that shows the machine's noise");
    app.add_option("--sweep", a.sweep,
                   "scaling sweep: sizes=500,1000,2000 generates a city per size (seed --seed) and benches each");
    app.add_flag("-q,--quiet", a.quiet, "no progress on stderr");
}

std::string commandLine(int argc, char** argv) {
    std::string s = kCmd;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        s += " " + (a.find(' ') != std::string::npos ? "'" + a + "'" : a);
    }
    return s;
}

// Turns the parsed flags into the bench configuration; errors name the flag.
Status configure(BenchArgs& a) {
    auto size = parseImageSize(a.size);
    if (!size) return size.status();
    a.cfg.width = size->width;
    a.cfg.height = size->height;
    auto sampling = parseSampling(a.sampling);
    if (!sampling) return sampling.status();
    a.cfg.sampleRuns = sampling.value();
    auto ref = parseReference(a.reference);
    if (!ref) return ref.status();
    a.cfg.referenceSsaa = ref.value();
    VISTA_RETURN_IF_ERROR(parseModeFlags(a.mode, a.cfg.options));
    auto modes = parseModeList(a.modes);
    if (!modes) return modes.status();
    a.cfg.modes = modes.value();
    for (const auto& m : a.cfg.modes)
        if (findRenderMode(m)->needsBaked && a.cfg.options.bakedFile.empty())
            return Status::error("mode " + m + " needs --baked city.baked.osgb (from 'vista bake')");
    a.cfg.quiet = a.quiet;
    VISTA_RETURN_IF_ERROR(validateBenchConfig(a.cfg));
    auto po = parsePathFlags(a.path);
    if (!po) return po.status();
    a.pathOptions = po.value();
    VISTA_RETURN_IF_ERROR(validatePagedReach(a.paged));
    VISTA_RETURN_IF_ERROR(validatePagedStream(a.stream));
    if (a.cfg.referenceSsaa == kNoReference && !a.sweep.empty())
        return Status::error("--reference none: not with --sweep (its table's speedups are against full)");
    if ((a.stream.stream || a.stream.preload) && !a.sweep.empty())
        return Status::error(std::string(a.stream.stream ? "--paged-stream" : "--paged-preload") +
                             ": not with --sweep (the sweep benches city files, not paged cities)");
    if (a.cfg.pace && a.cfg.sampleRuns != 1)
        return Status::error("--pace: needs --sampling consecutive (a drive at the path's own speed)");
    if (a.sweep.empty() && a.city.empty()) return Status::error("missing the city file argument (or use --sweep)");
    VISTA_RETURN_IF_ERROR(
        checkRunFiles(a.files.outputDirectory("--out", a.out).outputDirectory("--dump-rays", a.cfg.dumpRaysDir), a.city,
                      a.path, a.mode));
    if (a.sweep.empty()) {
        const Status modes = checkStreamingModes(a.cfg.modes);
        auto streamed = choosePagedStream(kCmd, a.stream, a.city, modes ? std::string() : modes.message(), a.quiet);
        if (!streamed) return streamed.status();
        a.streamed = *streamed;
    }
    if (!a.mode.traffic.empty()) {
        if (!a.sweep.empty()) return Status::error("--traffic: not with --sweep (the sweep makes its own cities)");
        auto tracks = loadTrafficFlag(a.mode.traffic);
        if (!tracks) return tracks.status();
        a.cfg.traffic = *tracks;
    }
    VISTA_RETURN_IF_ERROR(checkWritableDirectory("--out", a.out));  // before any work, so a run never fails at its end
    if (!a.cfg.dumpRaysDir.empty()) {
        if (!a.sweep.empty()) return Status::error("--dump-rays is not supported with --sweep (one city per run)");
        VISTA_RETURN_IF_ERROR(checkWritableDirectory("--dump-rays", a.cfg.dumpRaysDir));
    }
    std::error_code ec;
    fs::path top = fs::path(a.out).lexically_normal();
    if (!top.has_filename()) top = top.parent_path();  // "out/" -> "out"
    for (fs::path d = top; !d.empty() && !fs::exists(d, ec); d = d.parent_path()) {
        a.createdOut.push_back(d);
        if (!d.has_parent_path() || d.parent_path() == d) break;
    }
    fs::create_directories(a.out, ec);
    if (ec || !fs::is_directory(a.out)) return Status::error("--out '" + a.out + "': cannot create directory");
    return Status::ok();
}

void printTable(const BenchResult& r) {
    std::printf("%-12s %10s %10s %9s %10s %10s %12s\n", "mode", "median_ms", "p95_ms", "speedup", "psnr_med",
                "psnr_min", "triangles");
    for (const auto& m : r.modes) {
        const auto full = m.speedupMedianOfRatios.find("full");
        std::printf("%-12s %10.2f %10.2f %9.2f %10.2f %10.2f %12.0f\n", m.mode.c_str(), m.frameMsMedian, m.frameMsP95,
                    full != m.speedupMedianOfRatios.end() ? full->second : NAN, m.psnrDbMedian, m.psnrDbMin,
                    m.trianglesMedian);
    }
}

// One bench of one city file into one directory: load, path, run, print.
int benchCity(const BenchArgs& a, const std::string& cityFile, const std::string& outDir, BenchResult* res,
              size_t* cityTriangles = nullptr) {
    BenchConfig cfg = a.cfg;
    const bool rays = std::any_of(cfg.modes.begin(), cfg.modes.end(),
                                  [](const std::string& m) { return findRenderMode(m)->needsRays; });
    {
        // The estimate before anything is loaded: a run over the budget stops here.
        std::error_code ec;
        const uint64_t bytes = fs::file_size(cityFile, ec);
        if (!ec) {
            cfg.memoryEstimateMb = estimateCityRunMb(bytes, rays);
            if (Status s = checkMemoryBudget("--memory-budget", cfg.memoryBudgetGb, cfg.memoryEstimateMb, bytes, rays);
                !s)
                return reportBadInput(kCmd, s);
        }
    }
    WalkthroughRequest req;
    req.city = cityFile;
    req.cmd = kCmd;
    req.quiet = a.quiet;
    req.paged = a.paged;
    req.streamPaged = a.streamed;  // no region before the first frame: the stream brings them
    // A paged city: the walkthrough first (a CSV, or a seeded path on the
    // city's streets), then only the regions near it.
    req.pathNeedsStreets = a.path.file.empty();
    req.makePath = [&](const SceneModel& city) -> Result<Path> {
        auto p = walkthroughPath(a.path.file, a.pathOptions, city);
        if (p) VISTA_RETURN_IF_ERROR(checkFrameCount(cfg.frames, p->samples.size(), a.repeats));
        return p;
    };
    // The budget check of a city file, on the selected regions' bytes.
    req.beforePagedLoad = [&](uint64_t bytes) {
        cfg.memoryEstimateMb = estimateCityRunMb(bytes, rays);
        return checkMemoryBudget("--memory-budget", cfg.memoryBudgetGb, cfg.memoryEstimateMb, bytes, rays);
    };
    req.cityLoaded = [&] { cfg.memoryPhases.push_back(memoryPhase("load")); };
    // A baked file of another city, or a truncated one, is refused before anything is drawn.
    req.bakedModes = cfg.modes;
    req.effects = [&](const Effects& declared) { return runTimeEffects(a.effects, declared, a.quiet, kCmd); };
    auto walk = loadWalkthrough(req, cfg.options);
    if (!walk) return reportBadInput(kCmd, walk.status());
    const SceneModel& city = walk->city;
    cfg.loadMs = walk->cityLoadMs;
    cfg.pagedJson = walk->pagedJson;
    cfg.pagedManifest = walk->manifest.get();
    if (a.streamed && walk->manifest) {
        auto so = pagedStreamOptions(a.paged, a.stream, cfg.memoryBudgetGb, cfg.memoryEstimateMb);
        if (!so) return reportBadInput(kCmd, so.status());
        cfg.streamManifest = walk->manifest.get();
        cfg.stream = *so;
        if (!a.quiet) notePagedStream(kCmd, *walk->manifest, cfg.stream);
    }
    cfg.runUpS = a.path.file.empty() ? a.pathOptions.runUp : -1.0;
    cfg.outDir = outDir;
    cfg.cityLabel = fs::path(cityFile).filename().string();
    cfg.effectsDeclared = effectsToJson(city.params.effects);
    auto r = runBenchmark(&city, sceneRoot(city), walk->path, cfg);
    if (!r) return reportBadInput(kCmd, r.status());
    if (!a.quiet) printTable(r.value());
    if (res) *res = std::move(r.value());
    if (cityTriangles) *cityTriangles = city.triangles;
    return 0;
}

// `vista gen --size S --seed N` into `cityFile`.
int generateSweepCity(const BenchArgs& a, int size, const std::string& cityFile) {
    const std::string sz = std::to_string(size), sd = std::to_string(a.path.seed);
    std::vector<std::string> args = {"vista gen", "--size", sz, "--seed", sd, "-q", "-o", cityFile};
    std::vector<char*> av;
    for (auto& s : args) av.push_back(s.data());
    av.push_back(nullptr);
    if (!a.quiet) std::fprintf(stderr, "sweep: generating %d m city (seed %s)\n", size, sd.c_str());
    const int rc = runGen(int(args.size()), av.data());
    if (rc != 0) std::fprintf(stderr, "%s --sweep: `vista gen --size %d` failed (exit %d)\n", kCmd, size, rc);
    return rc;
}

struct SweepTable {
    nlohmann::json rows = nlohmann::json::array();
    std::map<std::string, PlotSeries> series;
    std::string markdown =
        "| city size (m) | triangles | mode | median ms | p95 ms | speedup vs full (median of same-frame ratios) | "
        "PSNR median (dB) | triangles drawn (median) |\n|---|---|---|---|---|---|---|---|\n";
    void add(int size, double tris, const ModeSummary& m) {
        const double speedup = m.speedupMedianOfRatios.at("full");
        rows.push_back({{"size_m", size},
                        {"city_triangles", tris},
                        {"mode", m.mode},
                        {"frame_ms_median", m.frameMsMedian},
                        {"frame_ms_p95", m.frameMsP95},
                        {"speedup_vs_full_median_of_ratios", speedup},
                        {"psnr_db_median", m.psnrDbMedian},
                        {"triangles_median", m.trianglesMedian}});
        char buf[256];
        std::snprintf(buf, sizeof(buf), "| %d | %.0f | %s | %.1f | %.1f | %.2f | %.1f | %.0f |\n", size, tris,
                      m.mode.c_str(), m.frameMsMedian, m.frameMsP95, speedup, m.psnrDbMedian, m.trianglesMedian);
        markdown += buf;
        PlotSeries& s = series[m.mode];
        s.label = m.mode;
        s.x.push_back(tris);
        s.y.push_back(m.frameMsMedian);
    }
    Status write(const BenchArgs& a, const std::vector<std::string>& modes) {
        PlotSpec ps;
        ps.title = "Median frame time vs city triangles";
        ps.xLabel = "city triangles";
        ps.yLabel = "ms";
        ps.logX = ps.logY = true;
        for (size_t ci = 0; ci < modes.size(); ++ci) {  // same colours as the per-bench plots
            auto it = series.find(modes[ci]);
            if (it == series.end()) continue;
            it->second.color = plotColor(ci);
            it->second.points = true;
            ps.series.push_back(it->second);
        }
        const nlohmann::json j = {{"command", a.cfg.command}, {"rows", rows}};
        VISTA_RETURN_IF_ERROR(writeFileAtomic((fs::path(a.out) / "sweep.json").string(), j.dump(2) + "\n"));
        VISTA_RETURN_IF_ERROR(writeFileAtomic((fs::path(a.out) / "sweep.md").string(), markdown));
        return writePng(renderPlot(ps), (fs::path(a.out) / "sweep.png").string());
    }
};

// --sweep sizes=...: a generated city per size, benched into out/size_S.
int runSweep(const BenchArgs& a) {
    auto sizes = parseSweep(a.sweep);
    if (!sizes) return reportBadInput(kCmd, sizes.status());
    if (!a.path.file.empty())
        return reportBadInput(kCmd, Status::error("--sweep makes its own paths: do not give --path"));
    SweepTable table;
    for (int size : sizes.value()) {
        const std::string cityFile = (fs::path(a.out) / ("city_" + std::to_string(size) + ".osgb")).string();
        if (int rc = generateSweepCity(a, size, cityFile); rc != 0) return rc;
        BenchResult r;
        size_t triangles = 0;
        if (int rc =
                benchCity(a, cityFile, (fs::path(a.out) / ("size_" + std::to_string(size))).string(), &r, &triangles);
            rc != 0)
            return rc;
        for (const auto& m : r.modes) table.add(size, double(triangles), m);
        std::error_code ec;
        fs::remove(cityFile, ec);  // cities are large; regenerate from the command if needed
    }
    if (Status s = table.write(a, withFullFirst(a.cfg).modes); !s) return reportBadInput(kCmd, s);
    std::printf("%s", table.markdown.c_str());
    return 0;
}

}  // namespace

int runBench(int argc, char** argv) {
    CLI::App app{
        "Headless walkthrough: render modes side by side (interleaved per frame), write frames.csv, "
        "summary.json, plots and difference images.",
        kCmd};
    BenchArgs a;
    declareFlags(app, a);
    if (int rc = parseOrExit(app, argc, argv); rc >= 0) return rc;
    a.cfg.command = commandLine(argc, argv);
    if (Status s = configure(a); !s) return reportBadInput(kCmd, s);
    int rc = requireDisplay(kCmd);
    if (rc < 0) rc = a.sweep.empty() ? benchCity(a, a.city, a.out, nullptr) : runSweep(a);
    // A failed run leaves no empty output folder behind (one it made itself).
    std::error_code ec;
    if (rc != 0)
        for (const fs::path& d : a.createdOut)
            if (!fs::is_empty(d, ec) || !fs::remove(d, ec)) break;
    return rc;
}

}  // namespace vista
