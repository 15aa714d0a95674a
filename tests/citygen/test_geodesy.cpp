// Geodesy of OSM imports: projected distances against Vincenty, round trips, the antimeridian,
// the geo reference in the parameters and in GeoJSON.
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
#include "tests/citygen/osm_fixtures.h"

using namespace vista;

// ---- geodesy ------------------------------------------------------------------

TEST(Geodesy, ProjectedDistancesMatchVincentyAnywhere) {
    // Points up to half the largest city's diagonal from the reference: pairs up to 90.5 km apart.
    const double reach = 0.5 * std::sqrt(2.0) * maxCitySize();
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> bearing(0, 360), dist(0, reach);
    const GeoReference refs[] = {{0, 0},        {48.2, 16.37}, {60, 10},  {-60, -70},      {89.5, 30},
                                 {-89.5, -150}, {89.95, 0},    {20, 180}, {-33.9, -179.99}};
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
        // 0.1 % is the contract; transverse Mercator's scale error at a distance d from its
        // central meridian is about d^2 / 2R^2 (2.5e-5 at the reach).
        const double R = 6371000.0, scaleError = reach * reach / (2 * R * R);
        EXPECT_LT(worst, 1e-3) << "reference " << ref.lat0_deg << ", " << ref.lon0_deg;
        EXPECT_LT(worst, 1.5 * scaleError) << "reference " << ref.lat0_deg << ", " << ref.lon0_deg;
    }
}

TEST(Geodesy, RoundTripWithinOneCentimetre) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> local(-20000, 20000), bearing(0, 360), dist(0, 20000);
    const GeoReference refs[] = {{0, 0},    {60, 10},  {89.5, 0},  {-89.5, 120}, {90, 0},
                                 {-90, 45}, {10, 180}, {-5, -180}, {0, 179.999}};
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
    struct Case {
        const char* json;
        const char* expect;
    };
    const Case cases[] = {
        {R"({"geo": {"projection": "tmerc", "lat0_deg": 95, "lon0_deg": 0}})",
         "'geo.lat0_deg' = 95 is out of range [-90, 90]"},
        {R"({"geo": {"projection": "tmerc", "lat0_deg": 0, "lon0_deg": -181}})",
         "'geo.lon0_deg' = -181 is out of range [-180, 180]"},
        {R"({"geo": {"projection": "utm", "lat0_deg": 0, "lon0_deg": 0}})",
         "'geo.projection' = \"utm\" is not supported"},
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
