// Where every command's outputs go, end to end: a device or FIFO as an
// output is written in place and stays what it was (a full device is exit 2
// naming the cause), one writer per output (a second vista process exits 2
// at once naming the lock), and every input and output path is resolved
// before any work (symbolic link loops, dangling links and unreachable
// directories: exit 2 naming the option, nothing left behind). Device nodes
// are private (mknod in the test's directory), never the system's.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "foundation/output_lock.h"
#include "runtime/scene/city_file.h"
#include "tests/bake/bake_fixtures.h"
#include "tests/common/run_vista.h"
#include "tests/common/special_files.h"
#include "tests/common/temp_dir.h"

namespace fs = std::filesystem;
using vista::OutputLock;
using vista::test::CliRun;
using vista::test::FifoReader;
using vista::test::isDevice;
using vista::test::isFifo;
using vista::test::kFullMinor;
using vista::test::kNoMknod;
using vista::test::kNullMinor;
using vista::test::listTree;
using vista::test::makeDevice;
using vista::test::readBytes;
using vista::test::runVista;
using vista::test::TempDir;

namespace {

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// The names in `dir` (not recursive: links that loop are listed, never followed).
std::set<std::string> names(const std::string& dir) {
    std::set<std::string> out;
    std::error_code ec;
    for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
        out.insert(it->path().filename().string());
    return out;
}

bool hasDisplay() {
    const char* d = std::getenv("DISPLAY");
    return d && *d;
}

constexpr const char* kNoDisplay = "no DISPLAY: run the tests under xvfb-run -a";

// One small generated city and a path over it, shared by the tests.
class OutputPlaces : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        ref = new TempDir("vista_places_ref");
        ASSERT_EQ(runVista("gen --size 300 --seed 3 -q -o " + city()).code, 0);
        ASSERT_EQ(runVista("path " + city() + " --duration 2 -o " + pathCsv()).code, 0);
    }
    static void TearDownTestSuite() {
        delete ref;
        ref = nullptr;
    }
    static std::string city() { return ref->file("city.osgb"); }
    static std::string pathCsv() { return ref->file("path.csv"); }
    static inline TempDir* ref = nullptr;
    TempDir dir{"vista_places"};

    // `null` and `full` device nodes named so in `dir` (false: mknod not permitted).
    bool devices(const std::string& null, const std::string& full) {
        return makeDevice(dir.file(null), kNullMinor) && makeDevice(dir.file(full), kFullMinor);
    }
    // Exit 0 into the null node, which stays a device.
    void intoNull(const std::string& args, const std::string& node) {
        const CliRun r = runVista(args);
        EXPECT_EQ(r.code, 0) << args << "\n" << r.err;
        EXPECT_TRUE(isDevice(dir.file(node), kNullMinor)) << args << ": " << node << " was replaced";
    }
    // Exit 2 naming the full node and the cause; it stays a device; `absent` (a regular output of the run) not written.
    void intoFull(const std::string& args, const std::string& node, const std::string& absent = "") {
        const CliRun r = runVista(args);
        EXPECT_EQ(r.code, 2) << args << "\n" << r.err;
        EXPECT_TRUE(has(r.err, "No space left on device") && has(r.err, dir.file(node))) << args << "\n" << r.err;
        EXPECT_TRUE(isDevice(dir.file(node), kFullMinor)) << args << ": " << node << " was replaced";
        if (!absent.empty()) { EXPECT_FALSE(fs::exists(dir.file(absent))) << args << ": " << absent << " written"; }
    }
};

}  // namespace

// --- Devices and FIFOs as outputs: written in place, never replaced ----------------------------

TEST_F(OutputPlaces, PathWritesItsCsvAndLanePositionsIntoDevicesAndPipes) {
    if (!devices("null", "full")) GTEST_SKIP() << kNoMknod;
    const std::string path = "path " + city() + " --duration 2 ";
    intoNull(path + "-o " + dir.file("null"), "null");
    intoFull(path + "-o " + dir.file("full"), "full");
    intoNull(path + "-o " + dir.file("a.csv") + " --xodr-positions " + dir.file("null"), "null");
    EXPECT_TRUE(fs::exists(dir.file("a.csv")));
    intoFull(path + "-o " + dir.file("b.csv") + " --xodr-positions " + dir.file("full"), "full", "b.csv");
    // A FIFO receives the bytes a regular file would hold.
    FifoReader reader(dir.file("pipe"));
    ASSERT_TRUE(reader.made());
    ASSERT_EQ(runVista(path + "-o " + dir.file("pipe")).code, 0);
    EXPECT_EQ(reader.finish(), readBytes(dir.file("a.csv")));
    EXPECT_TRUE(isFifo(dir.file("pipe")));
}

TEST_F(OutputPlaces, ExportWritesItsOpenDriveIntoDevicesInPlace) {
    if (!devices("null.xodr", "full.xodr")) GTEST_SKIP() << kNoMknod;
    intoNull("export -q " + city() + " --xodr " + dir.file("null.xodr"), "null.xodr");
    intoFull("export -q " + city() + " --xodr " + dir.file("full.xodr"), "full.xodr");
}

TEST_F(OutputPlaces, GenWritesItsCityStatsRoadsAndStreetsIntoDevicesInPlace) {
    if (!devices("null.osgb", "full.osgb") || !makeDevice(dir.file("null.xodr"), kNullMinor) ||
        !makeDevice(dir.file("full.xodr"), kFullMinor) || !makeDevice(dir.file("null"), kNullMinor) ||
        !makeDevice(dir.file("full"), kFullMinor))
        GTEST_SKIP() << kNoMknod;
    const std::string gen = "gen --size 300 --seed 3 -q ";
    // One null device for two outputs is no aliasing.
    intoNull(gen + "-o " + dir.file("null.osgb") + " --xodr " + dir.file("null.xodr") + " --stats " + dir.file("null") +
                 " --geojson " + dir.file("null"),
             "null.osgb");
    EXPECT_TRUE(isDevice(dir.file("null.xodr"), kNullMinor) && isDevice(dir.file("null"), kNullMinor));
    intoFull(gen + "-o " + dir.file("full.osgb"), "full.osgb");
    intoFull(gen + "-o " + dir.file("c.osgb") + " --stats " + dir.file("full"), "full", "c.osgb");
    intoFull(gen + "-o " + dir.file("c.osgb") + " --xodr " + dir.file("full.xodr"), "full.xodr", "c.osgb");
    intoFull(gen + "-o " + dir.file("c.osgb") + " --geojson " + dir.file("full"), "full", "c.osgb");
}

TEST_F(OutputPlaces, BakeWritesItsBakedCityAndStatsIntoDevicesInPlace) {
    if (!devices("null.osgb", "full.osgb") || !makeDevice(dir.file("full.json"), kFullMinor)) GTEST_SKIP() << kNoMknod;
    ASSERT_TRUE(vista::writeCityFile(vista::makeBakeCity(), dir.file("city.osgb")).isOk());
    const std::string bake = "bake " + dir.file("city.osgb") + " --out-size 120 --min-triangles 1 -q --placement all ";
    intoNull(bake + "-o " + dir.file("null.osgb") + " --work " + dir.file("w"), "null.osgb");
    intoFull(bake + "-o " + dir.file("full.osgb") + " --work " + dir.file("w"), "full.osgb");
    intoFull(bake + "-o " + dir.file("b.osgb") + " --stats " + dir.file("full.json") + " --work " + dir.file("w"),
             "full.json", "b.osgb");
}

TEST_F(OutputPlaces, ViewWritesItsScreenshotIntoDevicesInPlace) {
    if (!hasDisplay()) GTEST_SKIP() << kNoDisplay;
    if (!devices("null.png", "full.png")) GTEST_SKIP() << kNoMknod;
    const std::string view = "view " + city() + " --size 64x48 --frames 1 --screenshot ";
    intoNull(view + dir.file("null.png"), "null.png");
    intoFull(view + dir.file("full.png"), "full.png");
}

TEST_F(OutputPlaces, DirectoryOutputsRefuseDevicesAndPipes) {
    if (!makeDevice(dir.file("null"), kNullMinor)) GTEST_SKIP() << kNoMknod;
    ASSERT_EQ(::mkfifo(dir.file("pipe").c_str(), 0644), 0);
    for (const std::string& node : {dir.file("null"), dir.file("pipe")}) {
        for (const std::string& args : {"bench " + city() + " --path " + pathCsv() + " --frames 1 --out " + node,
                                        "render " + city() + " --path " + pathCsv() + " --frames 1 --out " + node}) {
            const CliRun r = runVista(args);
            EXPECT_EQ(r.code, 2) << args << "\n" << r.err;
            EXPECT_TRUE(has(r.err, "--out") && has(r.err, "not a directory")) << args << "\n" << r.err;
        }
    }
    EXPECT_TRUE(isDevice(dir.file("null"), kNullMinor) && isFifo(dir.file("pipe")));
    EXPECT_EQ(listTree(dir.path()), (std::set<std::string>{"null", "pipe"}));
}

// --- One writer per output ---------------------------------------------------------------------

// Each command, while another process holds an output's lock: exit 2 at once
// naming the option and the lock file, nothing written, the lock left alone.
TEST_F(OutputPlaces, EveryCommandRefusesAnOutputAnotherProcessIsWriting) {
    const std::string p = " --path " + pathCsv() + " --frames 1 --size 64x48 -q ";
    struct Case {
        std::string args, option, output;
        bool display;
    };
    const Case cases[] = {
        {"path " + city() + " -o " + dir.file("p.csv"), "-o", dir.file("p.csv"), false},
        {"path " + city() + " -o " + dir.file("p2.csv") + " --xodr-positions " + dir.file("pos.csv"),
         "--xodr-positions", dir.file("pos.csv"), false},
        {"export -q " + city() + " --xodr " + dir.file("r.xodr"), "--xodr", dir.file("r.xodr"), false},
        {"gen --size 300 -q -o " + dir.file("c.osgb"), "-o", dir.file("c.osgb"), false},
        {"gen --size 300 -q -o " + dir.file("c2.osgb") + " --stats " + dir.file("s.json"), "--stats",
         dir.file("s.json"), false},
        {"gen --size 1000 --region-size 500 -q -o " + dir.file("c.paged"), "-o", dir.file("c.paged"), false},
        {"bake -q " + city() + " -o " + dir.file("b.osgb"), "--output", dir.file("b.osgb"), false},
        {"bake -q " + city() + " -o " + dir.file("b2.osgb") + " --work " + dir.file("work"), "--work", dir.file("work"),
         false},
        {"bench " + city() + p + "--out " + dir.file("bench"), "--out", dir.file("bench"), true},
        {"render " + city() + p + "--out " + dir.file("gt"), "--out", dir.file("gt"), true},
        {"view " + city() + " --size 64x48 --frames 1 --screenshot " + dir.file("v.png"), "--screenshot",
         dir.file("v.png"), true},
    };
    for (const Case& c : cases) {
        if (c.display && !hasDisplay()) continue;  // refused before the display is opened, but run as a real one would
        auto held = OutputLock::acquire("test", c.output, false);
        ASSERT_TRUE(held.isOk()) << held.status().message();
        const CliRun r = runVista(c.args);
        EXPECT_EQ(r.code, 2) << c.args << "\n" << r.err;
        EXPECT_TRUE(has(r.err, c.option) && has(r.err, "another vista process") && has(r.err, c.output + ".lock"))
            << c.args << "\n"
            << r.err;
        EXPECT_EQ(listTree(dir.path()), std::set<std::string>{fs::path(c.output).filename().string() + ".lock"})
            << c.args;
    }
    EXPECT_EQ(listTree(dir.path()), std::set<std::string>{});  // every lock file went with its holder
}

// Two paged generations of different seeds into one directory at the same
// time: exactly one runs, the other exits 2 before doing any work; the city
// left is the winner's alone, whole (2 x 2 regions at facade detail 1: a run
// lasts seconds, long beyond both processes' start).
TEST_F(OutputPlaces, TwoPagedGensRacingOnOneDirectoryNeverMix) {
    const std::string out = dir.file("race.paged");
    CliRun runs[2];
    std::thread t[2];
    for (int k = 0; k < 2; ++k)
        t[k] = std::thread([&, k] {
            runs[k] = runVista("gen --size 1000 --detail 1 --region-size 500 -q --seed " + std::to_string(k + 1) +
                               " -o " + out);
        });
    for (auto& th : t) th.join();
    const int winners = (runs[0].code == 0) + (runs[1].code == 0);
    ASSERT_EQ(winners, 1) << runs[0].code << " " << runs[0].err << "\n" << runs[1].code << " " << runs[1].err;
    const int winner = runs[0].code == 0 ? 0 : 1;
    const CliRun& loser = runs[1 - winner];
    EXPECT_EQ(loser.code, 2);
    EXPECT_TRUE(has(loser.err, "another vista process") && has(loser.err, out + ".lock")) << loser.err;
    EXPECT_TRUE(has(readBytes(out + "/manifest.json"), "\"seed\": " + std::to_string(winner + 1)));
    // Every region the manifest lists checks out: a rerun of the winner's seed reuses them all.
    const CliRun again = runVista("gen --size 1000 --detail 1 --region-size 500 --seed " + std::to_string(winner + 1) +
                                  " -o " + out + " --stats " + dir.file("again.json"));
    ASSERT_EQ(again.code, 0) << again.err;
    EXPECT_TRUE(has(readBytes(dir.file("again.json")), "\"regions_generated\": 0"))
        << readBytes(dir.file("again.json"));
    EXPECT_FALSE(fs::exists(out + ".lock"));
}

// Two renders racing on one --out: the second exits 2 at once, the first
// finishes; no OUT.partial is left behind.
TEST_F(OutputPlaces, TwoRendersRacingOnOneOutExitAtOnceAndLeaveNoPartial) {
    if (!hasDisplay()) GTEST_SKIP() << kNoDisplay;
    const std::string out = dir.file("gt");
    CliRun runs[2];
    std::thread t[2];
    for (int k = 0; k < 2; ++k)
        t[k] = std::thread([&, k] {
            runs[k] =
                runVista("render " + city() + " --path " + pathCsv() + " --frames 12 --size 96x64 -q --out " + out);
        });
    for (auto& th : t) th.join();
    ASSERT_EQ((runs[0].code == 0) + (runs[1].code == 0), 1) << runs[0].code << " " << runs[0].err << "\n"
                                                            << runs[1].code << " " << runs[1].err;
    const CliRun& loser = runs[0].code == 0 ? runs[1] : runs[0];
    EXPECT_EQ(loser.code, 2);
    EXPECT_TRUE(has(loser.err, "--out") && has(loser.err, "another vista process")) << loser.err;
    EXPECT_TRUE(fs::is_directory(out));
    EXPECT_EQ(listTree(dir.path()).count("gt.partial"), 0u);
    EXPECT_FALSE(fs::exists(out + ".lock"));
}

// --- Every path resolved up front --------------------------------------------------------------

// A symbolic link loop or a dangling link as the city, and unreachable
// outputs: every command exits 2 naming the option (no abort), nothing left.
TEST_F(OutputPlaces, EveryCommandRefusesLoopsDanglingLinksAndUnreachableOutputsBeforeAnyWork) {
    ASSERT_EQ(::symlink("loop_b", dir.file("loop_a").c_str()), 0);
    ASSERT_EQ(::symlink("loop_a", dir.file("loop_b").c_str()), 0);
    ASSERT_EQ(::symlink("nowhere", dir.file("dangling").c_str()), 0);
    std::ofstream(dir.file("file")) << "x";
    const std::string loop = dir.file("loop_a"), dangling = dir.file("dangling");
    const std::set<std::string> before = names(dir.path());
    const std::string p = " --path " + pathCsv() + " --frames 2 --size 64x48 -q ";
    struct Case {
        std::string args;
        std::vector<std::string> parts;
    };
    const Case cases[] = {
        // The city (or parameters) is a loop or dangles.
        {"gen --params " + loop + " -q -o " + dir.file("c.osgb"), {"--params", "symbolic link loop"}},
        {"path " + loop + " -o " + dir.file("p.csv"), {"city", "symbolic link loop"}},
        {"path " + dangling + " -o " + dir.file("p.csv"), {"city", "dangling symbolic link"}},
        {"export " + loop + " --xodr " + dir.file("r.xodr"), {"city", "symbolic link loop"}},
        {"bake -q " + loop + " -o " + dir.file("b.osgb"), {"city", "symbolic link loop"}},
        {"view " + loop + " --frames 1", {"city", "symbolic link loop"}},
        {"bench " + loop + p + "--out " + dir.file("bench"), {"city", "symbolic link loop"}},
        {"render " + loop + p + "--out " + dir.file("gt"), {"city", "symbolic link loop"}},
        {"render " + city() + " --path " + loop + " --frames 2 -q --out " + dir.file("gt"), {"--path", "loop"}},
        // Outputs that loop, dangle or cannot be reached.
        {"gen --size 300 -q -o " + dir.file("file/c.osgb"), {"-o", "not a directory"}},
        {"gen --size 300 -q -o " + dir.file("c.osgb") + " --stats " + loop, {"--stats", "symbolic link loop"}},
        {"path " + city() + " -o " + dangling, {"-o", "dangling symbolic link"}},
        {"export " + city() + " --xodr " + loop + "/r.xodr", {"--xodr", "symbolic link loop"}},
        {"bake -q " + city() + " -o " + dir.file("b.osgb") + " --work " + loop, {"--work", "symbolic link loop"}},
        {"view " + city() + " --frames 1 --screenshot " + dangling, {"--screenshot", "dangling"}},
        {"bench " + city() + p + "--out " + dangling, {"--out", "dangling symbolic link"}},
        {"bench " + city() + p + "--out " + loop + "/deep", {"--out", "symbolic link loop"}},
        {"render " + city() + p + "--out " + dangling, {"--out", "dangling symbolic link"}},
        {"render " + city() + p + "--out " + loop, {"--out", "symbolic link loop"}},
    };
    for (const Case& c : cases) {
        const CliRun r = runVista(c.args);
        EXPECT_EQ(r.code, 2) << c.args << "\n" << r.err;
        for (const std::string& part : c.parts)
            EXPECT_TRUE(has(r.err, part)) << c.args << ": '" << part << "' not in\n" << r.err;
        EXPECT_EQ(names(dir.path()), before) << c.args;
    }
}
