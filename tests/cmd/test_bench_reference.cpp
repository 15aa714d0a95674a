// `vista bench` runs side by side: --reference none (a run timed and sized alone,
// scored against nothing) and the order of the modes within a frame.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/common/run_vista.h"
#include "tests/common/temp_dir.h"
#include "tests/nodes/render/render_fixtures.h"

using namespace vista;
namespace fs = std::filesystem;

namespace {

// A 300 m city benched with ARGS (frames, size, modes...) into DIR/b; the run's exit status.
test::CliRun benchTinyCity(const std::string& dir, const std::string& args) {
    const std::string city = dir + "/tiny.osgb";
    test::CliRun r = test::runVista("gen --size 300 --seed 3 -q -o " + city);
    if (r.code != 0) return r;
    return test::runVista("bench " + city + " --seed 4 --size 96x64 -q " + args + " --out " + dir + "/b");
}

}  // namespace

// --reference none: a run timed alone. Only the listed modes run (no `full`),
// nothing is scored (empty PSNR cells, null medians, no quality plot, no worst
// frames) and the frame times are all there; with --sweep it is refused.
TEST(BenchCli, NoReferenceRunsTheListedModesAlone) {
    REQUIRE_DISPLAY();
    ASSERT_TRUE(fs::exists(VISTA_BINARY)) << "the vista binary is a build dependency of this test";
    test::TempDir tmp("vista_noref");
    const std::string dir = tmp.path();
    test::CliRun r = benchTinyCity(dir, "--frames 3 --modes near,hybrid --reference none");
    ASSERT_EQ(r.code, 0) << r.err;
    std::ifstream f(dir + "/b/summary.json");
    const auto j = nlohmann::json::parse(f);
    EXPECT_EQ(j["reference"], "none");
    ASSERT_EQ(j["modes"].size(), 2u);
    EXPECT_FALSE(j["modes"].contains("full"));
    for (const char* m : {"near", "hybrid"}) {
        EXPECT_TRUE(j["modes"][m]["psnr_db_median"].is_null()) << m;
        EXPECT_GT(j["modes"][m]["frame_ms_median"].get<double>(), 0.0) << m;
        EXPECT_FALSE(j["modes"][m].contains("speedup_vs_full_median_of_ratios")) << m;
    }
    EXPECT_TRUE(j["modes"]["hybrid"].contains("speedup_vs_near_median_of_ratios"));
    EXPECT_FALSE(fs::exists(dir + "/b/quality.png"));
    EXPECT_TRUE(fs::exists(dir + "/b/frame_time.png"));
    std::ifstream csv(dir + "/b/frames.csv");
    std::string line;
    std::getline(csv, line);  // header: ...,rays_cast,psnr_db,diff_fraction,...
    int rows = 0;
    while (std::getline(csv, line)) {
        ++rows;
        std::vector<std::string> cells;
        std::stringstream ss(line);
        for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
        ASSERT_GT(cells.size(), 11u) << line;
        EXPECT_EQ(cells[10], "") << line;
        EXPECT_EQ(cells[11], "") << line;
    }
    EXPECT_EQ(rows, 6);
    for (const auto& e : fs::directory_iterator(dir + "/b/images"))
        EXPECT_EQ(e.path().filename().string().rfind("worst", 0), std::string::npos) << e.path();
    r = test::runVista("bench --sweep sizes=300 --reference none --out " + dir + "/s");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("--reference none"), std::string::npos) << r.err;
    r = test::runVista("bench " + dir + "/tiny.osgb --reference nothing --out " + dir + "/o");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("'none'"), std::string::npos) << r.err;
}

// Reads frames.csv of a bench run: (frame, run_order) -> mode.
std::map<std::pair<int, int>, std::string> rendersOf(const std::string& csvPath) {
    std::ifstream csv(csvPath);
    std::string line;
    std::getline(csv, line);
    std::vector<std::string> header;
    {
        std::stringstream ss(line);
        for (std::string c; std::getline(ss, c, ',');) header.push_back(c);
    }
    const auto col = [&](const std::string& name) {
        return size_t(std::find(header.begin(), header.end(), name) - header.begin());
    };
    const size_t frameCol = col("frame"), modeCol = col("mode"), orderCol = col("run_order");
    EXPECT_LT(orderCol, header.size()) << line;
    std::map<std::pair<int, int>, std::string> renders;
    while (std::getline(csv, line)) {
        std::vector<std::string> cells;
        std::stringstream ss(line);
        for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
        if (cells.size() <= std::max(orderCol, modeCol)) {
            ADD_FAILURE() << line;
            continue;
        }
        const bool fresh =
            renders.emplace(std::make_pair(std::stoi(cells[frameCol]), std::stoi(cells[orderCol])), cells[modeCol])
                .second;
        EXPECT_TRUE(fresh) << "two renders in one place: " << line;
    }
    return renders;
}

// Within each frame, how often each mode ran right after each other: mode -> predecessor -> count.
std::map<std::string, std::map<std::string, int>> predecessorsWithinFrames(
    const std::map<std::pair<int, int>, std::string>& renders) {
    std::map<std::string, std::map<std::string, int>> pred;
    for (const auto& [key, mode] : renders) {
        const auto before = renders.find({key.first, key.second - 1});
        if (before != renders.end()) ++pred[mode][before->second];
    }
    return pred;
}

// The modes' order changes frame by frame: over 6 frames of 3 modes each
// frame holds each place once, each mode takes every place twice, and each
// mode runs right after each other mode twice (no mode always runs on what one
// other mode left in the caches).
TEST(BenchCli, TheModesOrderIsBalancedOverFrames) {
    REQUIRE_DISPLAY();
    ASSERT_TRUE(fs::exists(VISTA_BINARY)) << "the vista binary is a build dependency of this test";
    test::TempDir tmp("vista_order");
    const std::string dir = tmp.path();
    const test::CliRun r = benchTinyCity(dir, "--frames 6 --sampling consecutive --modes near,raycast");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto renders = rendersOf(dir + "/b/frames.csv");
    ASSERT_EQ(renders.size(), 18u);  // full (the reference), near, raycast over 6 frames
    std::map<int, std::set<int>> placesOfFrame;
    std::map<std::string, std::map<int, int>> placesOfMode;
    for (const auto& [key, mode] : renders) {
        placesOfFrame[key.first].insert(key.second);
        ++placesOfMode[mode][key.second];
    }
    for (const auto& [frame, places] : placesOfFrame) EXPECT_EQ(places, (std::set<int>{0, 1, 2})) << "frame " << frame;
    ASSERT_EQ(placesOfMode.size(), 3u);
    for (const auto& [mode, places] : placesOfMode)
        EXPECT_EQ(places, (std::map<int, int>{{0, 2}, {1, 2}, {2, 2}})) << mode;
    const auto pred = predecessorsWithinFrames(renders);
    for (const std::string mode : {"full", "near", "raycast"})
        for (const std::string other : {"full", "near", "raycast"})
            if (other != mode) {
                const auto it = pred.find(mode);
                const int n = it == pred.end() || !it->second.count(other) ? 0 : it->second.at(other);
                EXPECT_EQ(n, 2) << mode << " right after " << other;
            }
}

// With --also-clear each mode runs right next to its clear twin, and over the
// frames a mode and its twin follow the same renders within a frame (the
// mode's predecessors, with and without effects swapped, are its twin's) and
// go first in their pair equally often: neither side of the same-frame ratio
// is the one that more often runs after another mode's work.
TEST(BenchCli, AModeAndItsClearTwinFollowTheSameRenders) {
    REQUIRE_DISPLAY();
    ASSERT_TRUE(fs::exists(VISTA_BINARY)) << "the vista binary is a build dependency of this test";
    test::TempDir tmp("vista_twin_order");
    const std::string dir = tmp.path();
    const test::CliRun r =
        benchTinyCity(dir, "--frames 8 --sampling consecutive --modes near --effects night --also-clear");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto renders = rendersOf(dir + "/b/frames.csv");
    ASSERT_EQ(renders.size(), 32u);  // full, near and their twins over 8 frames
    const std::string kTwin = "+clear";
    const auto twinOf = [&](const std::string& m) {
        const bool twin = m.size() > kTwin.size() && m.compare(m.size() - kTwin.size(), kTwin.size(), kTwin) == 0;
        return twin ? m.substr(0, m.size() - kTwin.size()) : m + kTwin;
    };
    std::map<std::string, int> firstOfPair;
    for (const auto& [key, mode] : renders) {
        // The twin is the render right before or right after this one, in the same frame.
        const auto before = renders.find({key.first, key.second - 1}),
                   after = renders.find({key.first, key.second + 1});
        const bool twinBefore = before != renders.end() && before->second == twinOf(mode);
        EXPECT_TRUE(twinBefore || (after != renders.end() && after->second == twinOf(mode)))
            << "frame " << key.first << ": " << mode << " not next to its twin";
        if (!twinBefore) ++firstOfPair[mode];
    }
    const auto pred = predecessorsWithinFrames(renders);
    for (const std::string mode : {"full", "near"}) {
        std::map<std::string, int> swapped;
        if (pred.count(mode))
            for (const auto& [p, n] : pred.at(mode)) swapped[twinOf(p)] += n;
        const std::map<std::string, int> twin =
            pred.count(twinOf(mode)) ? pred.at(twinOf(mode)) : std::map<std::string, int>{};
        EXPECT_EQ(swapped, twin) << mode << ": its predecessors, twins swapped, are not its twin's";
        EXPECT_EQ(firstOfPair[mode], firstOfPair[twinOf(mode)]) << mode;
    }
    EXPECT_FALSE(pred.empty());
}
