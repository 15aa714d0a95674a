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
#include "citygen/geodesy.h"
#include "citygen/osm_buildings.h"
#include "citygen/polygon.h"
#include "citygen/streets.h"
#include "tests/common/temp_dir.h"

using namespace vista;

namespace {

std::string fixture(const char* name) { return std::string(VISTA_TEST_DATA) + "/osm/" + name; }

constexpr double kD2R = 3.14159265358979323846 / 180.0;

// Vincenty's inverse formula on WGS84: geodesic distance in metres (independent of geodesy.cpp).
double vincenty(const GeoPoint& p, const GeoPoint& q) {
    const double a = 6378137.0, f = 1 / 298.257223563, b = a * (1 - f);
    const double L = std::remainder(q.lon_deg - p.lon_deg, 360.0) * kD2R;
    const double U1 = std::atan((1 - f) * std::tan(p.lat_deg * kD2R)), U2 = std::atan((1 - f) * std::tan(q.lat_deg * kD2R));
    const double sU1 = std::sin(U1), cU1 = std::cos(U1), sU2 = std::sin(U2), cU2 = std::cos(U2);
    double lam = L, sinS = 0, cosS = 0, sig = 0, cos2A = 0, cos2Sm = 0;
    for (int i = 0; i < 200; ++i) {
        const double sl = std::sin(lam), cl = std::cos(lam);
        sinS = std::hypot(cU2 * sl, cU1 * sU2 - sU1 * cU2 * cl);
        if (sinS == 0) return 0;
        cosS = sU1 * sU2 + cU1 * cU2 * cl;
        sig = std::atan2(sinS, cosS);
        const double sinA = cU1 * cU2 * sl / sinS;
        cos2A = 1 - sinA * sinA;
        cos2Sm = cos2A != 0 ? cosS - 2 * sU1 * sU2 / cos2A : 0;
        const double C = f / 16 * cos2A * (4 + f * (4 - 3 * cos2A));
        const double prev = lam;
        lam = L + (1 - C) * f * sinA * (sig + C * sinS * (cos2Sm + C * cosS * (-1 + 2 * cos2Sm * cos2Sm)));
        if (std::abs(lam - prev) < 1e-13) break;
    }
    const double u2 = cos2A * (a * a - b * b) / (b * b);
    const double A = 1 + u2 / 16384 * (4096 + u2 * (-768 + u2 * (320 - 175 * u2)));
    const double B = u2 / 1024 * (256 + u2 * (-128 + u2 * (74 - 47 * u2)));
    const double dS = B * sinS * (cos2Sm + B / 4 * (cosS * (-1 + 2 * cos2Sm * cos2Sm) -
                                                    B / 6 * cos2Sm * (-3 + 4 * sinS * sinS) * (-3 + 4 * cos2Sm * cos2Sm)));
    return b * A * (sig - dS);
}

// Point at `dist` metres and `bearing` degrees from p on a sphere (only to place test points).
GeoPoint destination(const GeoPoint& p, double bearingDeg, double dist) {
    const double d = dist / 6371000.0, t = bearingDeg * kD2R, f1 = p.lat_deg * kD2R;
    const double f2 = std::asin(std::sin(f1) * std::cos(d) + std::cos(f1) * std::sin(d) * std::cos(t));
    const double l2 = p.lon_deg * kD2R + std::atan2(std::sin(t) * std::sin(d) * std::cos(f1), std::cos(d) - std::sin(f1) * std::sin(f2));
    return {f2 / kD2R, std::remainder(l2 / kD2R, 360.0)};
}

// The largest city an OSM import may span (a single-file city; paged output takes no --osm).
double maxCitySize() { return kMaxSingleFileSizeM; }

// A synthetic .osm file; coordinates are written with 7 decimals (OSM's resolution) and
// remembered as written.
class OsmWriter {
public:
    int64_t node(const GeoPoint& p) {
        char buf[128];
        std::snprintf(buf, sizeof buf, "lat=\"%.7f\" lon=\"%.7f\"", p.lat_deg, p.lon_deg);
        GeoPoint written{std::round(p.lat_deg * 1e7) / 1e7, std::round(p.lon_deg * 1e7) / 1e7};
        const int64_t id = rawNode(buf);
        _geo[id] = written;
        return id;
    }
    int64_t rawNode(const std::string& attrs) {
        const int64_t id = _next++;
        _nodes += "  <node id=\"" + std::to_string(id) + "\" " + attrs + "/>\n";
        return id;
    }
    void way(const std::vector<int64_t>& refs, const char* highway = "residential") {
        _ways += "  <way id=\"" + std::to_string(_nextWay++) + "\">";
        for (int64_t r : refs) _ways += "<nd ref=\"" + std::to_string(r) + "\"/>";
        _ways += std::string("<tag k=\"highway\" v=\"") + highway + "\"/></way>\n";
    }
    // A grid of n x n crossing straight roads (no shared nodes) of side `side` metres about `centre`.
    void grid(const GeoPoint& centre, double side, int n) {
        for (int i = 0; i < n; ++i) {
            const double off = -0.5 * side + side * (i + 0.5) / n;
            const GeoPoint ew = destination(centre, 0, off), ns = destination(centre, 90, off);
            way({node(destination(ew, 270, 0.5 * side)), node(destination(ew, 90, 0.5 * side))});
            way({node(destination(ns, 180, 0.5 * side)), node(destination(ns, 0, 0.5 * side))});
        }
    }
    const GeoPoint& at(int64_t id) const { return _geo.at(id); }
    std::string text(const std::string& header = "") const {
        return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<osm version=\"0.6\" generator=\"vista-test\">\n" + header +
               _nodes + _ways + "</osm>\n";
    }
    std::string write(const test::TempDir& dir, const std::string& name, const std::string& header = "") const {
        const std::string path = dir.file(name);
        std::ofstream(path, std::ios::binary) << text(header);
        return path;
    }

private:
    int64_t _next = 1, _nextWay = 1;
    std::string _nodes, _ways;
    std::map<int64_t, GeoPoint> _geo;
};

Result<OsmImport> importText(const test::TempDir& dir, const std::string& text, const std::string& name = "t.osm") {
    const std::string path = dir.file(name);
    std::ofstream(path, std::ios::binary) << text;
    return importOsm(path, CityParams());
}

}  // namespace

// ---- geodesy ------------------------------------------------------------------

TEST(Geodesy, ProjectedDistancesMatchVincentyAnywhere) {
    // Points up to half the largest city's diagonal from the reference: pairs up to 22.6 km apart.
    const double reach = 0.5 * std::sqrt(2.0) * maxCitySize();
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> bearing(0, 360), dist(0, reach);
    const GeoReference refs[] = {{0, 0}, {48.2, 16.37}, {60, 10}, {-60, -70}, {89.5, 30}, {-89.5, -150}, {89.95, 0}, {20, 180}, {-33.9, -179.99}};
    for (const auto& ref : refs) {
        std::vector<GeoPoint> pts;
        for (int i = 0; i < 40; ++i) pts.push_back(destination({ref.lat0_deg, ref.lon0_deg}, bearing(rng), dist(rng)));
        double worst = 0;
        for (size_t i = 0; i < pts.size(); ++i)
            for (size_t j = i + 1; j < pts.size(); ++j) {
                const double geodesic = vincenty(pts[i], pts[j]);
                if (geodesic < 100) continue;
                const double projected = glm::length(projectToLocal(ref, pts[i]) - projectToLocal(ref, pts[j]));
                worst = std::max(worst, std::abs(projected - geodesic) / geodesic);
            }
        // 0.1 % is the contract; transverse Mercator is off by ~1e-6 at this size.
        EXPECT_LT(worst, 1e-3) << "reference " << ref.lat0_deg << ", " << ref.lon0_deg;
        EXPECT_LT(worst, 1e-5) << "reference " << ref.lat0_deg << ", " << ref.lon0_deg;
    }
}

TEST(Geodesy, RoundTripWithinOneCentimetre) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> local(-20000, 20000), bearing(0, 360), dist(0, 20000);
    const GeoReference refs[] = {{0, 0}, {60, 10}, {89.5, 0}, {-89.5, 120}, {90, 0}, {-90, 45}, {10, 180}, {-5, -180}, {0, 179.999}};
    for (const auto& ref : refs) {
        for (int i = 0; i < 200; ++i) {
            const glm::dvec2 xy(local(rng), local(rng));
            const GeoPoint g = localToGeo(ref, xy);
            EXPECT_LE(std::abs(g.lat_deg), 90.0);
            EXPECT_LE(std::abs(g.lon_deg), 180.0);
            EXPECT_LT(glm::length(projectToLocal(ref, g) - xy), 0.01) << ref.lat0_deg << ", " << ref.lon0_deg;
            const GeoPoint p = destination({ref.lat0_deg, ref.lon0_deg}, bearing(rng), dist(rng));
            EXPECT_LT(vincenty(localToGeo(ref, projectToLocal(ref, p)), p), 0.01) << p.lat_deg << ", " << p.lon_deg;
        }
        // The reference point is the origin.
        EXPECT_LT(glm::length(projectToLocal(ref, {ref.lat0_deg, ref.lon0_deg})), 1e-6);
    }
}

TEST(Geodesy, AntimeridianIsContinuous) {
    const GeoReference ref{10, 179.999};
    const glm::dvec2 east = projectToLocal(ref, {10, -179.999}), west = projectToLocal(ref, {10, 179.997});
    const double expected = vincenty({10, 179.997}, {10, -179.999});  // 0.004 deg of longitude: ~438 m
    EXPECT_NEAR(glm::length(east - west), expected, 1e-3 * expected);
    EXPECT_GT(east.x, 0);  // -179.999 lies east of 179.999
    EXPECT_LT(west.x, 0);
}

// ---- geo reference in the parameters and GeoJSON --------------------------------

TEST(OsmGeoReference, ParamsJsonRoundTripAndOmittedWhenAbsent) {
    CityParams p;
    const std::string plain = paramsToJson(p);
    EXPECT_EQ(plain.find("geo"), std::string::npos);
    p.geo = GeoReference{-33.8688197, 151.2092955};
    const std::string j = paramsToJson(p);
    EXPECT_EQ(j.substr(0, plain.size() - 2), plain.substr(0, plain.size() - 2));  // the same fields, then geo
    auto parsed = nlohmann::json::parse(j);
    EXPECT_EQ(parsed["geo"]["projection"], "tmerc");
    auto back = parseParamsJson(j, "round trip");
    ASSERT_TRUE(back.isOk()) << back.status().message();
    ASSERT_TRUE(back->geo.has_value());
    EXPECT_EQ(back->geo->lat0_deg, p.geo->lat0_deg);
    EXPECT_EQ(back->geo->lon0_deg, p.geo->lon0_deg);
    EXPECT_EQ(paramsToJson(*back), j);
    EXPECT_FALSE(parseParamsJson(plain, "plain")->geo.has_value());
}

TEST(OsmGeoReference, BadGeoObjectsAreRefusedNamingTheField) {
    struct Case { const char* json; const char* expect; };
    const Case cases[] = {
        {R"({"geo": {"projection": "tmerc", "lat0_deg": 95, "lon0_deg": 0}})", "'geo.lat0_deg' = 95 is out of range [-90, 90]"},
        {R"({"geo": {"projection": "tmerc", "lat0_deg": 0, "lon0_deg": -181}})", "'geo.lon0_deg' = -181 is out of range [-180, 180]"},
        {R"({"geo": {"projection": "utm", "lat0_deg": 0, "lon0_deg": 0}})", "'geo.projection' = \"utm\" is not supported"},
        {R"({"geo": {"projection": "tmerc", "lat0_deg": 0}})", "lacks 'lon0_deg'"},
        {R"({"geo": {"projection": "tmerc", "lat0_deg": 0, "lon0_deg": 0, "k0": 1}})", "unknown parameter 'geo.k0'"},
        {R"({"geo": {"projection": "tmerc", "lat0_deg": "0", "lon0_deg": 0}})", "'geo.lat0_deg' must be a number"},
        {R"({"geo": [48, 16]})", "'geo' must be an object"},
    };
    for (const auto& c : cases) {
        auto r = parseParamsJson(c.json, "g.json");
        ASSERT_FALSE(r.isOk()) << c.json;
        EXPECT_NE(r.status().message().find(c.expect), std::string::npos) << r.status().message();
    }
    CityParams p;
    p.geo = GeoReference{91, 0};
    EXPECT_FALSE(validateParams(p).isOk());
}

TEST(OsmGeoReference, GeoJsonInLonLatWithAReferenceAndMetresWithout) {
    StreetGraph g;
    g.nodes = {{-300, -200}, {400, 250}, {400, -200}};
    g.edges = {{0, 1, RoadClass::Local, 7.5f, 2}, {1, 2, RoadClass::Arterial, 13.0f, 4}};
    auto metres = nlohmann::json::parse(streetGraphToGeoJson(g, 1000, 2000));
    EXPECT_DOUBLE_EQ(metres["features"][0]["geometry"]["coordinates"][0][0].get<double>(), 700.0);
    EXPECT_EQ(streetGraphToGeoJson(g, 1000, 2000), streetGraphToGeoJson(g, 1000, 2000, std::nullopt));
    for (const GeoReference ref : {GeoReference{60, 10}, GeoReference{89.5, -45}}) {
        auto j = nlohmann::json::parse(streetGraphToGeoJson(g, 1000, 2000, ref));
        ASSERT_EQ(j["features"].size(), 2u);
        for (size_t e = 0; e < 2; ++e) {
            const auto& f = j["features"][e];
            EXPECT_EQ(f["geometry"]["type"], "LineString");
            for (int end = 0; end < 2; ++end) {
                const auto& c = f["geometry"]["coordinates"][end];
                const glm::dvec2 back = projectToLocal(ref, {c[1].get<double>(), c[0].get<double>()});  // [lon, lat]
                const glm::dvec2 node = g.nodes[end ? g.edges[e].b : g.edges[e].a];
                EXPECT_LT(glm::length(back - node), 0.01);  // the origin offset is not applied
            }
        }
    }
    // An edge across the antimeridian is cut in two at +-180 degrees.
    const GeoReference dateline{-16.5, 180};
    auto j = nlohmann::json::parse(streetGraphToGeoJson(g, 0, 0, dateline));
    const auto& geom = j["features"][0]["geometry"];
    ASSERT_EQ(geom["type"], "MultiLineString");
    const auto& parts = geom["coordinates"];
    EXPECT_LT(parts[0][0][0].get<double>(), 180.0);
    EXPECT_GT(parts[0][0][0].get<double>(), 179.9);
    EXPECT_EQ(std::abs(parts[0][1][0].get<double>()), 180.0);
    EXPECT_EQ(parts[1][0][0].get<double>(), -parts[0][1][0].get<double>());
    EXPECT_EQ(parts[1][0][1].get<double>(), parts[0][1][1].get<double>());
    EXPECT_LT(parts[1][1][0].get<double>(), -179.9);
    // The cut lies on the edge: x = 0 (the central meridian is 180), y on the line between the nodes.
    const glm::dvec2 cut = projectToLocal(dateline, {parts[0][1][1].get<double>(), 180.0});
    EXPECT_NEAR(cut.x, 0.0, 0.01);
    EXPECT_NEAR(cut.y, -200 + 450 * (300.0 / 700.0), 0.01);
}

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
        auto r = importOsm(w.write(dir, "spokes.osm"), CityParams());
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
            EXPECT_NEAR(len, expected, 1e-4 * expected) << "centre " << c.lat_deg << ", " << c.lon_deg << " spoke " << k;
            const glm::dvec2 a = g.nodes[g.edges[e].a], bb = g.nodes[g.edges[e].b];
            tips[size_t(k)] = glm::length(a) > glm::length(bb) ? a : bb;
        }
        for (int i = 0; i < 12; ++i)
            for (int j = i + 1; j < 12; ++j) {
                const double expected = vincenty(w.at(spokes[i].second), w.at(spokes[j].second));
                EXPECT_NEAR(glm::length(tips[i] - tips[j]), expected, 1e-4 * expected) << c.lat_deg << " tips " << i << " " << j;
            }
        // The frame is centred on the bounding box.
        glm::dvec2 lo(1e300), hi(-1e300);
        for (const auto& n : g.nodes) { lo = glm::min(lo, n); hi = glm::max(hi, n); }
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
    auto r = importOsm(w.write(dir, "fiji.osm"), CityParams());
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
    w.way({valid(120, 100), 999999});  // node missing from the file
    w.way({valid(130, 100), w.node(destination(c, 130, 500000))});  // 500 km away
    const std::string bounds = R"(  <bounds minlat="-1e300" minlon="16" maxlat="49" maxlon="1e300"/>)" "\n";
    auto r = importOsm(w.write(dir, "dirty.osm", bounds), CityParams());
    ASSERT_TRUE(r.isOk()) << r.status().message();
    EXPECT_EQ(r->invalidNodes, 6u);
    EXPECT_EQ(r->missingNodes, 1u);
    EXPECT_EQ(r->outlierNodes, 1u);
    EXPECT_EQ(r->dropSummary(), "dropped 8 nodes (6 with invalid coordinates, 1 missing from the file, 1 outlier farther than 22.6 km "
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
    {   // A road leaving the city for a place 1.2 x the limit away: too big, not an outlier.
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
        EXPECT_NE(m.find(" km east-west by 2.01 km north-south"), std::string::npos) << m;
        EXPECT_NE(m.find("size_m up to " + std::to_string(int(limit)) + " m"), std::string::npos) << m;
    }
    {   // The same place 2 x the limit away is an outlier (> sqrt(2) x limit): dropped, the city stays.
        test::TempDir dir("vista_osm");
        OsmWriter w;
        w.grid(c, 2000, 3);
        w.way({w.node(destination(c, 90, 900)), w.node(destination(c, 90, 2 * limit))});
        auto r = importOsm(w.write(dir, "far.osm"), CityParams());
        ASSERT_TRUE(r.isOk()) << r.status().message();
        EXPECT_EQ(r->outlierNodes, 1u);
        EXPECT_NEAR(r->extentX_m, 2000 * 1.0036, 3);
    }
    {   // Evenly spread roads wider than the limit: refused (nothing is an outlier).
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
    EXPECT_NE(r->dropSummary().find("dropped 1 way crossing itself more than 16 times"), std::string::npos) << r->dropSummary();
    ASSERT_EQ(r->streets.edges.size(), gridEdges);
    for (size_t i = 0; i < r->streets.nodes.size(); ++i)  // same graph (the frame may differ by < 2 cm of rounding)
        EXPECT_LT(glm::length(r->streets.nodes[i] - plain->streets.nodes[i]), 0.02);

    // A dense zigzag that never crosses itself (nodes 0.1 m apart along the way's axis, 80 m
    // wide) is simplified and snapped to a bounded graph.
    OsmWriter dense = base;
    std::vector<int64_t> saw;
    for (int i = 0; i < 5000; ++i) saw.push_back(dense.node(destination(destination(c, 0, -250 + 0.1 * i), 90, (i % 2) ? 40 : -40)));
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
        if (glm::length(n - centre) > 200) {
            EXPECT_NEAR(glm::length(n - centre), 300.0, 0.05);
        }
    }
    EXPECT_TRUE(junctionFound);
    for (size_t e = 0; e < r->streets.edges.size(); ++e) {
        const glm::dvec2 mid = 0.5 * (r->streets.nodes[r->streets.edges[e].a] + r->streets.nodes[r->streets.edges[e].b]);
        if (glm::length(mid - centre) > 200) {
            EXPECT_GT(glm::length(mid - centre), 300.0 - 0.6);
        }
    }
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

// ---- vista gen --osm ----------------------------------------------------------------

TEST(OsmGen, GeoReferenceReachesSceneAndGeoJsonAndDropsAreReported) {
    test::TempDir dir("vista_osm_gen");
    OsmWriter w;
    const GeoPoint c{-16.8, 179.999};  // 107 m west of the antimeridian
    w.grid(c, 400, 3);
    w.way({w.node(destination(c, 0, 150)), w.rawNode(R"(lat="-16.8" lon="1e300")"), w.node(destination(c, 10, 180))});
    const std::string osm = w.write(dir, "fiji.osm");
    auto run = [&](const std::string& args) {
        const std::string cmd = std::string(VISTA_BINARY) + " gen " + args + " 2>" + dir.file("err.txt") + " >/dev/null";
        const int st = std::system(cmd.c_str());
        return std::make_pair(WIFEXITED(st) ? WEXITSTATUS(st) : -1, test::readBytes(dir.file("err.txt")));
    };
    auto [code, err] = run("--osm " + osm + " --size 500 --detail 0 -q -o " + dir.file("c.osgb") + " --geojson " + dir.file("s.geojson"));
    ASSERT_EQ(code, 0) << err;
    EXPECT_NE(err.find("osm: dropped 1 node (1 with invalid coordinates)"), std::string::npos) << err;
    // The scene stores the geo reference with the parameters.
    const std::string scene = test::readBytes(dir.file("c.osgb"));
    EXPECT_NE(scene.find("\"projection\": \"tmerc\""), std::string::npos);
    // GeoJSON in lon/lat near the data, cut at the antimeridian where an edge crosses it.
    auto j = nlohmann::json::parse(test::readBytes(dir.file("s.geojson")));
    ASSERT_GT(j["features"].size(), 0u);
    size_t cut = 0;
    for (const auto& f : j["features"]) {
        const bool multi = f["geometry"]["type"] == "MultiLineString";
        cut += multi;
        for (const auto& line : multi ? f["geometry"]["coordinates"] : nlohmann::json::array({f["geometry"]["coordinates"]}))
            for (const auto& p : line) {
                EXPECT_NEAR(p[1].get<double>(), -16.8, 0.01);
                EXPECT_GT(std::abs(p[0].get<double>()), 179.99);
                EXPECT_LE(std::abs(p[0].get<double>()), 180.0);
            }
    }
    EXPECT_GT(cut, 0u);
    // Implausible extent: exit 2 with the message.
    OsmWriter wide;
    wide.grid(c, 1.5 * maxCitySize(), 2);
    std::tie(code, err) = run("--osm " + wide.write(dir, "wide.osm") + " -q -o " + dir.file("w.osgb"));
    EXPECT_EQ(code, 2);
    EXPECT_NE(err.find("the roads span"), std::string::npos) << err;
}

// ---- buildings from OSM -------------------------------------------------------------

namespace {

// The fixture's city: streets and buildings imported, then the whole pipeline.
struct OsmCity {
    OsmImport import;
    City city;
};
OsmCity osmCity(bool buildings = true) {
    CityParams p;
    p.size_m = 800;
    p.detail = 2;
    p.threads = 1;
    auto imp = importOsm(fixture("buildings.osm"), p, buildings);
    EXPECT_TRUE(imp.isOk()) << imp.status().message();
    p.geo = imp->geo;
    GenerateOptions o;
    o.streets = imp->streets;
    if (buildings) {
        o.osmBuildings = imp->buildings;
        o.osmStats = imp->buildingStats;
    }
    auto c = generateCity(p, o);
    EXPECT_TRUE(c.isOk()) << c.status().message();
    return {std::move(*imp), std::move(*c)};
}

const Building* byOsmId(const City& c, int64_t id) {
    for (const auto& b : c.buildings)
        if (b.source != BuildingSource::Procedural && b.osm_id == id) return &b;
    return nullptr;
}

}  // namespace

TEST(OsmBuildingTags, LengthsLevelsAndRoofShapes) {
    EXPECT_DOUBLE_EQ(parseOsmLength("12"), 12.0);
    EXPECT_DOUBLE_EQ(parseOsmLength("12 m"), 12.0);
    EXPECT_DOUBLE_EQ(parseOsmLength("12.5m"), 12.5);
    EXPECT_DOUBLE_EQ(parseOsmLength(" 7,5 "), 7.5);
    EXPECT_NEAR(parseOsmLength("40'"), 40 * 0.3048, 1e-12);
    EXPECT_NEAR(parseOsmLength("40 ft"), 40 * 0.3048, 1e-12);
    EXPECT_NEAR(parseOsmLength("12'6\""), 12.5 * 0.3048, 1e-12);
    for (const char* bad : {"", "tall", "-3", "1e300", "12 km", "12'13\"", "5000", "nan", "12..5"})
        EXPECT_TRUE(std::isnan(parseOsmLength(bad))) << bad;
    EXPECT_DOUBLE_EQ(parseOsmLevels("4"), 4.0);
    EXPECT_DOUBLE_EQ(parseOsmLevels("2.5"), 2.5);
    for (const char* bad : {"", "four", "-1", "3 floors", "1000"}) EXPECT_TRUE(std::isnan(parseOsmLevels(bad))) << bad;
    EXPECT_EQ(parseOsmRoofShape("gabled"), OsmRoofShape::Gabled);
    EXPECT_EQ(parseOsmRoofShape("gambrel"), OsmRoofShape::Gabled);
    EXPECT_EQ(parseOsmRoofShape("hipped"), OsmRoofShape::Hipped);
    EXPECT_EQ(parseOsmRoofShape("pyramidal"), OsmRoofShape::Hipped);
    EXPECT_EQ(parseOsmRoofShape("flat"), OsmRoofShape::Flat);
    EXPECT_EQ(parseOsmRoofShape("skillion"), OsmRoofShape::Flat);
    EXPECT_EQ(parseOsmRoofShape("banana"), OsmRoofShape::Flat);
    EXPECT_EQ(parseOsmRoofShape(""), OsmRoofShape::Absent);
}

TEST(FootprintRepair, BowTieSplitsIntoItsLargerHalfAndHolesTriangulate) {
    bool split = false;
    // Bow-tie whose left lobe (area 10 * 4 / 2 ... ) is larger: crossing at (4, 2).
    const Polygon2 bow{{0, 0}, {10, 5}, {10, 0}, {0, 4}};
    const Polygon2 r = makeSimpleRing(bow, split);
    EXPECT_TRUE(split);
    ASSERT_GE(r.size(), 3u);
    EXPECT_TRUE(isSimpleRingExact(r));
    EXPECT_GT(signedArea(r), 0.0);
    // Independent: the crossing of (0,0)-(10,5) and (10,0)-(0,4) is at x = 40/9; lobes are triangles.
    const double xc = 40.0 / 9.0, left = 0.5 * 4.0 * xc, right = 0.5 * 5.0 * (10.0 - xc);
    EXPECT_NEAR(signedArea(r), std::max(left, right), 1e-9);
    // A simple ring comes back unchanged (counter-clockwise), a degenerate one empty.
    const Polygon2 sq{{0, 0}, {0, 10}, {10, 10}, {10, 0}};
    const Polygon2 s2 = makeSimpleRing(sq, split);
    EXPECT_FALSE(split);
    EXPECT_NEAR(signedArea(s2), 100.0, 1e-12);
    EXPECT_TRUE(makeSimpleRing({{0, 0}, {1, 1}, {2, 2}}, split).empty());
    EXPECT_TRUE(makeSimpleRing({{0, 0}, {1, std::nan("")}, {2, 0}}, split).empty());
    // Nesting: strictly inside, touching, outside.
    const Polygon2 big{{0, 0}, {20, 0}, {20, 20}, {0, 20}};
    const Polygon2 hole{{5, 5}, {5, 15}, {15, 15}, {15, 5}};  // clockwise
    EXPECT_TRUE(ringStrictlyInside(hole, big));
    EXPECT_FALSE(ringStrictlyInside(Polygon2{{0, 5}, {5, 15}, {15, 5}}, big));
    EXPECT_FALSE(ringStrictlyInside(Polygon2{{25, 5}, {25, 15}, {30, 5}}, big));
    EXPECT_TRUE(ringsDisjoint(hole, Polygon2{{16, 16}, {16, 19}, {19, 16}}));
    EXPECT_FALSE(ringsDisjoint(hole, Polygon2{{6, 6}, {6, 9}, {9, 6}}));
    // Triangulation: area 400 - 100, no triangle covers the hole's centre.
    const auto tris = triangulateWithHoles(big, {hole});
    ASSERT_FALSE(tris.empty());
    double area = 0;
    for (const auto& t : tris) {
        const double a = signedArea({t[0], t[1], t[2]});
        EXPECT_GT(a, 0.0);
        area += a;
        EXPECT_FALSE(pointInPolygon({t[0], t[1], t[2]}, {10, 10}));
    }
    EXPECT_NEAR(area, 300.0, 1e-9);
}

TEST(OsmBuildings, FixtureImportsRepairsAndSkipsPerReason) {
    CityParams p;
    p.size_m = 800;
    auto r = importOsm(fixture("buildings.osm"), p, true);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    const OsmBuildingStats& s = r->buildingStats;
    EXPECT_TRUE(s.enabled);
    EXPECT_EQ(s.ways, 11u);
    EXPECT_EQ(s.relations, 2u);
    EXPECT_EQ(s.candidates, 13u);
    EXPECT_EQ(s.imported, 10u);
    EXPECT_EQ(r->buildings.size(), 10u);
    // Repaired (and imported).
    EXPECT_EQ(s.duplicateNodes, 1u);     // way 205
    EXPECT_EQ(s.unclosedRings, 1u);      // way 204
    EXPECT_EQ(s.selfIntersections, 1u);  // way 203 (bow-tie)
    EXPECT_EQ(s.innerRingsDropped, 1u);  // relation 301
    // Skipped, by reason.
    EXPECT_EQ(s.missingNodes, 1u);  // way 206
    EXPECT_EQ(s.tooSmall, 1u);      // way 207
    EXPECT_EQ(s.tooFewNodes, 1u);   // way 208
    EXPECT_EQ(s.selfIntersecting, 0u);
    EXPECT_EQ(s.outsideCity, 0u);
    EXPECT_EQ(s.noOuterRing, 0u);
    EXPECT_EQ(s.candidates, s.imported + s.missingNodes + s.tooSmall + s.tooFewNodes + s.selfIntersecting + s.outsideCity + s.noOuterRing);
    // Every footprint simple and counter-clockwise; holes clockwise, strictly inside.
    size_t withHoles = 0;
    for (const auto& f : r->buildings) {
        EXPECT_TRUE(isSimpleRingExact(f.outer)) << f.osm_id;
        EXPECT_GT(signedArea(f.outer), kOsmMinFootprintArea_m2) << f.osm_id;
        for (const auto& h : f.holes) {
            EXPECT_LT(signedArea(h), 0.0);
            EXPECT_TRUE(ringStrictlyInside(h, f.outer));
        }
        withHoles += f.holes.empty() ? 0 : 1;
        if (f.osm_id == 205) { EXPECT_EQ(f.outer.size(), 4u); }
        if (f.osm_id == 204) { EXPECT_EQ(f.outer.size(), 4u); }
        if (f.osm_id == 203) { EXPECT_EQ(f.outer.size(), 3u); }  // one lobe of the bow-tie
    }
    EXPECT_EQ(withHoles, 1u);
    // The same streets with buildings off, and no buildings read.
    auto off = importOsm(fixture("buildings.osm"), p, false);
    ASSERT_TRUE(off.isOk());
    EXPECT_TRUE(off->buildings.empty());
    EXPECT_FALSE(off->buildingStats.enabled);
    EXPECT_EQ(off->streets.edges.size(), r->streets.edges.size());
    // A city too small for the buildings: they are skipped as outside the city, never an error.
    p.size_m = 100;
    auto tiny = importOsm(fixture("buildings.osm"), p, true);
    ASSERT_TRUE(tiny.isOk());
    EXPECT_GT(tiny->buildingStats.outsideCity, 0u);
    for (const auto& f : tiny->buildings)
        for (const auto& q : f.outer) EXPECT_LE(std::max(std::abs(q.x), std::abs(q.y)), 50.0);
}

TEST(OsmBuildings, HeightsAndRoofsFollowTheTags) {
    const OsmCity oc = osmCity();
    const City& c = oc.city;
    const double storey = c.params.floor_height_m;
    auto top = [](const Building& b) { return b.height + b.roof_height; };
    struct Want { int64_t id; double top; };
    // Total heights from `height` (metres, "m" suffix, feet): independent of the parser.
    for (const Want& w : {Want{200, 12.0}, Want{203, 12.5}, Want{205, 40 * 0.3048}, Want{214, 6.0}, Want{300, 15.0}, Want{202, 9.0}}) {
        const Building* b = byOsmId(c, w.id);
        ASSERT_NE(b, nullptr) << w.id;
        EXPECT_NEAR(top(*b), w.top, 1e-9) << w.id;
        EXPECT_EQ(b->lot, kNoLot);
    }
    // building:levels x storey height.
    EXPECT_NEAR(byOsmId(c, 201)->height, 4 * storey, 1e-9);
    EXPECT_EQ(byOsmId(c, 201)->floors, 4);
    EXPECT_NEAR(byOsmId(c, 204)->height, 3 * storey, 1e-9);
    // Gabled with roof:height 3 on height 9: eaves at 6.
    const Building* g = byOsmId(c, 202);
    EXPECT_EQ(g->roof, RoofType::Gabled);
    EXPECT_NEAR(g->roof_height, 3.0, 1e-9);
    EXPECT_NEAR(g->height, 6.0, 1e-9);
    EXPECT_EQ(g->floors, 2);
    // Hipped on a simple footprint (its stray inner ring was dropped).
    const Building* h = byOsmId(c, 301);
    EXPECT_EQ(h->roof, RoofType::Hipped);
    EXPECT_TRUE(h->holes.empty());
    EXPECT_NEAR(h->height, 2 * storey, 1e-9);
    EXPECT_GT(h->roof_height, 0.0);
    // The courtyard building is flat; the untagged one procedural but positive.
    EXPECT_EQ(byOsmId(c, 300)->roof, RoofType::Flat);
    EXPECT_EQ(byOsmId(c, 300)->holes.size(), 1u);
    EXPECT_GT(byOsmId(c, 209)->height, 0.0);
    EXPECT_EQ(c.osmBuildings.heightFromTag, 6u);     // 200 202 203 205 214 300
    EXPECT_EQ(c.osmBuildings.heightFromLevels, 3u);  // 201 204 301
    EXPECT_EQ(c.osmBuildings.heightProcedural, 1u);  // 209
    EXPECT_EQ(c.osmBuildings.roofFromTag, 2u);       // 202 301
    EXPECT_EQ(c.osmBuildings.roofFallbackFlat, 0u);
}

TEST(OsmBuildings, CourtyardStaysOpen) {
    const OsmCity oc = osmCity();
    const City& c = oc.city;
    const Building* b = byOsmId(c, 300);
    ASSERT_NE(b, nullptr);
    ASSERT_EQ(b->holes.size(), 1u);
    const glm::dvec2 yard = centroid(b->holes[0]);
    ASSERT_TRUE(pointInPolygon(b->footprint, yard));
    // No building's solid (outer ring minus its holes) holds the courtyard point.
    for (const auto& o : c.buildings) {
        bool inHole = false;
        for (const auto& h : o.holes) inHole = inHole || pointInPolygon(h, yard);
        EXPECT_FALSE(pointInPolygon(o.footprint, yard) && !inHole) << o.osm_id;
    }
    // No roof triangle covers it; some roof triangles lie around it (the roof exists).
    size_t roofTris = 0, near = 0;
    for (const auto& t : c.tiles) {
        const Mesh& m = t.meshes[size_t(Material::Roof)];
        for (size_t k = 0; k + 2 < m.indices.size(); k += 3) {
            Polygon2 tri;
            for (int v = 0; v < 3; ++v) tri.push_back(glm::dvec2(t.origin) + glm::dvec2(m.positions[m.indices[k + size_t(v)]]));
            ++roofTris;
            if (std::abs(signedArea(tri)) < 1e-9) continue;
            EXPECT_FALSE(pointInPolygon(tri, yard));
            near += glm::length(centroid(tri) - yard) < 40.0 ? 1 : 0;
        }
    }
    EXPECT_GT(roofTris, 0u);
    EXPECT_GE(near, 4u);
    // Walls stand around the courtyard: wall vertices on the inner ring.
    // Faces of those walls (normal across the ring edge) face into the courtyard (the yard is convex).
    size_t onHole = 0, facingIn = 0;
    const Polygon2& ring = b->holes[0];
    for (const auto& t : c.tiles) {
        const Mesh& m = t.meshes[size_t(Material::Wall)];
        for (size_t v = 0; v < m.positions.size(); ++v) {
            const glm::dvec2 p = glm::dvec2(t.origin) + glm::dvec2(m.positions[v]);
            for (size_t k = 0; k < ring.size(); ++k) {
                const glm::dvec2 a = ring[k], e = ring[(k + 1) % ring.size()];
                if (pointSegmentDistance(p, a, e) >= 1e-3) continue;
                ++onHole;
                const glm::dvec2 n(m.normals[v].x, m.normals[v].y), dir = glm::normalize(e - a);
                if (glm::length(n) > 0.9 && std::abs(glm::dot(n, dir)) < 0.1) {
                    EXPECT_GT(glm::dot(n, yard - p), 0.0) << "a courtyard wall faces away from the courtyard";
                    ++facingIn;
                }
                break;
            }
        }
    }
    EXPECT_GT(onHole, 16u);
    EXPECT_GT(facingIn, 8u);
}

TEST(OsmBuildings, NoProceduralBuildingOverlapsAnImportedOne) {
    const OsmCity oc = osmCity();
    const City& c = oc.city;
    std::vector<const Building*> imported, procedural;
    for (const auto& b : c.buildings) (b.source == BuildingSource::Procedural ? procedural : imported).push_back(&b);
    EXPECT_EQ(imported.size(), 10u);
    EXPECT_GT(c.osmBuildings.lotsDropped, 0u);
    EXPECT_GE(c.osmBuildings.onCarriageway, 1u);  // way 214 stands on South Street
    for (const auto* p : procedural)
        for (const auto* i : imported) EXPECT_FALSE(polygonsOverlap(p->footprint, i->footprint, 1e-6)) << i->osm_id;
    // Without OSM buildings the same streets carry more procedural buildings and no imported one.
    const OsmCity off = osmCity(false);
    EXPECT_FALSE(off.city.osmBuildings.enabled);
    for (const auto& b : off.city.buildings) EXPECT_EQ(b.source, BuildingSource::Procedural);
    EXPECT_GT(off.city.buildings.size(), procedural.size());
    EXPECT_GE(off.city.lots.size(), c.lots.size() + c.osmBuildings.lotsDropped);
}

TEST(OsmGen, BuildingsAreDeterministicCountedAndCanBeTurnedOff) {
    test::TempDir dir("vista_osm_buildings");
    auto run = [&](const std::string& args) {
        const std::string cmd = std::string(VISTA_BINARY) + " gen --osm " + fixture("buildings.osm") + " --size 800 " + args +
                                " 2>" + dir.file("err.txt") + " >/dev/null";
        const int st = std::system(cmd.c_str());
        return std::make_pair(WIFEXITED(st) ? WEXITSTATUS(st) : -1, test::readBytes(dir.file("err.txt")));
    };
    auto [code, err] = run("-q -o " + dir.file("a.osgb") + " --stats " + dir.file("a.json"));
    ASSERT_EQ(code, 0) << err;
    EXPECT_NE(err.find("osm: skipped 3 of 13 building footprints"), std::string::npos) << err;
    std::tie(code, err) = run("-q --threads 2 -o " + dir.file("b.osgb"));
    ASSERT_EQ(code, 0) << err;
    const std::string a = test::readBytes(dir.file("a.osgb")), b = test::readBytes(dir.file("b.osgb"));
    ASSERT_FALSE(a.empty());
    EXPECT_TRUE(a == b) << "the same input gave different bytes";
    const auto j = nlohmann::json::parse(test::readBytes(dir.file("a.json")));
    ASSERT_TRUE(j.contains("osm_buildings"));
    const auto& o = j["osm_buildings"];
    EXPECT_EQ(o["imported"], 10);
    EXPECT_EQ(o["candidates"], 13);
    EXPECT_EQ(o["skipped"]["missing_nodes"], 1);
    EXPECT_EQ(o["skipped"]["too_small"], 1);
    EXPECT_EQ(o["skipped"]["too_few_nodes"], 1);
    EXPECT_EQ(o["repaired"]["self_intersections"], 1);
    EXPECT_EQ(o["repaired"]["unclosed_rings"], 1);
    EXPECT_EQ(o["repaired"]["duplicate_nodes"], 1);
    EXPECT_EQ(o["repaired"]["inner_rings_dropped"], 1);
    EXPECT_GE(j["buildings"].get<int>(), 10);
    // Off: no import, no stats object, different city.
    std::tie(code, err) = run("-q --osm-buildings off -o " + dir.file("c.osgb") + " --stats " + dir.file("c.json"));
    ASSERT_EQ(code, 0) << err;
    EXPECT_FALSE(nlohmann::json::parse(test::readBytes(dir.file("c.json"))).contains("osm_buildings"));
    EXPECT_FALSE(test::readBytes(dir.file("c.osgb")) == a);
    // A bad value: exit 2 naming the option.
    std::tie(code, err) = run("-q --osm-buildings maybe -o " + dir.file("d.osgb"));
    EXPECT_EQ(code, 2);
    EXPECT_NE(err.find("--osm-buildings"), std::string::npos) << err;
}

TEST(FootprintRepair, RandomRingsGiveSimpleCounterClockwiseRingsOrNothing) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-20.0, 20.0);
    std::uniform_int_distribution<int> count(3, 24);
    size_t repaired = 0, kept = 0;
    for (int k = 0; k < 400; ++k) {
        Polygon2 ring;
        const int n = count(rng);
        for (int i = 0; i < n; ++i) {
            // Snap some vertices to a coarse grid, so touching and collinear cases occur.
            glm::dvec2 p(u(rng), u(rng));
            if (i % 3 == 0) p = glm::round(p / 10.0) * 10.0;
            ring.push_back(p);
        }
        if (k % 5 == 0) ring.push_back(ring[size_t(n / 2)]);  // a repeated vertex further on
        bool split = false;
        const Polygon2 r = makeSimpleRing(ring, split);
        if (r.empty()) continue;
        ++kept;
        repaired += split ? 1 : 0;
        EXPECT_TRUE(isSimpleRingExact(r)) << k;
        EXPECT_GT(signedArea(r), 0.0) << k;
        // Every vertex of the result is an input vertex or lies on an input edge (a split point).
        for (const auto& q : r) {
            double best = 1e300;
            for (size_t i = 0; i < ring.size(); ++i) best = std::min(best, pointSegmentDistance(q, ring[i], ring[(i + 1) % ring.size()]));
            EXPECT_LT(best, 1e-9) << k;
        }
    }
    EXPECT_GT(kept, 300u);
    EXPECT_GT(repaired, 200u);
}

TEST(OsmBuildings, PbfGivesTheSameFootprintsAsXml) {
    // buildings.osm.pbf: buildings.osm converted to PBF by libosmium's writer.
    CityParams p;
    p.size_m = 800;
    auto x = importOsm(fixture("buildings.osm"), p, true), b = importOsm(fixture("buildings.osm.pbf"), p, true);
    ASSERT_TRUE(x.isOk() && b.isOk());
    ASSERT_EQ(x->buildings.size(), b->buildings.size());
    for (size_t i = 0; i < x->buildings.size(); ++i) {
        EXPECT_EQ(x->buildings[i].osm_id, b->buildings[i].osm_id);
        EXPECT_EQ(x->buildings[i].outer, b->buildings[i].outer);
        EXPECT_EQ(x->buildings[i].holes, b->buildings[i].holes);
    }
    EXPECT_EQ(x->buildingStats.missingNodes, b->buildingStats.missingNodes);
    EXPECT_EQ(x->buildingStats.innerRingsDropped, b->buildingStats.innerRingsDropped);
}
