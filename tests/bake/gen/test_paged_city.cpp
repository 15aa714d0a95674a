// Paged generation (vista gen -o DIR.paged): determinism across threads and
// shards, resume after an interruption, the PagedLOD index, building counts
// against the unpaged city, bad input, damaged region files.
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <tuple>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>
#include <osg/ComputeBoundsVisitor>
#include <osg/Group>
#include <osg/PagedLOD>
#include <osg/Texture2D>
#include <osgDB/ReadFile>
#include <osgViewer/Viewer>

#include "citygen/regions.h"
#include "runtime/scene/city_file.h"
#include "bake/gen/paged_city.h"
#include "runtime/scene/scene_file.h"
#include "runtime/scene/scene_graph.h"
#include "runtime/scene/tree_impostor_graph.h"
#include "tests/common/run_vista.h"
#include "tests/common/small_paged_city.h"
#include "tests/common/temp_dir.h"

namespace fs = std::filesystem;
using vista::test::CliRun;
using vista::test::listTree;
using vista::test::readBytes;
using vista::test::runVista;
using vista::test::TempDir;

namespace {

// The shared city's parameters (tests/common/small_paged_city.h): 1.5 km in 500 m regions (3 x 3).
const std::string kCity = std::string("gen ") + vista::test::kSmallPagedCityArgs + " -q";

// Every file under `dir` (relative name -> bytes), temporaries included.
std::map<std::string, std::string> snapshot(const std::string& dir) {
    std::map<std::string, std::string> out;
    for (const auto& name : listTree(dir))
        if (fs::is_regular_file(fs::path(dir) / name)) out[name] = readBytes((fs::path(dir) / name).string());
    return out;
}

void expectSameFiles(const std::map<std::string, std::string>& a, const std::map<std::string, std::string>& b,
                     const std::string& what) {
    std::set<std::string> na, nb;
    for (const auto& [k, v] : a) na.insert(k);
    for (const auto& [k, v] : b) nb.insert(k);
    ASSERT_EQ(na, nb) << what;
    for (const auto& [k, v] : a) EXPECT_TRUE(v == b.at(k)) << what << ": " << k << " differs";
}

nlohmann::json readJson(const std::string& path) { return nlohmann::json::parse(readBytes(path)); }

class Paged : public ::testing::Test {
protected:
    // One reference run shared by the tests (threads 1): tests/common/small_paged_city.h.
    static void SetUpTestSuite() {
        files = new std::map<std::string, std::string>(snapshot(refDir()));
        ASSERT_TRUE(files->count("manifest.json")) << refDir();
    }
    static void TearDownTestSuite() {
        delete files;
        files = nullptr;
    }
    static std::string refDir() { return vista::test::smallPagedCity().dir; }
    static std::string refStats() { return vista::test::smallPagedCity().stats; }
    static std::map<std::string, std::string>* files;
    TempDir tmp{"vista_paged"};
};
std::map<std::string, std::string>* Paged::files = nullptr;

}  // namespace

TEST(RegionGrid, EveryTileInExactlyOneRegion) {
    vista::CityParams p;
    p.size_m = 1600;  // 7 tiles of 250 m (the last one cut), regions of 3 tiles: 3 x 3, the last row/column of 1 tile
    const vista::RegionGrid g(p, 750);
    EXPECT_EQ(g.countX(), 3);
    EXPECT_EQ(g.tilesPerRegion(), 3);
    std::vector<int> seen(49, 0);
    for (int r = 0; r < g.count(); ++r) {
        glm::dvec2 lo, hi;
        g.bounds(r, lo, hi);
        for (int t : g.tilesOf(r)) {
            ASSERT_GE(t, 0);
            ASSERT_LT(t, 49);
            ++seen[size_t(t)];
            EXPECT_EQ(g.regionOfTile(t), r);
            const double x = -800 + (t % 7) * 250.0 + 1, y = -800 + (t / 7) * 250.0 + 1;  // inside tile t
            EXPECT_TRUE(x >= lo.x && x <= hi.x && y >= lo.y && y <= hi.y) << "tile " << t << " region " << r;
        }
    }
    for (int c : seen) EXPECT_EQ(c, 1);
    glm::dvec2 lo, hi;
    g.bounds(8, lo, hi);
    EXPECT_DOUBLE_EQ(lo.x, 700.0);
    EXPECT_DOUBLE_EQ(hi.x, 800.0);  // cut by the city border
}

TEST(RegionGrid, RegionSizeValidated) {
    vista::CityParams p;
    EXPECT_TRUE(vista::validateRegionSize(p, 2000).isOk());
    EXPECT_TRUE(vista::validateRegionSize(p, 250).isOk());
    for (double bad : {0.0, 100.0, 333.0, 16250.0, 1e9, -500.0}) {
        const vista::Status s = vista::validateRegionSize(p, bad);
        ASSERT_FALSE(s.isOk()) << bad;
        EXPECT_NE(s.message().find("region_size_m"), std::string::npos) << s.message();
        EXPECT_NE(s.message().find("250 .. 16000"), std::string::npos) << s.message();
    }
}

TEST_F(Paged, LayoutAndManifest) {
    const std::string dir = refDir();
    const auto m = readJson(dir + "/manifest.json");
    EXPECT_EQ(m["format"], "vista.paged_city");
    EXPECT_EQ(m["regions_x"], 3);
    EXPECT_EQ(m["region_size_m"], 500.0);
    EXPECT_EQ(m["params"]["size_m"], 1500.0);
    ASSERT_EQ(m["regions"].size(), 9u);
    size_t buildings = 0;
    for (const auto& r : m["regions"]) {
        buildings += r["buildings"].get<size_t>();
        if (r["empty"].get<bool>()) continue;
        ASSERT_EQ(r["files"].size(), 2u);
        for (const auto& f : r["files"]) {
            const std::string bytes = readBytes(dir + "/" + f["name"].get<std::string>());
            EXPECT_EQ(bytes.size(), f["bytes"].get<size_t>()) << f["name"];
            char hex[17];
            std::snprintf(hex, sizeof hex, "%016llx",
                          (unsigned long long)vista::hashBytes64(bytes.data(), bytes.size()));
            EXPECT_EQ(f["hash"].get<std::string>(), hex) << f["name"];
        }
    }
    EXPECT_EQ(buildings, m["totals"]["buildings"].get<size_t>());
    EXPECT_GT(buildings, 0u);
}

// The generation's identity: the manifest's generation is the params' seed and the key of every
// region's record, and each region file (full and coarse) carries both on its root.
TEST_F(Paged, EveryRegionFileCarriesTheManifestsGeneration) {
    const std::string dir = refDir();
    const auto m = readJson(dir + "/manifest.json");
    EXPECT_EQ(m["version"], vista::kPagedCityVersion);
    ASSERT_TRUE(m.contains("generation")) << m.dump();
    const std::string key = m["generation"]["key"].get<std::string>();
    EXPECT_EQ(m["generation"]["seed"], m["params"]["seed"]);
    EXPECT_EQ(key.size(), 16u);
    int files = 0;
    for (const auto& r : m["regions"]) {
        if (r["empty"].get<bool>()) continue;
        const std::string record = dir + "/records/region_" + std::to_string(r["ix"].get<int>()) + "_" +
                                   std::to_string(r["iy"].get<int>()) + ".json";
        EXPECT_EQ(readJson(record)["key"].get<std::string>(), key) << record;
        for (const auto& f : r["files"]) {
            auto root = vista::readSceneFile(dir + "/" + f["name"].get<std::string>());
            ASSERT_TRUE(root.isOk()) << root.status().message();
            std::string gen, seed;
            EXPECT_TRUE((*root)->getUserValue(vista::kPagedGenerationKey, gen)) << f["name"];
            EXPECT_TRUE((*root)->getUserValue(vista::kPagedSeedKey, seed)) << f["name"];
            EXPECT_EQ(gen, key) << f["name"];
            EXPECT_EQ(seed, std::to_string(m["params"]["seed"].get<uint64_t>())) << f["name"];
            ++files;
        }
    }
    EXPECT_GT(files, 0);
}

// Every building of the city lies in exactly one region (anchor: footprint
// centroid) and is the one the unpaged generator places on that lot, so the
// union of the regions' buildings is the unpaged city's building count.
TEST_F(Paged, BuildingCountsEqualTheUnpagedCity) {
    const CliRun r = runVista("gen --size 1500 --seed 4 --detail 1 -q -o " + tmp.file("one.osgb") + " --stats " +
                              tmp.file("one.json"));
    ASSERT_EQ(r.code, 0) << r.err;
    const auto one = readJson(tmp.file("one.json"));
    const auto m = readJson(refDir() + "/manifest.json");
    EXPECT_EQ(m["totals"]["buildings"].get<size_t>(), one["buildings"].get<size_t>());
    const auto stats = readJson(refStats());
    EXPECT_EQ(stats["buildings"].get<size_t>(), one["buildings"].get<size_t>());
    EXPECT_EQ(stats["street_edges"].get<size_t>(), one["street_edges"].get<size_t>());
    EXPECT_EQ(stats["blocks"].get<size_t>(), one["blocks"].get<size_t>());
    // Trees: the spacing filter runs per region and halo; the counts agree closely.
    const double trees = stats["trees"].get<double>(), oneTrees = one["trees"].get<double>();
    EXPECT_NEAR(trees, oneTrees, 0.02 * oneTrees);
}

TEST_F(Paged, SameBytesForAnyThreadCountAndShards) {
    const std::string two = tmp.file("two.paged");
    CliRun r = runVista(kCity + " --threads 2 -o " + two);
    ASSERT_EQ(r.code, 0) << r.err;
    expectSameFiles(*files, snapshot(two), "threads 2 vs 1");

    // Three shards as concurrent processes, then the merge.
    const std::string sh = tmp.file("shards.paged");
    std::vector<pid_t> pids;
    for (int i = 0; i < 3; ++i) {
        std::vector<std::string> args{"gen",       "--size",
                                      "1500",      "--seed",
                                      "4",         "--detail",
                                      "1",         "--region-size",
                                      "500",       "-q",
                                      "--threads", "1",
                                      "--shard",   std::to_string(i + 1) + "/3",
                                      "-o",        sh};
        pids.push_back(vista::test::startVista(args));
    }
    for (pid_t p : pids) {
        int st = 0;
        ASSERT_EQ(::waitpid(p, &st, 0), p);
        ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0);
    }
    EXPECT_FALSE(fs::exists(sh + "/index.osgb")) << "a shard wrote the index";
    EXPECT_FALSE(fs::exists(sh + "/manifest.json"));
    r = runVista(kCity + " --merge -o " + sh + " --stats " + tmp.file("merge.json"));
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(readJson(tmp.file("merge.json"))["regions_generated"], 0);
    expectSameFiles(*files, snapshot(sh), "3 shards + merge vs one run");
}

TEST_F(Paged, MergeRefusesMissingRegions) {
    const std::string sh = tmp.file("half.paged");
    ASSERT_EQ(runVista(kCity + " --shard 1/2 -o " + sh).code, 0);
    const auto before = snapshot(sh);
    const CliRun r = runVista(kCity + " --merge -o " + sh);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--merge"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("region_1_0.osgb"), std::string::npos) << r.err;  // region 1: shard 2/2, never run
    EXPECT_NE(r.err.find("--shards N"), std::string::npos) << "tells how to name the shards: " << r.err;
    EXPECT_FALSE(fs::exists(sh + "/index.osgb"));
    expectSameFiles(before, snapshot(sh), "a refused merge changes nothing");

    // Told the shard count, the merge names the shard to run again, and only that one.
    const CliRun named = runVista(kCity + " --merge --shards 2 -o " + sh);
    EXPECT_EQ(named.code, 2);
    EXPECT_NE(named.err.find("run shard 2/2 again"), std::string::npos) << named.err;
    EXPECT_EQ(named.err.find("1/2"), std::string::npos) << "shard 1/2 is done: " << named.err;
    // Each missing region names its shard, and the refusal gives the command
    // that runs that shard: the same parameters and output, --shard 2/2.
    const std::string kCityFlags = "--seed 4 --size 1500 --detail 1 --region-size 500";
    EXPECT_NE(named.err.find("region_1_0.osgb (shard 2/2)"), std::string::npos) << named.err;
    EXPECT_NE(named.err.find(": vista gen " + kCityFlags + " -o " + sh + " --shard 2/2; then the merge"),
              std::string::npos)
        << named.err;
    // Split in 4, regions 0..8 of the 3 x 3 grid: shard 1/2 wrote 0, 2, 4, 6, 8;
    // 1, 5 are shard 2/4's and 3, 7 shard 4/4's.
    const CliRun four = runVista(kCity + " --merge --shards 4 -o " + sh);
    EXPECT_EQ(four.code, 2);
    EXPECT_NE(four.err.find("run 2 shards 2/4, 4/4 again, each with: vista gen "), std::string::npos) << four.err;
    EXPECT_NE(four.err.find(" --shard K/4; then the merge"), std::string::npos) << four.err;
    expectSameFiles(before, snapshot(sh), "a refused merge changes nothing");
}

TEST_F(Paged, ResumeRegeneratesOnlyDamagedRegions) {
    const std::string dir = tmp.file("city.paged");
    fs::copy(refDir(), dir, fs::copy_options::recursive);
    fs::remove(dir + "/index.osgb");
    fs::remove(dir + "/manifest.json");
    fs::remove(dir + "/region_0_0.osgb");             // missing
    fs::resize_file(dir + "/region_1_1.osgb", 1000);  // truncated
    {
        std::fstream f(dir + "/region_2_2.coarse.osgb", std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(600);
        f.put('\x5a');  // one byte changed
    }
    fs::remove(dir + "/records/region_2_0.json");  // files but no record (killed before it)
    const CliRun r = runVista(kCity + " -o " + dir + " --stats " + tmp.file("s.json"));
    ASSERT_EQ(r.code, 0) << r.err;
    const auto s = readJson(tmp.file("s.json"));
    EXPECT_EQ(s["regions_generated"], 4);
    EXPECT_EQ(s["regions_reused"], 5);
    expectSameFiles(*files, snapshot(dir), "resumed vs uninterrupted");
}

TEST_F(Paged, KillNineThenResumeGivesTheSameBytes) {
    const std::string dir = tmp.file("killed.paged");
    std::vector<std::string> args{"gen",           "--size", "1500", "--seed",    "4", "--detail", "1",
                                  "--region-size", "500",    "-q",   "--threads", "1", "-o",       dir};
    const pid_t pid = vista::test::startVista(args);
    // Kill it once the first region is recorded (a record renamed into place; mid-run: 9 regions).
    auto recorded = [&] {
        for (const auto& n : listTree(dir + "/records"))
            if (n.size() > 5 && n.compare(n.size() - 5, 5, ".json") == 0) return true;
        return false;
    };
    for (int i = 0; i < 6000 && !recorded(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    ::kill(pid, SIGKILL);
    int st = 0;
    ::waitpid(pid, &st, 0);
    ASSERT_TRUE(WIFSIGNALED(st)) << "the run finished before it was killed";
    EXPECT_FALSE(fs::exists(dir + "/index.osgb"));
    const CliRun r = runVista(kCity + " --threads 1 -o " + dir + " --stats " + tmp.file("s.json"));
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_GE(readJson(tmp.file("s.json"))["regions_reused"].get<int>(), 1);
    expectSameFiles(*files, snapshot(dir), "killed + resumed vs uninterrupted");  // no temporaries left either
}

// The index loads with osgDB (vista's reader and the stock one); one PagedLOD
// per non-empty region naming its coarse and full files, whose bounding
// sphere contains the region's geometry; full detail nearer than the coarse level.
TEST_F(Paged, IndexHasOnePagedLodPerRegion) {
    const std::string dir = refDir();
    const auto m = readJson(dir + "/manifest.json");
    auto root = vista::readSceneFile(dir + "/index.osgb");
    ASSERT_TRUE(root.isOk()) << root.status().message();
    osg::Group* g = (*root)->asGroup();
    ASSERT_NE(g, nullptr);
    EXPECT_EQ(g->getName(), "vista.paged_city");
    size_t nonEmpty = 0;
    for (const auto& r : m["regions"]) nonEmpty += r["empty"].get<bool>() ? 0 : 1;
    ASSERT_EQ(g->getNumChildren(), nonEmpty);
    EXPECT_GT(nonEmpty, 0u);
    std::set<std::string> named;
    for (unsigned i = 0; i < g->getNumChildren(); ++i) {
        auto* lod = dynamic_cast<osg::PagedLOD*>(g->getChild(i));
        ASSERT_NE(lod, nullptr);
        ASSERT_EQ(lod->getNumFileNames(), 2u);
        const std::string coarse = lod->getFileName(0), full = lod->getFileName(1);
        EXPECT_EQ(full, lod->getName() + ".osgb");
        EXPECT_EQ(coarse, lod->getName() + ".coarse.osgb");
        named.insert(full);
        EXPECT_EQ(lod->getMinRange(1), 0.0f);
        EXPECT_EQ(lod->getMaxRange(1), lod->getMinRange(0));
        EXPECT_GT(lod->getMaxRange(0), lod->getMaxRange(1));
        const osg::BoundingSphere bs = lod->getBound();
        for (const std::string& f : {full, coarse}) {
            auto city = vista::loadCityFile(dir + "/" + f);
            ASSERT_TRUE(city.isOk()) << city.status().message();
            EXPECT_FALSE(city->tiles.empty()) << f;
            if (f == coarse) {  // plain prisms, no trees
                EXPECT_EQ(city->params.detail, 0);
                EXPECT_TRUE(city->instances.empty()) << f;
            } else {
                EXPECT_EQ(city->params.detail, 1);
            }
            osg::ComputeBoundsVisitor cbv;
            vista::sceneRoot(*city)->accept(cbv);
            const osg::BoundingBox box = cbv.getBoundingBox();
            ASSERT_TRUE(box.valid()) << f;
            for (unsigned c = 0; c < 8; ++c)
                EXPECT_LE((box.corner(c) - bs.center()).length(), bs.radius() * 1.0001f + 0.01f)
                    << f << " corner " << c;
        }
    }
    for (const auto& r : m["regions"])
        if (!r["empty"].get<bool>()) { EXPECT_EQ(named.count(r["files"][0]["name"].get<std::string>()), 1u); }
    // The stock reader: the PagedLODs get the index's directory as database path.
    osg::ref_ptr<osg::Node> stock = osgDB::readNodeFile(dir + "/index.osgb");
    ASSERT_TRUE(stock.valid());
    auto* lod = dynamic_cast<osg::PagedLOD*>(stock->asGroup()->getChild(0));
    ASSERT_NE(lod, nullptr);
    EXPECT_TRUE(fs::exists(lod->getDatabasePath() + lod->getFileName(1)))
        << lod->getDatabasePath() << lod->getFileName(1);
}

// A region file that is missing or damaged is an error for vista's reader and
// no crash for the stock one (the pager of osgviewer reads with it).
TEST_F(Paged, DamagedRegionFilesDoNotCrashReaders) {
    const std::string dir = tmp.file("city.paged");
    fs::copy(refDir(), dir, fs::copy_options::recursive);
    fs::remove(dir + "/region_0_0.osgb");
    fs::resize_file(dir + "/region_1_1.osgb", fs::file_size(dir + "/region_1_1.osgb") / 2);
    auto missing = vista::loadCityFile(dir + "/region_0_0.osgb");
    ASSERT_FALSE(missing.isOk());
    EXPECT_NE(missing.status().message().find("region_0_0.osgb"), std::string::npos);
    auto truncated = vista::loadCityFile(dir + "/region_1_1.osgb");
    ASSERT_FALSE(truncated.isOk());
    EXPECT_NE(truncated.status().message().find("region_1_1.osgb"), std::string::npos);
    EXPECT_FALSE(osg::ref_ptr<osg::Node>(osgDB::readNodeFile(dir + "/region_0_0.osgb")).valid());
    osg::ref_ptr<osg::Node> part = osgDB::readNodeFile(dir + "/region_1_1.osgb");  // may return a part; must not crash
    // The index and the other regions still load.
    EXPECT_TRUE(vista::readSceneFile(dir + "/index.osgb").isOk());
    EXPECT_TRUE(vista::loadCityFile(dir + "/region_0_1.osgb").isOk());
}

TEST_F(Paged, BadInputExitsTwoAndLeavesNothing) {
    std::ofstream(tmp.file("file.paged")) << "x";
    struct Case {
        std::string args, field;
    };
    const std::string out = " -o " + tmp.file("out.paged");
    const std::vector<Case> cases{
        {"gen --size 1500 -q --region-size 100" + out, "--region-size = '100' is out of range [250, 16000]"},
        {"gen --size 1500 -q --region-size 333" + out, "region_size_m"},
        {"gen --size 1500 -q --region-size 20000" + out, "16000"},
        {"gen --size 1500 -q -o " + tmp.file("file.paged"), "not a directory"},
        {"gen --size 1500 -q --shard 3/2" + out, "--shard"},
        {"gen --size 1500 -q --shard x" + out, "1 <= K <= N"},
        {"gen --size 1500 -q --shard 1/2 --merge" + out, "--merge"},
        {"gen --size 1500 -q --merge" + out, "missing"},
        {"gen --size 1500 -q --merge --shards 0" + out, "--shards = '0' is out of range [1, 100000]"},
        {"gen --size 1500 -q --merge --shards x2" + out, "--shards"},
        {"gen --size 1500 -q --shards 2" + out, "only with --merge"},
        {"gen --size 64001 -q" + out, "--size = '64001' is out of range [100, 64000]"},
        {"gen --size 1500 -q --gltf " + tmp.file("c.glb") + out, "--gltf"},
        {"gen --size 1500 -q --effects sun_shadows" + out, "effects"},
        {"gen --size 16001 -q -o " + tmp.file("c.osgb"), ".paged"},
        {"gen --size 1500 -q --region-size 500 -o " + tmp.file("c.osgb"), "--region-size"},
    };
    for (const auto& c : cases) {
        const std::set<std::string> before = listTree(tmp.path());
        const CliRun r = runVista(c.args);
        EXPECT_EQ(r.code, 2) << c.args << ": " << r.err;
        EXPECT_NE(r.err.find(c.field), std::string::npos) << c.args << ": " << r.err;
        EXPECT_EQ(listTree(tmp.path()), before) << c.args;
    }
}

// Stock OSG paging (what osgviewer does): a viewer over the index, the camera
// 150 m above region 0_0 looking down, pages in that region's coarse and then
// full file; the far corner region (beyond the full range) gets at most its
// coarse level.
TEST_F(Paged, StockViewerPagesTheNearRegionIn) {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) GTEST_SKIP() << "no DISPLAY: run the tests under xvfb-run -a";
    const std::string dir = refDir();
    osg::ref_ptr<osg::Node> index = osgDB::readNodeFile(dir + "/index.osgb");
    ASSERT_TRUE(index.valid());
    osg::PagedLOD *near = nullptr, *far = nullptr;
    for (unsigned i = 0; i < index->asGroup()->getNumChildren(); ++i) {
        auto* lod = dynamic_cast<osg::PagedLOD*>(index->asGroup()->getChild(i));
        ASSERT_NE(lod, nullptr);
        if (lod->getName() == "region_0_0") near = lod;
        if (lod->getName() == "region_2_2") far = lod;
    }
    ASSERT_NE(near, nullptr);
    ASSERT_NE(far, nullptr);
    const osg::Vec3 c = near->getCenter();
    ASSERT_GT((far->getCenter() - c).length(), far->getMaxRange(1)) << "the far region must be beyond its full range";

    osgViewer::Viewer viewer;
    viewer.setThreadingModel(osgViewer::Viewer::SingleThreaded);
    viewer.setUpViewInWindow(0, 0, 64, 64);
    viewer.setSceneData(index.get());
    viewer.realize();
    ASSERT_TRUE(viewer.isRealized());
    viewer.getCamera()->setViewMatrixAsLookAt(c + osg::Vec3(0, -1, 150), c, osg::Vec3(0, 1, 0));
    for (int frame = 0; frame < 3000 && near->getNumChildren() < 2; ++frame) {
        viewer.frame();
        viewer.getCamera()->setViewMatrixAsLookAt(c + osg::Vec3(0, -1, 150), c, osg::Vec3(0, 1, 0));
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    EXPECT_EQ(near->getNumChildren(), 2u) << "the near region's full level was not paged in";
    EXPECT_LE(far->getNumChildren(), 1u) << "the far region got its full level";
    if (near->getNumChildren() == 2) {
        osg::Group* full = near->getChild(1)->asGroup();
        ASSERT_NE(full, nullptr);
        EXPECT_EQ(full->getName(), "vista.city");
        EXPECT_GT(full->getNumChildren(), 0u);
    }
}

namespace {
struct FindImpostors : osg::NodeVisitor {
    FindImpostors() : osg::NodeVisitor(TRAVERSE_ALL_CHILDREN) {}
    size_t geometries = 0, instances = 0, textured = 0;
    void apply(osg::Geode& g) override {
        for (unsigned i = 0; i < g.getNumDrawables(); ++i) {
            const osg::Geometry* geo = g.getDrawable(i)->asGeometry();
            if (!geo || !vista::isTreeImpostorName(geo->getName())) continue;
            ++geometries;
            instances += size_t(geo->getPrimitiveSet(0)->getNumInstances());
            const osg::StateSet* ss = geo->getStateSet();
            auto* tex =
                ss ? dynamic_cast<const osg::Texture2D*>(ss->getTextureAttribute(0, osg::StateAttribute::TEXTURE))
                   : nullptr;
            if (tex && tex->getImage() && tex->getImage()->s() == 2 * vista::kCoarseImpostorCellPixels &&
                tex->getImage()->data())
                ++textured;
        }
    }
};
}  // namespace

// The coarse level keeps the region's trees as impostors: the coarse file
// loads (loadCityFile) with one impostor per tree of the full file, no
// prototype mesh, and the impostor geometries carry their atlas inline (the
// stock reader sees it too).
TEST_F(Paged, CoarseLevelDrawsTreesAsImpostors) {
    const std::string dir = refDir();
    size_t trees = 0;
    const auto manifest = readJson(dir + "/manifest.json");
    for (const auto& r : manifest["regions"]) {
        if (r["empty"].get<bool>()) continue;
        const std::string name =
            "region_" + std::to_string(r["ix"].get<int>()) + "_" + std::to_string(r["iy"].get<int>());
        auto full = vista::loadCityFile(dir + "/" + name + ".osgb");
        auto coarse = vista::loadCityFile(dir + "/" + name + ".coarse.osgb");
        ASSERT_TRUE(full.isOk() && coarse.isOk()) << name;
        EXPECT_TRUE(coarse->instances.empty()) << name;
        ASSERT_EQ(coarse->impostors.size(), full->instances.size()) << name;
        std::multiset<std::tuple<uint32_t, double, double>> a, b;
        for (const auto& in : full->instances) a.insert({in.prototype, in.transform[3].x, in.transform[3].y});
        for (const auto& in : coarse->impostors) b.insert({in.prototype, in.transform[3].x, in.transform[3].y});
        EXPECT_TRUE(a == b) << name << ": impostors at other places than the trees";
        trees += coarse->impostors.size();
        osg::ref_ptr<osg::Node> stock = osgDB::readNodeFile(dir + "/" + name + ".coarse.osgb");
        ASSERT_TRUE(stock.valid()) << name;
        FindImpostors f;
        stock->accept(f);
        EXPECT_EQ(f.instances, coarse->impostors.size()) << name;
        EXPECT_EQ(f.textured, f.geometries) << name << ": an impostor without its inline atlas";
    }
    EXPECT_GT(trees, 0u);
}

// An OSM extract written as a paged city (vista gen --osm X -o DIR.paged): the
// city is the extract's own extent, and the regions hold the single file's
// buildings (imported footprints and procedural lots beside them) once each.
TEST_F(Paged, OsmExtractPagesTheSingleFileCity) {
    const std::string town = std::string(VISTA_SOURCE_DIR) + "/tests/data/osm/town.osm";
    CliRun r = runVista("gen -q --detail 0 --osm " + town + " -o " + tmp.file("one.osgb") + " --stats " +
                        tmp.file("one.json"));
    ASSERT_EQ(r.code, 0) << r.err;
    r = runVista("gen -q --detail 0 --osm " + town + " --region-size 500 -o " + tmp.file("t.paged") + " --stats " +
                 tmp.file("paged.json"));
    ASSERT_EQ(r.code, 0) << r.err;
    const auto one = readJson(tmp.file("one.json")), paged = readJson(tmp.file("paged.json"));
    const auto m = readJson(tmp.file("t.paged") + "/manifest.json");
    EXPECT_EQ(m["params"]["size_m"], one["size_m"]);
    EXPECT_TRUE(m["params"].contains("geo")) << m["params"].dump();
    EXPECT_EQ(m["regions"].size(), 4u);  // 1 km in 500 m regions
    EXPECT_EQ(paged["street_edges"], one["street_edges"]);
    EXPECT_EQ(m["totals"]["buildings"].get<size_t>(), one["buildings"].get<size_t>());
    EXPECT_GT(one["osm_buildings"]["imported"].get<size_t>(), 0u);
    EXPECT_EQ(paged["osm_roads"], one["osm_roads"]);
    // The given streets travel beside the regions: a seeded path on the paged city is the
    // single file's path (a grown graph would be another city's streets).
    EXPECT_EQ(m["streets"], "streets.json");
    r = runVista("path " + tmp.file("t.paged") + " --seed 3 -o " + tmp.file("paged.csv"));
    ASSERT_EQ(r.code, 0) << r.err;
    r = runVista("path " + tmp.file("one.osgb") + " --seed 3 -o " + tmp.file("one.csv"));
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(readBytes(tmp.file("paged.csv")), readBytes(tmp.file("one.csv")));
    // The regions' records name the input: a rerun reuses them all.
    r = runVista("gen -q --detail 0 --osm " + town + " --region-size 500 -o " + tmp.file("t.paged") + " --stats " +
                 tmp.file("again.json"));
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(readJson(tmp.file("again.json"))["regions_reused"], 4);
}
