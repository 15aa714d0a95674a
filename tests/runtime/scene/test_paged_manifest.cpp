// The paged city's manifest.json as readPagedManifest() reads it
// (runtime/scene/paged_load.h, docs/formats.md "Paged city"): every field
// the reader uses is checked against its range and against the grid, and a
// bad one is refused naming the manifest file, the field and the value:
// byte counts that are negative or fractional (never wrapped to 2^64 - 5),
// a region size of 0 or below, a region listed twice, ix / iy off the grid,
// a file listed by two regions, and a manifest whose every region is empty.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "runtime/scene/paged_load.h"
#include "tests/common/small_paged_city.h"
#include "tests/common/temp_dir.h"

namespace fs = std::filesystem;
using Json = nlohmann::json;

namespace {

class PagedManifest : public vista::test::SmallPagedCity {
protected:
    // The fixture's manifest changed by `edit`, written alone into a fresh
    // directory (the reader opens no region file), and read back.
    vista::Result<vista::PagedManifest> readEdited(const std::function<void(Json&)>& edit) {
        Json j = Json::parse(vista::test::readBytes((fs::path(dir()) / "manifest.json").string()));
        edit(j);
        const std::string d = tmp.file("edited" + std::to_string(++_edits) + ".paged");
        fs::create_directories(d);
        std::ofstream(fs::path(d) / "manifest.json") << j.dump(2);
        return vista::readPagedManifest(d);
    }
    // The edit is refused with a message naming the manifest and every part of `wants`.
    void expectRefused(const std::string& what, const std::function<void(Json&)>& edit,
                       std::initializer_list<std::string> wants) {
        SCOPED_TRACE(what);
        auto m = readEdited(edit);
        ASSERT_FALSE(m.isOk());
        const std::string& msg = m.status().message();
        EXPECT_NE(msg.find("manifest.json"), std::string::npos) << msg;
        for (const std::string& w : wants) EXPECT_NE(msg.find(w), std::string::npos) << msg << "\nwant: " << w;
    }
    int _edits = 0;
};

// The first non-empty region's entry.
Json& firstFull(Json& j) {
    for (Json& e : j["regions"])
        if (!e["empty"].get<bool>()) return e;
    return j["regions"][0];
}

}  // namespace

TEST_F(PagedManifest, TheWrittenManifestIsAccepted) {
    auto m = readEdited([](Json&) {});
    ASSERT_TRUE(m.isOk()) << m.status().message();
    EXPECT_EQ(m->regions.size(), 9u);
    for (size_t i = 0; i < m->regions.size(); ++i) EXPECT_EQ(m->regions[i].region, int(i));
}

TEST_F(PagedManifest, ByteCountsAreIntegersInRange) {
    expectRefused("bytes -5", [](Json& j) { firstFull(j)["files"][0]["bytes"] = -5; },
                  {"files[0]", "field 'bytes' = -5", "out of range", "[1, 1099511627776]"});
    expectRefused("bytes 0", [](Json& j) { firstFull(j)["files"][1]["bytes"] = 0; }, {"field 'bytes' = 0"});
    expectRefused("bytes 1.5", [](Json& j) { firstFull(j)["files"][0]["bytes"] = 1.5; }, {"field 'bytes' = 1.5"});
    expectRefused("bytes 2^64 as text", [](Json& j) { firstFull(j)["files"][0]["bytes"] = 1.8446744073709552e19; },
                  {"field 'bytes'"});
    expectRefused("triangles -1", [](Json& j) { j["regions"][2]["triangles"] = -1; },
                  {"regions[2]", "field 'triangles' = -1"});
    expectRefused("bytes missing", [](Json& j) { firstFull(j)["files"][0].erase("bytes"); },
                  {"field 'bytes' is missing"});
}

TEST_F(PagedManifest, RegionSizeAndGridMatchTheCity) {
    for (double size : {0.0, -500.0, 1e300})
        expectRefused("region_size_m " + std::to_string(size), [&](Json& j) { j["region_size_m"] = size; },
                      {"region_size_m", "out of range"});
    expectRefused("region_size_m text", [](Json& j) { j["region_size_m"] = "500"; }, {"region_size_m", "not a number"});
    // 750 m is a valid size, but the city's 3 x 3 grid is of 500 m regions.
    expectRefused("region_size_m 750", [](Json& j) { j["region_size_m"] = 750.0; },
                  {"regions_x'/'regions_y' = 3/3", "expected 2/2"});
    expectRefused("regions_x 0", [](Json& j) { j["regions_x"] = 0; }, {"field 'regions_x' = 0", "[1, 4096]"});
}

TEST_F(PagedManifest, EachRegionIsListedOnceInOrder) {
    // Region 0 twice, region 1 dropped: the loader would load region 0 twice.
    expectRefused("region 0 twice", [](Json& j) { j["regions"][1] = j["regions"][0]; },
                  {"regions[1]", "field 'region' = 0 repeats regions[0]"});
    expectRefused("regions swapped", [](Json& j) { std::swap(j["regions"][0], j["regions"][1]); },
                  {"regions[0]", "field 'region' = 1"});
    expectRefused("region beyond the grid", [](Json& j) { j["regions"][8]["region"] = 9; },
                  {"regions[8]", "field 'region' = 9", "[0, 8]"});
    expectRefused("ix of another region", [](Json& j) { j["regions"][4]["ix"] = 0; },
                  {"regions[4]", "'ix'/'iy' = 0/1", "expected 1/1"});
    expectRefused("one file for two regions",
                  [](Json& j) { j["regions"][1]["files"][0]["name"] = j["regions"][0]["files"][0]["name"]; },
                  {"regions[1]", "is also listed by regions[0]"});
    expectRefused("empty not a boolean", [](Json& j) { j["regions"][3]["empty"] = 0; },
                  {"regions[3]", "field 'empty' = 0 is not true or false"});
    expectRefused("a third role", [](Json& j) { firstFull(j)["files"][0]["role"] = "preview"; },
                  {"field 'role' = \"preview\""});
    expectRefused("bounds min above max",
                  [](Json& j) {
                      Json& b = firstFull(j)["bounds"];
                      std::swap(b[0], b[3]);
                  },
                  {"field 'bounds'", "minimum above its maximum"});
}

TEST_F(PagedManifest, AManifestWithoutANonEmptyRegionIsRefused) {
    expectRefused("all empty",
                  [](Json& j) {
                      for (Json& e : j["regions"]) {
                          e["empty"] = true;
                          e.erase("files");
                          e.erase("bounds");
                      }
                  },
                  {"every region is 'empty'"});
}

TEST_F(PagedManifest, TheCommandsRefuseABadManifestWithExitTwo) {
    const std::string copy = tmp.file("bad.paged");
    fs::create_directories(copy);
    Json j = Json::parse(vista::test::readBytes((fs::path(dir()) / "manifest.json").string()));
    firstFull(j)["files"][0]["bytes"] = -5;
    std::ofstream(fs::path(copy) / "manifest.json") << j.dump(2);
    const auto r = vista::test::runVista("path " + copy + " -o " + tmp.file("p.csv"));
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("field 'bytes' = -5"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(tmp.file("p.csv")));
}
