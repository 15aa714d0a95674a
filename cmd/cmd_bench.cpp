// vista bench: headless walkthrough, modes side by side -> frames.csv,
// summary.json, plots, difference images. Also the size sweep (--sweep).
#include <cmath>
#include <cstdio>
#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cmd/bench.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_graph.h"
#include "cmd/cli.h"
#include "cmd/commands.h"
#include "runtime/scene/paths.h"
#include "cmd/plot.h"

namespace vista {

namespace {

Status parseSize(const std::string& s, int& w, int& h) {
    int a = 0, b = 0;
    char x = 0, extra = 0;
    if (std::sscanf(s.c_str(), "%d%c%d%c", &a, &x, &b, &extra) != 3 || (x != 'x' && x != 'X'))
        return Status::error("--size '" + s + "': expected WIDTHxHEIGHT, e.g. 640x480");
    if (a < 1 || b < 1 || a > 8192 || b > 8192)
        return Status::error("--size " + s + " out of range 1x1 .. 8192x8192");
    w = a;
    h = b;
    return Status::ok();
}

Status parseReference(const std::string& s, int& k) {
    if (s == "full") { k = 0; return Status::ok(); }
    int v = 0;
    char extra = 0;
    if (std::sscanf(s.c_str(), "ssaa:%d%c", &v, &extra) == 1 && v >= 2 && v <= 8) { k = v; return Status::ok(); }
    return Status::error("--reference '" + s + "': expected 'full' or 'ssaa:K' with K in 2..8");
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

std::string commandLine(int argc, char** argv) {
    std::string s = "vista bench";
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        s += " " + (a.find(' ') != std::string::npos ? "'" + a + "'" : a);
    }
    return s;
}

void printTable(const BenchResult& r) {
    std::printf("%-12s %10s %10s %9s %10s %10s %12s\n", "mode", "median_ms", "p95_ms", "speedup", "psnr_med", "psnr_min",
                "triangles");
    for (const auto& m : r.modes)
        std::printf("%-12s %10.2f %10.2f %9.2f %10.2f %10.2f %12.0f\n", m.mode.c_str(), m.frameMsMedian, m.frameMsP95,
                    m.speedupVsFullMedian, m.psnrDbMedian, m.psnrDbMin, m.trianglesMedian);
}

}  // namespace

int runBench(int argc, char** argv) {
    CLI::App app{"Headless walkthrough: render modes side by side (interleaved per frame), write frames.csv, "
                 "summary.json, plots and difference images.",
                 "vista bench"};
    std::string city, pathFile, sizeStr = "640x480", modesStr = "full,near", out, refStr = "full", kind = "car", sweep;
    uint64_t seed = 1;
    BenchConfig cfg;
    double duration = 60.0;
    std::string modeHelp = "comma-separated modes (default full,near); available:";
    for (const auto& m : modeTable()) modeHelp += std::string("\n    ") + m.name + ": " + m.summary;
    app.add_option("city", city, "city scene file (.osgb); not needed with --sweep");
    auto* pathOpt = app.add_option("--path", pathFile, "walkthrough path CSV (from `vista path`)");
    app.add_option("--seed", seed, "make the path from this seed instead of --path (default 1)")->excludes(pathOpt);
    app.add_option("--kind", kind, "path kind when made from --seed: walk, car, fly (default car)");
    app.add_option("--duration", duration, "path duration in seconds when made from --seed (default 60)");
    app.add_option("--frames", cfg.frames, "frames rendered, spread evenly over the whole path (default 120)");
    app.add_option("--size", sizeStr, "image size WIDTHxHEIGHT (default 640x480)");
    app.add_option("--modes", modesStr, modeHelp);
    std::string nearStr = "100", budgetStr = "unlimited";
    bool noCache = false;
    app.add_option("--near", nearStr,
                   "near-field distance in metres, 1 .. 100000, or 'auto' (hybrid: adaptive split per frame; "
                   "near/osgimpostor then use 100) (default 100)");
    app.add_option("--budget", budgetStr,
                   "hybrid: far-field rays per frame through the panoramic cache, 0 .. 1000000000, or "
                   "'unlimited' / -1 = trace every far pixel, cache bypassed (default unlimited)");
    app.add_option("--horizon-grid", cfg.options.horizonGrid,
                   "hybrid: horizon height-grid resolution, cells per side, 1 .. 8192 (default 512)");
    app.add_flag("--no-cache", noCache, "hybrid: panoramic image cache off (every far pixel traced)");
    app.add_option("--baked", cfg.options.bakedFile, "impostor: the baked file of this city (from `vista bake`)");
    app.add_option("--fov", cfg.fovYDeg, "vertical field of view in degrees (default 60)");
    app.add_option("--reference", refStr, "reference for the quality metrics: full (default) or ssaa:K (K x K supersampled full)");
    app.add_option("--diff-threshold", cfg.diffThreshold, "per-channel difference counted as a differing pixel (default 8)");
    app.add_option("--worst", cfg.worstFrames, "difference images for the N worst frames per mode (default 2)");
    app.add_option("--threads", cfg.options.threads, "worker threads for ray casting (0 = all cores)");
    app.add_option("--out", out, "output directory (created if missing)")->required();
    app.add_option("--sweep", sweep, "scaling sweep: sizes=500,1000,2000 generates a city per size (seed --seed) and benches each");
    bool quiet = false;
    app.add_flag("-q,--quiet", quiet, "no progress on stderr");
    int rc = parseOrExit(app, argc, argv);
    if (rc >= 0) return rc;

    const std::string cmd = "vista bench";
    cfg.quiet = quiet;
    cfg.command = commandLine(argc, argv);
    if (Status s = parseSize(sizeStr, cfg.width, cfg.height); !s) return reportBadInput(cmd, s);
    if (Status s = parseReference(refStr, cfg.referenceSsaa); !s) return reportBadInput(cmd, s);
    if (auto nd = parseNearDistance(nearStr); !nd) return reportBadInput(cmd, nd.status());
    else cfg.options.nearDistance = nd.value();
    if (auto pb = parsePixelBudget(budgetStr); !pb) return reportBadInput(cmd, pb.status());
    else cfg.options.pixelBudget = pb.value();
    cfg.options.cache = !noCache;
    if (!cfg.options.bakedFile.empty() && access(cfg.options.bakedFile.c_str(), R_OK) != 0)
        return reportBadInput(cmd, Status::error("--baked '" + cfg.options.bakedFile + "': cannot read the file"));
    auto modes = parseModeList(modesStr);
    if (!modes) return reportBadInput(cmd, modes.status());
    cfg.modes = modes.value();
    for (const auto& m : cfg.modes)
        if (m == "impostor" && cfg.options.bakedFile.empty())
            return reportBadInput(cmd, Status::error("mode impostor needs --baked city.baked.osgb (from 'vista bake')"));
    if (Status s = validateBenchConfig(cfg); !s) return reportBadInput(cmd, s);
    if (cfg.worstFrames < 0 || cfg.worstFrames > 100)
        return reportBadInput(cmd, Status::error("--worst " + std::to_string(cfg.worstFrames) + " out of range 0 .. 100"));
    auto k = parsePathKind(kind);
    if (!k) return reportBadInput(cmd, Status::error("--kind: " + k.status().message()));
    PathOptions po;
    po.seed = seed;
    po.kind = k.value();
    po.duration = duration;
    if (Status s = validatePathOptions(po); !s) return reportBadInput(cmd, s);
    std::error_code ec;
    std::filesystem::create_directories(out, ec);
    if (ec || !std::filesystem::is_directory(out))
        return reportBadInput(cmd, Status::error("--out '" + out + "': cannot create directory"));

    // One bench of one city file into one directory.
    auto benchOne = [&](const std::string& cityFile, const std::string& outDir, BenchResult* res) -> int {
        Path path;
        if (!pathFile.empty()) {
            auto p = loadPathCsv(pathFile);
            if (!p) return reportBadInput(cmd, p.status());
            path = std::move(p.value());
        }
        auto c = loadCityFile(cityFile);
        if (!c) return reportBadInput(cmd, c.status());
        if (pathFile.empty()) {
            auto p = generatePath(c->streets, c->params, po);
            if (!p) return reportBadInput(cmd, p.status());
            path = std::move(p.value());
        }
        BenchConfig cc = cfg;
        cc.outDir = outDir;
        cc.cityLabel = std::filesystem::path(cityFile).filename().string();
        auto r = runBenchmark(&c.value(), sceneRoot(*c), path, cc);
        if (!r) {
            std::fprintf(stderr, "vista bench: %s\n", r.status().message().c_str());
            return 1;
        }
        if (!quiet) printTable(r.value());
        if (res) *res = std::move(r.value());
        return 0;
    };

    if (sweep.empty()) {
        if (city.empty()) return reportBadInput(cmd, Status::error("missing the city file argument (or use --sweep)"));
        if (!std::filesystem::exists(city)) return reportBadInput(cmd, Status::error("city file '" + city + "' does not exist"));
        return benchOne(city, out, nullptr);
    }

    auto sizes = parseSweep(sweep);
    if (!sizes) return reportBadInput(cmd, sizes.status());
    if (!pathFile.empty()) return reportBadInput(cmd, Status::error("--sweep makes its own paths: do not give --path"));
    nlohmann::json rows = nlohmann::json::array();
    std::map<std::string, PlotSeries> series;
    std::string table = "| city size (m) | triangles | mode | median ms | p95 ms | speedup vs full | PSNR median (dB) | triangles drawn (median) |\n"
                        "|---|---|---|---|---|---|---|---|\n";
    for (int size : sizes.value()) {
        std::string cityFile = (std::filesystem::path(out) / ("city_" + std::to_string(size) + ".osgb")).string();
        std::string sz = std::to_string(size), sd = std::to_string(seed);
        std::vector<std::string> args = {"vista gen", "--size", sz, "--seed", sd, "-q", "-o", cityFile};
        std::vector<char*> av;
        for (auto& a : args) av.push_back(a.data());
        av.push_back(nullptr);
        if (!quiet) std::fprintf(stderr, "sweep: generating %d m city (seed %s)\n", size, sd.c_str());
        int grc = runGen(int(args.size()), av.data());
        if (grc != 0) {
            std::fprintf(stderr, "vista bench --sweep: `vista gen --size %d` failed (exit %d)\n", size, grc);
            return grc;
        }
        BenchResult r;
        int brc = benchOne(cityFile, (std::filesystem::path(out) / ("size_" + sz)).string(), &r);
        if (brc != 0) return brc;
        auto lc = loadCityFile(cityFile);
        double tris = lc ? double(lc->triangles) : 0.0;
        for (const auto& m : r.modes) {
            rows.push_back({{"size_m", size}, {"city_triangles", tris}, {"mode", m.mode},
                            {"frame_ms_median", m.frameMsMedian}, {"frame_ms_p95", m.frameMsP95},
                            {"speedup_vs_full_median", m.speedupVsFullMedian}, {"psnr_db_median", m.psnrDbMedian},
                            {"triangles_median", m.trianglesMedian}});
            char buf[256];
            std::snprintf(buf, sizeof(buf), "| %d | %.0f | %s | %.1f | %.1f | %.2f | %.1f | %.0f |\n", size, tris,
                          m.mode.c_str(), m.frameMsMedian, m.frameMsP95, m.speedupVsFullMedian, m.psnrDbMedian,
                          m.trianglesMedian);
            table += buf;
            auto& s = series[m.mode];
            s.label = m.mode;
            s.x.push_back(tris);
            s.y.push_back(m.frameMsMedian);
        }
        std::filesystem::remove(cityFile, ec);  // cities are large; regenerate from the command if needed
    }
    PlotSpec ps;
    ps.title = "Median frame time vs city triangles";
    ps.xLabel = "city triangles";
    ps.yLabel = "ms";
    ps.logX = true;
    ps.logY = true;
    size_t ci = 0;
    std::vector<std::string> order{"full"};  // same colours as the per-bench plots
    for (const auto& m : cfg.modes)
        if (m != "full") order.push_back(m);
    for (const auto& name : order) {
        auto it = series.find(name);
        size_t colour = ci++;
        if (it == series.end()) continue;
        it->second.color = plotColor(colour);
        it->second.points = true;
        ps.series.push_back(it->second);
    }
    nlohmann::json j = {{"command", cfg.command}, {"rows", rows}};
    for (const auto& [name, text] : {std::pair<std::string, std::string>{"sweep.json", j.dump(2) + "\n"}, {"sweep.md", table}}) {
        std::string dst = (std::filesystem::path(out) / name).string(), tmp = dst + ".tmp";
        std::ofstream(tmp, std::ios::binary | std::ios::trunc) << text;
        std::filesystem::rename(tmp, dst, ec);
        if (ec) {
            std::fprintf(stderr, "vista bench: cannot write %s\n", dst.c_str());
            return 1;
        }
    }
    if (Status s = writePng(renderPlot(ps), (std::filesystem::path(out) / "sweep.png").string()); !s) {
        std::fprintf(stderr, "vista bench: %s\n", s.message().c_str());
        return 1;
    }
    std::printf("%s", table.c_str());
    return 0;
}

}  // namespace vista
