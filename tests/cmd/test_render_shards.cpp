// `vista render --shard K/N`, `--merge --shards N` and `--dataset` through the
// CLI on two small generated cities: a 4-shard render of a two-city dataset
// (a camera drive and a sensor-rig drive per city) merges to the bytes of one
// unsharded run; frame shards of one hybrid drive (whose panoramic cache
// carries state from frame to frame) merge to the bytes of one run; a shard
// killed mid-way and run again gives the same bytes; the merge refuses a
// missing, damaged, corrupt or mismatched shard naming it and the command
// that runs it, writing nothing (a shard of another --path, or a merge given
// another path than its shards, names --path); a bad manifest exits 2 naming the field and
// leaves nothing behind. summary.json (timings, the command) is the one file
// compared by its fields only. Rendering: needs DISPLAY (ctest runs under xvfb-run).
#include <gtest/gtest.h>

#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "tests/common/run_vista.h"
#include "tests/common/temp_dir.h"

namespace vista {
namespace {

namespace fs = std::filesystem;
using test::runVista;
using test::TempDir;

// Every file under `dir` (relative path -> bytes) but summary.json.
std::map<std::string, std::string> outputFiles(const std::string& dir) {
    std::map<std::string, std::string> m;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.is_regular_file() && e.path().filename() != "summary.json")
            m[fs::relative(e.path(), dir).string()] = test::readBytes(e.path().string());
    return m;
}

void expectSameBytes(const std::string& ref, const std::string& out) {
    const auto a = outputFiles(ref), b = outputFiles(out);
    EXPECT_EQ(a.size(), b.size());
    for (const auto& [name, bytes] : a) {
        auto it = b.find(name);
        ASSERT_NE(it, b.end()) << name << " missing from " << out;
        EXPECT_TRUE(it->second == bytes) << name << " differs";
    }
    size_t summaries = 0;
    for (const auto& e : fs::recursive_directory_iterator(out))
        if (e.path().filename() == "summary.json") {
            ++summaries;
            const std::string rel = fs::relative(e.path(), out).string();
            const auto s = nlohmann::json::parse(test::readBytes(e.path().string()));
            const auto r = nlohmann::json::parse(test::readBytes(ref + "/" + rel));
            EXPECT_EQ(s["frames"], r["frames"]) << rel;
        }
    EXPECT_GT(summaries, 0u);
}

class RenderShards : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        const char* display = std::getenv("DISPLAY");
        if (!display || !*display) return;
        dir = new TempDir("vista_shards");
        ASSERT_EQ(runVista("gen --size 400 --seed 11 -q -o " + dir->file("a.osgb")).code, 0);
        ASSERT_EQ(runVista("gen --size 400 --seed 12 -q -o " + dir->file("b.osgb")).code, 0);
        ASSERT_EQ(runVista("path " + dir->file("a.osgb") + " --seed 2 --duration 3 -o " + dir->file("p.csv")).code, 0);
        std::ofstream(dir->file("lidar.json")) << R"({"sensors": [{"name": "top", "type": "lidar", "pose": {"z": 0.5},
            "beams": {"count": 8, "min_deg": -15, "max_deg": 5}, "columns": 90}]})";
        std::ofstream(dir->file("ds.json")) << R"({"cities": ["a.osgb", {"name": "b", "file": "b.osgb"}],
            "paths": [{"name": "p1", "seed": 2, "duration": 3}],
            "rigs": [{"name": "cam", "size": "64x48", "channels": "rgb,depth,semantic"}, {"file": "lidar.json"}],
            "options": {"frames": 3, "sampling": "consecutive"}})";
    }
    static void TearDownTestSuite() {
        delete dir;
        dir = nullptr;
    }
    void SetUp() override {
        const char* display = std::getenv("DISPLAY");
        if (!display || !*display) GTEST_SKIP() << "no DISPLAY: run the tests under xvfb-run -a";
    }
    // One hybrid drive, consecutive frames, a small ray budget: most far
    // pixels come from the panoramic cache, so a frame depends on the frames before it.
    static std::string hybrid(const std::string& out, const std::string& size = "96x72",
                              const std::string& near = "40") {
        return "render " + dir->file("a.osgb") + " --path " + dir->file("p.csv") +
               " --frames 5 --sampling consecutive --size " + size + " --mode hybrid --near " + near +
               " --budget 500 -q --out " + out;
    }
    static TempDir* dir;
};
TempDir* RenderShards::dir = nullptr;

TEST_F(RenderShards, FourShardsOfATwoCityDatasetMergeToOneRun) {
    const std::string ds = dir->file("ds.json"), one = dir->file("ds_one"), four = dir->file("ds_four");
    auto r = runVista("render --dataset " + ds + " -q --out " + one);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_FALSE(fs::exists(one + ".shards")) << "an unsharded run leaves no shard behind";
    for (const char* drive : {"a/p1/cam/rgb/000002.png", "b/p1/cam/depth/000000.npy", "b/p1/lidar/rig.json"})
        EXPECT_TRUE(fs::exists(one + "/" + drive)) << drive;
    const auto dataset = nlohmann::json::parse(test::readBytes(one + "/dataset.json"));
    ASSERT_EQ(dataset["drives"].size(), 4u);
    EXPECT_EQ(dataset["drives"][3]["name"], "b/p1/lidar");
    for (int k = 4; k >= 1; --k) {  // any order
        r = runVista("render --dataset " + ds + " -q --out " + four + " --shard " + std::to_string(k) + "/4");
        ASSERT_EQ(r.code, 0) << r.err;
        EXPECT_FALSE(fs::exists(four)) << "a shard writes only its own directory";
    }
    r = runVista("render --dataset " + ds + " -q --out " + four + " --merge --shards 4");
    ASSERT_EQ(r.code, 0) << r.err;
    expectSameBytes(one, four);
    // The cities differ: the two cities' camera drives are not the same bytes.
    EXPECT_NE(test::readBytes(one + "/a/p1/cam/rgb/000000.png"), test::readBytes(one + "/b/p1/cam/rgb/000000.png"));
}

TEST_F(RenderShards, FrameShardsOfAHybridDriveMergeToOneRun) {
    const std::string one = dir->file("hy_one"), sh = dir->file("hy_sh");
    auto r = runVista(hybrid(one));
    ASSERT_EQ(r.code, 0) << r.err;
    for (int k = 1; k <= 3; ++k) {
        r = runVista(hybrid(sh) + " --shard " + std::to_string(k) + "/3");
        ASSERT_EQ(r.code, 0) << r.err;
    }
    // Shard 3/3 holds frames 3 and 4 only (shardRange: 5 frames in 3 shards = [0,1) [1,3) [3,5)).
    EXPECT_FALSE(fs::exists(sh + ".shards/3-of-3/rgb/000002.png"));
    EXPECT_TRUE(fs::exists(sh + ".shards/3-of-3/rgb/000004.png"));
    r = runVista(hybrid(sh) + " --merge --shards 3");
    ASSERT_EQ(r.code, 0) << r.err;
    expectSameBytes(one, sh);
    EXPECT_EQ(nlohmann::json::parse(test::readBytes(sh + "/summary.json"))["shards"], 3);
}

TEST_F(RenderShards, AKilledShardResumesToTheSameBytes) {
    const std::string one = dir->file("kill_one"), sh = dir->file("kill_sh");
    auto r = runVista(hybrid(one));
    ASSERT_EQ(r.code, 0) << r.err;
    r = runVista(hybrid(sh) + " --shard 1/2");
    ASSERT_EQ(r.code, 0) << r.err;
    // Shard 2/2 (frames 2 .. 4) killed after one of its frames.
    r = runVista(hybrid(sh) + " --shard 2/2", "VISTA_RENDER_KILL_AFTER_FRAMES=1");
    ASSERT_TRUE(r.code == -1 || r.code == 128 + SIGKILL) << r.code << " " << r.err;
    EXPECT_TRUE(fs::exists(sh + ".shards/2-of-2.partial"));
    r = runVista(hybrid(sh) + " --merge --shards 2");
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("shard 2/2: unfinished"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(sh));
    r = runVista(hybrid(sh) + " --shard 2/2");
    ASSERT_EQ(r.code, 0) << r.err;
    r = runVista(hybrid(sh) + " --shard 2/2");  // done: nothing to do
    ASSERT_EQ(r.code, 0) << r.err;
    r = runVista(hybrid(sh) + " --merge --shards 2");
    ASSERT_EQ(r.code, 0) << r.err;
    expectSameBytes(one, sh);

    // A dataset shard killed inside its drive resumes that drive.
    const std::string ds = dir->file("ds.json"), d1 = dir->file("dsk_one"), d2 = dir->file("dsk");
    r = runVista("render --dataset " + ds + " -q --out " + d1);
    ASSERT_EQ(r.code, 0) << r.err;
    for (int k = 1; k <= 2; ++k) {
        const std::string cmd = "render --dataset " + ds + " -q --out " + d2 + " --shard " + std::to_string(k) + "/2";
        r = runVista(cmd, "VISTA_RENDER_KILL_AFTER_FRAMES=2");
        ASSERT_TRUE(r.code == -1 || r.code == 128 + SIGKILL) << r.code << " " << r.err;
        r = runVista(cmd);
        ASSERT_EQ(r.code, 0) << r.err;
    }
    r = runVista("render --dataset " + ds + " -q --out " + d2 + " --merge --shards 2");
    ASSERT_EQ(r.code, 0) << r.err;
    expectSameBytes(d1, d2);
}

TEST_F(RenderShards, TheMergeRefusesABadShardNamingIt) {
    const std::string sh = dir->file("bad_sh");
    for (int k = 1; k <= 3; ++k) ASSERT_EQ(runVista(hybrid(sh) + " --shard " + std::to_string(k) + "/3").code, 0);
    auto refused = [&](const std::string& expected, const std::string& size = "96x72") {
        const auto r = runVista(hybrid(sh, size) + " --merge --shards 3");
        EXPECT_EQ(r.code, 2) << r.err;
        EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(sh)) << "a refused merge writes nothing";
        EXPECT_FALSE(fs::exists(sh + ".partial"));
        return r.err;
    };
    const std::string shard2 = sh + ".shards/2-of-3";
    // Missing: named, with the command that runs it again.
    fs::rename(shard2, shard2 + ".away");
    const std::string err = refused("shard 2/3: missing");
    EXPECT_NE(err.find("; run shard 2/3 again: vista render "), std::string::npos) << err;
    EXPECT_NE(err.find(" --shard 2/3; then the merge"), std::string::npos) << err;
    EXPECT_EQ(err.find("--merge --shards"), std::string::npos) << "the rerun command is the shard's: " << err;
    fs::rename(shard2 + ".away", shard2);
    // Damaged: a frame file of shard 2 changed after it was recorded.
    const std::string png = shard2 + "/rgb/000001.png";
    const std::string bytes = test::readBytes(png);
    std::string changed = bytes;
    changed[changed.size() / 2] = char(changed[changed.size() / 2] ^ 0x21);
    std::ofstream(png, std::ios::binary | std::ios::trunc) << changed;
    refused("shard 2/3: rgb/000001.png: its content hash differs");
    // Corrupt record.
    std::ofstream(png, std::ios::binary | std::ios::trunc) << bytes;
    const std::string record = shard2 + "/shard.json", recordBytes = test::readBytes(record);
    std::ofstream(record, std::ios::binary | std::ios::trunc) << recordBytes.substr(0, recordBytes.size() / 2);
    refused("shard 2/3: shard.json is corrupt");
    std::ofstream(record, std::ios::binary | std::ios::trunc) << recordBytes;
    // Other inputs: the merge's arguments differ from the shards' (a field named with both values).
    refused("from other inputs: size (--size): 96x72 in the shard, 80x60 now", "80x60");
    // A shard rendered with other arguments than its siblings.
    fs::remove_all(sh + ".shards/3-of-3");
    ASSERT_EQ(runVista(hybrid(sh, "96x72", "60") + " --shard 3/3").code, 0);
    refused("shard 3/3: from other inputs: near (--near): 60 in the shard, 40 now");
    // A damaged shard run again renders itself again; then the merge succeeds.
    std::ofstream(png, std::ios::binary | std::ios::trunc) << changed;
    ASSERT_EQ(runVista(hybrid(sh) + " --shard 2/3").code, 0);
    ASSERT_EQ(runVista(hybrid(sh) + " --shard 3/3 --restart").code, 0);
    const auto r = runVista(hybrid(sh) + " --merge --shards 3");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(test::readBytes(sh + "/rgb/000001.png"), bytes);
}

TEST_F(RenderShards, TheMergeRefusesShardsOfAnotherPath) {
    const std::string q = dir->file("q.csv");
    ASSERT_EQ(runVista("path " + dir->file("a.osgb") + " --seed 3 --duration 3 -o " + q).code, 0);
    const std::string sh = dir->file("path_sh");
    auto render = [&](const std::string& path) {
        return "render " + dir->file("a.osgb") + " --path " + path +
               " --frames 4 --sampling consecutive --size 48x36 --channels rgb -q --out " + sh;
    };
    auto refused = [&](const std::string& path, const std::string& expected) {
        const auto r = runVista(render(path) + " --merge --shards 2");
        EXPECT_EQ(r.code, 2) << r.err;
        EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(sh)) << "a refused merge writes nothing";
        EXPECT_FALSE(fs::exists(sh + ".partial"));
    };
    // Shard 2 rendered along another path than shard 1 and the merge.
    ASSERT_EQ(runVista(render(dir->file("p.csv")) + " --shard 1/2").code, 0);
    ASSERT_EQ(runVista(render(q) + " --shard 2/2").code, 0);
    refused(dir->file("p.csv"), "shard 2/2: from other inputs: path (--path): file ");
    // Both shards along p.csv, the merge given q.csv: every shard is refused, naming --path.
    ASSERT_EQ(runVista(render(dir->file("p.csv")) + " --shard 2/2 --restart").code, 0);
    refused(q, "shard 1/2: from other inputs: path (--path): file ");
    refused(q, "shard 2/2: from other inputs: path (--path): file ");
    // A path made from flags: its seed is the differing input.
    const std::string seeded = dir->file("a.osgb") + " --seed 2 --duration 3 --frames 4 --sampling consecutive";
    fs::remove_all(sh + ".shards");
    ASSERT_EQ(runVista("render " + seeded + " --size 48x36 --channels rgb -q --out " + sh + " --shard 1/1").code, 0);
    auto r = runVista("render " + dir->file("a.osgb") + " --seed 5 --duration 3 --frames 4 --sampling consecutive" +
                      " --size 48x36 --channels rgb -q --out " + sh + " --merge --shards 1");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("path (--path): seed 2, kind car"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(sh));
    // Other frames of the same path: --frames is the differing input.
    r = runVista("render " + dir->file("a.osgb") + " --seed 2 --duration 3 --frames 3 --sampling consecutive" +
                 " --size 48x36 --channels rgb -q --out " + sh + " --merge --shards 1");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(
        r.err.find("sampling (--frames, --sampling): 4 frames, consecutive in the shard, 3 frames, consecutive now"),
        std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(sh));
    // The same arguments merge.
    EXPECT_EQ(runVista("render " + seeded + " --size 48x36 --channels rgb -q --out " + sh + " --merge --shards 1").code,
              0);
    EXPECT_TRUE(fs::exists(sh + "/rgb/000003.png"));
}

TEST_F(RenderShards, BadDatasetsAndFlagsExitTwoNamingTheField) {
    const std::string out = dir->file("bad_ds");
    auto refuse = [&](const std::string& manifest, const std::string& expected, const std::string& extra = "") {
        const std::string file = dir->file("bad.json");
        std::ofstream(file, std::ios::trunc) << manifest;
        const auto r = runVista("render --dataset " + file + " -q --out " + out + extra);
        EXPECT_EQ(r.code, 2) << manifest;
        EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(out));
        EXPECT_FALSE(fs::exists(out + ".shards"));
    };
    const std::string cities = R"("cities": ["a.osgb", "b.osgb"], "paths": [{"name": "p", "duration": 3}])";
    refuse("{" + cities + R"(, "rigs": [{"name": "c", "fov": 500}]})", "rigs[0].fov:");
    refuse("{" + cities + R"(, "rigs": [{"name": "c", "channels": "rgb,sky"}]})", "rigs[0].channels:");
    refuse("{" + cities + R"(, "rigs": [{"name": "c", "mode": "fast"}]})", "rigs[0].mode:");
    refuse(R"({"cities": ["a.osgb"], "paths": [{"name": "p", "duration": 0}], "rigs": [{"name": "c"}]})",
           "paths[0].duration: 0 out of range");
    refuse(R"({"cities": ["a.osgb"], "paths": [{"name": "p", "kind": "swim"}], "rigs": [{"name": "c"}]})", "paths[0]:");
    refuse(R"({"cities": ["nowhere.osgb"], "paths": [{"name": "p"}], "rigs": [{"name": "c"}]})",
           "cities[0].file: '" + dir->file("nowhere.osgb") + "' does not exist");
    refuse("{" + cities + R"(, "rigs": [{"name": "c"}]})", "option --size does not apply with --dataset",
           " --size 64x48");
    refuse("{" + cities + R"(, "rigs": [{"name": "c"}]})", "option --merge: needs --shards", " --merge");
    refuse("{" + cities + R"(, "rigs": [{"name": "c"}]})", "option --shard = '5/4'", " --shard 5/4");
    const auto r = runVista("render " + dir->file("a.osgb") + " --rig " + dir->file("lidar.json") + " -q --out " + out +
                            " --shard 1/2");
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--shard does not apply with --rig"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out + ".shards"));
}

}  // namespace
}  // namespace vista
