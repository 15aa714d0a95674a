// importOsm() and geodesy: fixtures in tests/data/osm (hard geometric cases,
// truncated XML, no roads) and synthetic .osm files written to a temp dir
// (any latitude, the antimeridian, outliers, absurd coordinates, tangles);
// the projection against an independent Vincenty geodesic; the geo
// reference in the params JSON, GeoJSON and the scene written by vista gen.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <random>

#include <nlohmann/json.hpp>

#include "citygen/footprint_repair.h"
#include "citygen/generate.h"
#include <bzlib.h>

#include "citygen/geodesy.h"
#include "citygen/osm_buildings.h"
#include "citygen/polygon.h"
#include "citygen/short_bends.h"
#include "citygen/streets.h"
#include "tests/common/temp_dir.h"
#include "tests/citygen/osm_fixtures.h"

using namespace vista;
namespace {
Result<OsmImport> importText(const test::TempDir& dir, const std::string& text, const std::string& name = "t.osm") {
    const std::string path = dir.file(name);
    std::ofstream(path, std::ios::binary) << text;
    return importOsm(path, CityParams());
}

}  // namespace

// ---- importOsm --------------------------------------------------------------------

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
    // Extent: the fixture spans 0.009 deg of longitude at 48.2 N, centred on the bounding box.
    double maxX = 0;
    for (const auto& n : g.nodes) maxX = std::max(maxX, std::abs(n.x));
    EXPECT_NEAR(maxX, 0.5 * vincenty({48.2, 16.370}, {48.2, 16.379}), 0.05);
    EXPECT_NEAR(r->geo.lat0_deg, 48.2, 1e-6);
    EXPECT_NEAR(r->geo.lon0_deg, 16.3745, 1e-6);
    EXPECT_EQ(r->dropSummary(), "");
    // The crossing residential way (no shared node) must be split into a 4-way junction.
    auto deg = g.degrees();
    EXPECT_GE(*std::max_element(deg.begin(), deg.end()), 4);
}

TEST(OsmImport, DistancesMatchGeodesicsAtAnyLatitude) {
    // Twelve disjoint spokes (inner end 300 m, outer end 2 .. 7.5 km from the centre) per centre;
    // each comes out as one edge: its length and the distances between the outer ends are
    // compared with Vincenty, pairs up to ~15 km apart.
    const GeoPoint centres[] = {{0, 0}, {60, 10}, {-60, 100}, {89.5, 45}, {89.95, 0}, {-89.5, -120}, {20, 179.99}};
    for (const auto& c : centres) {
        test::TempDir dir("vista_osm");
        OsmWriter w;
        std::vector<std::pair<int64_t, int64_t>> spokes;
        for (int k = 0; k < 12; ++k) {
            const double b = 30.0 * k + 7.0;
            spokes.emplace_back(w.node(destination(c, b, 300 + 10 * k)), w.node(destination(c, b, 2000 + 500 * k)));
            w.way({spokes.back().first, spokes.back().second});
        }
        CityParams big;
        big.size_m = 16000;  // the city holds every spoke (roads are clipped to the city square)
        auto r = importOsm(w.write(dir, "spokes.osm"), big);
        ASSERT_TRUE(r.isOk()) << r.status().message();
        const StreetGraph& g = r->streets;
        ASSERT_EQ(g.edges.size(), 12u) << c.lat_deg << ", " << c.lon_deg;
        std::vector<glm::dvec2> tips(12);
        for (size_t e = 0; e < g.edges.size(); ++e) {
            const double len = g.edgeLength(e);
            int k = 0;  // the spoke of this edge: lengths differ by ~500 m
            for (int s = 1; s < 12; ++s)
                if (std::abs(vincenty(w.at(spokes[s].first), w.at(spokes[s].second)) - len) <
                    std::abs(vincenty(w.at(spokes[k].first), w.at(spokes[k].second)) - len))
                    k = s;
            const double expected = vincenty(w.at(spokes[k].first), w.at(spokes[k].second));
            EXPECT_NEAR(len, expected, 1e-4 * expected)
                << "centre " << c.lat_deg << ", " << c.lon_deg << " spoke " << k;
            const glm::dvec2 a = g.nodes[g.edges[e].a], bb = g.nodes[g.edges[e].b];
            tips[size_t(k)] = glm::length(a) > glm::length(bb) ? a : bb;
        }
        for (int i = 0; i < 12; ++i)
            for (int j = i + 1; j < 12; ++j) {
                const double expected = vincenty(w.at(spokes[i].second), w.at(spokes[j].second));
                EXPECT_NEAR(glm::length(tips[i] - tips[j]), expected, 1e-4 * expected)
                    << c.lat_deg << " tips " << i << " " << j;
            }
        // The frame is centred on the bounding box.
        glm::dvec2 lo(1e300), hi(-1e300);
        for (const auto& n : g.nodes) {
            lo = glm::min(lo, n);
            hi = glm::max(hi, n);
        }
        EXPECT_NEAR(lo.x + hi.x, 0.0, 0.05);
        EXPECT_NEAR(lo.y + hi.y, 0.0, 0.05);
        EXPECT_NEAR(hi.x - lo.x, r->extentX_m, 1e-6);
    }
}

TEST(OsmImport, ExtractAcrossTheAntimeridianHasItsRealExtent) {
    test::TempDir dir("vista_osm");
    OsmWriter w;
    const GeoPoint centre{-16.8, 180.0};  // Fiji
    w.grid(centre, 3000, 4);              // 3 km square of roads across 180 degrees
    CityParams big;
    big.size_m = 4000;  // the city holds the whole extract (roads are clipped to the city square)
    auto r = importOsm(w.write(dir, "fiji.osm"), big);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    const double expectedX = vincenty(destination(centre, 270, 1500), destination(centre, 90, 1500));
    const double expectedY = vincenty(destination(centre, 180, 1500), destination(centre, 0, 1500));
    EXPECT_NEAR(r->extentX_m, expectedX, 1e-3 * expectedX);
    EXPECT_NEAR(r->extentY_m, expectedY, 1e-3 * expectedY);
    EXPECT_NEAR(std::abs(r->geo.lon0_deg), 180.0, 1e-4);
    for (const auto& n : r->streets.nodes) EXPECT_LT(std::abs(n.x), 0.5 * expectedX + 1);
    EXPECT_TRUE(checkPlanarGraph(r->streets, CityParams().min_segment_m).isOk());
    EXPECT_EQ(r->streets.edges.size(), 4u * 5u * 2u);  // 4 x 4 crossings split each road in 5
}

TEST(OsmImport, InvalidMissingAndOutlierNodesAreDroppedAndCounted) {
    test::TempDir dir("vista_osm");
    OsmWriter w;
    const GeoPoint c{48.2, 16.37};
    w.grid(c, 1000, 3);
    auto valid = [&](double bearing, double d) { return w.node(destination(c, bearing, d)); };
    // Invalid coordinates in every spelling libosmium would parse (XML numeric entities included).
    const int64_t absurd = w.rawNode(R"(lat="48.2" lon="1e300")");
    w.way({valid(10, 100), absurd, valid(20, 150), valid(30, 300)});
    w.way({valid(40, 100), w.rawNode(R"(lat="95" lon="16.37")"), valid(45, 200)});
    w.way({valid(50, 100), w.rawNode(R"(lat="nan" lon="16.37")"), valid(55, 200)});
    w.way({valid(60, 100), w.rawNode(R"(lat="&#49;e300" lon="16.37")"), valid(65, 200)});
    w.way({valid(70, 100), w.rawNode(R"(lat='48.2' lon='-1e300')"), valid(75, 200)});
    w.way({valid(80, 100), w.rawNode("lat = \"48.2\"\n lon\t=\t\"2e19\""), valid(85, 200)});
    w.rawNode(R"(lat="1e300" lon="1e300")");  // not on a road: not counted
    // Exponent notation within range is fine.
    const GeoPoint expoAt{48.201, 16.371};
    w.way({w.rawNode(R"(lat="4.8201e1" lon="16371e-3")"), w.node(destination(expoAt, 45, 60))});
    w.way({valid(120, 100), 999999});                               // node missing from the file
    w.way({valid(130, 100), w.node(destination(c, 130, 500000))});  // 500 km away
    const std::string bounds = R"(  <bounds minlat="-1e300" minlon="16" maxlat="49" maxlon="1e300"/>)"
                               "\n";
    auto r = importOsm(w.write(dir, "dirty.osm", bounds), CityParams());
    ASSERT_TRUE(r.isOk()) << r.status().message();
    EXPECT_EQ(r->invalidNodes, 6u);
    EXPECT_EQ(r->missingNodes, 1u);
    EXPECT_EQ(r->outlierNodes, 1u);
    EXPECT_EQ(r->dropSummary(),
              "dropped 8 nodes (6 with invalid coordinates, 1 missing from the file, 1 outlier farther than 90.5 km "
              "from the median position)");
    EXPECT_LT(std::max(r->extentX_m, r->extentY_m), 1100);  // the city, not 500 km
    EXPECT_TRUE(checkPlanarGraph(r->streets, CityParams().min_segment_m).isOk());
    // The exponent-notation node is kept: its position is on the graph.
    const glm::dvec2 expo = projectToLocal(r->geo, expoAt);
    double nearest = 1e300;
    for (const auto& n : r->streets.nodes) nearest = std::min(nearest, glm::length(n - expo));
    EXPECT_LT(nearest, 0.05);
}

TEST(OsmImport, ExtentBeyondTheLargestCityIsRefused) {
    const double limit = maxCitySize();
    const GeoPoint c{60.17, 24.94};
    {  // A road leaving the city for a place 1.2 x the limit away: too big, not an outlier.
        test::TempDir dir("vista_osm");
        OsmWriter w;
        w.grid(c, 2000, 3);
        w.way({w.node(destination(c, 90, 900)), w.node(destination(c, 90, 1.2 * limit))});
        auto r = importOsm(w.write(dir, "long.osm"), CityParams());
        ASSERT_FALSE(r.isOk());
        const std::string& m = r.status().message();
        EXPECT_NE(m.find("long.osm"), std::string::npos) << m;
        const size_t at = m.find("the roads span ");
        ASSERT_NE(at, std::string::npos) << m;
        // 1,000 m + 1.2 x limit on the sphere the test places points on; WGS84 at 60 N is 0.36 % wider.
        EXPECT_NEAR(std::stod(m.substr(at + 15)), (1000 + 1.2 * limit) * 1.0036 / 1000, 0.06) << m;
        EXPECT_NE(m.find(" km east-west by 2.0"), std::string::npos) << m;  // the 2 km grid (2.01-2.02 km)
        EXPECT_NE(m.find("size_m up to " + std::to_string(int(limit)) + " m"), std::string::npos) << m;
    }
    {  // The same place 2 x the limit away is an outlier (> sqrt(2) x limit): dropped, the city stays.
        test::TempDir dir("vista_osm");
        OsmWriter w;
        w.grid(c, 2000, 3);
        w.way({w.node(destination(c, 90, 900)), w.node(destination(c, 90, 2 * limit))});
        auto r = importOsm(w.write(dir, "far.osm"), CityParams());
        ASSERT_TRUE(r.isOk()) << r.status().message();
        EXPECT_EQ(r->outlierNodes, 1u);
        EXPECT_NEAR(r->extentX_m, 2000 * 1.0036, 3);
    }
    {  // Evenly spread roads wider than the limit: refused (nothing is an outlier).
        test::TempDir dir("vista_osm");
        OsmWriter w;
        w.grid(c, 1.1 * limit, 3);
        auto r = importOsm(w.write(dir, "wide.osm"), CityParams());
        ASSERT_FALSE(r.isOk());
        const std::string& m = r.status().message();
        const size_t at = m.find("the roads span ");
        ASSERT_NE(at, std::string::npos) << m;
        EXPECT_NEAR(std::stod(m.substr(at + 15)), 1.1 * limit * 1.0036 / 1000, 0.06) << m;
    }
}

TEST(OsmImport, UnsafeXmlIsRefused) {
    test::TempDir dir("vista_osm");
    OsmWriter w;
    w.grid({48.2, 16.37}, 500, 2);
    // A DOCTYPE could give every node a default lat="1e300" the scan never sees as text.
    std::string text = w.text();
    text.insert(text.find("<osm"), "<!DOCTYPE osm [<!ATTLIST node lat CDATA \"1e300\">]>\n");
    auto r = importText(dir, text, "doctype.osm");
    ASSERT_FALSE(r.isOk());
    EXPECT_NE(r.status().message().find("DOCTYPE"), std::string::npos) << r.status().message();
    r = importText(dir, std::string("\xFF\xFE<\0?\0x\0m\0l\0", 12), "utf16.osm");
    ASSERT_FALSE(r.isOk());
    EXPECT_NE(r.status().message().find("UTF-16"), std::string::npos) << r.status().message();
    r = importText(dir, w.text(), "roads.opl");
    ASSERT_FALSE(r.isOk());
    EXPECT_NE(r.status().message().find("not supported"), std::string::npos) << r.status().message();
    // A tag the scanner cannot follow is an error, not skipped.
    text = w.text();
    text.insert(text.find("<way"), "<node id=\"77\" lat=\"1\" lon=2/>\n");
    r = importText(dir, text, "broken.osm");
    ASSERT_FALSE(r.isOk());
    EXPECT_NE(r.status().message().find("malformed"), std::string::npos) << r.status().message();
    // The same roads, well formed, import.
    EXPECT_TRUE(importText(dir, w.text(), "good.osm").isOk());
}

TEST(OsmImport, LongZigzagWaysAreBounded) {
    const GeoPoint c{48.2, 16.37};
    test::TempDir dir("vista_osm");
    OsmWriter base;
    base.grid(c, 1000, 4);
    auto plain = importOsm(base.write(dir, "grid.osm"), CityParams());
    ASSERT_TRUE(plain.isOk()) << plain.status().message();
    const size_t gridEdges = plain->streets.edges.size();
    EXPECT_EQ(gridEdges, 40u);

    // One way of 5,000 nodes zigzagging at random across the grid: ~2.5 million self-crossings
    // (unbounded, this took minutes and > 11 GB). It is dropped; the grid comes out unchanged.
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-450, 450);
    OsmWriter w = base;
    std::vector<int64_t> zig;
    for (int i = 0; i < 5000; ++i) zig.push_back(w.node(destination(destination(c, 0, u(rng)), 90, u(rng))));
    w.way(zig);
    auto r = importOsm(w.write(dir, "zigzag.osm"), CityParams());
    ASSERT_TRUE(r.isOk()) << r.status().message();
    EXPECT_EQ(r->tangledWays, 1u);
    EXPECT_NE(r->dropSummary().find("dropped 1 way crossing itself more than 16 times"), std::string::npos)
        << r->dropSummary();
    ASSERT_EQ(r->streets.edges.size(), gridEdges);
    for (size_t i = 0; i < r->streets.nodes.size(); ++i)  // same graph (the frame may differ by < 2 cm of rounding)
        EXPECT_LT(glm::length(r->streets.nodes[i] - plain->streets.nodes[i]), 0.02);

    // A dense zigzag that never crosses itself (nodes 0.1 m apart along the way's axis, 80 m
    // wide) is simplified and snapped to a bounded graph.
    OsmWriter dense = base;
    std::vector<int64_t> saw;
    for (int i = 0; i < 5000; ++i)
        saw.push_back(dense.node(destination(destination(c, 0, -250 + 0.1 * i), 90, (i % 2) ? 40 : -40)));
    dense.way(saw);
    r = importOsm(dense.write(dir, "saw.osm"), CityParams());
    ASSERT_TRUE(r.isOk()) << r.status().message();
    EXPECT_EQ(r->tangledWays, 0u);
    EXPECT_LT(r->streets.edges.size(), gridEdges + 200);
    EXPECT_TRUE(checkPlanarGraph(r->streets, CityParams().min_segment_m).isOk());

    // Many separate ways crossing each other everywhere: refused before planarization.
    OsmWriter tangle;
    for (int i = 0; i < 1200; ++i)
        tangle.way({tangle.node(destination(destination(c, 0, u(rng)), 90, u(rng))),
                    tangle.node(destination(destination(c, 0, u(rng)), 90, u(rng)))});
    r = importOsm(tangle.write(dir, "tangle.osm"), CityParams());
    ASSERT_FALSE(r.isOk());
    EXPECT_NE(r.status().message().find("more than 100000 times"), std::string::npos) << r.status().message();
}

TEST(OsmImport, SimplificationKeepsJunctionsAndShape) {
    // A curved road of 400 nodes 1 m apart (radius 300 m) with a side road meeting it at node 200
    // (placed through a transverse Mercator frame of its own: this tests simplification).
    const GeoPoint c{35.68, 139.77};
    const GeoReference placement{c.lat_deg, c.lon_deg};
    test::TempDir dir("vista_osm");
    OsmWriter w;
    std::vector<int64_t> arc;
    for (int i = 0; i < 400; ++i) {
        const double a = i / 300.0;  // radians along the arc
        arc.push_back(w.node(localToGeo(placement, 300.0 * glm::dvec2(std::sin(a), std::cos(a)))));
    }
    w.way(arc, "secondary");
    w.way({arc[200], w.node(localToGeo(placement, {40, 40}))});
    auto r = importOsm(w.write(dir, "arc.osm"), CityParams());
    ASSERT_TRUE(r.isOk()) << r.status().message();
    EXPECT_GT(r->simplifiedNodes, 300u);
    // Every node stays within the simplification tolerance of the circle; the junction survives.
    const glm::dvec2 centre = projectToLocal(r->geo, c), junction = projectToLocal(r->geo, w.at(arc[200]));
    auto deg = r->streets.degrees();
    bool junctionFound = false;
    for (size_t i = 0; i < r->streets.nodes.size(); ++i) {
        const glm::dvec2 n = r->streets.nodes[i];
        if (glm::length(n - junction) < 0.01) junctionFound = deg[i] == 3;
        if (glm::length(n - centre) > 200) { EXPECT_NEAR(glm::length(n - centre), 300.0, 0.05); }
    }
    EXPECT_TRUE(junctionFound);
    // Edge midpoints stay within the tolerance too; an arm of the junction may run straight
    // over a slight bend next to it, within kShortBendDeviation of the nodes it drops
    // (short_bends.h), which lie on the circle.
    for (size_t e = 0; e < r->streets.edges.size(); ++e) {
        const StreetEdge& E = r->streets.edges[e];
        const glm::dvec2 mid = 0.5 * (r->streets.nodes[E.a] + r->streets.nodes[E.b]);
        const bool arm = glm::length(r->streets.nodes[E.a] - junction) < 0.01 ||
                         glm::length(r->streets.nodes[E.b] - junction) < 0.01;
        const double tolerance = arm ? kShortBendDeviation + 0.05 : 0.6;
        if (glm::length(mid - centre) > 200) { EXPECT_GT(glm::length(mid - centre), 300.0 - tolerance); }
    }
}

TEST(OsmImport, TruncatedFileIsAnErrorNamingTheFile) {
    auto r = importOsm(fixture("truncated.osm"), CityParams());
    ASSERT_FALSE(r.isOk());
    EXPECT_NE(r.status().message().find("truncated.osm"), std::string::npos) << r.status().message();
}

// A .osm.bz2 cut short says so in words (libbz2 reports only a number).
TEST(OsmImport, TruncatedBzip2IsNamedInWords) {
    test::TempDir dir("vista_osm");
    const std::string xml = vista::test::readBytes(fixture("hard_cases.osm"));
    std::vector<char> packed(xml.size() + 1024);
    unsigned int size = unsigned(packed.size());
    ASSERT_EQ(
        BZ2_bzBuffToBuffCompress(packed.data(), &size, const_cast<char*>(xml.data()), unsigned(xml.size()), 9, 0, 0),
        BZ_OK);
    const std::string path = dir.file("cut.osm.bz2");
    std::ofstream(path, std::ios::binary).write(packed.data(), std::streamsize(size / 2));
    auto r = importOsm(path, CityParams());
    ASSERT_FALSE(r.isOk());
    const std::string& m = r.status().message();
    EXPECT_NE(m.find("cut.osm.bz2"), std::string::npos) << m;
    EXPECT_NE(m.find("truncated"), std::string::npos) << m;
    EXPECT_EQ(m.find("-7"), std::string::npos) << m;
}

// An extract larger than the city: its roads are clipped to the city square,
// so every street (and every seeded path on them) lies inside the city.
TEST(OsmImport, RoadsBeyondTheCitySquareAreClipped) {
    test::TempDir dir("vista_osm");
    OsmWriter w;
    w.grid({48.2, 16.37}, 3000, 4);  // roads 3 km long, 750 m apart
    CityParams p;
    p.size_m = 1000;
    auto r = importOsm(w.write(dir, "big.osm"), p);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    ASSERT_FALSE(r->streets.edges.empty());
    for (const auto& n : r->streets.nodes) {
        EXPECT_LE(std::abs(n.x), 500.0 + 1e-6);
        EXPECT_LE(std::abs(n.y), 500.0 + 1e-6);
    }
    EXPECT_GT(r->clippedSegments, 0u);
    EXPECT_NE(r->dropSummary().find("clipped"), std::string::npos) << r->dropSummary();
    EXPECT_TRUE(checkPlanarGraph(r->streets, p.min_segment_m).isOk());
    // The roads at +-375 m cross the square: 2 x 2 crossings inside it.
    size_t inner = 0;
    for (const auto& n : r->streets.nodes) inner += std::abs(n.x) < 499 && std::abs(n.y) < 499;
    EXPECT_EQ(inner, 4u);
    // A city smaller than any gap between the roads: refused, naming the square.
    p.size_m = 100;
    OsmWriter off;  // two roads 800 m apart: the data's centre, where the city lies, has none
    for (double north : {-400.0, 400.0}) {
        const GeoPoint a = destination({48.2, 16.37}, 0, north);
        off.way({off.node(a), off.node(destination(a, 90, 100))});
    }
    auto none = importOsm(off.write(dir, "off.osm"), p);
    ASSERT_FALSE(none.isOk());
    EXPECT_NE(none.status().message().find("city square"), std::string::npos) << none.status().message();
}

// By default (OsmExtent::Extract) the city is the extract's own extent: every road is kept and
// the square holds the roads' bounding box with the margin, in whole tiles. With a city square
// smaller than the extract, the summary says how much was kept: 4 of the 8 roads (3 km each,
// 750 m apart) cross the 1 km square, each keeping 1 km; the other 4 lie wholly outside.
TEST(OsmImport, ExtractExtentByDefaultAndTheClipSaysHowMuchWasCut) {
    test::TempDir dir("vista_osm");
    OsmWriter w;
    w.grid({48.2, 16.37}, 3000, 4);
    const std::string path = w.write(dir, "big.osm");
    auto whole = importOsm(path, CityParams(), false, OsmExtent::Extract);
    ASSERT_TRUE(whole.isOk()) << whole.status().message();
    EXPECT_EQ(whole->clippedSegments, 0u);
    EXPECT_EQ(whole->dropSummary(), "");
    EXPECT_NEAR(whole->roadLength_m, 8 * 3000.0, 0.01 * 8 * 3000.0);
    EXPECT_DOUBLE_EQ(whole->keptLength_m, whole->roadLength_m);
    const double need = std::max(whole->extentX_m, whole->extentY_m) + 2 * kOsmExtentMargin_m;
    EXPECT_GE(whole->citySize_m, need);
    EXPECT_LT(whole->citySize_m, need + CityParams().tile_size_m);
    EXPECT_DOUBLE_EQ(std::fmod(whole->citySize_m, CityParams().tile_size_m), 0.0);
    size_t inner = 0;  // all 4 x 4 crossings
    for (const auto& n : whole->streets.nodes) {
        EXPECT_LE(std::max(std::abs(n.x), std::abs(n.y)), 0.5 * whole->citySize_m - kOsmExtentMargin_m + 1e-6);
        inner += std::abs(n.x) < 1400 && std::abs(n.y) < 1400;
    }
    EXPECT_EQ(inner, 16u);

    CityParams p;
    p.size_m = 1000;
    auto cut = importOsm(path, p);
    ASSERT_TRUE(cut.isOk()) << cut.status().message();
    EXPECT_DOUBLE_EQ(cut->citySize_m, 1000.0);
    EXPECT_EQ(cut->roadSegments, 8u);
    EXPECT_EQ(cut->clippedSegments, 8u);
    EXPECT_EQ(cut->clippedWays, 4u);
    EXPECT_NEAR(cut->keptLength_m, 4 * 1000.0, 1.0);
    const std::string m = cut->dropSummary();
    EXPECT_NE(m.find("clipped the roads to the city square of size_m = 1 km: kept 4.0 km of "), std::string::npos) << m;
    const size_t pct = m.find(" of road (");
    ASSERT_NE(pct, std::string::npos) << m;
    EXPECT_NEAR(std::stod(m.substr(pct + 10)), 100.0 * 4000.0 / (8 * 3000.0), 0.3) << m;
    EXPECT_NE(m.find("8 of 8 road segments cut or dropped, 4 of 8 ways wholly outside"), std::string::npos) << m;
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
