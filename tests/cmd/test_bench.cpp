// Offscreen renderer, bench modes and the `vista bench` command.
// Rendering tests need an X display: run under `xvfb-run -a` (they skip
// with a message when DISPLAY is unset).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <unistd.h>

#include <osg/Geode>
#include <osg/Geometry>
#include <osg/MatrixTransform>
#include <glm/gtc/type_ptr.hpp>
#include <nlohmann/json.hpp>

#include "citygen/lighting.h"
#include "foundation/units.h"
#include "cmd/bench.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_graph.h"
#include "runtime/engine/metrics.h"
#include "nodes/far_field_node.h"
#include "nodes/render/offscreen.h"
#include "runtime/scene/paths.h"
#include "runtime/engine/ray_scene.h"
#include "tests/nodes/render/render_fixtures.h"

using namespace vista;
namespace fs = std::filesystem;
namespace {
std::string tmpDir(const std::string& name) {
    fs::path p = fs::temp_directory_path() / ("vista_test_bench_" + std::to_string(::getpid()) + "_" + name);
    fs::create_directories(p);
    return p.string();
}

int runVista(const std::string& args, std::string* output = nullptr) {
    std::string log = tmpDir("cli") + "/out.txt";
    int rc = std::system((std::string(VISTA_BINARY) + " " + args + " > " + log + " 2>&1").c_str());
    if (output) {
        std::ifstream f(log);
        std::stringstream ss;
        ss << f.rdbuf();
        *output = ss.str();
    }
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

}  // namespace

TEST(RenderModes, RegistryListsEveryModeOnce) {
    std::vector<std::string> names;
    for (const auto& m : renderModes()) names.push_back(m.name);
    EXPECT_EQ(names, (std::vector<std::string>{"full", "near", "raycast", "osgimpostor", "osglod", "hybrid",
                                               "hybrid-fixed", "impostor", "lodmesh"}));
    EXPECT_EQ(renderModeNames(), "full, near, raycast, osgimpostor, osglod, hybrid, hybrid-fixed, impostor, lodmesh");
    EXPECT_TRUE(findRenderMode("raycast")->needsRays);
    EXPECT_TRUE(findRenderMode("hybrid")->needsRays);
    EXPECT_TRUE(findRenderMode("hybrid-fixed")->needsRays);
    EXPECT_FALSE(findRenderMode("osglod")->needsRays);
    EXPECT_TRUE(findRenderMode("impostor")->needsBaked);
    EXPECT_FALSE(findRenderMode("full")->needsBaked);
    EXPECT_EQ(findRenderMode("warp"), nullptr);
    ModeContext ctx;
    auto unknown = createRenderMode("nope", ctx);
    ASSERT_FALSE(unknown.isOk());
    EXPECT_NE(unknown.status().message().find("available modes: full, near"), std::string::npos);
    auto noScene = createRenderMode("full", ctx);
    ASSERT_FALSE(noScene.isOk());
    EXPECT_NE(noScene.status().message().find("scene graph"), std::string::npos) << noScene.status().message();
    osg::ref_ptr<osg::Group> empty = new osg::Group;
    ctx.scene = empty.get();
    auto noRays = createRenderMode("hybrid", ctx);
    ASSERT_FALSE(noRays.isOk());
    EXPECT_NE(noRays.status().message().find("ray scene"), std::string::npos) << noRays.status().message();
    auto noBaked = createRenderMode("impostor", ctx);
    ASSERT_FALSE(noBaked.isOk());
    EXPECT_NE(noBaked.status().message().find("--baked"), std::string::npos) << noBaked.status().message();
    EXPECT_TRUE(createRenderMode("osgimpostor", ctx).isOk()) << "GL modes are created without a renderer (viewer)";
    BenchConfig c;
    c.frames = 0;
    EXPECT_FALSE(validateBenchConfig(c).isOk());
    c.frames = 1;
    c.width = 0;
    EXPECT_FALSE(validateBenchConfig(c).isOk());
    c.width = 64;
    c.options.horizonGrid = -1;
    auto s = validateBenchConfig(c);
    ASSERT_FALSE(s.isOk());
    EXPECT_NE(s.message().find("--horizon-grid"), std::string::npos) << s.message();
    c.options.horizonGrid = 8192;
    c.options.nearDistance = -1;  // auto
    EXPECT_TRUE(validateBenchConfig(c).isOk());
    c.options.nearDistance = 0.5;
    EXPECT_FALSE(validateBenchConfig(c).isOk());
    EXPECT_DOUBLE_EQ(percentile({3, 1, 2}, 0.5), 2.0);
    EXPECT_DOUBLE_EQ(percentile({1, 2, 3, 4, 5}, 0.95), 4.8);
}

// The speedup is the median of same-frame ratios, not the ratio of medians.
TEST(BenchSummary, SpeedupIsTheMedianOfSameFrameRatios) {
    const double fullMs[5] = {10, 20, 30, 40, 50}, modeMs[5] = {5, 40, 10, 20, 100};
    BenchResult r;
    for (int f = 0; f < 5; ++f)
        for (const char* m : {"full", "x"}) {
            BenchFrameRecord rec;
            rec.frame = f;
            rec.mode = m;
            rec.stats.frameMs = std::string(m) == "full" ? fullMs[f] : modeMs[f];
            rec.stats.raysCast = uint64_t(10 * f);
            r.frames.push_back(rec);
        }
    const ModeSummary s = summariseMode(r, "x", speedupBases(), 100.0);
    ASSERT_EQ(s.speedupMedianOfRatios.count("full"), 1u);
    EXPECT_DOUBLE_EQ(s.speedupMedianOfRatios.at("full"), 2.0);   // ratios 2, 0.5, 3, 2, 0.5
    EXPECT_NE(s.speedupMedianOfRatios.at("full"), 30.0 / 20.0);  // the ratio of the medians
    EXPECT_EQ(s.speedupMedianOfRatios.count("near"), 0u);        // near did not run
    EXPECT_DOUBLE_EQ(s.frameMsMedian, 20.0);
    EXPECT_DOUBLE_EQ(s.raysMedian, 20.0);
    EXPECT_DOUBLE_EQ(medianOfSameFrameRatios({10, 0, 30}, {5, 5, 0}), 2.0);  // frames without a time are skipped
    EXPECT_TRUE(std::isnan(medianOfSameFrameRatios({}, {})));
    EXPECT_EQ(modeFrameTimes(r, "x"), (std::vector<double>{5, 40, 10, 20, 100}));
}
namespace {
std::vector<std::vector<std::string>> readCsv(const std::string& file) {
    std::ifstream f(file);
    std::vector<std::vector<std::string>> rows;
    for (std::string line; std::getline(f, line);) {
        std::vector<std::string> cells;
        std::stringstream ss(line);
        for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
        rows.push_back(cells);
    }
    return rows;
}

// Per mode, the frame_ms column of frames.csv in frame order.
std::map<std::string, std::vector<double>> frameTimesFromCsv(const std::string& file) {
    auto rows = readCsv(file);
    std::map<std::string, std::vector<double>> out;
    if (rows.empty()) return out;
    const auto& h = rows[0];
    const size_t mode = size_t(std::find(h.begin(), h.end(), "mode") - h.begin());
    const size_t ms = size_t(std::find(h.begin(), h.end(), "frame_ms") - h.begin());
    for (size_t i = 1; i < rows.size(); ++i) out[rows[i][mode]].push_back(std::stod(rows[i][ms]));
    return out;
}

double medianOf(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t h = v.size() / 2;
    return v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
}

// The speedups of summary.json recomputed from frames.csv.
void expectSpeedupsFromCsv(const std::string& dir) {
    std::ifstream f(dir + "/summary.json");
    ASSERT_TRUE(f.good()) << dir;
    const auto j = nlohmann::json::parse(f);
    const auto times = frameTimesFromCsv(dir + "/frames.csv");
    for (const auto& [mode, ms] : times)
        for (const char* base : {"full", "near", "raycast"}) {
            const std::string key = std::string("speedup_vs_") + base + "_median_of_ratios";
            if (!times.count(base)) {
                EXPECT_FALSE(j["modes"][mode].contains(key)) << mode << "." << key;
                continue;
            }
            std::vector<double> ratios;
            for (size_t k = 0; k < ms.size(); ++k) ratios.push_back(times.at(base)[k] / ms[k]);
            ASSERT_TRUE(j["modes"][mode][key].is_number()) << mode << "." << key;
            EXPECT_NEAR(j["modes"][mode][key].get<double>(), medianOf(ratios), 1e-3 * medianOf(ratios))
                << mode << "." << key;
        }
}

}  // namespace

TEST(Bench, SyntheticSceneSmokeRun) {
    REQUIRE_DISPLAY();
    SceneModel city = tinyCity();
    Path path;
    for (int i = 0; i < 4; ++i) {
        PathSample s;
        s.t = i;
        s.position = kWorld + glm::dvec3(0, -30.0 + 5 * i, 1.7);
        s.heading = 0.1 * i;
        path.samples.push_back(s);
    }
    BenchConfig cfg;
    cfg.width = 96;
    cfg.height = 72;
    cfg.frames = 3;
    cfg.modes = {"near", "osgimpostor", "osglod"};  // full is added as the reference
    cfg.options.nearDistance = 40;                  // the blocks (100 m ahead) lie beyond it
    cfg.outDir = tmpDir("smoke");
    cfg.quiet = true;
    cfg.loadMs = 12.5;
    auto r = runBenchmark(nullptr, sceneRoot(city), path, cfg);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    ASSERT_EQ(r->modes.size(), 4u);
    EXPECT_EQ(r->modes[0].mode, "full");
    EXPECT_EQ(r->modes[0].psnrDbMin, kPsnrCapDb);
    EXPECT_DOUBLE_EQ(r->modes[0].speedupMedianOfRatios.at("full"), 1.0);
    EXPECT_GT(r->modes[0].trianglesMedian, 0.0);
    EXPECT_LT(r->modes[1].trianglesMedian, r->modes[0].trianglesMedian) << "near draws fewer triangles than full";
    EXPECT_LT(r->modes[1].psnrDbMedian, kPsnrCapDb) << "near misses the blocks beyond 40 m";
    EXPECT_DOUBLE_EQ(r->modes[1].speedupMedianOfRatios.at("near"), 1.0);
    EXPECT_EQ(r->motion.frames, 3u);
    EXPECT_NEAR(r->motion.metresMedian, 7.5, 1e-9);  // samples 0, 2, 3 (spread) are 10 m and 5 m apart

    std::ifstream f(cfg.outDir + "/summary.json");
    ASSERT_TRUE(f.good());
    auto j = nlohmann::json::parse(f);
    for (const char* mode : {"full", "near", "osgimpostor", "osglod"}) {
        ASSERT_TRUE(j["modes"].contains(mode)) << mode;
        const auto& m = j["modes"][mode];
        for (const char* key :
             {"frame_ms_median", "frame_ms_p95", "speedup_vs_full_median_of_ratios", "speedup_vs_near_median_of_ratios",
              "psnr_db_median", "psnr_db_min", "triangles_median", "rays_per_frame_median"})
            EXPECT_TRUE(m[key].is_number()) << mode << "." << key;
        EXPECT_FALSE(m.contains("speedup_vs_full_median")) << "the old name would hide what the number is";
        EXPECT_FALSE(m.contains("speedup_vs_raycast_median_of_ratios")) << "raycast did not run";
        EXPECT_EQ(m["setup_ms"]["load"].get<double>(), 12.5) << mode;
        EXPECT_EQ(m["rays_per_frame_median"].get<double>(), 0.0) << mode;
    }
    EXPECT_TRUE(j["modes"]["full"]["setup_ms"].contains("chunking"));
    EXPECT_TRUE(j["modes"]["osglod"]["setup_ms"].contains("simplify"));
    EXPECT_TRUE(j["modes"]["osgimpostor"]["setup_ms"].contains("impostors"));
    EXPECT_NEAR(j["path_motion"]["metres_per_frame_median"].get<double>(), 7.5, 1e-9);
    EXPECT_TRUE(j["path_motion"]["degrees_per_frame_max"].is_number());
    EXPECT_TRUE(j["path_run_up_s"].is_null()) << "a hand-made path: run-up unknown";
    expectSpeedupsFromCsv(cfg.outDir);
    auto rows = readCsv(cfg.outDir + "/frames.csv");
    EXPECT_EQ(rows.size(), 1u + 4u * 3u);
    EXPECT_NE(std::find(rows[0].begin(), rows[0].end(), "rays_cast"), rows[0].end());
    for (const char* file : {"frame_time.png", "quality.png", "images/first_full.png", "images/first_osglod.png"})
        EXPECT_TRUE(fs::exists(cfg.outDir + "/" + file)) << file;
    fs::remove_all(cfg.outDir);
}

// frames.csv carries the hybrid's near/far split of each frame: split_near_m, split_reason,
// split_model_ms and split_rays_predicted (--near auto), the fixed distance and "fixed" for
// hybrid-fixed, empty cells for a mode without a split; the split's note is not repeated in notes.
TEST(Bench, FramesCsvCarriesTheSplitOfEachHybridFrame) {
    REQUIRE_DISPLAY();
    SceneModel city = tinyCity();
    Path path;
    for (int i = 0; i < 4; ++i) {
        PathSample s;
        s.t = i;
        s.position = kWorld + glm::dvec3(0, -30.0 + 5 * i, 1.7);
        path.samples.push_back(s);
    }
    BenchConfig cfg;
    cfg.width = 96;
    cfg.height = 72;
    cfg.frames = 4;
    cfg.modes = {"raycast", "hybrid-fixed", "hybrid"};
    cfg.options.nearDistance = -1;  // auto
    cfg.outDir = tmpDir("split_columns");
    cfg.quiet = true;
    auto r = runBenchmark(&city, sceneRoot(city), path, cfg);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    const auto rows = readCsv(cfg.outDir + "/frames.csv");
    ASSERT_GT(rows.size(), 1u);
    const auto& h = rows[0];
    auto col = [&](const char* name) {
        const size_t c = size_t(std::find(h.begin(), h.end(), name) - h.begin());
        EXPECT_LT(c, h.size()) << name;
        return c;
    };
    const size_t mode = col("mode"), nearM = col("split_near_m"), reason = col("split_reason"),
                 model = col("split_model_ms"), rays = col("split_rays_predicted"), notes = col("notes");
    int hybrid = 0;
    for (size_t i = 1; i < rows.size(); ++i) {
        const auto& row = rows[i];
        ASSERT_GT(row.size(), rays);
        const std::string note = notes < row.size() ? row[notes] : "";  // an empty last cell is not read
        EXPECT_EQ(note.find("split: "), std::string::npos) << note;
        if (row[mode] == "hybrid-fixed") {
            EXPECT_EQ(row[nearM], "100.00");
            EXPECT_EQ(row[reason], "fixed");
            EXPECT_EQ(row[model], "");
        } else if (row[mode] == "hybrid") {
            ++hybrid;
            EXPECT_TRUE(row[reason] == "model" || row[reason] == "guard" || row[reason] == "measure") << row[reason];
            const double d = std::stod(row[nearM]);  // "inf" for everything
            EXPECT_GE(d, 0.0);
            if (d > 0) EXPECT_GE(std::stod(row[model]), 0.0);  // ray casting: priced by the probe's rate, left out
            else EXPECT_EQ(row[model], "");
            EXPECT_GE(std::stod(row[rays]), 0.0);
            EXPECT_NE(note.find("near auto: "), std::string::npos) << note;
        } else {
            for (size_t c : {nearM, reason, model, rays}) EXPECT_EQ(row[c], "") << row[mode];
        }
    }
    EXPECT_EQ(hybrid, 4);
    fs::remove_all(cfg.outDir);
}

TEST(Bench, SupersampledReferenceIsCloserToItselfThanAliasedFrames) {
    REQUIRE_DISPLAY();
    SceneModel city = tinyCity();
    Path path;
    PathSample s;
    s.position = kWorld + glm::dvec3(0, -20, 1.7);
    path.samples.push_back(s);
    BenchConfig cfg;
    cfg.width = 64;
    cfg.height = 48;
    cfg.frames = 1;
    cfg.modes = {"full"};
    cfg.referenceSsaa = 3;
    cfg.quiet = true;
    auto r = runBenchmark(nullptr, sceneRoot(city), path, cfg);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    // The aliased full frame differs from the 3x3 supersampled reference
    // (edges), but stays close to it.
    EXPECT_LT(r->modes[0].psnrDbMin, kPsnrCapDb);
    EXPECT_GT(r->modes[0].psnrDbMin, 20.0);
}

TEST(BenchCli, BadInputExitsWithTwo) {
    ASSERT_TRUE(fs::exists(VISTA_BINARY)) << "the vista binary is a build dependency of this test";
    std::string dir = tmpDir("badcli"), out;
    std::string dummy = dir + "/dummy.osgb";
    std::ofstream(dummy) << "x";
    EXPECT_EQ(runVista("bench " + dir + "/missing.osgb --out " + dir + "/o", &out), 2) << out;
    EXPECT_NE(out.find("missing.osgb"), std::string::npos) << out;
    EXPECT_EQ(runVista("bench " + dummy + " --modes full,warp --out " + dir + "/o", &out), 2) << out;
    EXPECT_NE(out.find("available modes"), std::string::npos) << out;
    EXPECT_EQ(runVista("bench " + dummy + " --size 0x0 --out " + dir + "/o", &out), 2) << out;
    EXPECT_NE(out.find("--size"), std::string::npos) << out;
    EXPECT_EQ(runVista("bench " + dummy + " --frames 0 --out " + dir + "/o", &out), 2) << out;
    EXPECT_NE(out.find("--frames"), std::string::npos) << out;
    EXPECT_EQ(runVista("path " + dir + "/missing.osgb -o " + dir + "/p.csv", &out), 2) << out;
    EXPECT_EQ(runVista("bench " + dummy + " --reference ssaa:99 --out " + dir + "/o", &out), 2) << out;
    EXPECT_EQ(runVista("bench " + dummy + " --fov 0 --out " + dir + "/o", &out), 2) << out;
    EXPECT_NE(out.find("--fov"), std::string::npos) << out;
    EXPECT_EQ(runVista("bench " + dummy + " --modes full,impostor --out " + dir + "/o", &out), 2) << out;
    EXPECT_NE(out.find("--baked"), std::string::npos) << out;
    // The viewer parses the same options with the same parsers.
    const std::pair<const char*, const char*> view[] = {{"--size 0x0", "--size"},
                                                        {"--size 640", "--size"},
                                                        {"--mode warp", "available modes"},
                                                        {"--near 0", "--near"},
                                                        {"--budget x", "--budget"},
                                                        {"--fov 200", "--fov"},
                                                        {"--triangle-budget -1", "--triangle-budget"},
                                                        {"--step --frames 2", "--step"}};
    for (const auto& [args, what] : view) {
        EXPECT_EQ(runVista("view " + dummy + " " + args, &out), 2) << args << ": " << out;
        EXPECT_NE(out.find(what), std::string::npos) << args << ": " << out;
    }
    fs::remove_all(dir);
}

// End to end on a generated tiny city: gen -> path -> bench (every mode but
// impostor), checking values: what each mode draws, traces and costs.
TEST(BenchCli, TinyGeneratedCity) {
    REQUIRE_DISPLAY();
    ASSERT_TRUE(fs::exists(VISTA_BINARY)) << "the vista binary is a build dependency of this test";
    std::string dir = tmpDir("e2e"), out;
    std::string city = dir + "/tiny.osgb";
    ASSERT_EQ(runVista("gen --size 300 --seed 3 -q -o " + city, &out), 0) << out;
    auto loaded = loadCityFile(city);
    ASSERT_TRUE(loaded.isOk()) << loaded.status().message();
    ASSERT_EQ(runVista("path " + city + " --seed 4 --duration 10 -o " + dir + "/p.csv", &out), 0) << out;
    {  // the path drives on the generated city's streets
        auto p = loadPathCsv(dir + "/p.csv");
        ASSERT_TRUE(p.isOk()) << p.status().message();
        const auto& L = loaded.value();
        glm::dvec2 origin(L.params.origin_x, L.params.origin_y);
        for (const auto& s : p->samples) {
            int e = -1;
            double d = distanceToStreets(L.streets, glm::dvec2(s.position) - origin, &e);
            ASSERT_GE(e, 0);
            EXPECT_LE(d, 0.5 * L.streets.edges[size_t(e)].width + 0.5) << "t = " << s.t;
        }
    }
    // A short near distance: most of the city is far field (traced by hybrid,
    // simplified by osglod).
    ASSERT_EQ(runVista("bench " + city + " --path " + dir +
                           "/p.csv --frames 4 --size 160x120 -q --near 10 "
                           "--modes full,near,raycast,osgimpostor,osglod,hybrid --out " +
                           dir + "/bench",
                       &out),
              0)
        << out;
    std::ifstream f(dir + "/bench/summary.json");
    auto j = nlohmann::json::parse(f);
    ASSERT_EQ(j["modes"].size(), 6u);
    const auto& m = j["modes"];
    auto tri = [&](const char* mode) { return m[mode]["triangles_median"].get<double>(); };
    EXPECT_LT(tri("near"), tri("full")) << "near draws fewer triangles than full";
    EXPECT_LT(tri("osglod"), tri("full")) << "osglod draws simplified chunks beyond 10 m";
    EXPECT_LT(tri("hybrid"), tri("full")) << "hybrid rasterises only the near field";
    const double lodPsnr = m["osglod"]["psnr_db_median"].get<double>();
    EXPECT_TRUE(std::isfinite(lodPsnr));
    EXPECT_LT(lodPsnr, kPsnrCapDb) << "osglod is lossy";
    EXPECT_GT(lodPsnr, 15.0) << "osglod still shows the city";
    EXPECT_GT(m["hybrid"]["pixels"]["ray_hit"]["mean_count"].get<double>(), 0.0) << "hybrid traced far pixels";
    EXPECT_EQ(m["raycast"]["rays_per_frame_median"].get<double>(), 160.0 * 120.0);
    EXPECT_EQ(m["osgimpostor"]["psnr_db_min"].get<double>(), kPsnrCapDb)
        << "a 300 m city lies within osgimpostor's threshold: geometry, no sprite (see mode_osgimpostor.h)";
    for (const char* mode : {"raycast", "hybrid"}) EXPECT_GT(m[mode]["setup_ms"]["bvh"].get<double>(), 0.0) << mode;
    EXPECT_FALSE(m["full"]["setup_ms"].contains("bvh"));
    EXPECT_GT(m["hybrid"]["setup_ms"]["height_grid"].get<double>(), 0.0);
    EXPECT_GT(m["osglod"]["setup_ms"]["simplify"].get<double>(), 0.0);
    EXPECT_GT(m["full"]["setup_ms"]["load"].get<double>(), 0.0);
    for (const char* mode : {"full", "near", "osgimpostor", "osglod", "hybrid"})
        EXPECT_TRUE(m[mode]["speedup_vs_raycast_median_of_ratios"].is_number()) << mode;
    EXPECT_GT(j["path_motion"]["metres_per_frame_median"].get<double>(), 0.0);
    expectSpeedupsFromCsv(dir + "/bench");
    EXPECT_TRUE(fs::exists(dir + "/bench/frame_time.png"));
    {  // Memory: the peak per phase (never falling), the up-front estimate beside it.
        const auto& mem = j["memory"];
        ASSERT_EQ(mem["phases"].size(), 3u);
        double last = 0;
        for (const auto& p : mem["phases"]) {
            EXPECT_GE(p["peak_rss_mb"].get<double>(), last) << p["phase"];
            EXPECT_GT(p["rss_mb"].get<double>(), 0.0);
            EXPECT_LE(p["rss_mb"].get<double>(), p["peak_rss_mb"].get<double>() + 1.0);
            last = p["peak_rss_mb"].get<double>();
        }
        EXPECT_EQ(mem["phases"][0]["phase"], "load");
        EXPECT_EQ(mem["peak_rss_mb"].get<double>(), last);
        EXPECT_GT(mem["estimate_mb"].get<double>(), 0.0);
        EXPECT_TRUE(mem["budget_gb"].is_null());
    }
    // A budget below the estimate stops the run up front: exit 2, the estimate in the message, no output.
    const double estimateGb = j["memory"]["estimate_mb"].get<double>() / 1024.0;
    EXPECT_EQ(runVista("bench " + city + " --path " + dir +
                           "/p.csv --frames 2 --size 160x120 -q --modes full,hybrid "
                           "--memory-budget " +
                           std::to_string(0.5 * estimateGb) + " --out " + dir + "/over",
                       &out),
              2)
        << out;
    EXPECT_NE(out.find("estimated to peak"), std::string::npos) << out;
    EXPECT_FALSE(fs::exists(dir + "/over"));
    EXPECT_EQ(runVista("view " + dir + "/missing.osgb --frames 1", &out), 2) << out;
    fs::remove_all(dir);
}

// `vista view --frames N --screenshot` works for every mode, and the viewer
// shows the bench's picture for the same camera and mode (--step: the bench's
// frames; window size = bench size; no HUD).
TEST(BenchCli, FarFieldFlagsRejectBadValues) {
    ASSERT_TRUE(fs::exists(VISTA_BINARY)) << "the vista binary is a build dependency of this test";
    std::string dir = tmpDir("badff"), out;
    std::string dummy = dir + "/dummy.osgb";
    std::ofstream(dummy) << "x";
    const std::pair<const char*, const char*> bad[] = {{"--near -5", "--near"},
                                                       {"--near abc", "--near"},
                                                       {"--horizon-grid -1", "--horizon-grid"},
                                                       {"--budget -7", "--budget"},
                                                       {"--horizon-grid 9000", "--horizon-grid"},
                                                       {"--far-step 3", "--far-step"},
                                                       {"--point-splat 5", "--point-splat"},
                                                       {"--point-splat wide", "[0.05, 4]"},
                                                       {"--memory-budget 0", "--memory-budget"},
                                                       {"--memory-budget lots", "--memory-budget"}};
    for (const auto& [args, flag] : bad) {
        EXPECT_EQ(runVista("bench " + dummy + " " + args + " --out " + dir + "/o", &out), 2) << args << ": " << out;
        EXPECT_NE(out.find(flag), std::string::npos) << args << ": " << out;
    }
    fs::remove_all(dir);
}

// Hybrid on a generated tiny city: per-mode pixel classes and stage times in
// summary.json; the far-field flags are accepted and recorded.
TEST(BenchCli, HybridPixelClassesAndOptions) {
    REQUIRE_DISPLAY();
    ASSERT_TRUE(fs::exists(VISTA_BINARY)) << "the vista binary is a build dependency of this test";
    std::string dir = tmpDir("hybrid"), out;
    std::string city = dir + "/tiny.osgb";
    ASSERT_EQ(runVista("gen --size 300 --seed 3 -q -o " + city, &out), 0) << out;
    struct Run {
        std::string flags;
        nlohmann::json near, budget, grid;
        bool cache;
        uint64_t triangleBudget;
    };
    const Run runs[] = {
        {"--near auto --budget 1000 --no-cache --horizon-grid 64", "auto", 1000, 64, false, 0},
        {"--near 60 --budget unlimited", 60.0, "unlimited", "auto", true, 0},
        {"--triangle-budget 5000", "auto", "unlimited", "auto", true, 5000},  // the default --near (unused: a budget)
    };
    for (size_t i = 0; i < 3; ++i) {
        const Run& r = runs[i];
        std::string o = dir + "/b" + std::to_string(i);
        ASSERT_EQ(
            runVista("bench " + city + " --seed 4 --duration 10 --frames 3 --size 160x120 -q --modes full,hybrid " +
                         r.flags + " --out " + o,
                     &out),
            0)
            << r.flags << ": " << out;
        std::ifstream f(o + "/summary.json");
        ASSERT_TRUE(f.good()) << r.flags;
        auto j = nlohmann::json::parse(f);
        const auto& opt = j["options"];
        EXPECT_EQ(opt["near_m"], r.near) << r.flags;
        EXPECT_EQ(opt["pixel_budget"], r.budget) << r.flags;
        EXPECT_EQ(opt["horizon_grid"], r.grid) << r.flags;
        EXPECT_EQ(opt["cache"], r.cache) << r.flags;
        EXPECT_EQ(opt["triangle_budget"], r.triangleBudget) << r.flags;
        if (r.triangleBudget > 0) {  // the nearest chunks up to the budget
            EXPECT_LT(j["modes"]["hybrid"]["triangles_median"].get<double>(),
                      j["modes"]["full"]["triangles_median"].get<double>());
        }
        ASSERT_TRUE(j["modes"]["hybrid"].contains("pixels")) << j["modes"]["hybrid"].dump();
        const auto& px = j["modes"]["hybrid"]["pixels"];
        double sum = 0;
        for (const char* cls : {"covered", "horizon_culled", "cache", "ray_hit", "ray_miss"}) {
            ASSERT_TRUE(px.contains(cls)) << cls;
            for (const char* k : {"min_pct", "mean_pct", "max_pct", "mean_count"})
                ASSERT_TRUE(px[cls][k].is_number()) << cls << "." << k;
            EXPECT_LE(px[cls]["min_pct"].get<double>(), px[cls]["mean_pct"].get<double>() + 1e-9) << cls;
            EXPECT_LE(px[cls]["mean_pct"].get<double>(), px[cls]["max_pct"].get<double>() + 1e-9) << cls;
            EXPECT_NEAR(px[cls]["mean_count"].get<double>(), px[cls]["mean_pct"].get<double>() / 100.0 * 160 * 120,
                        1e-6);
            sum += px[cls]["mean_pct"].get<double>();
        }
        EXPECT_NEAR(sum, 100.0, 0.1) << px.dump();
        if (!r.cache) { EXPECT_EQ(px["cache"]["max_pct"].get<double>(), 0.0); }
        // Stage times: every stage that ran has a mean and a run count within the frame count.
        const auto& stages = j["modes"]["hybrid"]["stages_ms"];
        ASSERT_TRUE(stages.contains("opacity")) << stages.dump();
        for (auto it = stages.begin(); it != stages.end(); ++it) {
            EXPECT_GE(it.value().get<double>(), 0.0) << it.key();
            int runsN = j["modes"]["hybrid"]["stage_runs"][it.key()].get<int>();
            EXPECT_GE(runsN, 1) << it.key();
            EXPECT_LE(runsN, 3) << it.key();
        }
        EXPECT_FALSE(j["modes"]["full"].contains("pixels"));  // full classifies nothing (documented)
    }

    fs::remove_all(dir);
}

TEST(BenchCli, SweepTableListsEveryCityWithItsTrianglesAndFullFirst) {
    REQUIRE_DISPLAY();
    std::string dir = tmpDir("sweep"), out;
    ASSERT_EQ(runVista("bench --sweep sizes=300,400 --seed 2 --frames 2 --size 160x120 --modes near,full --out " + dir +
                           "/s -q",
                       &out),
              0)
        << out;
    const auto top = nlohmann::json::parse(std::ifstream(dir + "/s/sweep.json"));
    const auto& j = top.at("rows");
    ASSERT_TRUE(j.is_array()) << top.dump();
    ASSERT_EQ(j.size(), 4u) << j.dump();  // 2 cities x 2 modes
    std::map<int, double> trianglesOf;
    for (size_t i = 0; i < j.size(); ++i) {
        const int size = j[i]["size_m"].get<int>();
        const double tris = j[i]["city_triangles"].get<double>();
        EXPECT_GT(tris, 1000.0) << "city " << size << ": its triangle count comes from the benched city";
        trianglesOf[size] = tris;
        EXPECT_EQ(j[i]["mode"].get<std::string>(), i % 2 == 0 ? "full" : "near")
            << "full is listed first for every city";
    }
    ASSERT_EQ(trianglesOf.size(), 2u);
    EXPECT_GT(trianglesOf[400], trianglesOf[300]) << "a larger city has more triangles";
}
