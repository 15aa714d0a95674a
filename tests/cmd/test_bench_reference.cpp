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

// The modes run in an order that rotates frame by frame: frames.csv's run_order is, in every
// frame, each place once, and over as many frames as modes each mode takes every place once.
TEST(BenchCli, TheModesOrderRotatesFrameByFrame) {
    REQUIRE_DISPLAY();
    ASSERT_TRUE(fs::exists(VISTA_BINARY)) << "the vista binary is a build dependency of this test";
    test::TempDir tmp("vista_order");
    const std::string dir = tmp.path();
    const test::CliRun r = benchTinyCity(dir, "--frames 3 --sampling consecutive --modes near,raycast");
    ASSERT_EQ(r.code, 0) << r.err;
    std::ifstream csv(dir + "/b/frames.csv");
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
    ASSERT_LT(orderCol, header.size()) << line;
    std::map<int, std::set<int>> placesOfFrame;
    std::map<std::string, std::set<int>> placesOfMode;
    int rows = 0;
    while (std::getline(csv, line)) {
        std::vector<std::string> cells;
        std::stringstream ss(line);
        for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
        ASSERT_GT(cells.size(), orderCol) << line;
        const int place = std::stoi(cells[orderCol]);
        EXPECT_TRUE(placesOfFrame[std::stoi(cells[frameCol])].insert(place).second) << line;
        placesOfMode[cells[modeCol]].insert(place);
        ++rows;
    }
    EXPECT_EQ(rows, 9);  // full (the reference), near, raycast over 3 frames
    for (const auto& [frame, places] : placesOfFrame) EXPECT_EQ(places, (std::set<int>{0, 1, 2})) << "frame " << frame;
    ASSERT_EQ(placesOfMode.size(), 3u);
    for (const auto& [mode, places] : placesOfMode) EXPECT_EQ(places, (std::set<int>{0, 1, 2})) << mode;
}

// With --also-clear each mode runs right next to its clear twin, and over the
// frames a mode and its twin follow the same renders (the mode's predecessors,
// with and without effects swapped, are its twin's; the first render of the
// run has none): neither side of the same-frame ratio is the one that more
// often runs after another mode's work.
TEST(BenchCli, AModeAndItsClearTwinFollowTheSameRenders) {
    REQUIRE_DISPLAY();
    ASSERT_TRUE(fs::exists(VISTA_BINARY)) << "the vista binary is a build dependency of this test";
    test::TempDir tmp("vista_twin_order");
    const std::string dir = tmp.path();
    const test::CliRun r =
        benchTinyCity(dir, "--frames 8 --sampling consecutive --modes near --effects night --also-clear");
    ASSERT_EQ(r.code, 0) << r.err;
    std::ifstream csv(dir + "/b/frames.csv");
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
    ASSERT_LT(orderCol, header.size()) << line;
    std::map<std::pair<int, int>, std::string> renders;  // (frame, place) -> mode
    while (std::getline(csv, line)) {
        std::vector<std::string> cells;
        std::stringstream ss(line);
        for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
        ASSERT_GT(cells.size(), orderCol) << line;
        renders[{std::stoi(cells[frameCol]), std::stoi(cells[orderCol])}] = cells[modeCol];
    }
    ASSERT_EQ(renders.size(), 32u);  // full, near and their twins over 8 frames
    const std::string kTwin = "+clear";
    const auto twinOf = [&](const std::string& m) {
        const bool twin = m.size() > kTwin.size() && m.compare(m.size() - kTwin.size(), kTwin.size(), kTwin) == 0;
        return twin ? m.substr(0, m.size() - kTwin.size()) : m + kTwin;
    };
    std::map<std::string, std::map<std::string, int>> predecessors;  // mode -> its predecessor's mode -> count
    std::map<std::string, int> firstOfPair;
    std::string previous;
    for (const auto& [key, mode] : renders) {
        if (!previous.empty()) ++predecessors[mode][previous];
        if (!previous.empty() && previous != twinOf(mode)) ++firstOfPair[mode];
        previous = mode;
        // The twin is the render right before or right after this one, in the same frame.
        const auto before = renders.find({key.first, key.second - 1}),
                   after = renders.find({key.first, key.second + 1});
        EXPECT_TRUE((before != renders.end() && before->second == twinOf(mode)) ||
                    (after != renders.end() && after->second == twinOf(mode)))
            << "frame " << key.first << ": " << mode << " not next to its twin";
    }
    for (const std::string mode : {"full", "near"}) {
        std::map<std::string, int> swapped;
        for (const auto& [p, n] : predecessors[mode]) swapped[twinOf(p)] += n;
        const std::map<std::string, int>& twin = predecessors[twinOf(mode)];
        std::set<std::string> all;
        for (const auto& [p, n] : swapped) all.insert(p);
        for (const auto& [p, n] : twin) all.insert(p);
        for (const std::string& p : all) {
            const int a = swapped.count(p) ? swapped.at(p) : 0, b = twin.count(p) ? twin.at(p) : 0;
            EXPECT_LE(std::abs(a - b), 1) << mode << " after the twin of " << p << " " << a << " times, its twin after "
                                          << p << " " << b << " times";
        }
    }
    // Both sides go first in their pair about as often.
    EXPECT_LE(std::abs(firstOfPair["near"] - firstOfPair["near" + kTwin]), 1);
}
