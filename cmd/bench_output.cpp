// The files of a bench run: frames.csv, summary.json and the plots (bench.h;
// the keys are documented in docs/user-guide.md). All writes are atomic.
#include "cmd/bench.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "cmd/options.h"
#include "cmd/paged_stream.h"
#include "cmd/plot.h"
#include "foundation/atomic_file.h"
#include "foundation/statistics.h"
#include "runtime/engine/metrics.h"
#include "runtime/scene/scene_model.h"

namespace vista {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string cpuModel() {
    std::ifstream f("/proc/cpuinfo");
    std::string line;
    while (std::getline(f, line))
        if (line.rfind("model name", 0) == 0) {
            auto p = line.find(':');
            if (p != std::string::npos) return line.substr(p + 2);
        }
    return "unknown";
}

json num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

// The hybrid's split note ("split: near_m=D reason=R [model_ms=M rays_predicted=P]", mode_hybrid.cpp)
// as the four split_* cells (empty for a frame without one); the other notes go to `rest`.
std::string splitCells(const std::vector<std::string>& notes, std::vector<std::string>& rest) {
    std::string cells[4];
    const char* keys[4] = {"near_m=", "reason=", "model_ms=", "rays_predicted="};
    for (const auto& n : notes) {
        if (n.rfind("split: ", 0) != 0) {
            rest.push_back(n);
            continue;
        }
        std::istringstream words(n.substr(7));
        for (std::string w; words >> w;)
            for (int k = 0; k < 4; ++k)
                if (w.rfind(keys[k], 0) == 0) cells[k] = w.substr(std::strlen(keys[k]));
    }
    return cells[0] + "," + cells[1] + "," + cells[2] + "," + cells[3];
}

std::string framesCsv(const BenchResult& result) {
    std::ostringstream csv;
    csv << "frame,path_index,t_s,mode,frame_ms,cull_ms,draw_ms,triangles,draw_calls,rays_cast,psnr_db,diff_fraction,"
           "px_covered,px_horizon_culled,px_cache,px_ray_hit,px_ray_miss,px_interpolated,regions_arrived,run_order,"
           "split_near_m,split_reason,split_model_ms,split_rays_predicted,stages_ms,notes\n";
    char buf[512];
    for (const auto& r : result.frames) {
        const FrameStats& s = r.stats;
        char score[64] = ",";  // no reference: both cells empty
        if (!std::isnan(r.psnrDb)) std::snprintf(score, sizeof score, "%.3f,%.6f", r.psnrDb, r.diffFraction);
        std::snprintf(buf, sizeof(buf),
                      "%d,%zu,%.4f,%s,%.4f,%.4f,%.4f,%llu,%llu,%llu,%s,%llu,%llu,%llu,%llu,%llu,%llu,%d,%d,", r.frame,
                      r.pathIndex, r.t, r.mode.c_str(), s.frameMs, s.cullMs, s.drawMs, (unsigned long long)s.triangles,
                      (unsigned long long)s.drawCalls, (unsigned long long)s.raysCast, score,
                      (unsigned long long)s.pixels.covered, (unsigned long long)s.pixels.horizonCulled,
                      (unsigned long long)s.pixels.cache, (unsigned long long)s.pixels.rayHit,
                      (unsigned long long)s.pixels.rayMiss, (unsigned long long)s.pixels.interpolated, r.regionsArrived,
                      r.runOrder);
        csv << buf;
        std::vector<std::string> notes;
        csv << splitCells(s.notes, notes) << ",";
        std::string st;
        s.stages.forEach([&](Stage stage, double ms) {
            std::snprintf(buf, sizeof(buf), "%s%s=%.3f", st.empty() ? "" : ";", stageName(stage), ms);
            st += buf;
        });
        std::string noteCell;
        for (const auto& n : notes) noteCell += (noteCell.empty() ? "" : ";") + n;
        std::replace(noteCell.begin(), noteCell.end(), ',', ' ');
        csv << st << "," << noteCell << "\n";
    }
    return csv.str();
}

// summary.json paged.stream: the block every streamed run writes (paged_stream.h)
// and the frame thread's splice times between frames.
json streamJson(const BenchResult& r, const BenchConfig& cfg) {
    json j = pagedStreamJson(r.streamOptions, r.stream, r.framesWithArrivals, r.streamDamaged, r.streamDetail);
    // Waiting makes the regions of a frame independent of load timing; a mode whose frames
    // follow measured times (hybrid's adaptive split or cache pauses) still is not.
    const bool timed = std::any_of(cfg.modes.begin(), cfg.modes.end(),
                                   [&](const std::string& m) { return modeFollowsTimings(m, cfg.options); });
    j["frames_deterministic"] = cfg.stream.wait && !timed;
    j["advance_ms_median"] = num(percentile(r.advanceMs, 0.5));
    j["advance_ms_p99"] = num(percentile(r.advanceMs, 0.99));
    j["advance_ms_max"] = num(r.advanceMs.empty() ? 0.0 : *std::max_element(r.advanceMs.begin(), r.advanceMs.end()));
    return j;
}

json pixelClasses(const ModeSummary& s) {
    auto cls = [](const PixelClassSummary& c) {
        return json{{"min_pct", num(c.minPct)},
                    {"mean_pct", num(c.meanPct)},
                    {"max_pct", num(c.maxPct)},
                    {"mean_count", num(c.meanCount)}};
    };
    return {{"covered", cls(s.covered)},  {"horizon_culled", cls(s.horizonCulled)},
            {"cache", cls(s.cache)},      {"ray_hit", cls(s.rayHit)},
            {"ray_miss", cls(s.rayMiss)}, {"interpolated", cls(s.interpolated)}};
}

json modeJson(const ModeSummary& s) {
    json m = {{"frame_ms_median", num(s.frameMsMedian)},
              {"frame_ms_p95", num(s.frameMsP95)},
              {"frame_ms_mean", num(s.frameMsMean)},
              {"frame_ms_p99", num(s.frameMsP99)},
              {"frame_ms_max", num(s.frameMsMax)},
              {"psnr_db_median", num(s.psnrDbMedian)},
              {"psnr_db_min", num(s.psnrDbMin)},
              {"diff_fraction_median", num(s.diffFractionMedian)},
              {"triangles_median", num(s.trianglesMedian)},
              {"draw_calls_median", num(s.drawCallsMedian)},
              {"cull_ms_median", num(s.cullMsMedian)},
              {"draw_ms_median", num(s.drawMsMedian)},
              {"rays_per_frame_median", num(s.raysMedian)}};
    for (const auto& [base, v] : s.speedupMedianOfRatios) m["speedup_vs_" + base + "_median_of_ratios"] = num(v);
    if (s.hasPixels) m["pixels"] = pixelClasses(s);
    if (s.streamed) {
        auto times = [](const ModeSummary::FrameTimes& t) {
            return json{{"frames", t.frames},
                        {"frame_ms_median", num(t.medianMs)},
                        {"frame_ms_p99", num(t.p99Ms)},
                        {"frame_ms_max", num(t.maxMs)}};
        };
        m["frames_with_arrivals"] = times(s.withArrivals);
        m["frames_without_arrivals"] = times(s.withoutArrivals);
    }
    json stages = json::object(), runs = json::object(), setup = json::object();
    for (const auto& kv : s.stagesMsMean) stages[kv.first] = num(kv.second);
    for (const auto& kv : s.stageRuns) runs[kv.first] = kv.second;
    for (const auto& kv : s.setupMs) setup[kv.first] = num(kv.second);
    m["stages_ms"] = stages;
    m["stage_runs"] = runs;
    json fxMs = json::object(), fxRuns = json::object();
    for (const auto& kv : s.effectsMsMean) fxMs[kv.first] = num(kv.second);
    for (const auto& kv : s.effectRuns) fxRuns[kv.first] = kv.second;
    m["effects_ms"] = fxMs;
    m["effect_runs"] = fxRuns;
    m["glass_pixels_mean"] = num(s.glassPixelsMean);
    m["reflection_rays_mean"] = num(s.reflectionRaysMean);
    m["setup_ms"] = setup;
    return m;
}

json summaryJson(const BenchResult& result, const BenchConfig& cfg, const SceneModel* city, const Path& path) {
    const ModeOptions& o = cfg.options;
    json j;
    j["command"] = cfg.command;
    j["city"] = cfg.cityLabel;
    j["city_triangles"] = city ? city->triangles : 0;
    if (!cfg.pagedJson.empty()) j["paged"] = json::parse(cfg.pagedJson);
    if (result.streamed) j["paged"]["stream"] = streamJson(result, cfg);
    j["size"] = {cfg.width, cfg.height};
    j["frames"] = cfg.frames;
    j["sampling"] = samplingName(cfg.sampleRuns);
    j["fov_y_deg"] = cfg.fovYDeg;
    j["near_m"] = o.nearDistance;  // < 0 = auto; "options" holds every mode option, "auto" spelled out
    j["options"] = {{"near_m", o.nearDistance < 0 ? json("auto") : json(o.nearDistance)},
                    {"triangle_budget", o.triangleBudget},
                    {"pixel_budget", o.pixelBudget < 0 ? json("unlimited") : json(o.pixelBudget)},
                    {"horizon_grid", o.horizonGrid > 0 ? json(o.horizonGrid) : json("auto")},
                    {"cache", o.cache},
                    {"cache_error_px", o.cacheErrorPx},
                    {"cache_adaptive", o.cacheAdaptive},
                    {"horizon_adaptive", o.horizonAdaptive},
                    {"far_step", o.farStep},
                    {"point_splat_px", o.splatSigma > 0 ? json(o.splatSigma) : json("off")},
                    {"overlap", o.overlap},
                    {"frame_ms_target", o.frameMsTarget},
                    {"threads", o.threads}};
    j["effects"] = json::parse(cfg.effectsDeclared);
    const FrameEffects& fx = o.effects;
    j["effects_run_time"] = {{"haze", fx.haze ? json(fx.visibility) : json(nullptr)},
                             {"glass_reflections", fx.glass && fx.glassMarked},
                             {"reflection_ray_budget", fx.rayBudget},
                             {"night_sky", fx.night}};
    j["reference"] = cfg.referenceSsaa >= 2              ? "ssaa:" + std::to_string(cfg.referenceSsaa)
                     : cfg.referenceSsaa == kNoReference ? std::string("none")
                                                         : std::string("full");
    j["psnr_cap_db"] = kPsnrCapDb;
    j["diff_threshold"] = cfg.diffThreshold;
    j["path_samples"] = path.samples.size();
    j["path_run_up_s"] = cfg.runUpS >= 0 ? json(cfg.runUpS) : json(nullptr);
    j["paced"] = cfg.pace;  // --pace: frames at the path's own speed
    const PathMotion& pm = result.motion;
    j["path_motion"] = {{"frames", pm.frames},
                        {"metres_per_frame_median", pm.metresMedian},
                        {"metres_per_frame_max", pm.metresMax},
                        {"degrees_per_frame_median", pm.degreesMedian},
                        {"degrees_per_frame_max", pm.degreesMax}};
    j["machine"] = {{"gl_renderer", result.glRenderer},
                    {"cpu", cpuModel()},
                    {"hardware_threads", std::thread::hardware_concurrency()},
                    {"load_avg_1min_start", result.loadAvgStart},
                    {"load_avg_1min_end", result.loadAvgEnd}};
    json phases = json::array();
    for (const MemoryPhase& p : result.memory)
        phases.push_back({{"phase", p.name}, {"peak_rss_mb", p.peakRssMb}, {"rss_mb", p.rssMb}});
    j["memory"] = {{"peak_rss_mb", result.memory.empty() ? json(nullptr) : json(result.memory.back().peakRssMb)},
                   {"estimate_mb", cfg.memoryEstimateMb > 0 ? json(cfg.memoryEstimateMb) : json(nullptr)},
                   {"budget_gb", cfg.memoryBudgetGb > 0 ? json(cfg.memoryBudgetGb) : json(nullptr)},
                   {"phases", phases}};
    json modes = json::object();
    std::vector<std::string> order;
    for (const auto& s : result.modes) {
        modes[s.mode] = modeJson(s);
        order.push_back(s.mode);
    }
    j["modes"] = modes;
    j["mode_order"] = order;
    return j;
}

// Frame time per frame (thesis Fig. 4.8) and quality per frame.
Status writePlots(const BenchResult& result, const BenchConfig& cfg, OutputBatch& batch) {
    PlotSpec pt, pq;
    pt.title = "Frame time per frame";
    pt.xLabel = "frame";
    pt.yLabel = "ms";
    pq.title = "Quality vs reference (luma PSNR, cap 99 dB)";
    pq.xLabel = "frame";
    pq.yLabel = "dB";
    pq.yFromZero = false;
    for (size_t mi = 0; mi < result.modes.size(); ++mi) {
        PlotSeries st, sq;
        st.label = sq.label = result.modes[mi].mode;
        st.color = sq.color = plotColor(mi);
        for (const auto& r : result.frames) {
            if (r.mode != st.label) continue;
            st.x.push_back(double(r.frame));
            st.y.push_back(r.stats.frameMs);
            sq.x.push_back(double(r.frame));
            sq.y.push_back(r.psnrDb);
        }
        pt.series.push_back(st);
        if (cfg.referenceSsaa != kNoReference && (mi > 0 || cfg.referenceSsaa >= 2)) pq.series.push_back(sq);
    }
    VISTA_RETURN_IF_ERROR(writePng(renderPlot(pt), batch.stage((fs::path(cfg.outDir) / "frame_time.png").string())));
    if (cfg.referenceSsaa == kNoReference) return Status::ok();  // nothing scored: no quality plot
    return writePng(renderPlot(pq), batch.stage((fs::path(cfg.outDir) / "quality.png").string()));
}

}  // namespace

Status writeBenchOutputs(const BenchResult& result, const BenchConfig& cfg, const SceneModel* city, const Path& path,
                         OutputBatch& batch) {
    const fs::path dir(cfg.outDir);
    VISTA_RETURN_IF_ERROR(writeFileAtomic(batch.stage((dir / "frames.csv").string()), framesCsv(result)));
    VISTA_RETURN_IF_ERROR(writeFileAtomic(batch.stage((dir / "summary.json").string()),
                                          summaryJson(result, cfg, city, path).dump(2) + "\n"));
    return writePlots(result, cfg, batch);
}

}  // namespace vista
