// Values the commands once took silently or with the wrong reason, through
// the CLI on a small generated city: an option given with an empty value
// (`--rig ""` ran a plain render, `--xodr-positions ""` wrote nothing) is
// refused naming it; --frames above the path's sample count is refused
// naming the count unless --allow-repeated-frames; a path sample outside the
// city between two rendered frames (it bends a LiDAR sweep) is refused naming
// the sample and the bounds; --lht where no lane is driven is refused; lane
// positions of a city whose lanes cannot be driven name the reason and the
// user's file, never a staged temporary; without a display the drawing
// commands exit 1 (docs/reference/cli.md) and leave nothing. Every refusal
// exits 2 with nothing written.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/common/run_vista.h"
#include "tests/common/temp_dir.h"

namespace vista {
namespace {

namespace fs = std::filesystem;
using test::CliRun;
using test::listTree;
using test::readBytes;
using test::runVista;
using test::TempDir;

// One small pinhole camera with depth only: ray cast, no display needed.
const char* const kRig = R"({"sensors": [{"name": "cam", "type": "pinhole",
   "intrinsics": {"width": 16, "height": 12, "fx": 12, "fy": 12, "cx": 7.5, "cy": 5.5}, "channels": ["depth"]}]})";

class ValuesCli : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        dir = new TempDir("vista_values");
        city = dir->file("city.osgb");
        pathCsv = dir->file("path.csv");
        rig = dir->file("rig.json");
        std::ofstream(rig) << kRig;
        CliRun r = runVista("gen --size 400 --seed 11 --detail 0 -q -o " + city);
        ASSERT_EQ(r.code, 0) << r.err;
        r = runVista("path " + city + " --seed 2 --duration 1 -o " + pathCsv);
        ASSERT_EQ(r.code, 0) << r.err;
    }
    static void TearDownTestSuite() {
        delete dir;
        dir = nullptr;
    }
    // The data lines of the shared path CSV (no header).
    static std::vector<std::string> pathLines() {
        std::istringstream in(readBytes(pathCsv));
        std::vector<std::string> lines;
        for (std::string l; std::getline(in, l);)
            if (!l.empty() && l.rfind("t_s", 0) != 0) lines.push_back(l);
        return lines;
    }
    // Runs `args`; expects exit 2, a message with every part of `wants`, and nothing new under tmp.
    void expectRefused(const std::string& args, std::initializer_list<std::string> wants) {
        const auto before = listTree(tmp.path());
        const CliRun r = runVista(args);
        EXPECT_EQ(r.code, 2) << args << "\n" << r.err;
        for (const std::string& w : wants) EXPECT_NE(r.err.find(w), std::string::npos) << args << "\n" << r.err;
        EXPECT_EQ(listTree(tmp.path()), before) << args;
    }
    static TempDir* dir;
    static std::string city, pathCsv, rig;
    TempDir tmp{"vista_values_out"};
};
TempDir* ValuesCli::dir = nullptr;
std::string ValuesCli::city, ValuesCli::pathCsv, ValuesCli::rig;

bool haveDisplay() {
    const char* d = std::getenv("DISPLAY");
    return d && *d;
}

TEST_F(ValuesCli, AnOptionGivenEmptyIsRefusedNamingIt) {
    const std::string out = tmp.file("out");
    // --rig "" once ran a plain (OpenGL) render; --xodr-positions "" wrote nothing and exited 0.
    expectRefused("render " + city + " --rig '' --frames 2 --out " + out, {"option --rig = ''", "empty"});
    expectRefused("path " + city + " -o " + tmp.file("p.csv") + " --xodr-positions ''",
                  {"option --xodr-positions = ''", "empty"});
    // Every other value: one rule in the option parsing of every command.
    expectRefused("path " + city + " -o ''", {"option --output = ''"});
    expectRefused("path '' -o " + tmp.file("p.csv"), {"argument city = ''"});
    expectRefused("export " + city + " --xodr ''", {"option --xodr = ''"});
    expectRefused("gen --size 400 -o " + tmp.file("c.osgb") + " --stats ''", {"option --stats = ''"});
    expectRefused("gen --size 400 -o " + tmp.file("c.osgb") + " --geojson ''", {"option --geojson = ''"});
    expectRefused("bake " + city + " -o " + tmp.file("b.osgb") + " --work ''", {"option --work = ''"});
    expectRefused("bench " + city + " --out " + out + " --path ''", {"option --path = ''"});
    expectRefused("bench " + city + " --out " + out + " --dump-rays ''", {"option --dump-rays = ''"});
    expectRefused("view " + city + " --frames 1 --screenshot ''", {"option --screenshot = ''"});
    expectRefused("view " + city + " --frames 1 --baked ''", {"option --baked = ''"});
    expectRefused("render " + city + " --out " + out + " --path ''", {"option --path = ''"});
}

TEST_F(ValuesCli, FramesBeyondThePathsSamplesAreRefusedUnlessAsked) {
    const size_t n = pathLines().size();
    ASSERT_GT(n, 10u);
    const std::string base = "render " + city + " --rig " + rig + " --path " + pathCsv + " -q";
    const std::string count = "the path has " + std::to_string(n) + " samples";
    expectRefused(base + " --frames " + std::to_string(n + 1) + " --out " + tmp.file("a"),
                  {"option --frames = " + std::to_string(n + 1), count, "--allow-repeated-frames"});
    expectRefused(base + " --frames 5000 --sampling consecutive --out " + tmp.file("a"), {count});
    // As many frames as samples: each sample once.
    CliRun r = runVista(base + " --frames " + std::to_string(n) + " --out " + tmp.file("all"));
    ASSERT_EQ(r.code, 0) << r.err;
    // Asked for: the repeats are rendered (times.txt lists every frame's time, samples repeating).
    r = runVista(base + " --frames " + std::to_string(2 * n) + " --allow-repeated-frames --out " + tmp.file("rep"));
    ASSERT_EQ(r.code, 0) << r.err;
    std::istringstream times(readBytes(tmp.file("rep") + "/times.txt"));
    std::vector<std::string> t;
    for (std::string l; std::getline(times, l);) t.push_back(l);
    ASSERT_EQ(t.size(), 2 * n);
    size_t repeated = 0;
    for (size_t i = 1; i < t.size(); ++i) repeated += t[i] == t[i - 1];
    EXPECT_GE(repeated, n - 1);
    // bench and view --step take the same rule.
    if (haveDisplay()) {
        expectRefused("bench " + city + " --path " + pathCsv + " --frames " + std::to_string(n + 1) +
                          " --modes full --size 32x24 -q --out " + tmp.file("b"),
                      {"option --frames", count});
        expectRefused("view " + city + " --path " + pathCsv + " --step --frames " + std::to_string(n + 1),
                      {"option --frames", count});
        expectRefused("view " + city + " --path " + pathCsv + " --frames 2 --allow-repeated-frames",
                      {"option --allow-repeated-frames", "only with --step"});
    }
}

TEST_F(ValuesCli, APathSampleOutsideTheCityIsRefusedEvenBetweenFrames) {
    // Sample 3 far east of the 400 m city; the two frames (samples 0 and the
    // last) stay inside, but a LiDAR sweep interpolates through sample 3.
    std::vector<std::string> lines = pathLines();
    std::ostringstream csv;
    csv << "t_s,x_m,y_m,z_m,heading_deg,pitch_deg\n";
    for (size_t i = 0; i < lines.size(); ++i) {
        if (i != 3) {
            csv << lines[i] << "\n";
            continue;
        }
        const size_t a = lines[i].find(','), b = lines[i].find(',', a + 1);
        const double x = std::stod(lines[i].substr(a + 1, b - a - 1));
        csv << lines[i].substr(0, a + 1) << x + 5000.0 << lines[i].substr(b) << "\n";
    }
    const std::string bad = dir->file("outside.csv");
    std::ofstream(bad) << csv.str();
    expectRefused("render " + city + " --rig " + rig + " --path " + bad + " --frames 2 -q --out " + tmp.file("o"),
                  {"path sample 3", "outside the city square", "grown by 50 m", "[-250, 250]"});
}

TEST_F(ValuesCli, LeftHandTrafficIsRefusedWhereNoLaneIsDriven) {
    for (const char* kind : {"walk", "fly"}) {
        expectRefused("path " + city + " --kind " + kind + " --lht -o " + tmp.file("p.csv"),
                      {"option --lht", "applies to car paths", std::string("--kind ") + kind});
        expectRefused(
            "render " + city + " --rig " + rig + " --kind " + kind + " --lht --frames 2 -q --out " + tmp.file("o"),
            {"option --lht", "car paths"});
    }
    expectRefused(
        "render " + city + " --rig " + rig + " --path " + pathCsv + " --lht --frames 2 -q --out " + tmp.file("o"),
        {"option --lht", "--path"});
    // A car path made here takes it.
    const CliRun r = runVista("path " + city + " --lht --duration 2 -o " + tmp.file("car.csv"));
    EXPECT_EQ(r.code, 0) << r.err;
}

TEST_F(ValuesCli, LanePositionsOfACityWithoutDrivableLanesNameTheReasonAndTheUsersFile) {
    // One one-way street between two dead ends: no lane can be driven on and
    // on, so the car follows the centre line and has no lane positions.
    const std::string osm = tmp.file("oneway.osm");
    std::ofstream(osm) << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<osm version=\"0.6\">\n"
                          "<node id=\"1\" lat=\"48.2000000\" lon=\"16.3700000\"/>\n"
                          "<node id=\"2\" lat=\"48.2000000\" lon=\"16.3760000\"/>\n"
                          "<way id=\"1\"><nd ref=\"1\"/><nd ref=\"2\"/><tag k=\"highway\" v=\"residential\"/>"
                          "<tag k=\"oneway\" v=\"yes\"/></way>\n</osm>\n";
    const std::string c = tmp.file("oneway.osgb");
    CliRun r = runVista("gen --osm " + osm + " --size 600 --detail 0 -q -o " + c);
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string pos = tmp.file("pos.csv");
    expectRefused("path " + c + " -o " + tmp.file("p.csv") + " --xodr-positions " + pos,
                  {"option --xodr-positions = '" + pos + "'", "no lane positions", "one-way dead ends"});
    r = runVista("path " + c + " -o " + tmp.file("p.csv") + " --xodr-positions " + pos);
    EXPECT_EQ(r.err.find(".stage"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("the path has none"), std::string::npos) << r.err;
    // The path itself is made.
    r = runVista("path " + c + " -o " + tmp.file("p.csv"));
    EXPECT_EQ(r.code, 0) << r.err;
}

TEST_F(ValuesCli, NoDisplayExitsOneAndLeavesNothing) {
    const std::string noDisplay = "env -u DISPLAY";
    const auto before = listTree(tmp.path());
    CliRun r = runVista("render " + city + " --frames 1 --size 32x24 -q --out " + tmp.file("r"), noDisplay);
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_NE(r.err.find("no X display"), std::string::npos) << r.err;
    r = runVista("bench " + city + " --frames 1 --size 32x24 --modes full -q --out " + tmp.file("b/c"), noDisplay);
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_NE(r.err.find("no X display"), std::string::npos) << r.err;
    r = runVista("view " + city + " --frames 1", noDisplay);
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_EQ(listTree(tmp.path()), before);
    // Bad input stays exit 2 without a display; a rig render casts rays and needs none.
    r = runVista("render " + city + " --frames 0 --out " + tmp.file("r"), noDisplay);
    EXPECT_EQ(r.code, 2) << r.err;
    r = runVista("render " + city + " --rig " + rig + " --frames 1 -q --out " + tmp.file("rig"), noDisplay);
    EXPECT_EQ(r.code, 0) << r.err;
}

}  // namespace
}  // namespace vista
