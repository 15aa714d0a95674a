// The traffic room without SUMO: the network reader, the seeded demand and
// the floating-car data, on small hand-written SUMO files.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <regex>
#include <set>
#include <string>

#include "foundation/units.h"
#include "citygen/params.h"
#include "citygen/labels.h"
#include "citygen/lighting.h"
#include "citygen/terrain.h"
#include "runtime/traffic/agent_models.h"
#include "runtime/traffic/ego_path.h"
#include "runtime/traffic/sumo_net.h"
#include "runtime/traffic/signal_states.h"
#include "runtime/traffic/sumo_process.h"
#include "runtime/traffic/traffic_demand.h"
#include "runtime/traffic/traffic_run.h"
#include "runtime/traffic/traffic_tracks.h"
#include "tests/common/temp_dir.h"

using namespace vista;
using vista::test::readBytes;
using vista::test::TempDir;
using vista::test::writeText;

namespace {

// A ring of four two-lane edges a→b→c→d→a (strongly connected for cars),
// a dead-end spur e that leaves the ring (no way back), sidewalks on a and c
// linked through a walking area, and one traffic light.
std::string ringNet(double offX = 100.0, double offY = -50.0) {
    auto edge = [](const std::string& id, double x, double y, const std::string& extra = "") {
        return "  <edge id=\"" + id + "\" from=\"j\" to=\"k\">\n    <lane id=\"" + id +
               "_0\" index=\"0\" disallow=\"pedestrian\" speed=\"13.9\" length=\"80.00\" shape=\"" + std::to_string(x) +
               "," + std::to_string(y) + " " + std::to_string(x + 80) + "," + std::to_string(y) + "\"/>\n" + extra +
               "  </edge>\n";
    };
    const std::string sidewalk = "    <lane id=\"X_1\" index=\"1\" allow=\"pedestrian\" length=\"80.00\"/>\n";
    return "<?xml version=\"1.0\"?>\n<net version=\"1.9\">\n  <location netOffset=\"" + std::to_string(offX) + "," +
           std::to_string(offY) + "\" convBoundary=\"0,0,1,1\"/>\n" + edge("a", 0, 0, sidewalk) + edge("b", 100, 0) +
           edge("c", 100, 100, sidewalk) + edge("d", 0, 100) + edge("e", 500, 500) +
           "  <edge id=\":w0\" function=\"walkingarea\">\n    <lane id=\":w0_0\" index=\"0\" allow=\"pedestrian\" "
           "length=\"5.00\"/>\n  </edge>\n"
           "  <edge id=\":i0\" function=\"internal\">\n    <lane id=\":i0_0\" index=\"0\" length=\"5.00\"/>\n  "
           "</edge>\n"
           "  <tlLogic id=\"J1\" type=\"static\" programID=\"0\" offset=\"0\"/>\n"
           "  <connection from=\"a\" to=\"b\" fromLane=\"0\" toLane=\"0\"/>\n"
           "  <connection from=\"b\" to=\"c\" fromLane=\"0\" toLane=\"0\"/>\n"
           "  <connection from=\"c\" to=\"d\" fromLane=\"0\" toLane=\"0\"/>\n"
           "  <connection from=\"d\" to=\"a\" fromLane=\"0\" toLane=\"0\"/>\n"
           "  <connection from=\"b\" to=\"e\" fromLane=\"0\" toLane=\"0\"/>\n"
           "  <connection from=\"a\" to=\":w0\" fromLane=\"1\" toLane=\"0\"/>\n"
           "  <connection from=\":w0\" to=\"c\" fromLane=\"0\" toLane=\"1\"/>\n"
           "</net>\n";
}

}  // namespace

TEST(SumoNet, PermissionsFollowAllowThenDisallow) {
    EXPECT_EQ(sumoPermissions(nullptr, nullptr), kAllTrafficClasses);
    EXPECT_EQ(sumoPermissions("pedestrian", nullptr), uint32_t(kClassPedestrian));
    EXPECT_EQ(sumoPermissions("all", nullptr), kAllTrafficClasses);
    EXPECT_EQ(sumoPermissions(nullptr, "pedestrian bicycle tram"),
              kAllTrafficClasses & ~uint32_t(kClassPedestrian | kClassBicycle));
    // allow wins over disallow, as in SUMO.
    EXPECT_EQ(sumoPermissions("bus", "bus"), uint32_t(kClassBus));
}

TEST(SumoNet, ReadsOffsetEdgesLanesConnectionsAndLights) {
    TempDir dir("vista_sumo_net");
    writeText(dir.file("n.net.xml"), ringNet());
    auto net = readSumoNet(dir.file("n.net.xml"));
    ASSERT_TRUE(net) << net.status().message();
    EXPECT_DOUBLE_EQ(net->offsetX, 100.0);
    EXPECT_DOUBLE_EQ(net->offsetY, -50.0);
    ASSERT_EQ(net->edges.size(), 7u);
    EXPECT_EQ(net->edges[0].id, "a");
    ASSERT_EQ(net->edges[0].lanes.size(), 2u);
    EXPECT_EQ(net->edges[0].lanes[1].allow, uint32_t(kClassPedestrian));
    EXPECT_FALSE(net->edges[0].lanes[0].allow & kClassPedestrian);
    EXPECT_TRUE(net->edges[0].lanes[0].allow & kClassPassenger);
    EXPECT_TRUE(net->edges[0].normal());
    EXPECT_FALSE(net->edges[5].normal());  // the walking area
    EXPECT_EQ(net->connections.size(), 7u);
    ASSERT_EQ(net->trafficLights.size(), 1u);
    EXPECT_EQ(net->trafficLights[0], "J1");
}

TEST(SumoNet, BadFilesAreErrorsNamingTheFileAndLine) {
    TempDir dir("vista_sumo_net_bad");
    const std::string full = ringNet();
    writeText(dir.file("cut.net.xml"), full.substr(0, full.size() / 2));
    auto cut = readSumoNet(dir.file("cut.net.xml"));
    ASSERT_FALSE(cut);
    EXPECT_NE(cut.status().message().find("cut.net.xml"), std::string::npos);
    EXPECT_NE(cut.status().message().find("line"), std::string::npos);

    writeText(dir.file("root.xml"), "<routes/>");
    auto root = readSumoNet(dir.file("root.xml"));
    ASSERT_FALSE(root);
    EXPECT_NE(root.status().message().find("<net>"), std::string::npos);

    std::string dangling = full;
    dangling.replace(dangling.find("to=\"e\""), 6, "to=\"zz\"");
    writeText(dir.file("dangling.net.xml"), dangling);
    auto bad = readSumoNet(dir.file("dangling.net.xml"));
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.status().message().find("'zz'"), std::string::npos);

    EXPECT_FALSE(readSumoNet(dir.file("missing.net.xml")));
}

namespace {

SumoNet parsedRing() {
    TempDir dir("vista_sumo_ring");
    writeText(dir.file("n.net.xml"), ringNet());
    auto net = readSumoNet(dir.file("n.net.xml"));
    EXPECT_TRUE(net);
    return *net;
}

struct Trip {
    std::string id, type, from, to;
    double depart;
};

std::vector<Trip> tripsOf(const std::string& xml) {
    std::vector<Trip> out;
    const std::regex trip(
        "<trip id=\"([^\"]+)\" type=\"([^\"]+)\" depart=\"([0-9.]+)\" from=\"([^\"]+)\" to=\"([^\"]+)\"");
    for (auto it = std::sregex_iterator(xml.begin(), xml.end(), trip); it != std::sregex_iterator(); ++it)
        out.push_back({(*it)[1], (*it)[2], (*it)[4], (*it)[5], std::stod((*it)[3])});
    const std::regex walk(
        "<person id=\"([^\"]+)\" type=\"pedestrian\" depart=\"([0-9.]+)\">\\s*<walk from=\"([^\"]+)\" "
        "to=\"([^\"]+)\"");
    for (auto it = std::sregex_iterator(xml.begin(), xml.end(), walk); it != std::sregex_iterator(); ++it)
        out.push_back({(*it)[1], "pedestrian", (*it)[3], (*it)[4], std::stod((*it)[2])});
    return out;
}

}  // namespace

TEST(TrafficDemand, TripsStayInTheConnectedPartAndAreSeeded) {
    const SumoNet net = parsedRing();
    TrafficDemandOptions opt;
    opt.vehicles = 60;
    opt.pedestrians = 25;
    opt.durationS = 120.0;
    opt.seed = 7;
    TrafficDemandCounts counts;
    auto xml = makeDemandXml(net, opt, &counts);
    ASSERT_TRUE(xml) << xml.status().message();
    const auto trips = tripsOf(*xml);
    ASSERT_EQ(trips.size(), 85u);
    int vehicles = 0, people = 0;
    for (const Trip& t : trips) {
        if (t.type == "pedestrian") {
            ++people;
            // Walkable and connected: the sidewalks of a and c only.
            EXPECT_TRUE(t.from == "a" || t.from == "c") << t.from;
            EXPECT_TRUE(t.to == "a" || t.to == "c") << t.to;
        } else {
            ++vehicles;
            // The spur e is reachable but has no way back: never an end of a trip.
            EXPECT_NE(t.from, "e");
            EXPECT_NE(t.to, "e");
            EXPECT_NE(t.from, t.to);
        }
        EXPECT_GE(t.depart, 0.0);
        EXPECT_LT(t.depart, opt.durationS);
    }
    EXPECT_EQ(vehicles, 60);
    EXPECT_EQ(people, 25);
    int total = 0;
    for (int n : counts.byType) total += n;
    EXPECT_EQ(total, 85);
    // Every vehicle class is allowed on the ring: no substitution.
    EXPECT_EQ(counts.substituted, 0);
    // sumo needs the file sorted by departure.
    std::vector<double> departs;
    for (size_t at = xml->find("depart=\""); at != std::string::npos; at = xml->find("depart=\"", at + 1))
        departs.push_back(std::stod(xml->substr(at + 8)));
    EXPECT_TRUE(std::is_sorted(departs.begin(), departs.end()));
    // Same options, same bytes; another seed, another demand.
    EXPECT_EQ(*xml, *makeDemandXml(net, opt, nullptr));
    opt.seed = 8;
    EXPECT_NE(*xml, *makeDemandXml(net, opt, nullptr));
}

TEST(TrafficDemand, TypesFollowTheMixWithinSamplingError) {
    const SumoNet net = parsedRing();
    TrafficDemandOptions opt;
    opt.vehicles = 4000;
    opt.pedestrians = 0;
    TrafficDemandCounts counts;
    ASSERT_TRUE(makeDemandXml(net, opt, &counts));
    for (int t = 0; t < 5; ++t) {
        const double p = kDefaultMix[size_t(t)], n = opt.vehicles;
        const double sigma = std::sqrt(n * p * (1 - p));
        EXPECT_NEAR(counts.byType[size_t(t)], n * p, 4.0 * sigma) << agentTypeInfo(AgentType(t)).id;
    }
    EXPECT_EQ(counts.byType[size_t(AgentType::Pedestrian)], 0);
}

TEST(TrafficDemand, ANetworkWithoutSidewalksOrRoadsIsAnError) {
    SumoNet net = parsedRing();
    for (SumoEdge& e : net.edges)
        for (SumoLane& l : e.lanes) l.allow &= ~uint32_t(kClassPedestrian);
    TrafficDemandOptions opt;
    auto noWalk = makeDemandXml(net, opt, nullptr);
    ASSERT_FALSE(noWalk);
    EXPECT_NE(noWalk.status().message().find("--pedestrians 0"), std::string::npos);
    opt.pedestrians = 0;
    EXPECT_TRUE(makeDemandXml(net, opt, nullptr));
    for (SumoEdge& e : net.edges)
        for (SumoLane& l : e.lanes) l.allow = 0;
    auto noRoad = makeDemandXml(net, opt, nullptr);
    ASSERT_FALSE(noRoad);
    EXPECT_NE(noRoad.status().message().find("--vehicles 0"), std::string::npos);
}

TEST(TrafficDemand, AClassWithoutNetworkBecomesCars) {
    SumoNet net = parsedRing();
    for (SumoEdge& e : net.edges)
        for (SumoLane& l : e.lanes) l.allow &= ~uint32_t(kClassBus);
    TrafficDemandOptions opt;
    opt.vehicles = 500;
    opt.pedestrians = 0;
    TrafficDemandCounts counts;
    auto xml = makeDemandXml(net, opt, &counts);
    ASSERT_TRUE(xml);
    EXPECT_EQ(counts.byType[size_t(AgentType::Bus)], 0);
    EXPECT_GT(counts.substituted, 0);
    EXPECT_EQ(xml->find("type=\"bus\" depart"), std::string::npos);
}

namespace {

const char* kFcd =
    "<?xml version=\"1.0\"?>\n<!-- generated by Eclipse SUMO -->\n<fcd-export>\n"
    "  <timestep time=\"0.00\">\n"
    "    <vehicle id=\"v1\" x=\"110.00\" y=\"-40.00\" angle=\"90.00\" type=\"car\" speed=\"10.00\" lane=\"a_0\"/>\n"
    "    <person id=\"p1\" x=\"100.00\" y=\"-50.00\" angle=\"350.00\" speed=\"1.20\" edge=\"a\"/>\n"
    "  </timestep>\n"
    "  <timestep time=\"0.50\">\n"
    "    <vehicle id=\"v1\" x=\"115.00\" y=\"-40.00\" angle=\"90.00\" type=\"car\" speed=\"10.00\" lane=\"a_0\"/>\n"
    "    <person id=\"p1\" x=\"100.00\" y=\"-49.40\" angle=\"10.00\" speed=\"1.20\" edge=\"a\"/>\n"
    "    <vehicle id=\"v2\" x=\"0.00\" y=\"0.00\" angle=\"180.00\" type=\"bus\" speed=\"0.00\" lane=\"b_0\"/>\n"
    "  </timestep>\n"
    "  <timestep time=\"1.00\">\n"
    "    <vehicle id=\"v2\" x=\"0.00\" y=\"-1.00\" angle=\"180.00\" type=\"bus\" speed=\"2.00\" lane=\"b_0\"/>\n"
    "  </timestep>\n"
    "</fcd-export>\n";

}  // namespace

TEST(TrafficTracks, ReadsAgentsInTheWorldFrame) {
    TempDir dir("vista_fcd");
    writeText(dir.file("fcd.xml"), kFcd);
    auto t = readFcd(dir.file("fcd.xml"), 100.0, -50.0);
    ASSERT_TRUE(t) << t.status().message();
    ASSERT_EQ(t->frames(), 3u);
    ASSERT_EQ(t->agentIds.size(), 3u);
    EXPECT_EQ(t->agentIds[0], "v1");
    EXPECT_EQ(t->agentTypes[0], AgentType::Car);
    EXPECT_EQ(t->agentTypes[1], AgentType::Pedestrian);
    EXPECT_EQ(t->agentTypes[2], AgentType::Bus);
    const AgentPose& v1 = t->poses[t->frameStart[0]];
    EXPECT_FLOAT_EQ(v1.x, 10.f);          // 110 - 100
    EXPECT_FLOAT_EQ(v1.y, 10.f);          // -40 + 50
    EXPECT_NEAR(v1.heading, 0.f, 1e-6f);  // SUMO 90 deg = east = +x
    // Frames hold their poses sorted by agent.
    for (size_t f = 0; f < t->frames(); ++f) {
        const size_t end = f + 1 < t->frames() ? t->frameStart[f + 1] : t->poses.size();
        for (size_t i = t->frameStart[f] + 1; i < end; ++i) EXPECT_LT(t->poses[i - 1].agent, t->poses[i].agent);
    }
}

// SUMO writes steps before its first insertion with nobody in them: frames
// without poses, read as such.
TEST(TrafficTracks, EmptyStepsAreFramesWithoutPoses) {
    TempDir dir("vista_fcd_empty");
    std::string text = kFcd;
    text.replace(text.find("  <timestep time=\"0.00\">"), 0,
                 "  <timestep time=\"-1.00\"/>\n  <timestep time=\"-0.50\"></timestep>\n");
    writeText(dir.file("fcd.xml"), text);
    auto t = readFcd(dir.file("fcd.xml"), 0, 0);
    ASSERT_TRUE(t) << t.status().message();
    ASSERT_EQ(t->frames(), 5u);
    EXPECT_EQ(t->frameStart[0], 0u);
    EXPECT_EQ(t->frameStart[1], 0u);
    EXPECT_EQ(t->frameStart[2], 0u);
    EXPECT_EQ(t->poses.size(), 6u);
    AgentPose p;
    EXPECT_FALSE(t->poseAt(0, -0.75, &p));
}

TEST(TrafficTracks, PoseAtInterpolatesBetweenSamplesAndTurnsTheShortWay) {
    TempDir dir("vista_fcd_pose");
    writeText(dir.file("fcd.xml"), kFcd);
    auto t = readFcd(dir.file("fcd.xml"), 100.0, -50.0);
    ASSERT_TRUE(t);
    AgentPose p;
    ASSERT_TRUE(t->poseAt(0, 0.2, &p));
    EXPECT_NEAR(p.x, 10.0 + 5.0 * 0.4, 1e-5);
    EXPECT_NEAR(p.y, 10.0, 1e-5);
    // The person turns from 350 to 10 degrees (north-west to north-east):
    // half-way it heads north (SUMO 0 deg = +y = pi/2), not south.
    ASSERT_TRUE(t->poseAt(1, 0.25, &p));
    EXPECT_NEAR(std::remainder(p.heading - kHalfPi, kTwoPi), 0.0, 1e-5);
    EXPECT_NEAR(p.y, 0.3, 1e-5);
    // v1 left after 0.5 s; v2 arrives at 0.5 s; nobody exists outside the run.
    EXPECT_FALSE(t->poseAt(0, 0.75, &p));
    EXPECT_FALSE(t->poseAt(2, 0.25, &p));
    ASSERT_TRUE(t->poseAt(2, 0.75, &p));
    EXPECT_NEAR(p.y, 50.0 - 0.5, 1e-5);
    EXPECT_FALSE(t->poseAt(2, 1.5, &p));
    EXPECT_EQ(t->frameAt(0.74), 1u);
    EXPECT_EQ(t->frameAt(-1.0), 0u);
}

TEST(TrafficTracks, BadFilesAreErrors) {
    TempDir dir("vista_fcd_bad");
    const std::string full = kFcd;
    writeText(dir.file("cut.xml"), full.substr(0, full.size() * 2 / 3));
    EXPECT_FALSE(readFcd(dir.file("cut.xml"), 0, 0));
    std::string back = full;
    back.replace(back.find("time=\"1.00\""), 11, "time=\"0.25\"");
    writeText(dir.file("back.xml"), back);
    auto b = readFcd(dir.file("back.xml"), 0, 0);
    ASSERT_FALSE(b);
    EXPECT_NE(b.status().message().find("does not follow"), std::string::npos);
    std::string type = full;
    type.replace(type.find("type=\"bus\""), 10, "type=\"tank\"");
    writeText(dir.file("type.xml"), type);
    auto ty = readFcd(dir.file("type.xml"), 0, 0);
    ASSERT_FALSE(ty);
    EXPECT_NE(ty.status().message().find("'tank'"), std::string::npos);
    writeText(dir.file("root.xml"), "<net/>");
    EXPECT_FALSE(readFcd(dir.file("root.xml"), 0, 0));
    // A step as the root element: refused, not read as a step (found by fuzz_fcd).
    writeText(dir.file("step_root.xml"), "<timestep time=\"0\"></timestep>");
    auto sr = readFcd(dir.file("step_root.xml"), 0, 0);
    ASSERT_FALSE(sr);
    EXPECT_NE(sr.status().message().find("not <fcd-export>"), std::string::npos) << sr.status().message();
}

// Values a pose cannot mean (and that would not fit its floats) are refused
// naming the agent; the same values one step inside the ranges are read.
TEST(TrafficTracks, ValuesOutOfRangeAreErrorsNamingTheAgent) {
    TempDir dir("vista_fcd_range");
    const std::string full = kFcd;
    struct Case {
        const char* from;
        const char* to;
        const char* says;
    };
    for (const Case& c : {Case{"x=\"115.00\"", "x=\"1e300\"", "outside |x|, |y|"},
                          Case{"y=\"-40.00\" angle=\"90.00\" type=\"car\" speed=\"10.00\" lane=\"a_0\"/>\n    <person",
                               "y=\"-3e7\" angle=\"90.00\" type=\"car\" speed=\"10.00\" lane=\"a_0\"/>\n    <person",
                               "outside |x|, |y|"},
                          Case{"angle=\"180.00\" type=\"bus\" speed=\"0.00\"",
                               "angle=\"1e40\" type=\"bus\" speed=\"0.00\"", "angle outside"},
                          Case{"speed=\"2.00\"", "speed=\"-2\"", "speed outside"},
                          Case{"speed=\"2.00\"", "speed=\"fast\"", "not a number"},
                          Case{"time=\"1.00\"", "time=\"2e9\"", "outside [-1e9, 1e9]"}}) {
        std::string text = full;
        ASSERT_NE(text.find(c.from), std::string::npos) << c.from;
        text.replace(text.find(c.from), std::strlen(c.from), c.to);
        writeText(dir.file("r.xml"), text);
        auto r = readFcd(dir.file("r.xml"), 0, 0);
        ASSERT_FALSE(r) << c.to;
        EXPECT_NE(r.status().message().find(c.says), std::string::npos) << r.status().message();
        EXPECT_NE(r.status().message().find("line "), std::string::npos) << r.status().message();
    }
    std::string edge = full;
    const std::string at = "x=\"115.00\"";
    edge.replace(edge.find(at), at.size(), "x=\"19999999\"");
    writeText(dir.file("edge.xml"), edge);
    auto e = readFcd(dir.file("edge.xml"), 0, 0);
    EXPECT_TRUE(e) << e.status().message();
}

TEST(SumoProcess, TheGeneratedDateIsRemovedAndNothingElse) {
    TempDir dir("vista_sumo_date");
    const std::string body(10000, 'x');
    const std::string text =
        "<?xml version=\"1.0\"?>\n\n<!-- generated on 2026-12-07 05:48:40 by Eclipse SUMO sumo "
        "Version 1.15.0\n<configuration/>\n-->\n<a>" +
        body + "</a>\n";
    writeText(dir.file("out.xml"), text);
    ASSERT_TRUE(stripGeneratedDate(dir.file("out.xml")));
    const std::string got = readBytes(dir.file("out.xml"));
    EXPECT_EQ(got,
              "<?xml version=\"1.0\"?>\n\n<!-- generated by Eclipse SUMO sumo Version 1.15.0\n<configuration/>\n-->"
              "\n<a>" +
                  body + "</a>\n");
    // A file without the comment (and a small one) stays as it is.
    writeText(dir.file("plain.xml"), "<a/>");
    ASSERT_TRUE(stripGeneratedDate(dir.file("plain.xml")));
    EXPECT_EQ(readBytes(dir.file("plain.xml")), "<a/>");
}

// SUMO 1.15's collision output (the records of a town run: a car turning
// across a crossing, two buses inside a junction over two steps).
TEST(TrafficRun, CollisionRecordsAreCountedByVictim) {
    TempDir dir("vista_sumo_collisions");
    const std::string head =
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n\n<!-- generated by Eclipse SUMO sumo Version 1.15.0\n-->\n\n"
        "<collisions xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\">\n";
    const std::string records =
        "    <collision time=\"295.00\" type=\"crossing\" lane=\":97_c1_0\" pos=\"6.74\" collider=\"veh133\" "
        "victim=\"ped23\" colliderType=\"car\" victimType=\"pedestrian\" colliderSpeed=\"5.79\" "
        "victimSpeed=\"1.54\"/>\n"
        "    <collision time=\"347.00\" type=\"junction\" lane=\":107_12_0\" pos=\"2.68\" collider=\"veh150\" "
        "victim=\"veh168\" colliderType=\"bus\" victimType=\"bus\" colliderSpeed=\"5.42\" victimSpeed=\"7.59\"/>\n"
        "    <collision time=\"347.50\" type=\"junction\" lane=\":107_12_0\" pos=\"2.68\" collider=\"veh150\" "
        "victim=\"veh168\" colliderType=\"bus\" victimType=\"bus\" colliderSpeed=\"5.42\" victimSpeed=\"7.59\"/>\n";
    writeText(dir.file("collisions.xml"), head + records + "</collisions>\n");
    auto c = readCollisions(dir.file("collisions.xml"));
    ASSERT_TRUE(c) << c.status().message();
    EXPECT_EQ(c->events, 3);
    EXPECT_EQ(c->withPedestrians, 1);
    EXPECT_EQ(c->betweenVehicles, 2);

    writeText(dir.file("none.xml"), head + "</collisions>\n");
    auto none = readCollisions(dir.file("none.xml"));
    ASSERT_TRUE(none) << none.status().message();
    EXPECT_EQ(none->events, 0);

    // Truncated, foreign and missing files are errors naming the file.
    writeText(dir.file("cut.xml"), head + records.substr(0, 100));
    writeText(dir.file("other.xml"), "<statistics/>\n");
    for (const char* name : {"cut.xml", "other.xml", "missing.xml"}) {
        auto bad = readCollisions(dir.file(name));
        ASSERT_FALSE(bad) << name;
        EXPECT_NE(bad.status().message().find(name), std::string::npos) << bad.status().message();
    }
}

namespace {

// A junction J with one light: the OpenDRIVE signal 7 controls the two links
// of edge a (indices 0 and 1: straight and left), signal 9 the link of edge b
// (index 2); signal 8 is a sign without a link.
std::string signalNet() {
    auto internal = [](const std::string& id, const std::string& signal) {
        return "  <edge id=\"" + id + "\" function=\"internal\">\n    <lane id=\"" + id +
               "_0\" index=\"0\" length=\"5.00\" shape=\"0,0 5,0\">\n      <param key=\"signalID\" value=\"" + signal +
               "\"/>\n    </lane>\n  </edge>\n";
    };
    return "<?xml version=\"1.0\"?>\n<net version=\"1.9\">\n  <location netOffset=\"0,0\"/>\n" + internal(":J_0", "7") +
           internal(":J_1", "7") + internal(":J_2", "9") +
           "  <edge id=\"a\">\n    <lane id=\"a_0\" index=\"0\" length=\"50.00\"/>\n  </edge>\n"
           "  <edge id=\"b\">\n    <lane id=\"b_0\" index=\"0\" length=\"50.00\"/>\n  </edge>\n"
           "  <edge id=\"c\">\n    <lane id=\"c_0\" index=\"0\" length=\"50.00\"/>\n  </edge>\n"
           "  <tlLogic id=\"J\" type=\"static\" programID=\"0\" offset=\"0\"/>\n"
           "  <connection from=\"a\" to=\"c\" fromLane=\"0\" toLane=\"0\" via=\":J_0_0\" tl=\"J\" linkIndex=\"0\"/>\n"
           "  <connection from=\"a\" to=\"b\" fromLane=\"0\" toLane=\"0\" via=\":J_1_0\" tl=\"J\" linkIndex=\"1\"/>\n"
           "  <connection from=\"b\" to=\"c\" fromLane=\"0\" toLane=\"0\" via=\":J_2_0\" tl=\"J\" linkIndex=\"2\"/>\n"
           "  <connection from=\":J_0\" to=\"c\" fromLane=\"0\" toLane=\"0\"/>\n"
           "</net>\n";
}

std::string tlsStates(const std::string& records) {
    return "<?xml version=\"1.0\"?>\n<tlsStates>\n" + records + "</tlsStates>\n";
}

}  // namespace

TEST(SignalStates, EachHeadShowsTheStateOfItsOwnLinksAtTheTime) {
    TempDir dir("vista_signal_states");
    writeText(dir.file("city.net.xml"), signalNet());
    writeText(dir.file("signals.xml"),
              tlsStates("  <tlsState time=\"0.00\" id=\"J\" programID=\"0\" phase=\"0\" state=\"rrG\"/>\n"
                        "  <tlsState time=\"30.00\" id=\"J\" programID=\"0\" phase=\"1\" state=\"rry\"/>\n"
                        "  <tlsState time=\"33.00\" id=\"J\" programID=\"0\" phase=\"2\" state=\"Ggr\"/>\n"
                        "  <tlsState time=\"60.00\" id=\"J\" programID=\"0\" phase=\"3\" state=\"yyr\"/>\n"
                        "  <tlsState time=\"63.00\" id=\"J\" programID=\"0\" phase=\"4\" state=\"rgr\"/>\n"));
    auto net = readSumoNet(dir.file("city.net.xml"));
    ASSERT_TRUE(net) << net.status().message();
    ASSERT_EQ(net->signalLinks.size(), 3u);
    auto states = loadSignalStates(dir.path());
    ASSERT_TRUE(states) << states.status().message();
    const auto links7 = states->linksOf(7);
    ASSERT_EQ(links7.size(), 2u);
    EXPECT_EQ(links7[0].linkIndex, 0);
    EXPECT_EQ(links7[1].linkIndex, 1);
    EXPECT_EQ(net->trafficLights[links7[0].light], "J");
    // Signal 7 (links 0, 1) while SUMO says red for both, then green, amber, a green left arrow.
    EXPECT_EQ(states->lampAt(7, 0.0), LampState::Red);
    EXPECT_EQ(states->lampAt(7, 32.99), LampState::Red);
    EXPECT_EQ(states->lampAt(7, 33.0), LampState::Green);
    EXPECT_EQ(states->lampAt(7, 61.0), LampState::Amber);
    EXPECT_EQ(states->lampAt(7, 100.0), LampState::Green);
    // Signal 9 (link 2) at the same times: the other approach.
    EXPECT_EQ(states->lampAt(9, 0.0), LampState::Green);
    EXPECT_EQ(states->lampAt(9, 31.0), LampState::Amber);
    EXPECT_EQ(states->lampAt(9, 33.0), LampState::Red);
    EXPECT_EQ(states->lampAt(9, 1000.0), LampState::Red);
    // No links, or before the first record: off.
    EXPECT_TRUE(states->linksOf(8).empty());
    EXPECT_EQ(states->lampAt(8, 10.0), LampState::Off);
    EXPECT_EQ(states->lampAt(7, -1.0), LampState::Off);
    EXPECT_EQ(lampOfLetters("ru"), LampState::RedAmber);
    EXPECT_EQ(lampOfLetters("oO"), LampState::Off);
    EXPECT_STREQ(lampStateName(LampState::Amber), "amber");
}

TEST(SignalStates, BadFilesAreErrorsNamingTheFileAndLine) {
    TempDir dir("vista_signal_states_bad");
    writeText(dir.file("city.net.xml"), signalNet());
    auto net = readSumoNet(dir.file("city.net.xml"));
    ASSERT_TRUE(net) << net.status().message();
    const std::string ok = "  <tlsState time=\"5.00\" id=\"J\" programID=\"0\" phase=\"0\" state=\"rrG\"/>\n";
    struct Case {
        const char* name;
        std::string text;
        const char* says;
    } cases[] = {
        {"cut.xml", tlsStates(ok).substr(0, 60), "cut.xml"},
        {"root.xml", "<statistics/>\n", "<tlsStates>"},
        {"light.xml", tlsStates("  <tlsState time=\"0\" id=\"K\" state=\"r\"/>\n"), "'K'"},
        {"back.xml", tlsStates(ok + "  <tlsState time=\"1\" id=\"J\" state=\"rrr\"/>\n"), "back in time"},
        {"time.xml", tlsStates("  <tlsState time=\"soon\" id=\"J\" state=\"r\"/>\n"), "soon"},
        {"attrs.xml", tlsStates("  <tlsState time=\"0\" id=\"J\"/>\n"), "lacks"},
    };
    for (const Case& c : cases) {
        writeText(dir.file(c.name), c.text);
        auto s = readSignalStates(*net, dir.file(c.name));
        ASSERT_FALSE(s) << c.name;
        EXPECT_NE(s.status().message().find(c.says), std::string::npos) << s.status().message();
        EXPECT_NE(s.status().message().find(c.name), std::string::npos) << s.status().message();
    }
    EXPECT_FALSE(readSignalStates(*net, dir.file("missing.xml")));
}

TEST(SumoProcess, ErrorLinesAreTheLastErrors) {
    EXPECT_EQ(sumoErrorLines("Warning: w\nError: one\nok\nError: two\n"), "Error: one; Error: two");
    EXPECT_EQ(sumoErrorLines("Error: a\nError: b\nError: c\nError: d\n", 2), "Error: c; Error: d");
    EXPECT_EQ(sumoErrorLines("Loading...\nQuitting (on error).\n"), "Quitting (on error).");
}

TEST(EgoPath, RidesTheVehicleFromBehindItsFrontBumper) {
    TempDir dir("vista_ego");
    writeText(dir.file("fcd.xml"), kFcd);
    auto t = readFcd(dir.file("fcd.xml"), 100.0, -50.0);
    ASSERT_TRUE(t);
    auto ego = chooseEgo(*t, "v1", 1);
    ASSERT_TRUE(ego);
    CityParams params;
    auto path = egoPath(*t, *ego, params, 0.25, 60.0, 1.2);
    ASSERT_TRUE(path) << path.status().message();
    // v1 is present from 0 to 0.5 s: three samples at 0.25 s, never padded.
    ASSERT_EQ(path->samples.size(), 3u);
    const double back = kEgoEyeBack * agentTypeInfo(AgentType::Car).length;
    for (size_t i = 0; i < 3; ++i) {
        const PathSample& s = path->samples[i];
        EXPECT_DOUBLE_EQ(s.t, 0.25 * double(i));
        // Heading east (+x): the eye is `back` metres west of the bumper.
        EXPECT_NEAR(s.position.x, 10.0 + 10.0 * s.t - back, 1e-4);
        EXPECT_NEAR(s.position.y, 10.0, 1e-4);
        EXPECT_NEAR(s.heading, kHalfPi, 1e-6);  // clockwise from north: east
        EXPECT_DOUBLE_EQ(s.pitch, 0.0);
    }
    EXPECT_FALSE(chooseEgo(*t, "p1", 1));  // a pedestrian
    EXPECT_FALSE(chooseEgo(*t, "v9", 1));  // unknown
    // Without an id the seed picks a car: v1 is the only one.
    auto picked = chooseEgo(*t, "", 42);
    ASSERT_TRUE(picked);
    EXPECT_EQ(t->agentIds[*picked], "v1");
}

TEST(EgoPath, KeepsTheTrafficsClock) {
    TempDir dir("vista_ego_clock");
    writeText(dir.file("fcd.xml"), kFcd);
    auto t = readFcd(dir.file("fcd.xml"), 100.0, -50.0);
    ASSERT_TRUE(t);
    auto ego = chooseEgo(*t, "v2", 1);  // present from 0.5 s to 1 s
    ASSERT_TRUE(ego) << ego.status().message();
    auto path = egoPath(*t, *ego, CityParams(), 0.25, 60.0, 1.2);
    ASSERT_TRUE(path) << path.status().message();
    ASSERT_EQ(path->samples.size(), 3u);
    for (size_t i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(path->samples[i].t, 0.5 + 0.25 * double(i));
}

TEST(AgentModels, PlacementsStandBehindTheFrontBumperOnTheTerrain) {
    TempDir dir("vista_agents");
    writeText(dir.file("fcd.xml"), kFcd);
    auto t = readFcd(dir.file("fcd.xml"), 100.0, -50.0);
    ASSERT_TRUE(t);
    CityParams params;
    params.hills_amplitude_m = 8.0;  // a terrain that is not flat
    const AgentModels models = agentModels(Lighting(params));
    for (const AgentModel& m : models.models) {
        EXPECT_FALSE(m.mesh.empty());
        // The footprint's centre at the origin, standing on z = 0.
        glm::vec3 lo(1e9f), hi(-1e9f);
        for (const glm::vec3& p : m.mesh.positions) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
        EXPECT_NEAR(lo.z, 0.0f, 1e-4f);
        EXPECT_NEAR(hi.z, float(m.height), 0.05f);
        EXPECT_NEAR(0.5f * (lo.x + hi.x), 0.0f, 0.05f);
        // A vehicle's front bumper (the reference point) is half its length ahead of the centre.
        if (m.type != AgentType::Pedestrian && m.type != AgentType::Bicycle) {
            EXPECT_NEAR(hi.x, 0.5f * float(m.length), 0.01f);
        }
    }
    // At 0.75 s: v2 (a bus heading south, bumper at (-100, 49.5) then) and nobody else (v1 and p1 left at 0.5 s).
    const auto placed = placeAgents(*t, models, params, 0.75);
    ASSERT_EQ(placed.size(), 1u);
    const AgentPlacement& a = placed[0];
    EXPECT_EQ(t->agentIds[a.agent], "v2");
    const double L = models.models[a.prototype].length;
    EXPECT_NEAR(a.centre.x, -100.0, 1e-4);
    EXPECT_NEAR(a.centre.y, 50.0 - 0.5 + 0.5 * L, 1e-4);  // half a length behind (north of) the bumper
    EXPECT_NEAR(a.centre.z, terrainHeight(params, glm::dvec2(a.centre)), 1e-9);
    EXPECT_NEAR(a.transform[0].y, -1.0, 1e-6);  // the model's +x along the heading (south)
    EXPECT_EQ(agentLabel(AgentType::Bus, a.agent) >> 28, uint32_t(InstanceKind::Vehicle));
    EXPECT_EQ(agentLabel(AgentType::Pedestrian, 7) >> 28, uint32_t(InstanceKind::Pedestrian));
    EXPECT_TRUE(placeAgents(*t, models, params, 5.0).empty());  // after the run
}
