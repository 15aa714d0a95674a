// far_field_sweep: the far-field measurements of docs/measurements/modes.md
// in one command. Runs the bench (runBenchmark, modes interleaved per
// frame in one process) on consecutive samples of one car walkthrough (30 fps
// spacing, so the panoramic cache sees real frame-to-frame coherence) for:
//   modes640 / modes320  full, near, raycast, osgimpostor, osglod, hybrid (Figs 4.8, 4.10)
//   near                 hybrid at near = 25, 50, 100, 200, 400 m and auto (Fig 4.9)
//   budget, grid, cache  pixel budgets, horizon grid resolutions, cache on/off
// and writes OUT/far_field.md (tables: Table 4.1 layout, frame times, speedups,
// PSNR vs frame time with the Pareto front), OUT/far_field.json, and plots
// OUT/fig_4_9_near.png, OUT/accuracy_vs_time.png (+ each run's bench output
// in OUT/<run>/). Every figure comes from the bench's own summaries
// (ModeSummary: speedups are medians of same-frame ratios, as in summary.json);
// nothing is recomputed here.
//
// Usage: far_field_sweep CITY.osgb OUT [--frames N] [--only a,b] [--budget B] [--seed N] [--run-up S]
// (--seed: the car path's seed, default 1; --run-up: seconds driven before the
// first frame, default that of `vista path`, 8).
// Needs an X display (xvfb-run -a).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cmd/bench.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_graph.h"
#include "runtime/scene/paths.h"
#include "cmd/plot.h"

using namespace vista;
namespace fs = std::filesystem;

namespace {

struct RunSpec {
    std::string name, group, label;
    int width = 640, height = 480;
    std::vector<std::string> modes;
    ModeOptions options;
    double x = 0;  // parameter value (for plots)
};

// Table 4.1 rows in the thesis' order.
const PixelClassSummary* pixelRows(const ModeSummary& s, int k) {
    const PixelClassSummary* rows[5] = {&s.rayHit, &s.rayMiss, &s.cache, &s.horizonCulled, &s.covered};
    return rows[k];
}

double speedup(const ModeSummary& s) {
    auto it = s.speedupMedianOfRatios.find("full");
    return it == s.speedupMedianOfRatios.end() ? std::nan("") : it->second;
}

std::string fmt(double v, int prec = 1) {
    char b[64];
    std::snprintf(b, sizeof b, "%.*f", prec, v);
    return b;
}

struct SweepArgs {
    std::string cityPath, out;
    int frames = 40;
    PathOptions po;
    int64_t budget = 20000;
    std::set<std::string> only;
};

// The command line; false (after the usage line) when CITY and OUT are missing.
bool parseArgs(int argc, char** argv, SweepArgs& a) {
    if (argc < 3) {
        std::fprintf(
            stderr,
            "usage: far_field_sweep CITY.osgb OUT [--frames N] [--only a,b] [--budget B] [--seed N] [--run-up S]\n");
        return false;
    }
    a.cityPath = argv[1];
    a.out = argv[2];
    a.po.seed = 1;
    a.po.kind = PathKind::Car;
    for (int i = 3; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--frames") && i + 1 < argc) a.frames = std::atoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--seed") && i + 1 < argc) a.po.seed = std::strtoull(argv[++i], nullptr, 10);
        else if (!std::strcmp(argv[i], "--run-up") && i + 1 < argc) a.po.runUp = std::atof(argv[++i]);
        else if (!std::strcmp(argv[i], "--budget") && i + 1 < argc) a.budget = std::atoll(argv[++i]);
        else if (!std::strcmp(argv[i], "--only") && i + 1 < argc) {
            std::stringstream ss(argv[++i]);
            std::string t;
            while (std::getline(ss, t, ',')) a.only.insert(t);
        }
    }
    return true;
}

// Every run of the sweep whose group --only selects (all without --only), in table order.
std::vector<RunSpec> sweepRuns(const SweepArgs& a) {
    ModeOptions base;
    base.nearDistance = 100;
    base.pixelBudget = a.budget;
    base.horizonGrid = 512;
    base.cache = true;
    std::vector<RunSpec> runs;
    auto add = [&](RunSpec r) {
        if (a.only.empty() || a.only.count(r.group)) runs.push_back(std::move(r));
    };
    for (int res : {640, 320}) {
        RunSpec r;
        r.group = res == 640 ? "modes640" : "modes320";
        r.name = r.group;
        r.label = std::to_string(res) + "x" + std::to_string(res * 3 / 4);
        r.width = res;
        r.height = res * 3 / 4;
        r.modes = {"full", "near", "raycast", "osgimpostor", "osglod", "hybrid"};
        r.options = base;
        add(r);
    }
    for (double d : {25.0, 50.0, 100.0, 200.0, 400.0, -1.0}) {
        RunSpec r;
        r.group = "near";
        r.name = d > 0 ? "near_" + std::to_string(int(d)) : "near_auto";
        r.label = d > 0 ? "near " + std::to_string(int(d)) + " m" : "near auto";
        r.modes = {"full", "hybrid"};
        r.options = base;
        r.options.nearDistance = d;
        r.x = d;
        add(r);
    }
    for (int64_t b : {int64_t(2000), int64_t(5000), int64_t(50000), int64_t(-1)}) {
        RunSpec r;
        r.group = "budget";
        r.name = b >= 0 ? "budget_" + std::to_string(b) : "budget_unlimited";
        r.label = b >= 0 ? "budget " + std::to_string(b) : "budget unlimited (cache bypassed)";
        r.modes = {"full", "hybrid"};
        r.options = base;
        r.options.pixelBudget = b;
        r.x = double(b);
        add(r);
    }
    for (int g : {64, 128, 256, 1024}) {
        RunSpec r;
        r.group = "grid";
        r.name = "grid_" + std::to_string(g);
        r.label = "horizon grid " + std::to_string(g);
        r.modes = {"full", "hybrid"};
        r.options = base;
        r.options.horizonGrid = g;
        r.x = g;
        add(r);
    }
    {
        RunSpec r;
        r.group = "cache";
        r.name = "cache_off";
        r.label = "cache off";
        r.modes = {"full", "hybrid"};
        r.options = base;
        r.options.cache = false;
        add(r);
    }
    return runs;
}

// Accuracy vs time: x = speedup of hybrid over full measured in the same
// run (frames interleaved; the median of same-frame ratios, as `vista
// bench` reports it), robust against the machine's load changing between
// runs; absolute medians are listed too.
struct Point {
    std::string label;
    double speedup, ms, psnr;
};

// What the runs measured: far_field.json's content, the accuracy points,
// every mode's summary and frame times by run name.
struct SweepResults {
    nlohmann::json J;
    std::vector<Point> accuracy;
    std::map<std::string, std::map<std::string, ModeSummary>> all;
    std::map<std::string, std::map<std::string, std::vector<double>>> frameMs;
};

// far_field.json's entry of one run (its modes' summaries, hybrid's pixel classes, stages and notes).
nlohmann::json runJson(const RunSpec& rs, const BenchResult& r, SweepResults& res) {
    const ModeSummary& h = res.all[rs.name]["hybrid"];
    nlohmann::json jr;
    jr["label"] = rs.label;
    jr["size"] = {rs.width, rs.height};
    for (const auto& m : rs.modes) {
        const ModeSummary& a = res.all[rs.name][m];
        jr["modes"][m] = {{"frame_ms_median", a.frameMsMedian},
                          {"frame_ms_mean", a.frameMsMean},
                          {"frame_ms_p95", a.frameMsP95},
                          {"psnr_db_median", a.psnrDbMedian},
                          {"psnr_db_min", a.psnrDbMin},
                          {"frame_ms", res.frameMs[rs.name][m]},
                          {"speedup_vs_full_median_of_ratios", speedup(a)}};
    }
    jr["hybrid_speedup_vs_full_median_of_ratios"] = speedup(h);
    jr["path_motion"] = {{"metres_per_frame_median", r.motion.metresMedian},
                         {"degrees_per_frame_median", r.motion.degreesMedian}};
    const char* names[5] = {"ray_hit", "ray_miss", "cache", "horizon_culled", "covered"};
    for (int k = 0; k < 5; ++k) {
        const PixelClassSummary& c = *pixelRows(h, k);
        jr["pixels"][names[k]] = {
            {"min_pct", c.minPct}, {"mean_pct", c.meanPct}, {"max_pct", c.maxPct}, {"mean_count", c.meanCount}};
    }
    jr["stages_ms_mean"] = h.stagesMsMean;
    std::vector<std::string> notes;
    for (const auto& [note, n] : h.noteCounts) notes.push_back(note + " (" + std::to_string(n) + " frames)");
    jr["notes"] = notes;
    return jr;
}

// Benches every run (modes interleaved per frame) into OUT/<run>/ and
// collects the results; false when a run fails (the message is printed).
bool runAll(const SweepArgs& a, const std::vector<RunSpec>& runs, const SceneModel& city, const Path& path,
            SweepResults& res) {
    for (const RunSpec& rs : runs) {
        BenchConfig cfg;
        cfg.width = rs.width;
        cfg.height = rs.height;
        cfg.frames = a.frames;
        cfg.modes = rs.modes;
        cfg.outDir = (fs::path(a.out) / rs.name).string();
        cfg.options = rs.options;
        cfg.quiet = true;
        cfg.worstFrames = 1;
        cfg.cityLabel = res.J["city"];
        cfg.command = "far_field_sweep " + a.cityPath + " (run " + rs.name + ")";
        std::fprintf(stderr, "run %s ...\n", rs.name.c_str());
        auto r = runBenchmark(&city, sceneRoot(city), path, cfg);
        if (!r) {
            std::fprintf(stderr, "run %s failed: %s\n", rs.name.c_str(), r.status().message().c_str());
            return false;
        }
        for (const auto& m : r->modes) {
            res.all[rs.name][m.mode] = m;
            res.frameMs[rs.name][m.mode] = modeFrameTimes(*r, m.mode);
        }
        const ModeSummary& h = res.all[rs.name]["hybrid"];
        res.J["runs"][rs.name] = runJson(rs, *r, res);
        if (rs.group != "modes320" && rs.group != "modes640")
            res.accuracy.push_back({rs.label, speedup(h), h.frameMsMedian, h.psnrDbMedian});
        if (rs.name == "modes640")
            res.accuracy.push_back({"default (near 100, budget " + std::to_string(a.budget) + ", grid 512)", speedup(h),
                                    h.frameMsMedian, h.psnrDbMedian});
    }
    return true;
}

// Table 4.1 (pixel classes), hybrid's stage times and the frame times of every mode, per image size.
void writeModeTables(std::ostringstream& md, const std::vector<RunSpec>& runs, SweepResults& res) {
    const char* rowNames[5] = {"ray cast and hit an object", "ray cast and missed", "taken from the image cache",
                               "culled by horizon tracing", "covered by polygons"};
    for (const char* run : {"modes640", "modes320"}) {
        if (!res.all.count(run)) continue;
        const ModeSummary& h = res.all[run]["hybrid"];
        const RunSpec* rs = nullptr;
        for (const auto& x : runs)
            if (x.name == run) rs = &x;
        md << "**Table 4.1 (" << rs->label << ")** — of " << rs->width * rs->height << " pixels:\n\n";
        md << "| Of " << rs->width * rs->height
           << " pixels ... | Min [%] | Avg. [%] | Max [%] | Avg. [#] |\n|---|---:|---:|---:|---:|\n";
        for (int k = 0; k < 5; ++k) {
            const PixelClassSummary& c = *pixelRows(h, k);
            md << "| " << rowNames[k] << " | " << fmt(c.minPct, 2) << " | " << fmt(c.meanPct, 2) << " | "
               << fmt(c.maxPct, 2) << " | " << fmt(c.meanCount, 0) << " |\n";
        }
        md << "\nHybrid stage times (mean ms over the frames each ran in):";
        for (const auto& [st, ms] : h.stagesMsMean) md << " " << st << " " << fmt(ms, 2) << ";";
        md << "\n\n";
        md << "**Frame times (" << rs->label
           << ")**\n\n| mode | median ms | mean ms | p95 ms | speedup vs full (median of same-frame ratios) | PSNR "
              "median dB | PSNR min dB |\n|---|---:|---:|---:|---:|---:|---:|\n";
        for (const auto& m : rs->modes) {
            const ModeSummary& a = res.all[run][m];
            md << "| " << m << " | " << fmt(a.frameMsMedian) << " | " << fmt(a.frameMsMean) << " | "
               << fmt(a.frameMsP95) << " | " << fmt(speedup(a), 2) << " | " << fmt(a.psnrDbMedian) << " | "
               << fmt(a.psnrDbMin) << " |\n";
        }
        md << "\nFrame time per frame: `" << run << "/frame_time.png`.\n\n";
    }
}

// One parameter sweep's table (the runs of `group`), if any ran.
void writeSweepTable(std::ostringstream& md, const std::vector<RunSpec>& runs, SweepResults& res,
                     const std::string& group, const std::string& title) {
    bool any = false;
    for (const auto& rs : runs) any = any || rs.group == group;
    if (!any) return;
    md << "**" << title
       << "**\n\n| run | hybrid median ms | hybrid p95 ms | full median ms | speedup (median of same-frame ratios) | "
          "PSNR median dB | PSNR min dB | traced px/frame (mean) | cache px (mean) "
          "|\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const auto& rs : runs) {
        if (rs.group != group) continue;
        const ModeSummary& h = res.all[rs.name]["hybrid"];
        const ModeSummary& f = res.all[rs.name]["full"];
        md << "| " << rs.label << " | " << fmt(h.frameMsMedian) << " | " << fmt(h.frameMsP95) << " | "
           << fmt(f.frameMsMedian) << " | " << fmt(speedup(h), 2) << " | " << fmt(h.psnrDbMedian) << " | "
           << fmt(h.psnrDbMin) << " | " << fmt(h.rayHit.meanCount + h.rayMiss.meanCount, 0) << " | "
           << fmt(h.cache.meanCount, 0) << " |\n";
    }
    md << "\n";
}

// Fig 4.9 plot: frame time per frame per near distance.
void plotNearDistances(std::ostringstream& md, const std::vector<RunSpec>& runs, SweepResults& res,
                       const std::string& out) {
    PlotSpec ps;
    ps.title = "hybrid frame time vs near distance (640x480)";
    ps.xLabel = "frame";
    ps.yLabel = "ms";
    size_t ci = 0;
    for (const auto& rs : runs) {
        if (rs.group != "near") continue;
        PlotSeries s;
        s.label = rs.label;
        s.color = plotColor(ci++);
        s.y = res.frameMs[rs.name]["hybrid"];
        for (size_t i = 0; i < s.y.size(); ++i) s.x.push_back(double(i));
        ps.series.push_back(s);
    }
    if (!ps.series.empty()) {
        writePng(renderPlot(ps), (fs::path(out) / "fig_4_9_near.png").string());
        md << "Plot: `fig_4_9_near.png` (frame time per frame for each near distance).\n\n";
    }
}

// Accuracy vs time with the Pareto front (min time, max PSNR): the plot and its table.
void plotAccuracy(std::ostringstream& md, const std::vector<Point>& accuracy, const std::string& out) {
    if (accuracy.empty()) return;
    std::vector<Point> sorted = accuracy;
    std::sort(sorted.begin(), sorted.end(), [](const Point& a, const Point& b) { return a.speedup > b.speedup; });
    std::vector<Point> front;  // fastest first; on the front if more accurate than every faster one
    double best = -1e9;
    for (const auto& p : sorted)
        if (p.psnr > best) {
            front.push_back(p);
            best = p.psnr;
        }
    PlotSpec ps;
    ps.title = "what accuracy costs: PSNR vs speedup over full (640x480)";
    ps.xLabel = "speedup of hybrid over full (median of same-frame ratios)";
    ps.yLabel = "median PSNR dB";
    ps.yFromZero = false;
    PlotSeries pts;
    pts.label = "configurations";
    pts.line = false;
    pts.points = true;
    pts.color = plotColor(0);
    for (const auto& p : accuracy) {
        pts.x.push_back(p.speedup);
        pts.y.push_back(p.psnr);
    }
    PlotSeries fr;
    fr.label = "pareto front";
    fr.points = true;
    fr.color = plotColor(1);
    for (const auto& p : front) {
        fr.x.push_back(p.speedup);
        fr.y.push_back(p.psnr);
    }
    ps.series = {pts, fr};
    writePng(renderPlot(ps), (fs::path(out) / "accuracy_vs_time.png").string());
    md << "**What accuracy costs** (`accuracy_vs_time.png`; * = on the Pareto front: no other configuration is both "
          "faster and more accurate)\n\n| configuration | speedup vs full | hybrid median ms | median PSNR dB | Pareto "
          "|\n"
          "|---|---:|---:|---:|:---:|\n";
    for (const auto& p : sorted) {
        bool onFront = false;
        for (const auto& q : front) onFront = onFront || (q.label == p.label);
        md << "| " << p.label << " | " << fmt(p.speedup, 2) << " | " << fmt(p.ms) << " | " << fmt(p.psnr) << " | "
           << (onFront ? "*" : "") << " |\n";
    }
    md << "\n";
}

// far_field.md: the city and defaults, the mode tables, the sweeps, the plots.
std::string markdown(const SweepArgs& a, const std::vector<RunSpec>& runs, const SceneModel& city, SweepResults& res) {
    std::ostringstream md;
    md << "City: `" << res.J["city"].get<std::string>() << "` (" << city.triangles
       << " triangles), car walkthrough seed " << a.po.seed << " (run-up " << a.po.runUp << " s), " << a.frames
       << " consecutive frames at 30 fps spacing; hybrid defaults: near 100 m, pixel budget " << a.budget
       << ", horizon grid 512, cache on.\n\n";
    writeModeTables(md, runs, res);
    writeSweepTable(md, runs, res, "near", "Fig. 4.9: frame time vs near distance (640x480)");
    writeSweepTable(md, runs, res, "budget", "Pixel budget (640x480)");
    writeSweepTable(md, runs, res, "grid", "Horizon grid resolution (640x480)");
    writeSweepTable(md, runs, res, "cache", "Cache off (640x480; every far pixel traced)");
    plotNearDistances(md, runs, res, a.out);
    plotAccuracy(md, res.accuracy, a.out);
    return md.str();
}

}  // namespace

// The steps: arguments, city and path, the runs, far_field.md/.json and plots.
int main(int argc, char** argv) {
    SweepArgs a;
    if (!parseArgs(argc, argv, a)) return 2;
    auto city = loadCityFile(a.cityPath);
    if (!city) {
        std::fprintf(stderr, "%s\n", city.status().message().c_str());
        return 2;
    }
    a.po.duration = (a.frames - 1) * a.po.dt;
    auto path = generatePath(city->streets, city->params, a.po);
    if (!path) {
        std::fprintf(stderr, "%s\n", path.status().message().c_str());
        return 2;
    }
    fs::create_directories(a.out);
    const std::vector<RunSpec> runs = sweepRuns(a);

    SweepResults res;
    res.J["city"] = fs::path(a.cityPath).filename().string();
    res.J["city_triangles"] = city->triangles;
    res.J["frames"] = a.frames;
    res.J["default_budget"] = a.budget;
    if (!runAll(a, runs, *city, *path, res)) return 1;
    const std::string md = markdown(a, runs, *city, res);
    {
        std::ofstream f(fs::path(a.out) / "far_field.md");
        f << md;
        std::ofstream j(fs::path(a.out) / "far_field.json");
        j << res.J.dump(1) << "\n";
    }
    std::printf("%s", md.c_str());
    return 0;
}
