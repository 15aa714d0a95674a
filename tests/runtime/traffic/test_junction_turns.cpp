// Long vehicles keep off tight junction turns (junction_turns.h): the radius
// of a sampled arc with straight ends, the turning need against the sagitta
// written out, and the net edit closing exactly the lanes and classes whose
// need exceeds the radius, every other byte kept; bad files are errors that
// leave the file as it was. Demand: a type whose part of the network
// (through the turns open to it) is under half the cars' becomes cars.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "foundation/units.h"
#include "runtime/traffic/junction_turns.h"
#include "runtime/traffic/sumo_net.h"
#include "runtime/traffic/traffic_demand.h"
#include "tests/common/temp_dir.h"

using namespace vista;
using vista::test::readBytes;
using vista::test::TempDir;
using vista::test::writeText;

namespace {

// A quarter turn of radius r sampled every 0.5 m, with 5 m straight ends,
// as netconvert writes a shape.
std::string quarterTurn(double r) {
    std::string s = "0.00,-5.00";
    const int n = int(std::ceil(0.5 * kPi * r / 0.5));
    for (int i = 0; i <= n; ++i) {
        const double a = 0.5 * kPi * i / n;
        char buf[64];
        std::snprintf(buf, sizeof buf, " %.2f,%.2f", r - r * std::cos(a), r * std::sin(a));
        s += buf;
    }
    char buf[64];
    std::snprintf(buf, sizeof buf, " %.2f,%.2f", r + 5.0, r);
    return s + buf;
}

std::vector<std::pair<double, double>> points(const std::string& shape) {
    std::vector<std::pair<double, double>> p;
    size_t at = 0;
    while (at < shape.size()) {
        double x = 0, y = 0;
        int used = 0;
        if (std::sscanf(shape.c_str() + at, " %lf,%lf%n", &x, &y, &used) != 2) break;
        p.push_back({x, y});
        at += size_t(used);
    }
    return p;
}

}  // namespace

TEST(JunctionTurns, RadiusOfASampledArcAndNeedFromTheSagitta) {
    // Coordinates written to 1 cm (as netconvert does) bend the first and the
    // last chord of a wide arc by less than the vertex threshold: up to one
    // chord at each end may fall off the bend, so the radius comes out low.
    for (double r : {5.0, 6.5, 12.0, 25.0}) {
        const double got = turnRadius(points(quarterTurn(r)));
        EXPECT_LE(got, r * 1.01) << r;
        EXPECT_GE(got, r * (1.0 - 2.0 * 0.5 / (0.5 * kPi * r)) - 0.01 * r) << r;
    }
    EXPECT_TRUE(std::isinf(turnRadius({{0, 0}, {10, 0}, {20, 0.5}})));  // under 10 degrees: straight
    EXPECT_TRUE(std::isinf(turnRadius({{0, 0}})));
    for (double len : {4.5, 8.5, 12.0}) {
        const double need = turningNeedM(len);
        auto sagitta = [&](double r) { return r * (1.0 - std::cos(len / (2.0 * r))); };
        EXPECT_NEAR(sagitta(need), kMaxBoxCutM, 1e-6) << len;
        EXPECT_GT(sagitta(0.95 * need), kMaxBoxCutM) << len;
    }
    EXPECT_EQ(turningNeedM(0.5), 0.0);  // shorter than the allowed cut: any radius
}

TEST(JunctionTurns, ClosesTightTurnsToLongClassesAndNothingElseChanges) {
    const std::string tight = quarterTurn(6.5), wide = quarterTurn(30.0);
    const std::string net =
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<net version=\"1.9\">\n"
        "    <edge id=\":J_0\" function=\"internal\">\n"
        "        <lane id=\":J_0_0\" index=\"0\" disallow=\"pedestrian tram\" length=\"20.00\" shape=\"" +
        tight +
        "\" changeLeft=\"ignoring\"/>\n"
        "        <lane id=\":J_0_1\" index=\"1\" allow=\"passenger bus truck\" shape=\"" +
        tight +
        "\"/>\n"
        "        <lane id=\":J_0_2\" index=\"2\" shape=\"" +
        tight +
        "\"/>\n"
        "        <lane id=\":J_0_3\" index=\"3\" disallow=\"bus\" shape=\"" +
        tight +
        "\"/>\n"
        "    </edge>\n"
        "    <edge id=\":J_1\" function=\"internal\">\n"
        "        <lane id=\":J_1_0\" index=\"0\" disallow=\"pedestrian\" shape=\"" +
        wide +
        "\"/>\n"
        "    </edge>\n"
        "    <edge id=\"a\">\n"
        "        <lane id=\"a_0\" index=\"0\" length=\"50.00\" shape=\"" +
        tight +
        "\"/>\n"
        "    </edge>\n</net>\n";
    TempDir tmp("vista_junction_turns");
    const std::string path = tmp.file("n.net.xml");
    writeText(path, net);
    const std::vector<TurnClass> classes = {{"passenger", 4.5}, {"bus", 12.0}, {"truck", 8.5}};
    auto closed = restrictTightTurns(path, classes);
    ASSERT_TRUE(closed) << closed.status().message();
    // A 6.5 m turn is below the bus's and the truck's need, above the car's;
    // the 30 m turn and the normal edge stay open.
    ASSERT_LT(turningNeedM(4.5), 6.5);
    ASSERT_GT(turningNeedM(8.5), 6.5);
    ASSERT_LT(turningNeedM(12.0), 30.0);
    EXPECT_EQ((*closed)[0], 0u);
    EXPECT_EQ((*closed)[1], 3u);  // :J_0_3 already disallows buses
    EXPECT_EQ((*closed)[2], 4u);
    std::string expect = net;
    auto replace = [&](const std::string& from, const std::string& to) {
        const size_t at = expect.find(from);
        ASSERT_NE(at, std::string::npos) << from;
        expect.replace(at, from.size(), to);
    };
    replace("disallow=\"pedestrian tram\"", "disallow=\"pedestrian tram bus truck\"");
    replace("allow=\"passenger bus truck\"", "allow=\"passenger\"");
    replace("<lane id=\":J_0_2\" index=\"2\" shape=\"" + tight + "\"",
            "<lane id=\":J_0_2\" index=\"2\" shape=\"" + tight + "\" disallow=\"bus truck\"");
    replace("disallow=\"bus\"", "disallow=\"bus truck\"");
    EXPECT_EQ(readBytes(path), expect);
    // The permissions read back as SUMO reads them.
    auto read = readSumoNet(path);
    ASSERT_TRUE(read) << read.status().message();
    for (const SumoLane& l : read->edges[0].lanes) EXPECT_EQ(l.allow & (kClassBus | kClassTruck), 0u) << l.index;
    EXPECT_NE(read->edges[0].lanes[0].allow & kClassPassenger, 0u);
    EXPECT_NE(read->edges[1].lanes[0].allow & kClassBus, 0u);
}

TEST(JunctionTurns, BadFilesAreErrorsAndLeaveTheFileAsItWas) {
    TempDir tmp("vista_junction_turns");
    const std::vector<TurnClass> classes = {{"bus", 12.0}};
    auto missing = restrictTightTurns(tmp.file("missing.net.xml"), classes);
    ASSERT_FALSE(missing);
    EXPECT_NE(missing.status().message().find("missing.net.xml"), std::string::npos);
    const std::string net =
        "<net>\n  <edge id=\":J_0\" function=\"internal\">\n    <lane id=\":J_0_0\" index=\"0\" shape=\"" +
        quarterTurn(6.5) + "\"/>\n  </edge>\n</net>\n";
    const struct {
        const char* name;
        std::string body;
        const char* why;
    } cases[] = {
        {"truncated.net.xml", net.substr(0, net.find("</edge>") + 3), "line"},
        {"other.net.xml", "<routes>\n</routes>\n", "not <net>"},
        {"empty.net.xml", "", "line"},
    };
    for (const auto& c : cases) {
        const std::string path = tmp.file(c.name);
        writeText(path, c.body);
        auto bad = restrictTightTurns(path, classes);
        ASSERT_FALSE(bad) << c.name;
        EXPECT_NE(bad.status().message().find(path), std::string::npos) << bad.status().message();
        EXPECT_NE(bad.status().message().find(c.why), std::string::npos) << bad.status().message();
        EXPECT_EQ(readBytes(path), c.body) << c.name;
    }
}

// Five roads in a ring a→b→c→d→e→a and a pair a↔b, every connection through
// an internal lane; the lane of c→d is closed to buses. Cars reach all five
// roads, buses only a and b through the open turns (fewer than half the
// cars'): buses become cars; with c→d open they take part.
TEST(JunctionTurns, DemandKeepsClassesToTheTurnsOpenToThem) {
    SumoNet net;
    auto addEdge = [&](const std::string& id, const std::string& function, uint32_t allow) {
        SumoEdge e;
        e.id = id;
        e.function = function;
        e.lanes.push_back({0, 50.0, allow});
        e.x = double(net.edges.size()) * 100.0;
        net.edges.push_back(e);
        return uint32_t(net.edges.size() - 1);
    };
    const uint32_t vehicles = kAllTrafficClasses & ~uint32_t(kClassPedestrian);
    std::vector<uint32_t> road;
    for (const char* id : {"a", "b", "c", "d", "e"}) road.push_back(addEdge(id, "", vehicles));
    const std::pair<int, int> links[] = {{0, 1}, {1, 2}, {2, 3}, {3, 4}, {4, 0}, {1, 0}};
    for (const auto& [f, t] : links) {
        const bool closed = f == 2 && t == 3;
        const uint32_t via = addEdge(":J" + std::to_string(f) + std::to_string(t), "internal",
                                     closed ? vehicles & ~uint32_t(kClassBus) : vehicles);
        SumoConnection c{road[size_t(f)], road[size_t(t)], 0, 0};
        c.viaEdge = via;
        net.connections.push_back(c);
    }
    TrafficDemandOptions opt;
    opt.vehicles = 400;
    opt.pedestrians = 0;
    TrafficDemandCounts counts;
    auto xml = makeDemandXml(net, opt, &counts);
    ASSERT_TRUE(xml) << xml.status().message();
    EXPECT_EQ(counts.byType[size_t(AgentType::Bus)], 0);
    EXPECT_GT(counts.byType[size_t(AgentType::Truck)], 0);  // trucks keep every turn here
    EXPECT_GT(counts.substituted, 0);
    EXPECT_EQ(xml->find("type=\"bus\" depart"), std::string::npos);
    // The same ring with c→d open: buses take part.
    net.edges[net.connections[2].viaEdge].lanes[0].allow = vehicles;
    auto open = makeDemandXml(net, opt, &counts);
    ASSERT_TRUE(open);
    EXPECT_GT(counts.byType[size_t(AgentType::Bus)], 0);
}
