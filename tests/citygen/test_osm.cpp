// importOsm(): fixtures in tests/data/osm (hard geometric cases, truncated XML, no roads).
#include <gtest/gtest.h>

#include <cmath>

#include "citygen/streets.h"

using namespace vista;

namespace {
std::string fixture(const char* name) { return std::string(VISTA_TEST_DATA) + "/osm/" + name; }
}  // namespace

TEST(OsmImport, HardCasesGivePlanarGraph) {
    CityParams p;
    auto r = importOsm(fixture("hard_cases.osm"), p);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    const StreetGraph& g = r->streets;
    EXPECT_TRUE(checkPlanarGraph(g, p.min_segment_m).isOk()) << checkPlanarGraph(g, p.min_segment_m).message();
    for (const auto& n : g.nodes) EXPECT_TRUE(std::isfinite(n.x) && std::isfinite(n.y));
    // Footways are skipped, primary/secondary/residential kept: all three classes present.
    int cnt[3] = {0, 0, 0};
    for (const auto& e : g.edges) cnt[int(e.cls)]++;
    EXPECT_GT(cnt[int(RoadClass::Highway)], 0);
    EXPECT_GT(cnt[int(RoadClass::Arterial)], 0);
    EXPECT_GT(cnt[int(RoadClass::Local)], 0);
    // Extent: the fixture spans 0.009 deg of longitude at 48.2 N (~668 m) about its centre.
    double maxX = 0;
    for (const auto& n : g.nodes) maxX = std::max(maxX, std::abs(n.x));
    double expected = 0.0045 * 3.14159265358979 / 180.0 * 6371008.8 * std::cos(48.2 * 3.14159265358979 / 180.0);
    EXPECT_NEAR(maxX, expected, 2.0);
    // The crossing residential way (no shared node) must be split into a 4-way junction.
    auto deg = g.degrees();
    EXPECT_GE(*std::max_element(deg.begin(), deg.end()), 4);
}

TEST(OsmImport, TruncatedFileIsAnErrorNamingTheFile) {
    auto r = importOsm(fixture("truncated.osm"), CityParams());
    ASSERT_FALSE(r.isOk());
    EXPECT_NE(r.status().message().find("truncated.osm"), std::string::npos) << r.status().message();
}

TEST(OsmImport, MissingFileIsAnError) {
    auto r = importOsm(fixture("does_not_exist.osm"), CityParams());
    ASSERT_FALSE(r.isOk());
    EXPECT_NE(r.status().message().find("does_not_exist.osm"), std::string::npos);
}

TEST(OsmImport, NoHighwaysIsAClearError) {
    auto r = importOsm(fixture("no_highways.osm"), CityParams());
    ASSERT_FALSE(r.isOk());
    EXPECT_NE(r.status().message().find("highway"), std::string::npos) << r.status().message();
}

TEST(OsmImport, GarbageFileIsAnError) {
    // A non-OSM file must not crash the reader.
    auto r = importOsm(std::string(VISTA_SOURCE_DIR) + "/tests/data/osm/garbage.osm", CityParams());
    EXPECT_FALSE(r.isOk());
}
