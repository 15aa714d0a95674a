// Streaming a paged city in `vista render`, `vista bench` and `vista view`
// (the default; cmd/paged_stream.h): a paged city streams with no option
// (--paged-preload preloads) and the runs count the frames that drew a
// region below the detail its distance asks for; render's ground truth of a
// streamed city that waits is the preloaded run's, byte for byte, and
// resumes to the bytes of an uninterrupted run; a streamed render and a
// scripted viewer drive load and unload regions along the path; the
// viewer's streamed hybrid shows render's streamed hybrid frame; a stream
// that cannot stream (unreadable region files, a region of another
// generation, a budget that cannot hold the regions at the camera) exits 2
// naming the files or the budget they need; bad combinations exit 2 naming
// the flag. Rendering tests: run under `xvfb-run -a`.
#include <gtest/gtest.h>

#include <filesystem>
#include <cstdint>
#include <fstream>
#include <algorithm>
#include <regex>
#include <string>

#include <nlohmann/json.hpp>

#include "runtime/engine/image.h"
#include "runtime/engine/metrics.h"
#include "runtime/scene/paged_load.h"
#include "tests/common/run_vista.h"
#include "tests/common/small_paged_city.h"
#include "tests/common/temp_dir.h"

namespace fs = std::filesystem;
using vista::test::CliRun;
using vista::test::readBytes;
using vista::test::runVista;
using vista::test::TempDir;

namespace {

// A drive that leaves regions behind: full detail within 100 m, coarse within 400 m.
const std::string kNear = " --paged-radius 100 --paged-far 400";

nlohmann::json readJson(const std::string& path) { return nlohmann::json::parse(readBytes(path)); }

class PagedStream : public vista::test::SmallPagedCity {};

// The number before `what` in the viewer's "paged stream:" line (-1 if absent).
int streamCount(const std::string& err, const std::string& what) {
    std::smatch m;
    if (!std::regex_search(err, m, std::regex("([0-9]+) " + what))) return -1;
    return std::stoi(m[1]);
}

}  // namespace

TEST_F(PagedStream, AStreamedRenderThatWaitsWritesThePreloadedGroundTruth) {
    // Every region within reach of every frame: the streamed city holds the preloaded regions.
    const std::string run = " --seed 4 --frames 3 --size 160x120 -q --paged-radius 5000";
    CliRun r = runVista("render " + dir() + run + " --paged-preload --out " + tmp.file("pre"));
    ASSERT_EQ(r.code, 0) << r.err;
    r = runVista("render " + dir() + run + " --paged-wait --paged-prefetch 2 --out " + tmp.file("str"));
    ASSERT_EQ(r.code, 0) << r.err;
    for (int f = 0; f < 3; ++f) {
        const std::string name = "00000" + std::to_string(f);
        for (const std::string& file :
             {"rgb/" + name + ".png", "depth/" + name + ".npy", "semantic/" + name + ".png"}) {
            ASSERT_TRUE(fs::exists(tmp.file("pre/" + file))) << file;
            EXPECT_TRUE(readBytes(tmp.file("pre/" + file)) == readBytes(tmp.file("str/" + file))) << file;
        }
        // Instance ids of a paged city are numbered per region: not written.
        EXPECT_FALSE(fs::exists(tmp.file("str/instance/" + name + ".npy")));
    }
    EXPECT_TRUE(readBytes(tmp.file("pre/cameras.json")) == readBytes(tmp.file("str/cameras.json")));
    const auto s = readJson(tmp.file("str/summary.json"));
    ASSERT_TRUE(s["paged"].contains("stream")) << s.dump();
    const auto& st = s["paged"]["stream"];
    EXPECT_TRUE(st["frames_deterministic"].get<bool>());
    EXPECT_EQ(st["loads"].get<int>(), 9);
    EXPECT_EQ(st["unloads"].get<int>(), 0);
    EXPECT_EQ(st["bytes_read"].get<uint64_t>(),
              readJson(tmp.file("pre/summary.json"))["paged"]["bytes_loaded"].get<uint64_t>());
    EXPECT_EQ(s["channels"].get<std::string>(), "rgb,depth,semantic");
}

// The streamed hybrid in render: with every region within reach, a waiting run draws what the
// preloaded run draws (a fixed split and a cache that never pauses: no frame follows timings).
TEST_F(PagedStream, AStreamedHybridRenderThatWaitsWritesThePreloadedFrames) {
    const std::string run =
        " --seed 4 --frames 3 --size 160x120 -q --channels rgb --paged-radius 5000 --mode hybrid --near 100 "
        "--cache-always";
    CliRun r = runVista("render " + dir() + run + " --paged-preload --out " + tmp.file("pre"));
    ASSERT_EQ(r.code, 0) << r.err;
    r = runVista("render " + dir() + run + " --paged-wait --out " + tmp.file("str"));
    ASSERT_EQ(r.code, 0) << r.err;
    for (int f = 0; f < 3; ++f) {
        const std::string file = "rgb/00000" + std::to_string(f) + ".png";
        ASSERT_TRUE(fs::exists(tmp.file("pre/" + file))) << file;
        EXPECT_TRUE(readBytes(tmp.file("pre/" + file)) == readBytes(tmp.file("str/" + file))) << file;
    }
    // Every region level once, and the near field's chunks as parts of their own for the full
    // regions within the hybrid's near band.
    const auto st = readJson(tmp.file("str/summary.json"))["paged"]["stream"];
    EXPECT_EQ(st["loads"].get<int>() - st["chunk_part_loads"].get<int>(), 9);
    EXPECT_GT(st["chunk_part_loads"].get<int>(), 0);
    EXPECT_GT(st["chunk_radius_m"].get<double>(), 100.0);
}

TEST_F(PagedStream, AStreamedRenderLoadsAndUnloadsAlongThePath) {
    const std::string run = " --seed 4 --frames 12 --size 160x120 -q --channels rgb,depth" + kNear;
    for (const char* out : {"w1", "w2"}) {
        const CliRun r = runVista("render " + dir() + run + " --paged-wait --out " + tmp.file(out));
        ASSERT_EQ(r.code, 0) << r.err;
    }
    // Frames that wait do not depend on the load timing.
    for (int f = 0; f < 12; ++f) {
        char name[32];
        std::snprintf(name, sizeof name, "%06d", f);
        for (const std::string& file : {std::string("rgb/") + name + ".png", std::string("depth/") + name + ".npy"})
            EXPECT_TRUE(readBytes(tmp.file("w1/" + file)) == readBytes(tmp.file("w2/" + file))) << file;
    }
    const auto st = readJson(tmp.file("w1/summary.json"))["paged"]["stream"];
    EXPECT_GT(st["loads"].get<int>(), 3);
    EXPECT_GT(st["unloads"].get<int>(), 0);
    EXPECT_GT(st["frames_with_arrivals"].get<int>(), 0);
    EXPECT_GE(st["bytes_read"].get<uint64_t>(), st["peak_resident_file_bytes"].get<uint64_t>());
    // Without waiting, the first frame still has its regions; the rest is timing.
    const CliRun r = runVista("render " + dir() + run + " --paged-stream --out " + tmp.file("nw"));
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_FALSE(readJson(tmp.file("nw/summary.json"))["paged"]["stream"]["frames_deterministic"].get<bool>());
}

TEST_F(PagedStream, AStreamedRenderResumesToTheUninterruptedBytes) {
    const std::string run = " --seed 4 --frames 6 --size 160x120 -q --channels rgb,depth --paged-wait" + kNear;
    CliRun r = runVista("render " + dir() + run + " --out " + tmp.file("ref"));
    ASSERT_EQ(r.code, 0) << r.err;
    r = runVista("render " + dir() + run + " --out " + tmp.file("res"), "VISTA_RENDER_KILL_AFTER_FRAMES=2");
    ASSERT_NE(r.code, 0) << "the hook kills the run";
    // The reach is part of the work directory's manifest: another one does not resume it.
    r = runVista("render " + dir() + run + " --paged-prefetch 1 --out " + tmp.file("res"));
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("other parameters"), std::string::npos) << r.err;
    r = runVista("render " + dir() + run + " --out " + tmp.file("res"));
    ASSERT_EQ(r.code, 0) << r.err;
    for (int f = 0; f < 6; ++f) {
        char name[32];
        std::snprintf(name, sizeof name, "%06d", f);
        for (const std::string& file : {std::string("rgb/") + name + ".png", std::string("depth/") + name + ".npy"})
            EXPECT_TRUE(readBytes(tmp.file("ref/" + file)) == readBytes(tmp.file("res/" + file))) << file;
    }
    EXPECT_EQ(readJson(tmp.file("res/summary.json"))["frames_resumed"].get<int>(), 2);
}

TEST_F(PagedStream, AScriptedViewerDriveStreamsTheCity) {
    const std::string run = " --seed 4 --step --frames 12 --size 160x120 --no-hud" + kNear;
    CliRun r = runVista("view " + dir() + run + " --paged-wait");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("paged city: streaming its 9 regions"), std::string::npos) << r.err;
    ASSERT_NE(r.err.find("paged stream:"), std::string::npos) << r.err;
    EXPECT_GT(streamCount(r.err, "loads"), 3) << r.err;
    EXPECT_GT(streamCount(r.err, "unloads"), 0) << r.err;
    // Every frame waited for its regions: none drew a coarse level where full detail was wanted.
    EXPECT_EQ(streamCount(r.err, "drew a region"), 0) << r.err;
    // Without waiting the viewer drives on (the first frame waits for the start's regions).
    r = runVista("view " + dir() + run + " --paged-stream --mode raycast --paged-prefetch 8");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_GT(streamCount(r.err, "loads"), 0) << r.err;
    EXPECT_GE(streamCount(r.err, "of 12 frames waited"), 1) << r.err;
}

// The viewer streams the hybrid as render does: with the regions around each frame waited for,
// its last frame is render's last frame of the same drive (the viewer face draws the split node
// and far-field node over the stream's resident chunks).
TEST_F(PagedStream, AScriptedViewerHybridDriveShowsTheStreamedFrames) {
    const std::string run = " --seed 4 --frames 4 --size 160x120 --mode hybrid --near 100 --cache-always --paged-wait";
    CliRun r = runVista("render " + dir() + run + " -q --channels rgb --out " + tmp.file("gt"));
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string png = tmp.file("view.png");
    r = runVista("view " + dir() + run + " --step --no-hud --screenshot " + png);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(streamCount(r.err, "drew a region"), 0) << r.err;
    EXPECT_GT(streamCount(r.err, "triangles"), 0) << "the split node drew the stream's chunks near the camera\n"
                                                  << r.err;
    auto view = vista::readPng(png);
    auto frame = vista::readPng(tmp.file("gt/rgb/000003.png"));
    ASSERT_TRUE(view.isOk() && frame.isOk());
    ASSERT_EQ(view.value().width, frame.value().width);
    ASSERT_EQ(view.value().height, frame.value().height);
    EXPECT_GE(vista::lumaPsnr(view.value(), frame.value()), 50.0) << "the viewer's streamed hybrid frame differs";
}

// With no option a paged city streams in bench, render and view; the first frame waits for the
// regions at its camera (none below the detail asked for when every region is within reach of
// every frame), and summary.json, stderr and the viewer's exit line count such frames.
TEST_F(PagedStream, APagedCityStreamsByDefault) {
    const std::string run = " --seed 4 --frames 3 --size 160x120 --paged-radius 5000";
    // A drive at the path's own speed (--pace).
    CliRun r =
        runVista("bench " + dir() + run + " -q --modes raycast --sampling consecutive --pace --out " + tmp.file("b"));
    ASSERT_EQ(r.code, 0) << r.err;
    auto s = readJson(tmp.file("b/summary.json"));
    EXPECT_TRUE(s["paced"].get<bool>());
    ASSERT_TRUE(s["paged"].contains("stream")) << s.dump();
    EXPECT_FALSE(s["paged"].contains("regions_loaded")) << "nothing preloaded";
    EXPECT_EQ(s["paged"]["stream"]["frames_below_detail"].get<int>(), 0) << s["paged"].dump();
    EXPECT_EQ(s["paged"]["stream"]["frames_below_detail_after_first_second"].get<int>(), 0);
    EXPECT_NE(r.err.find("0 of 3 frames drew a region below the detail its distance asks for"), std::string::npos)
        << r.err;
    // render streams and every frame waits: its ground truth does not follow load timing.
    r = runVista("render " + dir() + run + " -q --channels rgb --out " + tmp.file("r"));
    ASSERT_EQ(r.code, 0) << r.err;
    s = readJson(tmp.file("r/summary.json"));
    ASSERT_TRUE(s["paged"].contains("stream")) << s.dump();
    EXPECT_TRUE(s["paged"]["stream"]["frames_deterministic"].get<bool>());
    EXPECT_EQ(s["paged"]["stream"]["frames_below_detail"].get<int>(), 0);
    r = runVista("view " + dir() + run + " --step --no-hud");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("paged city: streaming its 9 regions"), std::string::npos) << r.err;
    EXPECT_EQ(streamCount(r.err, "drew a region"), 0) << r.err;
    // --paged-preload: the regions around the path before the first frame, no stream.
    r = runVista("bench " + dir() + run + " -q --modes raycast --paged-preload --out " + tmp.file("p"));
    ASSERT_EQ(r.code, 0) << r.err;
    s = readJson(tmp.file("p/summary.json"));
    EXPECT_FALSE(s["paged"].contains("stream")) << s.dump();
    EXPECT_EQ(s["paged"]["regions_loaded"].get<int>(), 9);
    // A run that cannot stream (a mode that needs the whole loaded city) preloads, and says so.
    r = runVista("bench " + dir() + run + " --modes osglod --out " + tmp.file("o"));
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("preloading the regions around the path (mode osglod does not stream"), std::string::npos)
        << r.err;
}

// A drive that leaves regions behind at full detail reports the frames drawn below it when the
// frames do not wait, and none when they do.
TEST_F(PagedStream, FramesBelowTheAskedDetailAreCounted) {
    const std::string run = " --seed 4 --frames 12 --size 160x120 -q --modes raycast" + kNear;
    CliRun r = runVista("bench " + dir() + run + " --paged-wait --out " + tmp.file("w"));
    ASSERT_EQ(r.code, 0) << r.err;
    const auto w = readJson(tmp.file("w/summary.json"))["paged"]["stream"];
    EXPECT_EQ(w["frames_below_detail"].get<int>(), 0) << w.dump();
#if defined(__SANITIZE_ADDRESS__)
    // The rest sets a budget 700 MB above the regions' room, the process's own memory a normal
    // build stays under; AddressSanitizer's shadow memory and quarantine put a sanitized
    // process above it, so that budget could not hold even the coarse levels.
    GTEST_SKIP() << "the tight-budget half needs a process under 700 MB of its own, which a sanitized one is not";
#endif
    // A budget that holds the coarse levels at the camera but no full region: every frame is below.
    auto manifest = vista::readPagedManifest(dir());
    ASSERT_TRUE(manifest.isOk()) << manifest.status().message();
    uint64_t smallest = UINT64_MAX;
    for (const auto& e : manifest->regions)
        if (!e.empty) smallest = std::min(smallest, e.bytes);
    const double weight = w["bytes_per_file_byte"]["full"].get<double>();
    const double leftMb =
        (double(w["loading_reserve_bytes"].get<uint64_t>()) + 0.8 * double(smallest) * weight) / (1024.0 * 1024.0);
    char gb[32];
    std::snprintf(gb, sizeof gb, "%.6f", (700.0 + leftMb) / 1024.0);
    r = runVista("bench " + dir() + run + " --paged-wait --memory-budget " + gb + " --out " + tmp.file("b"));
    ASSERT_EQ(r.code, 0) << r.err;
    const auto b = readJson(tmp.file("b/summary.json"))["paged"]["stream"];
    EXPECT_EQ(b["frames_below_detail"].get<int>(), 12) << b.dump();
    EXPECT_NE(r.err.find("12 of 12 frames drew a region below the detail"), std::string::npos) << r.err;
}

// A budget that cannot hold even the coarse levels of the regions at the camera: exit 2 naming
// --memory-budget and the budget they need, which then runs.
TEST_F(PagedStream, ABudgetThatCannotHoldTheRegionsAtTheCameraExitsTwo) {
    const std::string run = " --seed 4 --frames 1 --size 160x120 -q" + kNear;
    char gb[32];
    std::snprintf(gb, sizeof gb, "%.6f", 700.01 / 1024.0);  // 10 kB beside the run's own 700 MB
    for (const std::string& cmd : {"bench " + dir() + run + " --modes raycast --out " + tmp.file("b"),
                                   "render " + dir() + run + " --channels rgb --out " + tmp.file("r"),
                                   "view " + dir() + " --seed 4 --frames 1 --step --size 160x120" + kNear}) {
        const CliRun r = runVista(cmd + " --memory-budget " + gb);
        EXPECT_EQ(r.code, 2) << cmd << ": " << r.err;
        EXPECT_NE(r.err.find("--memory-budget"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("cannot hold the regions at the camera"), std::string::npos) << r.err;
    }
    EXPECT_FALSE(fs::exists(tmp.file("b/summary.json")));
    EXPECT_FALSE(fs::exists(tmp.file("r")));
#if defined(__SANITIZE_ADDRESS__)
    // The figure the message names is one measurement of the process's own memory; a sanitized
    // process's own memory is above the 700 MB a normal build is held to and varies from run to
    // run by more than the regions' room, so the next run may need more than it named.
    GTEST_SKIP() << "a sanitized process's own memory varies by more than the regions' room";
#endif
    // The budget the message names holds them.
    CliRun r = runVista("bench " + dir() + run + " --modes raycast --memory-budget " + gb + " --out " + tmp.file("b"));
    std::smatch m;
    ASSERT_TRUE(std::regex_search(r.err, m, std::regex("needs at least ([0-9.]+) GB"))) << r.err;
    r = runVista("bench " + dir() + run + " --modes raycast --memory-budget " + m[1].str() + " --out " +
                 tmp.file("b2"));
    EXPECT_EQ(r.code, 0) << r.err;
}

// Region files that cannot be read stop a stream (exit 2, naming them): all of them deleted, or
// one truncated; the preloading loader still draws the rest around a damaged one.
TEST_F(PagedStream, UnreadableRegionFilesStopAStreamNamingThem) {
    const std::string copy = tmp.file("copy.paged");
    fs::copy(dir(), copy, fs::copy_options::recursive);
    const std::string run = " --seed 4 --frames 2 --size 160x120 -q --paged-radius 5000";
    fs::resize_file(fs::path(copy) / "region_1_1.osgb", 1000);
    for (const std::string& cmd : {"bench " + copy + run + " --modes raycast --out " + tmp.file("b"),
                                   "render " + copy + run + " --channels rgb --out " + tmp.file("r"),
                                   "view " + copy + " --seed 4 --frames 2 --step --size 160x120 --paged-radius 5000"}) {
        const CliRun r = runVista(cmd);
        EXPECT_EQ(r.code, 2) << cmd << ": " << r.err;
        EXPECT_NE(r.err.find("region_1_1.osgb"), std::string::npos) << cmd << ": " << r.err;
    }
    EXPECT_FALSE(fs::exists(tmp.file("b/summary.json")));
    CliRun r = runVista("bench " + copy + run + " --modes raycast --paged-preload --out " + tmp.file("p"));
    EXPECT_EQ(r.code, 0) << r.err;
    // Every region file gone.
    for (const auto& e : fs::directory_iterator(copy))
        if (e.path().filename().string().rfind("region_", 0) == 0) fs::remove(e.path());
    r = runVista("bench " + copy + run + " --modes raycast --out " + tmp.file("b3"));
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("region_0_0.osgb"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("region_0_0.coarse.osgb"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(tmp.file("b3/summary.json")));
}

// A region file of another generation (another seed's city of the same grid) swapped into the
// directory, its size written into the manifest as a racing writer's would be: every reader
// refuses the directory, naming the region file and the manifest. The other city is generated
// in part: its shard 4/4 of 2 x 2 regions is region 3, region_1_1 alone.
TEST_F(PagedStream, ARegionOfAnotherGenerationIsRefused) {
    CliRun r =
        runVista("gen --size 1000 --seed 5 --detail 1 --region-size 500 -q --shard 4/4 -o " + tmp.file("other.paged"));
    ASSERT_EQ(r.code, 0) << r.err;
    ASSERT_TRUE(fs::exists(tmp.file("other.paged/region_1_1.osgb")));
    const std::string copy = tmp.file("copy.paged");
    fs::copy(dir(), copy, fs::copy_options::recursive);
    const fs::path region = fs::path(copy) / "region_1_1.osgb";
    fs::copy_file(fs::path(tmp.file("other.paged")) / "region_1_1.osgb", region, fs::copy_options::overwrite_existing);
    auto manifest = readJson(copy + "/manifest.json");
    for (auto& e : manifest["regions"])
        for (auto& f : e["files"])
            if (f["name"] == "region_1_1.osgb") f["bytes"] = fs::file_size(region);
    std::ofstream(copy + "/manifest.json", std::ios::trunc) << manifest.dump(2);
    const std::string run = " --seed 4 --frames 2 --size 160x120 -q --paged-radius 5000";
    for (const std::string& cmd :
         {"bench " + copy + run + " --modes raycast --out " + tmp.file("b"),
          "bench " + copy + run + " --modes raycast --paged-preload --out " + tmp.file("p"),
          "render " + copy + run + " --channels rgb --out " + tmp.file("r"),
          "render " + copy + run + " --channels rgb --paged-preload --out " + tmp.file("rp")}) {
        r = runVista(cmd);
        EXPECT_EQ(r.code, 2) << cmd << ": " << r.err;
        EXPECT_NE(r.err.find("region_1_1.osgb"), std::string::npos) << cmd << ": " << r.err;
        EXPECT_NE(r.err.find("another generation"), std::string::npos) << cmd << ": " << r.err;
        EXPECT_NE(r.err.find("manifest.json"), std::string::npos) << cmd << ": " << r.err;
    }
    EXPECT_FALSE(fs::exists(tmp.file("p/summary.json")));
    EXPECT_FALSE(fs::exists(tmp.file("rp")));
}

TEST_F(PagedStream, BadCombinationsExitTwoNamingTheFlag) {
    const std::string one = tmp.file("one.osgb");
    fs::copy_file(fs::path(dir()) / "region_0_0.osgb", one);
    struct Case {
        std::string args, flag;
    };
    const std::string r = " --seed 4 --frames 2 --size 160x120 -q --out " + tmp.file("o");
    for (const Case& c : std::vector<Case>{
             {"render " + one + r + " --paged-stream", "--paged-stream"},
             {"render " + dir() + r + " --paged-preload --paged-prefetch 2", "--paged-preload"},
             {"render " + dir() + r + " --paged-preload --paged-wait", "--paged-preload"},
             {"render " + one + r + " --paged-preload", "--paged-preload"},
             {"bench " + dir() + r + " --pace", "--pace"},
             {"render " + dir() + r + " --channels rgb,instance", "--channels"},
             {"render " + dir() + " --seed 4 -q --paged-stream --rig rig.json --out " + tmp.file("o"),
              "--paged-stream"},
             {"render " + dir() + r + " --paged-wait --paged-prefetch 601", "--paged-prefetch"},
             {"view " + one + " --frames 1 --paged-stream", "--paged-stream"},
             {"view " + dir() + " --frames 1 --paged-stream --mode osglod", "--paged-stream"},
             {"view " + dir() + " --frames 1 --paged-preload --paged-stream", "--paged-preload"},
             {"view " + dir() + " --frames 1 --pace", "--pace"},
         }) {
        const CliRun run = runVista(c.args);
        EXPECT_EQ(run.code, 2) << c.args << ": " << run.err;
        EXPECT_NE(run.err.find(c.flag), std::string::npos) << c.args << ": " << run.err;
    }
    EXPECT_FALSE(fs::exists(tmp.file("o")));
}
