// OpenDRIVE through the tool: `vista gen --xodr` and `vista export` write the same bytes;
// `vista gen --xodr --stats` counts the road network; bad input is exit 2 without a file.
#include <gtest/gtest.h>

#include <expat.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "citygen/generate.h"
#include "citygen/lanes.h"
#include "citygen/opendrive.h"
#include "citygen/streets.h"
#include "tests/common/run_vista.h"
#include "tests/common/temp_dir.h"
#include "tests/citygen/opendrive_fixtures.h"

namespace fs = std::filesystem;
using namespace vista;
using vista::test::readBytes;
using vista::test::runVista;
using vista::test::TempDir;

TEST(OpenDrive, GenAndExportWriteTheSameBytes) {
    TempDir dir("vista_xodr_cli");
    const std::string city = dir.file("c.osgb"), a = dir.file("a.xodr"), b = dir.file("b.xodr");
    auto r = runVista("gen --size 300 --seed 4 --detail 0 -q -o " + city + " --xodr " + a);
    ASSERT_EQ(r.code, 0) << r.err;
    r = runVista("export " + city + " --xodr " + b + " -q");
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string x = readBytes(a);
    EXPECT_GT(x.size(), 1000u);
    EXPECT_EQ(x, readBytes(b));
}

// The network's counts: `gen --stats` carries them under "opendrive", `export
// --stats` writes the same object; an output path given twice is exit 2.
TEST(OpenDrive, GenAndExportCountTheSameNetwork) {
    TempDir dir("vista_xodr_stats");
    const std::string city = dir.file("c.osgb"), a = dir.file("a.xodr"), b = dir.file("b.xodr");
    auto r = runVista("gen --size 300 --seed 4 --detail 0 -q -o " + city + " --xodr " + a + " --stats " +
                      dir.file("gen.json"));
    ASSERT_EQ(r.code, 0) << r.err;
    r = runVista("export " + city + " --xodr " + b + " --stats " + dir.file("export.json") + " -q");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto gen = nlohmann::json::parse(readBytes(dir.file("gen.json")));
    const auto exp = nlohmann::json::parse(readBytes(dir.file("export.json")));
    ASSERT_TRUE(gen.contains("opendrive"));
    EXPECT_EQ(gen["opendrive"], exp);
    for (const char* key :
         {"roads", "junctions", "connecting_roads", "dropped_turns", "tight_turns", "tight_turns_kept",
          "crossing_turns", "crossing_turns_kept", "joined_edges", "overlapping_arms", "unlinked_lanes"})
        EXPECT_TRUE(exp.contains(key)) << key;
    EXPECT_GT(exp["roads"].get<int>(), 0);
    EXPECT_GE(exp["min_turn_radius_m"].get<double>(), kMinTurnRadiusLocal);
    const std::string c = dir.file("c2.xodr");
    r = runVista("export " + city + " --xodr " + c + " --stats " + c + " -q");
    EXPECT_EQ(r.code, 2);
    EXPECT_FALSE(fs::exists(c));
}

TEST(OpenDrive, ExportBadInputIsExit2WithoutFile) {
    TempDir dir("vista_xodr_bad");
    const std::string out = dir.file("x.xodr");
    auto r = runVista("export " + dir.file("missing.osgb") + " --xodr " + out);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("missing.osgb"), std::string::npos) << r.err;
    r = runVista("export " + dir.file("missing.osgb") + " --xodr " + dir.file("x.txt"));
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find(".xodr"), std::string::npos) << r.err;
    r = runVista("export " + dir.file("missing.osgb") + " --xodr " + dir.file("no/such/dir/x.xodr"));
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--xodr"), std::string::npos) << r.err;
    r = runVista("export " + dir.file("missing.osgb"));
    EXPECT_EQ(r.code, 2);
    r = runVista("gen --size 300 -q -o " + dir.file("c.osgb") + " --xodr " + dir.file("c.txt"));
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--xodr"), std::string::npos) << r.err;
    EXPECT_TRUE(vista::test::listTree(dir.path()).empty());
}

// `vista gen --xodr --stats` counts the road network in the stats (object
// "opendrive"): its roads, junctions and signals are those of the file
// (counted here from the XML), no junction lane is left without a
// connection in or out, and without --xodr the object is absent.
TEST(OpenDrive, GenStatsCountTheRoadNetwork) {
    TempDir dir("vista_xodr_stats");
    const std::string city = dir.file("c.osgb"), x = dir.file("c.xodr"), st = dir.file("s.json");
    auto r = runVista("gen --osm " + std::string(VISTA_TEST_DATA) + "/osm/lanes.osm --detail 0 -q -o " + city +
                      " --xodr " + x + " --stats " + st);
    ASSERT_EQ(r.code, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(readBytes(st));
    ASSERT_TRUE(j.contains("opendrive")) << j.dump();
    const nlohmann::json& o = j["opendrive"];
    std::string err;
    auto doc = parseXml(readBytes(x), &err);
    ASSERT_TRUE(doc) << err;
    size_t roads = 0, connecting = 0, lights = 0, signs = 0, tapered = 0;
    for (const Element* rd : doc->all("road")) {
        if (rd->str("junction") != "-1") ++connecting;
        else if (rd->str("name").rfind("transition", 0) != 0) ++roads;  // street roads, not transitions
        if (rd->str("junction") != "-1" || rd->str("name").rfind("transition", 0) == 0) {
            // Link-road driving lanes whose single width cubic is 0 at s = 0 or at s = length.
            const double L = rd->num("length");
            for (const Element* sec : rd->first("lanes")->all("laneSection"))
                for (const char* side : {"left", "right"})
                    if (const Element* lanes = sec->first(side))
                        for (const Element* lane : lanes->all("lane")) {
                            const Element* w = lane->first("width");
                            if (lane->str("type") != "driving" || !w) continue;
                            const double w0 = w->num("a"),
                                         w1 = w0 + L * (w->num("b") + L * (w->num("c") + L * w->num("d")));
                            tapered += std::abs(w0) < 1e-9 || std::abs(w1) < 1e-6;
                        }
        }
        if (const Element* s = rd->first("signals"))
            for (const Element* sg : s->all("signal")) ++(sg->str("dynamic") == "yes" ? lights : signs);
    }
    EXPECT_EQ(o["roads"].get<size_t>(), roads);
    EXPECT_EQ(o["connecting_roads"].get<size_t>(), connecting);
    EXPECT_EQ(o["junctions"].get<size_t>(), doc->all("junction").size());
    EXPECT_EQ(o["traffic_lights"].get<size_t>(), lights);
    EXPECT_EQ(o["signs"].get<size_t>(), signs);
    EXPECT_EQ(o["unlinked_lanes"].get<size_t>(), 0u);
    EXPECT_EQ(o["unfed_lanes"].get<size_t>(), 0u);
    EXPECT_EQ(o["tapered_lanes"].get<size_t>(), tapered);
    r = runVista("gen --size 300 --seed 4 --detail 0 -q -o " + dir.file("d.osgb") + " --stats " + dir.file("t.json"));
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_FALSE(nlohmann::json::parse(readBytes(dir.file("t.json"))).contains("opendrive"));
}

// Paged output writes the whole road network as one .xodr with the index: the
// bytes of the single-file city (same streets), its counts in --stats; a run
// that reuses every region writes it again; a shard is refused (exit 2,
// naming --xodr, nothing written).
TEST(OpenDrive, PagedOutputWritesTheWholeNetwork) {
    TempDir dir("vista_xodr_paged");
    const std::string single = dir.file("single.xodr"), paged = dir.file("paged.xodr"), st = dir.file("s.json");
    auto r = runVista("gen --size 500 --seed 4 --detail 0 -q -o " + dir.file("c.osgb") + " --xodr " + single);
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string city = " --size 500 --seed 4 --detail 0 --region-size 250 -q -o " + dir.file("c.paged");
    r = runVista("gen" + city + " --xodr " + paged + " --stats " + st);
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string bytes = readBytes(paged);
    EXPECT_GT(bytes.size(), 1000u);
    EXPECT_EQ(bytes, readBytes(single));
    const nlohmann::json j = nlohmann::json::parse(readBytes(st));
    ASSERT_TRUE(j.contains("opendrive")) << j.dump();
    EXPECT_GT(j["opendrive"]["roads"].get<int>(), 0);
    fs::remove(paged);
    r = runVista("gen" + city + " --xodr " + paged);  // every region reused
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(readBytes(paged), bytes);
    const std::string shard = dir.file("shard.xodr");
    r = runVista("gen --size 500 --seed 4 --detail 0 --region-size 250 -q -o " + dir.file("s.paged") +
                 " --shard 1/2 --xodr " + shard);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--xodr"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(shard));
    EXPECT_FALSE(fs::exists(dir.file("s.paged")));
}
