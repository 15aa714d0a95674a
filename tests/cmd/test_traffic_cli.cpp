// vista traffic on the command line: a small city simulated by SUMO gives the
// same bytes for the same seed; bad options, an existing output and a missing
// SUMO are refused with exit 2 and leave nothing behind.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/common/run_vista.h"
#include "tests/common/sumo_city.h"
#include "tests/common/temp_dir.h"

namespace fs = std::filesystem;
using vista::test::listTree;
using vista::test::readBytes;
using vista::test::runVista;
using vista::test::TempDir;

namespace {

// One small city for every test of this file (generated once).
const std::string& smallCity() {
    static TempDir dir("vista_traffic_city");  // lives for the whole run, removed at exit
    static std::string city;
    if (city.empty()) {
        city = dir.file("city.osgb");
        const auto r = vista::test::genTrafficCity(city);
        EXPECT_EQ(r.code, 0) << r.err;
    }
    return city;
}

}  // namespace

TEST(TrafficCli, SameSeedSameBytesAndTheManifestCountsTheAgents) {
    VISTA_SKIP_WITHOUT_SUMO();
    TempDir tmp("vista_traffic_run");
    const std::string args = " --vehicles 30 --pedestrians 30 --duration 90 --seed 4 -q -o ";
    const auto a = runVista("traffic " + smallCity() + args + tmp.file("a"));
    ASSERT_EQ(a.code, 0) << a.err;
    const auto b = runVista("traffic " + smallCity() + args + tmp.file("b"));
    ASSERT_EQ(b.code, 0) << b.err;
    const auto files = listTree(tmp.file("a"));
    EXPECT_EQ(files, listTree(tmp.file("b")));
    for (const char* f : {"city.xodr", "city.net.xml", "demand.rou.xml", "traffic.sumocfg", "fcd.xml", "signals.xml",
                          "statistics.xml", "traffic.json"}) {
        ASSERT_TRUE(files.count(f)) << f;
        EXPECT_EQ(readBytes(tmp.file("a") + "/" + f), readBytes(tmp.file("b") + "/" + f)) << f << " differs";
    }
    // No work folder or log is left.
    EXPECT_FALSE(fs::exists(tmp.file("a.partial")));
    EXPECT_FALSE(files.count("sumo.log"));
    const auto j = nlohmann::json::parse(readBytes(tmp.file("a/traffic.json")));
    int total = 0;
    for (const auto& [type, n] : j["agents_by_type"].items()) total += n.get<int>();
    EXPECT_EQ(total, 60);
    EXPECT_EQ(j["agents_by_type"]["pedestrian"].get<int>(), 30);
    EXPECT_EQ(j["sumo"]["vehicles_inserted"].get<int>(), 30);
    EXPECT_EQ(j["sumo"]["teleports"].get<int>(), 0);
    // The FCD holds vehicles and persons; SUMO's date is not in it.
    const std::string fcd = readBytes(tmp.file("a/fcd.xml"));
    EXPECT_NE(fcd.find("<vehicle id=\"veh"), std::string::npos);
    EXPECT_NE(fcd.find("<person id=\"ped"), std::string::npos);
    EXPECT_EQ(fcd.find("generated on"), std::string::npos);
    // Another seed, other traffic.
    const auto c = runVista("traffic " + smallCity() + " --vehicles 30 --pedestrians 30 --duration 90 --seed 5 -q -o " +
                            tmp.file("c"));
    ASSERT_EQ(c.code, 0) << c.err;
    EXPECT_NE(readBytes(tmp.file("a/fcd.xml")), readBytes(tmp.file("c/fcd.xml")));
}

TEST(TrafficCli, BadOptionsNameTheOptionAndItsRange) {
    TempDir tmp("vista_traffic_bad");
    struct Case {
        const char* args;
        const char* named;
    } cases[] = {
        {"--step 0", "--step"},
        {"--step 3", "--step"},
        {"--duration 0.5", "--duration"},
        {"--duration 10 --step 0.3", "not a whole number of --step"},
        {"--vehicles -1", "--vehicles"},
        {"--pedestrians 100001", "--pedestrians"},
        {"--vehicles 0 --pedestrians 0", "no traffic"},
        {"--seed -1", "--seed"},
    };
    for (const Case& c : cases) {
        const auto r = runVista("traffic " + tmp.file("no-city.osgb") + " -o " + tmp.file("out") + " " + c.args);
        EXPECT_EQ(r.code, 2) << c.args << ": " << r.err;
        EXPECT_NE(r.err.find(c.named), std::string::npos) << c.args << ": " << r.err;
        EXPECT_FALSE(fs::exists(tmp.file("out"))) << c.args;
    }
}

TEST(TrafficCli, AnExistingOutputAMissingCityAndAMissingSumoAreRefused) {
    TempDir tmp("vista_traffic_refused");
    fs::create_directories(tmp.file("taken"));
    std::ofstream(tmp.file("taken/keep.txt")) << "mine";
    const auto taken = runVista("traffic " + smallCity() + " -o " + tmp.file("taken"));
    EXPECT_EQ(taken.code, 2) << taken.err;
    EXPECT_NE(taken.err.find("exists"), std::string::npos) << taken.err;
    EXPECT_EQ(readBytes(tmp.file("taken/keep.txt")), "mine");
    EXPECT_EQ(listTree(tmp.file("taken")).size(), 1u);

    const auto missing = runVista("traffic " + tmp.file("nowhere.osgb") + " -o " + tmp.file("out1"));
    EXPECT_EQ(missing.code, 2) << missing.err;
    EXPECT_NE(missing.err.find("nowhere.osgb"), std::string::npos) << missing.err;
    EXPECT_FALSE(fs::exists(tmp.file("out1")));

    fs::create_directories(tmp.file("empty-bin"));
    const auto noSumo =
        runVista("traffic " + smallCity() + " -o " + tmp.file("out2"), "VISTA_SUMO_BIN=" + tmp.file("empty-bin"));
    EXPECT_EQ(noSumo.code, 2) << noSumo.err;
    EXPECT_NE(noSumo.err.find("SUMO is not installed"), std::string::npos) << noSumo.err;
    EXPECT_FALSE(fs::exists(tmp.file("out2")));
    EXPECT_FALSE(fs::exists(tmp.file("out2.partial")));
}
