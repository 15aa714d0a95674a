// OSM road tags (osm_road_tags.h): the parsers, the per-way resolution of
// lanes / oneway / turn lanes / maxspeed / width, their transfer onto the
// planar edges of importOsm() (pieces of a split way, edges running against
// their way, dual carriageways kept as two one-way edges), the counts vista gen
// --stats reports for the fixture tests/data/osm/lanes.osm, and the street
// graph JSON of the new edge fields (round trip, refusals, generated cities
// without them).
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "citygen/osm_road_tags.h"
#include "citygen/streets.h"
#include "tests/common/temp_dir.h"

using namespace vista;

namespace {

std::string fixture(const char* name) { return std::string(VISTA_TEST_DATA) + "/osm/" + name; }

constexpr float kMph = 1.609344f;

// readOsmRoadTags() on a plain tag map.
OsmRoadTags read(const std::map<std::string, std::string>& tags, RoadClass cls, OsmRoadTagStats& st) {
    return readOsmRoadTags(
        [&](const char* key) {
            auto it = tags.find(key);
            return it == tags.end() ? nullptr : it->second.c_str();
        },
        cls, st);
}
OsmRoadTags read(const std::map<std::string, std::string>& tags, RoadClass cls = RoadClass::Local) {
    OsmRoadTagStats st;
    return read(tags, cls, st);
}

}  // namespace

TEST(OsmRoadTags, LaneCountsOnewayAndTurnLanesParse) {
    EXPECT_EQ(parseOsmLaneCount("2"), 2);
    EXPECT_EQ(parseOsmLaneCount(" 3 "), 3);
    EXPECT_EQ(parseOsmLaneCount("12"), 12);
    EXPECT_EQ(parseOsmLaneCount("16"), kMaxLanesTotal);
    for (const char* bad : {"", "0", "-1", "two", "2;3", "2.5", "+2", "2 lanes", "99999999", "17"})
        EXPECT_FALSE(parseOsmLaneCount(bad).has_value()) << bad;
    EXPECT_EQ(parseOsmDirectionLaneCount("8"), kMaxLanesPerDirection);
    EXPECT_FALSE(parseOsmDirectionLaneCount("9").has_value());
    EXPECT_FALSE(parseOsmDirectionLaneCount("0").has_value());

    EXPECT_EQ(parseOsmOneway("yes"), OsmOneway::Forward);
    EXPECT_EQ(parseOsmOneway("true"), OsmOneway::Forward);
    EXPECT_EQ(parseOsmOneway("1"), OsmOneway::Forward);
    EXPECT_EQ(parseOsmOneway("-1"), OsmOneway::Backward);
    EXPECT_EQ(parseOsmOneway("reverse"), OsmOneway::Backward);
    EXPECT_EQ(parseOsmOneway("no"), OsmOneway::No);
    EXPECT_EQ(parseOsmOneway("false"), OsmOneway::No);
    for (const char* bad : {"", "maybe", "reversible", "alternating", "YES"})
        EXPECT_FALSE(parseOsmOneway(bad).has_value()) << bad;

    auto t = parseOsmTurnLanes("left|through;right");
    ASSERT_TRUE(t.has_value());
    EXPECT_EQ(t->lanes, 2);
    EXPECT_EQ(t->value, "left|through;right");
    t = parseOsmTurnLanes(" left | through ; slight_right ||none");
    ASSERT_TRUE(t.has_value());
    EXPECT_EQ(t->lanes, 4);
    EXPECT_EQ(t->value, "left|through;slight_right||none");
    t = parseOsmTurnLanes("|");  // two lanes without markings
    ASSERT_TRUE(t.has_value());
    EXPECT_EQ(t->lanes, 2);
    for (const char* bad : {"", " ", "left|up", "left;;right", "Left", "l|l|l|l|l|l|l|l|l",
                            "left|through|through|through|through|through|through|through|right"})
        EXPECT_FALSE(parseOsmTurnLanes(bad).has_value()) << bad;
}

TEST(OsmRoadTags, MaxspeedUnitsWordsAndCountryCodes) {
    auto near = [](const std::optional<float>& v, double want) { return v && std::abs(*v - want) < 1e-3; };
    EXPECT_TRUE(near(parseOsmMaxspeed("50"), 50));
    EXPECT_TRUE(near(parseOsmMaxspeed("50 km/h"), 50));
    EXPECT_TRUE(near(parseOsmMaxspeed("80kmh"), 80));
    EXPECT_TRUE(near(parseOsmMaxspeed("30 mph"), 30 * 1.609344));
    EXPECT_TRUE(near(parseOsmMaxspeed("30mph"), 30 * 1.609344));
    EXPECT_TRUE(near(parseOsmMaxspeed("10 knots"), 18.52));
    EXPECT_TRUE(near(parseOsmMaxspeed("none"), kMaxspeedNoneKmh));
    EXPECT_TRUE(near(parseOsmMaxspeed("walk"), kMaxspeedWalkKmh));
    EXPECT_TRUE(near(parseOsmMaxspeed("DE:urban"), 50));
    EXPECT_TRUE(near(parseOsmMaxspeed("DE:rural"), 100));
    EXPECT_TRUE(near(parseOsmMaxspeed("DE:motorway"), kMaxspeedNoneKmh));
    EXPECT_TRUE(near(parseOsmMaxspeed("FR:rural"), 80));
    EXPECT_TRUE(near(parseOsmMaxspeed("AT:motorway"), 130));
    EXPECT_TRUE(near(parseOsmMaxspeed("DE:zone30"), 30));
    EXPECT_TRUE(near(parseOsmMaxspeed("DE:zone:20"), 20));
    EXPECT_TRUE(near(parseOsmMaxspeed("GB:zone20"), 20 * 1.609344));
    EXPECT_TRUE(near(parseOsmMaxspeed("GB:nsl_single"), 60 * 1.609344));
    EXPECT_TRUE(near(parseOsmMaxspeed("DE:living_street"), kMaxspeedWalkKmh));
    // Plausible limits are [5, 250] km/h, both included; beyond them the value is not used.
    EXPECT_TRUE(near(parseOsmMaxspeed("5"), kMinMaxspeedKmh));
    EXPECT_TRUE(near(parseOsmMaxspeed("250"), kMaxMaxspeedKmh));
    for (const char* bad : {"",
                            "0",
                            "signals",
                            "variable",
                            "fast",
                            "50;30",
                            "50 km",
                            "-30",
                            "XX:urban",
                            "de:urban",
                            "DE:school",
                            "DE:trunk",
                            "DE:zone",
                            "1e3",
                            "50..5",
                            "2",
                            "1000",
                            "200 mph",
                            "DE:zone99999999999999999999",
                            "DE:zone:4",
                            "GB:zone200"})
        EXPECT_FALSE(parseOsmMaxspeed(bad).has_value()) << bad;
}

TEST(OsmRoadTags, DirectionsAndLaneCountsResolve) {
    // Two-way without directional tags: derived (-1) from the total.
    OsmRoadTags t = read({{"lanes", "4"}});
    EXPECT_EQ(t.lanes, 4);
    EXPECT_EQ(t.lanesForward, -1);
    EXPECT_EQ(t.lanesBackward, -1);
    t = read({}, RoadClass::Arterial);
    EXPECT_EQ(t.lanes, 0);  // the class default stays
    EXPECT_EQ(t.lanesForward, -1);
    // One direction tagged: the other from the total, else the derived split.
    t = read({{"lanes", "4"}, {"lanes:forward", "3"}});
    EXPECT_EQ(t.lanesForward, 3);
    EXPECT_EQ(t.lanesBackward, 1);
    t = read({{"lanes", "2"}, {"lanes:forward", "3"}});  // inconsistent: lanes:forward wins (below)
    EXPECT_EQ(t.lanesForward, 3);
    EXPECT_EQ(t.lanesBackward, 1);
    EXPECT_EQ(t.lanes, 4);
    t = read({{"lanes:backward", "2"}}, RoadClass::Arterial);  // forward: the derived split of the class total 4
    EXPECT_EQ(t.lanesForward, 2);
    EXPECT_EQ(t.lanesBackward, 2);
    EXPECT_EQ(t.lanes, 4);
    // Counts from turn lanes.
    t = read({{"lanes", "4"}, {"turn:lanes:backward", "left|through|through;right"}});
    EXPECT_EQ(t.lanesBackward, 3);
    EXPECT_EQ(t.lanesForward, 1);
    EXPECT_EQ(t.turnBackward, "left|through|through;right");
    EXPECT_EQ(t.turnForward, "");
    // Beyond 8 per direction or 16 in total: not used (the class default), never clamped.
    t = read({{"lanes", "20"}, {"lanes:forward", "12"}, {"lanes:backward", "9"}});
    EXPECT_EQ(t.lanes, 0);
    EXPECT_EQ(t.lanesForward, -1);
    EXPECT_EQ(t.lanesBackward, -1);
    // One-way along the way, against it, implied; oneway=no overrides the implication.
    t = read({{"oneway", "yes"}, {"lanes", "3"}});
    EXPECT_EQ(t.lanesForward, 3);
    EXPECT_EQ(t.lanesBackward, 0);
    EXPECT_EQ(t.lanes, 3);
    t = read({{"oneway", "-1"}, {"lanes:backward", "2"}, {"turn:lanes", "left|through"}});
    EXPECT_EQ(t.lanesForward, 0);
    EXPECT_EQ(t.lanesBackward, 2);
    EXPECT_EQ(t.turnBackward, "left|through");
    EXPECT_EQ(t.turnForward, "");
    EXPECT_TRUE(t.onlyBackward());
    EXPECT_TRUE(t.reversed().onlyForward());
    EXPECT_EQ(t.reversed().turnForward, "left|through");
    t = read({{"highway", "motorway"}}, RoadClass::Highway);
    EXPECT_EQ(t.lanesForward, 3);  // ceil(6 / 2)
    EXPECT_EQ(t.lanesBackward, 0);
    t = read({{"highway", "motorway"}, {"oneway", "no"}}, RoadClass::Highway);
    EXPECT_EQ(t.lanesForward, -1);
    t = read({{"junction", "roundabout"}});
    EXPECT_EQ(t.lanesForward, 1);
    EXPECT_EQ(t.lanesBackward, 0);
    t = read({{"junction", "circular"}, {"lanes", "2"}});
    EXPECT_EQ(t.lanesForward, 2);
    EXPECT_EQ(t.lanesBackward, 0);
    t = read({{"oneway", "yes"}, {"lanes:forward", "11"}});
    EXPECT_EQ(t.lanesForward, 1);  // ceil(2 / 2): the class default
    EXPECT_EQ(t.lanes, 1);
    t = read({{"oneway", "yes"}, {"lanes", "12"}}, RoadClass::Arterial);  // more than one direction holds
    EXPECT_EQ(t.lanesForward, 2);
    EXPECT_EQ(t.lanes, 2);
}

// The lanes written (forward + backward, as the lane model and the .xodr
// take them) against the `lanes` tag: a way counts `lanes` as used only when
// the two agree; otherwise the directional tags win and the way is counted
// as inconsistent. Implausible values (maxspeed beyond 250 km/h, lane counts
// beyond 8 a direction) fall back to the class default and are counted.
TEST(OsmRoadTags, ImplausibleAndInconsistentTagsFallBackAndAreCounted) {
    struct Case {
        std::map<std::string, std::string> tags;
        int forward, backward;  // resolved; -1 = derived by the lane model
        bool lanesUsed, inconsistent;
    };
    const Case cases[] = {
        {{{"lanes", "1"}, {"lanes:forward", "5"}}, 5, 1, false, true},
        {{{"oneway", "yes"}, {"lanes", "1"}, {"lanes:forward", "5"}}, 5, 0, false, true},
        {{{"oneway", "-1"}, {"lanes", "3"}, {"lanes:backward", "2"}}, 0, 2, false, true},
        {{{"lanes", "4"}, {"lanes:forward", "1"}, {"lanes:backward", "1"}}, 1, 1, false, true},
        {{{"lanes", "16"}, {"lanes:forward", "1"}}, 1, 1, false, true},  // would leave 15 backward
        {{{"lanes", "3"}, {"lanes:forward", "2"}, {"lanes:backward", "1"}}, 2, 1, true, false},
        {{{"lanes", "4"}, {"lanes:forward", "3"}}, 3, 1, true, false},
        {{{"oneway", "yes"}, {"lanes", "2"}, {"lanes:forward", "2"}}, 2, 0, true, false},
        {{{"lanes", "5"}}, -1, -1, true, false},
    };
    for (const Case& c : cases) {
        std::string what;
        for (const auto& [k, v] : c.tags) what += k + "=" + v + " ";
        SCOPED_TRACE(what);
        OsmRoadTagStats st;
        const OsmRoadTags t = read(c.tags, RoadClass::Local, st);
        EXPECT_EQ(t.lanesForward, c.forward);
        EXPECT_EQ(t.lanesBackward, c.backward);
        EXPECT_EQ(st.lanes.used, c.lanesUsed ? 1u : 0u);
        EXPECT_EQ(st.lanes.fallback, c.lanesUsed ? 0u : 1u);
        EXPECT_EQ(st.lanesInconsistent, c.inconsistent ? 1u : 0u);
        // `lanes` agrees with the lanes written whenever the directions are known.
        if (t.lanesForward >= 0) { EXPECT_EQ(t.lanes, t.lanesForward + t.lanesBackward); }
        if (c.lanesUsed) { EXPECT_EQ(t.lanes, std::stoi(c.tags.at("lanes"))); }
    }
    // maxspeed=DE:zone99999999999999999999 is no limit of 250 km/h: the class default, counted.
    OsmRoadTagStats st;
    const OsmRoadTags t = read({{"maxspeed", "DE:zone99999999999999999999"}}, RoadClass::Arterial, st);
    EXPECT_EQ(t.maxspeedKmh, 0.0f);
    EXPECT_EQ(st.maxspeed.fallback, 1u);
    EXPECT_EQ(st.maxspeed.used, 0u);
    EXPECT_EQ(st.defaultMaxspeed, 1u);
    // The counts reach --stats.
    st.lanesInconsistent = 3;
    EXPECT_EQ(nlohmann::json::parse(osmRoadTagStatsJson(st))["tags"]["lanes"]["inconsistent"], 3);
}

// An over-long tag value names the tag and the way (libosmium alone says "OSM tag value is too long").
TEST(OsmRoadTags, AnOverLongTagValueNamesTheTagAndTheWay) {
    test::TempDir dir("vista_osm_long_tag");
    const std::string file = dir.file("long.osm");
    std::ofstream(file) << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<osm version=\"0.6\">\n"
                           "<node id=\"1\" lat=\"48.2\" lon=\"16.37\"/><node id=\"2\" lat=\"48.2\" lon=\"16.376\"/>\n"
                           "<way id=\"4242\"><nd ref=\"1\"/><nd ref=\"2\"/><tag k=\"highway\" v=\"primary\"/>"
                           "<tag k=\"name\" v=\""
                        << std::string(1100, 'x') << "\"/></way>\n</osm>\n";
    auto r = importOsm(file, CityParams());
    ASSERT_FALSE(r.isOk());
    const std::string& m = r.status().message();
    EXPECT_NE(m.find("way 4242"), std::string::npos) << m;
    EXPECT_NE(m.find("tag 'name'"), std::string::npos) << m;
    EXPECT_NE(m.find("1100 bytes"), std::string::npos) << m;
    EXPECT_NE(m.find("1024"), std::string::npos) << m;
    // References count as the bytes they stand for: 1000 x "&amp;" is 1000 bytes, within the limit.
    std::string amps;
    for (int i = 0; i < 1000; ++i) amps += "&amp;";
    std::ofstream(file) << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<osm version=\"0.6\">\n"
                           "<node id=\"1\" lat=\"48.2\" lon=\"16.37\"/><node id=\"2\" lat=\"48.2\" lon=\"16.376\"/>\n"
                           "<way id=\"7\"><nd ref=\"1\"/><nd ref=\"2\"/><tag k=\"highway\" v=\"primary\"/>"
                           "<tag k=\"name\" v=\""
                        << amps << "\"/></way>\n</osm>\n";
    auto ok = importOsm(file, CityParams());
    if (!ok) { EXPECT_EQ(ok.status().message().find("limit of 1024"), std::string::npos) << ok.status().message(); }
}

TEST(OsmRoadTags, UnusableValuesFallBackAndAreCounted) {
    OsmRoadTagStats st;
    // Turn lanes whose count contradicts the lane count, turn:lanes on a two-way road.
    OsmRoadTags t =
        read({{"oneway", "yes"}, {"lanes", "2"}, {"turn:lanes", "left|through|right"}}, RoadClass::Local, st);
    EXPECT_EQ(t.lanesForward, 2);
    EXPECT_EQ(t.turnForward, "");
    t = read({{"turn:lanes", "left|through"}, {"lanes", "2"}}, RoadClass::Local, st);
    EXPECT_EQ(t.turnForward, "");
    EXPECT_EQ(t.turnBackward, "");
    EXPECT_EQ(st.turnLanes.used, 0u);
    EXPECT_EQ(st.turnLanes.fallback, 2u);
    // Contradicting the one-way: lanes:backward and turn:lanes:backward on oneway=yes.
    t = read({{"oneway", "yes"}, {"lanes:backward", "2"}, {"turn:lanes:backward", "left"}}, RoadClass::Local, st);
    EXPECT_EQ(t.lanesForward, 1);
    EXPECT_EQ(t.lanesBackward, 0);
    EXPECT_EQ(t.turnBackward, "");
    EXPECT_EQ(st.lanesBackward.fallback, 1u);
    EXPECT_EQ(st.turnLanesBackward.fallback, 1u);
    // Invalid values: class defaults, each counted.
    OsmRoadTagStats bad;
    t = read(
        {{"oneway", "reversible"}, {"lanes", "0"}, {"maxspeed", "signals"}, {"width", "0.2"}, {"lanes:forward", "x"}},
        RoadClass::Local, bad);
    EXPECT_EQ(t.lanes, 0);
    EXPECT_EQ(t.lanesForward, -1);
    EXPECT_EQ(t.lanesBackward, -1);
    EXPECT_EQ(t.maxspeedKmh, 0.0f);
    EXPECT_EQ(t.width, 0.0f);
    EXPECT_EQ(bad.ways, 1u);
    EXPECT_EQ(bad.oneway.fallback, 1u);
    EXPECT_EQ(bad.lanes.fallback, 1u);
    EXPECT_EQ(bad.lanesForward.fallback, 1u);
    EXPECT_EQ(bad.maxspeed.fallback, 1u);
    EXPECT_EQ(bad.width.fallback, 1u);
    EXPECT_EQ(bad.defaultLanes + bad.defaultMaxspeed + bad.defaultWidth, 3u);
    EXPECT_EQ(bad.oneway.used + bad.lanes.used + bad.maxspeed.used + bad.width.used, 0u);
    // Widths: metres and feet; too narrow or too wide is unusable.
    EXPECT_FLOAT_EQ(read({{"width", "3.5 m"}}).width, 3.5f);
    EXPECT_FLOAT_EQ(read({{"width", "12'"}}).width, float(12 * 0.3048));
    EXPECT_EQ(read({{"width", "150"}}).width, 0.0f);
}

// ---- the fixture: edges and --stats ---------------------------------------------------

namespace {

// What the ways of lanes.osm carry, in the way's direction (make_lanes.py).
struct WayExpect {
    const char* name;
    glm::dvec2 p, q;  // the way's line, drawn from p towards q (metres, city frame)
    RoadClass cls;
    int lanes, forward, backward;
    const char* turnForward;
    const char* turnBackward;
    float maxspeed, width;
};
const WayExpect kLanesWays[] = {
    {"main", {-200, 0}, {200, 0}, RoadClass::Highway, 3, 2, 1, "left|through;right", "", 50, 10.5f},
    {"102", {0, 150}, {0, -150}, RoadClass::Arterial, 3, 2, 1, "left|through", "through;right", 50, 13.0f},
    // One-way ways without a width tag: their lanes at the class's lane width (7.5 m / 2, 20 m / 6, 13 m / 4).
    {"103", {100, -150}, {100, 0}, RoadClass::Local, 1, 0, 1, "", "", kMaxspeedWalkKmh, 3.75f},
    {"104", {-100, 0}, {-100, 150}, RoadClass::Local, 2, 2, 0, "left|through", "", 30 * kMph, float(24 * 0.3048)},
    {"107", {-100, 150}, {100, 150}, RoadClass::Local, 2, -1, -1, "", "", 0, 7.5f},
    {"motorway", {200, -150}, {-200, -150}, RoadClass::Highway, 3, 3, 0, "", "", kMaxspeedNoneKmh, 10.0f},
    {"108", {0, -75}, {100, -75}, RoadClass::Arterial, 2, 2, 0, "", "", 60, 6.5f},
};

double pointLineDistance(const glm::dvec2& x, const glm::dvec2& p, const glm::dvec2& q) {
    const glm::dvec2 d = q - p;
    const double t = std::clamp(glm::dot(x - p, d) / glm::dot(d, d), 0.0, 1.0);
    return glm::length(x - (p + t * d));
}

}  // namespace

TEST(OsmRoadTags, FixtureEdgesCarryTheirWaysTagsInTheirDirection) {
    auto imp = importOsm(fixture("lanes.osm"), CityParams());
    ASSERT_TRUE(imp.isOk()) << imp.status().message();
    const StreetGraph& g = imp->streets;
    ASSERT_EQ(g.edges.size(), 16u);
    std::map<std::string, int> pieces;
    int against = 0;
    for (const auto& e : g.edges) {
        const glm::dvec2 a = g.nodes[e.a], b = g.nodes[e.b], mid = 0.5 * (a + b);
        const WayExpect* w = nullptr;
        for (const auto& x : kLanesWays)
            if (pointLineDistance(mid, x.p, x.q) < 1.0 && pointLineDistance(a, x.p, x.q) < 1.0 &&
                pointLineDistance(b, x.p, x.q) < 1.0)
                w = &x;
        ASSERT_NE(w, nullptr) << "edge at (" << mid.x << ", " << mid.y << ") lies on no way of the fixture";
        ++pieces[w->name];
        const bool along = glm::dot(b - a, w->q - w->p) > 0;
        against += !along;
        if (w->forward == 0 || w->backward == 0) {  // one-way: the edge runs along its traffic
            EXPECT_EQ(along, w->backward == 0) << w->name;
        }
        SCOPED_TRACE(std::string("way ") + w->name + (along ? " (edge along the way)" : " (edge against the way)"));
        EXPECT_EQ(e.cls, w->cls);
        EXPECT_EQ(int(e.lanes), w->lanes);
        EXPECT_EQ(int(e.lanesForward), along ? w->forward : w->backward);
        EXPECT_EQ(int(e.lanesBackward), along ? w->backward : w->forward);
        EXPECT_EQ(e.turnForward, along ? w->turnForward : w->turnBackward);
        EXPECT_EQ(e.turnBackward, along ? w->turnBackward : w->turnForward);
        EXPECT_NEAR(e.maxspeedKmh, w->maxspeed, 1e-3);
        EXPECT_NEAR(e.width, w->width, 1e-4);
    }
    // Split ways: every piece carries the tags.
    EXPECT_EQ(pieces["main"], 4);
    EXPECT_EQ(pieces["102"], 3);
    EXPECT_EQ(pieces["motorway"], 3);
    EXPECT_EQ(pieces["103"], 2);
    // Way 102 is drawn north -> south, so its edges (a south of b) run against it; so does 103
    // (oneway=-1: its edges run along its traffic, against its drawing).
    EXPECT_GE(against, 5);
    const OsmRoadTagStats& st = imp->roadTagStats;
    EXPECT_EQ(st.edgesMatched, 16u);
    EXPECT_EQ(st.edgesUnmatched, 0u);
    EXPECT_EQ(st.edgesMergedOneWays, 0u);
}

TEST(OsmRoadTags, StatsReportTagUseAndFallbacks) {
    test::TempDir dir("vista_osm_lanes");
    const std::string cmd = std::string(VISTA_BINARY) + " gen --osm " + fixture("lanes.osm") +
                            " --size 600 --detail 0 -q -o " + dir.file("c.osgb") + " --stats " + dir.file("s.json") +
                            " 2>" + dir.file("err.txt");
    const int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << test::readBytes(dir.file("err.txt"));
    const auto j = nlohmann::json::parse(test::readBytes(dir.file("s.json")));
    ASSERT_TRUE(j.contains("osm_roads")) << j.dump(2);
    const auto& o = j["osm_roads"];
    EXPECT_EQ(o["ways"], 7);
    const auto& t = o["tags"];
    auto use = [&](const char* tag, int used, int fallback) {
        EXPECT_EQ(t[tag]["used"], used) << tag;
        EXPECT_EQ(t[tag]["fallback"], fallback) << tag;
    };
    use("lanes", 3, 2);  // 100, 103, 105; "two", 108's 12 on a one-way
    EXPECT_EQ(t["lanes"]["inconsistent"], 0);
    use("lanes:forward", 2, 0);                 // 100, 102
    use("lanes:backward", 2, 1);                // 100, 102; on the one-way 108
    use("oneway", 3, 1);                        // 103, 104, 108; "maybe"
    EXPECT_EQ(t["oneway"]["implied"], 1);       // the motorway
    use("turn:lanes", 1, 0);                    // 104
    use("turn:lanes:forward", 2, 1);            // 100, 102; "left|up"
    use("turn:lanes:backward", 1, 0);           // 102
    use("maxspeed", 6, 1);                      // all but 107 ("signals")
    use("width", 2, 1);                         // 100, 104; "wide"
    EXPECT_EQ(o["class_default"]["lanes"], 2);  // 107, 108
    EXPECT_EQ(o["class_default"]["maxspeed"], 1);
    EXPECT_EQ(o["class_default"]["width"], 5);
    EXPECT_EQ(o["edges"]["matched"], j["street_edges"]);
    EXPECT_EQ(o["edges"]["unmatched"], 0);
    // A generated city reports no osm_roads.
    const std::string gen = std::string(VISTA_BINARY) + " gen --size 400 --detail 0 -q -o " + dir.file("g.osgb") +
                            " --stats " + dir.file("g.json") + " 2>" + dir.file("err.txt");
    ASSERT_EQ(std::system(gen.c_str()), 0) << test::readBytes(dir.file("err.txt"));
    EXPECT_FALSE(nlohmann::json::parse(test::readBytes(dir.file("g.json"))).contains("osm_roads"));
}

namespace {

// An .osm text: nodes 1..n at `pts` (metres about 48.21 N, 16.36 E), then ways of node ids and
// their tags as written XML ("<tag .../>...").
std::string osmText(const std::vector<glm::dvec2>& pts,
                    const std::vector<std::pair<std::vector<int>, std::string>>& ways) {
    const double lat0 = 48.21, mLat = 1.0 / 111132.0, mLon = 1.0 / (111320.0 * std::cos(lat0 * 3.14159265358979 / 180));
    std::string xml = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<osm version=\"0.6\" generator=\"vista-test\">\n";
    for (size_t i = 0; i < pts.size(); ++i) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "  <node id=\"%zu\" lat=\"%.7f\" lon=\"%.7f\"/>\n", i + 1,
                      lat0 + pts[i].y * mLat, 16.36 + pts[i].x * mLon);
        xml += buf;
    }
    for (size_t w = 0; w < ways.size(); ++w) {
        xml += "  <way id=\"" + std::to_string(w + 1) + "\">";
        for (int r : ways[w].first) xml += "<nd ref=\"" + std::to_string(r) + "\"/>";
        xml += ways[w].second + "</way>\n";
    }
    return xml + "</osm>\n";
}

Result<OsmImport> importText(const std::string& xml) {
    test::TempDir dir("vista_osm_road_tags");
    std::ofstream(dir.file("t.osm"), std::ios::binary) << xml;
    return importOsm(dir.file("t.osm"), CityParams());
}

}  // namespace

TEST(OsmRoadTags, OppositeOneWaysStayTwoOneWayEdgesWithTheirOwnTags) {
    // A dual carriageway 8 m wide: two one-way ways sharing their end nodes, closer than the snap
    // radius and the minimum segment. Each stays its own edges, one-way along its traffic, with
    // its own lanes, turn lanes and a width of its lanes (primary: 20 m / 6 lanes each).
    auto imp = importText(
        osmText({{-200, 0}, {-100, 4}, {100, 4}, {200, 0}, {100, -4}, {-100, -4}},
                {{{1, 2, 3, 4},
                  R"(<tag k="highway" v="primary"/><tag k="oneway" v="yes"/><tag k="lanes" v="2"/>)"
                  R"(<tag k="turn:lanes" v="through|right"/>)"},
                 {{4, 5, 6, 1}, R"(<tag k="highway" v="primary"/><tag k="oneway" v="yes"/><tag k="lanes" v="1"/>)"}}));
    ASSERT_TRUE(imp.isOk()) << imp.status().message();
    const StreetGraph& g = imp->streets;
    ASSERT_EQ(g.edges.size(), 6u) << "the carriageways were merged";
    int north = 0, south = 0;
    for (const auto& e : g.edges) {
        const glm::dvec2 a = g.nodes[e.a], b = g.nodes[e.b];
        const bool northern = a.y + b.y > 0;  // way 1 (eastward); way 2 runs west on the south side
        (northern ? north : south)++;
        SCOPED_TRACE(northern ? "northern carriageway" : "southern carriageway");
        EXPECT_EQ(b.x > a.x, northern) << "the edge does not run along its traffic";
        EXPECT_EQ(int(e.lanesForward), northern ? 2 : 1);
        EXPECT_EQ(int(e.lanesBackward), 0);
        EXPECT_EQ(e.turnForward, northern ? "through|right" : "");
        EXPECT_EQ(e.turnBackward, "");
        EXPECT_EQ(int(e.lanes), northern ? 2 : 1);
        EXPECT_NEAR(e.width, (northern ? 2 : 1) * 20.0 / 6.0, 1e-4);
    }
    EXPECT_EQ(north, 3);
    EXPECT_EQ(south, 3);
    EXPECT_EQ(imp->roadTagStats.edgesMergedOneWays, 0u);
}

TEST(OsmRoadTags, OppositeOneWaysOnTheSameLineGiveOneDirectionEach) {
    // Two one-way ways drawn over the same nodes' positions (duplicated data, closer than
    // kCarriagewayMerge_m): their segments overlap, so one edge carries both directions.
    auto imp = importText(
        osmText({{-200, 0}, {0, 0.5}, {200, 0}, {0, -0.5}},
                {{{1, 2, 3}, R"(<tag k="highway" v="primary"/><tag k="oneway" v="yes"/><tag k="lanes" v="2"/>)"},
                 {{3, 4, 1}, R"(<tag k="highway" v="primary"/><tag k="oneway" v="yes"/><tag k="lanes" v="1"/>)"}}));
    ASSERT_TRUE(imp.isOk()) << imp.status().message();
    const StreetGraph& g = imp->streets;
    ASSERT_FALSE(g.edges.empty());
    ASSERT_LT(g.edges.size(), 4u) << "the duplicated ways were not merged";
    for (const auto& e : g.edges) {
        const bool eastward = g.nodes[e.b].x > g.nodes[e.a].x;  // way 1 runs east
        EXPECT_EQ(int(e.lanesForward), eastward ? 2 : 1);
        EXPECT_EQ(int(e.lanesBackward), eastward ? 1 : 2);
    }
    EXPECT_EQ(imp->roadTagStats.edgesMergedOneWays, g.edges.size());
}

TEST(OsmRoadTags, ShortEdgeAtAJunctionKeepsItsOwnWayNotTheCrossingOne) {
    // One-way A runs east through a junction, bending by 13 degrees 15 m after it (too much for
    // the bend to be straightened, short_bends.h); one-way B crosses at the junction at 63
    // degrees, its part near that 15 m piece running the other way along x.
    auto imp = importText(osmText(
        {{-100, 0}, {0, 0}, {15, 0}, {100, 20}, {40, -80}, {-40, 80}},
        {{{1, 2, 3, 4}, R"(<tag k="highway" v="residential"/><tag k="oneway" v="yes"/><tag k="maxspeed" v="30"/>)"},
         {{5, 2, 6}, R"(<tag k="highway" v="residential"/><tag k="oneway" v="yes"/><tag k="lanes" v="2"/>)"}}));
    ASSERT_TRUE(imp.isOk()) << imp.status().message();
    const StreetGraph& g = imp->streets;
    int found = 0;
    for (const auto& e : g.edges) {
        const glm::dvec2 a = g.nodes[e.a], b = g.nodes[e.b];
        if (pointLineDistance(a, {40, -80}, {-40, 80}) < 1 && pointLineDistance(b, {40, -80}, {-40, 80}) < 1)
            continue;  // way B
        ++found;
        const bool eastward = b.x > a.x;
        EXPECT_EQ(int(e.lanesForward), eastward ? 1 : 0);
        EXPECT_EQ(int(e.lanesBackward), eastward ? 0 : 1);
        EXPECT_EQ(int(e.lanes), 1);
        EXPECT_FLOAT_EQ(e.maxspeedKmh, 30.0f);
    }
    EXPECT_EQ(found, 3);
    EXPECT_EQ(imp->roadTagStats.edgesMergedOneWays, 0u);
}

// ---- the street graph JSON of the new fields ------------------------------------------

TEST(OsmRoadTags, GraphJsonRoundTripsTheFieldsAndRefusesBadValues) {
    auto imp = importOsm(fixture("lanes.osm"), CityParams());
    ASSERT_TRUE(imp.isOk()) << imp.status().message();
    const StreetGraph& g = imp->streets;
    const std::string text = streetGraphToJson(g);
    auto back = streetGraphFromJson(text);
    ASSERT_TRUE(back.isOk()) << back.status().message();
    ASSERT_EQ(back->edges.size(), g.edges.size());
    size_t withExtras = 0;
    for (size_t i = 0; i < g.edges.size(); ++i) {
        const StreetEdge &x = g.edges[i], &y = back->edges[i];
        EXPECT_EQ(x.lanesForward, y.lanesForward) << i;
        EXPECT_EQ(x.lanesBackward, y.lanesBackward) << i;
        EXPECT_EQ(x.maxspeedKmh, y.maxspeedKmh) << i;
        EXPECT_EQ(x.turnForward, y.turnForward) << i;
        EXPECT_EQ(x.turnBackward, y.turnBackward) << i;
        EXPECT_EQ(x.width, y.width) << i;
        EXPECT_EQ(x.lanes, y.lanes) << i;
        withExtras += x.lanesForward != -1 || x.maxspeedKmh != 0;
    }
    EXPECT_EQ(streetGraphToJson(*back), text);
    // Only the edges of way 107 (no usable tag) keep the five-element form.
    const auto j = nlohmann::json::parse(text);
    size_t six = 0;
    for (const auto& e : j["edges"]) six += e.size() == 6;
    EXPECT_EQ(six, withExtras);
    EXPECT_EQ(six, g.edges.size() - 2);

    const std::string head = R"({"nodes":[[0,0],[100,0]],"edges":[[0,1,2,7.5,3,)";
    auto ok =
        streetGraphFromJson(head + R"({"forward":2,"backward":1,"maxspeed":50,"turn_forward":"left|through"}]]})");
    ASSERT_TRUE(ok.isOk()) << ok.status().message();
    EXPECT_EQ(ok->edges[0].lanesForward, 2);
    EXPECT_EQ(ok->edges[0].turnForward, "left|through");
    // Turn lanes against the derived split: lanes 3 -> forward 2, backward 1.
    EXPECT_TRUE(streetGraphFromJson(head + R"({"turn_backward":"left"}]]})").isOk());
    const std::map<std::string, std::string> bad = {
        {R"({"forward":9})", "forward = 9 is out of range [0, 8]"},
        {R"({"backward":-1})", "backward = -1 is out of range [0, 8]"},
        {R"({"forward":1.5})", "forward must be an integer"},
        {R"({"maxspeed":300})", "maxspeed"},
        {R"({"maxspeed":0})", "maxspeed"},
        {R"({"maxspeed":"fast"})", "maxspeed is not a number"},
        {R"({"turn_forward":"left|up"})", "is not a turn:lanes value"},
        {R"({"turn_forward":""})", "is not a turn:lanes value"},
        {R"({"turn_forward":" left|through"})", "is not a turn:lanes value"},
        {R"({"turn_forward":7})", "turn_forward must be a string"},
        {R"({"forward":2,"turn_forward":"left"})", "turn_forward lists 1 lanes, the direction has 2"},
        {R"({"forward":1,"backward":0,"turn_backward":"left"})", "turn_backward lists 1 lanes, the direction has 0"},
        {R"({"forward":0,"backward":0})", "no driving lane"},
        {R"({"lanes_forward":2})", "unknown key 'lanes_forward'"},
        {R"([2,1])", "must be an object"},
    };
    for (const auto& [extra, message] : bad) {
        auto r = streetGraphFromJson(head + extra + "]]}");
        ASSERT_FALSE(r.isOk()) << extra;
        EXPECT_NE(r.status().message().find(message), std::string::npos) << extra << ": " << r.status().message();
        EXPECT_NE(r.status().message().find("edges[0][5]"), std::string::npos) << r.status().message();
    }
    EXPECT_FALSE(streetGraphFromJson(R"({"nodes":[[0,0],[100,0]],"edges":[[0,1,2,7.5,3,{},{}]]})").isOk());
    // A coordinate of 1e308 is printed short, not as 309 digits.
    auto far = streetGraphFromJson(R"({"nodes":[[1e308,0],[100,0]],"edges":[]})");
    ASSERT_FALSE(far.isOk());
    EXPECT_NE(far.status().message().find("[1e+308, 0]"), std::string::npos) << far.status().message();
    EXPECT_LT(far.status().message().size(), 200u);
}

TEST(OsmRoadTags, GeneratedCitiesKeepTheDefaultsAndTheFiveElementJson) {
    CityParams p;
    p.seed = 11;
    p.size_m = 800;
    const StreetGraph g = growStreets(p, nullptr);
    ASSERT_FALSE(g.edges.empty());
    for (const auto& e : g.edges) {
        EXPECT_EQ(e.lanesForward, -1);
        EXPECT_EQ(e.lanesBackward, -1);
        EXPECT_EQ(e.maxspeedKmh, 0.0f);
        EXPECT_TRUE(e.turnForward.empty() && e.turnBackward.empty());
    }
    const auto j = nlohmann::json::parse(streetGraphToJson(g));
    for (const auto& e : j["edges"]) ASSERT_EQ(e.size(), 5u) << e.dump();
}
