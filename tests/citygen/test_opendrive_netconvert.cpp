// OpenDRIVE files read by SUMO netconvert (a reader vista did not write): generated, hilly,
// odd-lane and OSM cities convert without errors and without a lane "not connected" from
// any incoming edge or to any outgoing one at a junction, and keep their roads and lanes.
#include <gtest/gtest.h>

#include <expat.h>

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
namespace {
// ---- netconvert --------------------------------------------------------------
std::string shellOut(const std::string& cmd) {
    std::string out;
    FILE* f = ::popen(cmd.c_str(), "r");
    if (!f) return out;
    char buf[512];
    while (std::fgets(buf, sizeof buf, f)) out += buf;
    ::pclose(f);
    while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
    return out;
}

// The netconvert on PATH, or "" (then the caller skips). netconvert needs
// SUMO_HOME for its built-in type maps: set it from the install prefix (the
// data are in Debian's sumo-tools, which .ci/setup.sh installs).
std::string findNetconvert() {
    std::string path = shellOut("command -v netconvert 2>/dev/null");
    if (path.empty()) return path;
    if (!std::getenv("SUMO_HOME")) {
        std::error_code ec;
        fs::path real = fs::canonical(path, ec);
        fs::path home = (ec ? fs::path(path) : real).parent_path().parent_path() / "share" / "sumo";
        if (fs::exists(home / "data")) ::setenv("SUMO_HOME", home.c_str(), 1);
    }
    return path;
}

bool allDigits(const std::string& s) {
    if (s.empty()) return false;
    for (char c : s)
        if (c < '0' || c > '9') return false;
    return true;
}

struct NetCheck {
    int exitCode = -1;
    int errors = 0;
    // "Lane ... is not connected from any incoming edge" / "... to any outgoing edge" warnings, at
    // junctions (netconvert node id = the OpenDRIVE junction id, digits only) and elsewhere.
    int notConnectedAtJunctions = 0, notConnectedElsewhere = 0;
    std::string log;
    std::unique_ptr<Element> net;
};

// netconvert is not ours and not built with sanitizers: it runs without the
// sanitizer runtime that .ci/sanitize.sh preloads into the tests (LD_PRELOAD),
// whose leak checker would otherwise report the allocations of netconvert's
// own libraries (libproj) at its exit and fail the run.
NetCheck runNetconvert(const std::string& netconvert, const std::string& xodr, const std::string& dir) {
    NetCheck r;
    const std::string net = dir + "/city.net.xml", log = dir + "/netconvert.log";
    const int st = std::system(("env -u LD_PRELOAD " + netconvert + " --aggregate-warnings -1 --opendrive-files " +
                                xodr + " -o " + net + " >" + log + " 2>&1")
                                   .c_str());
    r.exitCode = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    r.log = readBytes(log);
    for (size_t pos = 0; (pos = r.log.find("Error", pos)) != std::string::npos; ++pos)
        if (pos == 0 || r.log[pos - 1] == '\n') ++r.errors;
    for (const char* what : {"not connected from any incoming edge", "not connected to any outgoing"})
        for (size_t pos = 0; (pos = r.log.find(what, pos)) != std::string::npos; ++pos) {
            const size_t at = r.log.find("at junction '", pos), eol = r.log.find('\n', pos);
            std::string node;
            if (at != std::string::npos && at < eol) node = r.log.substr(at + 13, r.log.find('\'', at + 13) - at - 13);
            ++(allDigits(node) ? r.notConnectedAtJunctions : r.notConnectedElsewhere);
        }
    std::string err;
    r.net = parseXml(readBytes(net), &err);
    EXPECT_TRUE(r.net) << "net.xml does not parse: " << err;
    return r;
}

// netconvert's net against the graph: one junction (id = the OpenDRIVE
// junction id, digits only) per node of degree >= 3 or group of them joined
// by edges without lanes; road ends without a
// link become "<road>.begin"/"<road>.end" nodes, each transition road two
// "<road>.<road>" nodes; one traffic-light program per signalised junction;
// "internal" junctions are netconvert's own (inside junctions). Every road
// becomes edge "-<id>" (right lanes) and "<id>" (left lanes) with the
// lane model's driving lane counts (sidewalks are not imported by default).
void checkNet(const City& city, const std::string& label) {
    const std::string netconvert = findNetconvert();
    if (netconvert.empty()) GTEST_SKIP() << "netconvert (SUMO) is not on PATH: install the Debian package 'sumo'";
    TempDir dir("vista_xodr");
    OpenDriveCounts n;
    auto xodr = openDriveXml(city.streets, city.params, &city.blocks, &n);
    ASSERT_TRUE(xodr.isOk()) << xodr.status().message();
    {
        std::ofstream f(dir.file("city.xodr"), std::ios::binary);
        f << *xodr;
    }
    NetCheck r = runNetconvert(netconvert, dir.file("city.xodr"), dir.path());
    EXPECT_EQ(r.exitCode, 0) << label << "\n" << r.log;
    EXPECT_EQ(r.errors, 0) << label << "\n" << r.log;
    // Every full-width driving lane at a junction has a connection in and out.
    EXPECT_EQ(r.notConnectedAtJunctions, 0) << label << "\n" << r.log;
    EXPECT_EQ(n.unlinkedLanes, 0u) << label;
    EXPECT_EQ(n.unfedLanes, 0u) << label;
    ASSERT_TRUE(r.net);

    const LaneModel M = buildLaneModel(city.streets, city.params, &city.blocks);
    // Elsewhere netconvert warns only of lanes that taper in inside a transition beside lanes
    // that arrive (width 0 where their traffic enters, no predecessor, as ASAM's
    // zero_width_at_start rule asks: netconvert keeps their first, narrow metres as a lane
    // that nothing feeds); on a straight road (within 35 degrees) a lane appears at a through
    // junction instead (lanes.h), unless one direction has lanes leaving but none arriving.
    const double straight = 35.0 * 3.14159265358979323846 / 180;
    int tapersIn = 0, tapersInStraight = 0;
    for (const LinkRoad& t : M.links) {
        if (t.junction >= 0) continue;
        int n = 0;
        bool deadStart = false;              // a side with lanes leaving and none arriving
        bool arrive = false, leave = false;  // lanes arrive at / leave from the side's entering end
        for (const LinkRoad::Lane& l : t.right) arrive = arrive || (!l.sidewalk && l.from);
        for (const LinkRoad::Lane& l : t.right) leave = leave || (!l.sidewalk && l.to);
        for (const LinkRoad::Lane& l : t.right) n += arrive && !l.sidewalk && l.w0 == 0 && l.to;
        deadStart = leave && !arrive;
        arrive = leave = false;
        for (const LinkRoad::Lane& l : t.left) arrive = arrive || (!l.sidewalk && l.to);
        for (const LinkRoad::Lane& l : t.left) leave = leave || (!l.sidewalk && l.from);
        for (const LinkRoad::Lane& l : t.left) n += arrive && !l.sidewalk && l.w1 == 0 && l.from;
        deadStart = deadStart || (leave && !arrive);
        tapersIn += n;
        if (std::abs(t.angle) <= straight && !deadStart) tapersInStraight += n;
    }
    EXPECT_EQ(tapersInStraight, 0) << label;
    EXPECT_LE(r.notConnectedElsewhere, tapersIn) << label << "\n" << r.log;
    // Junctions: nodes of degree >= 3, those joined by an edge without lanes
    // between two of them counted once (junction joining, lanes.h).
    std::vector<size_t> group(M.degree.size());
    for (size_t v = 0; v < group.size(); ++v) group[v] = v;
    auto root = [&](size_t v) {
        while (group[v] != v) v = group[v] = group[group[v]];
        return v;
    };
    size_t graphJunctions = 0;
    for (int d : M.degree) graphJunctions += d >= 3;
    for (const Junction& J : M.junctions) graphJunctions += J.through;
    for (size_t e = 0; e < M.edges.size(); ++e) {
        const StreetEdge& E = city.streets.edges[e];
        if (M.edges[e].valid || E.a == E.b || M.degree[E.a] < 3 || M.degree[E.b] < 3) continue;
        const size_t a = root(E.a), b = root(E.b);
        if (a != b) group[a] = b, --graphJunctions;
    }
    // Road ends without a link: dead ends, and both roads at a corner too
    // sharp for a transition (LaneModel::sharpCorners; a through junction
    // links its two).
    size_t openEnds = 0;
    for (size_t e = 0; e < M.edges.size(); ++e) {
        const EdgeLanes& L = M.edges[e];
        if (!L.valid) continue;
        for (uint32_t v : {city.streets.edges[e].a, city.streets.edges[e].b}) {
            const int link = v == city.streets.edges[e].a ? L.linkA : L.linkB;
            const int junction = v == city.streets.edges[e].a ? L.junctionA : L.junctionB;
            openEnds += M.degree[size_t(v)] == 1 || (M.degree[size_t(v)] == 2 && link < 0 && junction < 0);
        }
    }
    EXPECT_EQ(graphJunctions, M.junctions.size());
    EXPECT_EQ(n.junctions, M.junctions.size());
    size_t transitions = 0;
    for (const LinkRoad& r : M.links) transitions += r.junction < 0;
    EXPECT_EQ(n.transitions, transitions);
    size_t netJunctions = 0, netEnds = 0, netLinks = 0;
    for (const Element* j : r.net->all("junction")) {
        const std::string id = j->str("id"), type = j->str("type");
        if (type == "internal" || id.empty() || id[0] == ':') continue;
        // "<road>#<k>": netconvert splits a road where its lane count
        // changes (a lane tapering in or out inside a transition).
        if (id.find('#') != std::string::npos) continue;
        if (allDigits(id)) {
            const size_t jid = std::stoul(id);
            EXPECT_GE(jid, city.streets.edges.size()) << id;
            EXPECT_LT(jid, city.streets.edges.size() + M.junctions.size()) << id;
            ++netJunctions;
        } else if ((id.size() > 6 && id.compare(id.size() - 6, 6, ".begin") == 0) ||
                   (id.size() > 4 && id.compare(id.size() - 4, 4, ".end") == 0)) {
            ++netEnds;
        } else {
            ++netLinks;
        }
    }
    // Traffic lights: netconvert builds one traffic-light program per
    // junction whose approaches carry dynamic signals.
    std::set<int> lit;
    for (const SignalPlacement& sp : M.signals)
        if (sp.kind == SignalPlacement::Kind::TrafficLight) lit.insert(sp.junction);
    EXPECT_EQ(r.net->all("tlLogic").size(), lit.size()) << label;
    EXPECT_EQ(netJunctions, graphJunctions) << label;
    EXPECT_EQ(netEnds, openEnds) << label;
    // A transition road between two street roads: two road-to-road nodes.
    EXPECT_EQ(netLinks, 2 * transitions) << label;

    std::map<std::string, int> netLanes;
    for (const Element* e : r.net->all("edge")) {
        if (e->str("function") == "internal") continue;
        netLanes[e->str("id")] = int(e->all("lane").size());
    }
    size_t roads = 0, lanes = 0;
    for (size_t e = 0; e < M.edges.size(); ++e) {
        const EdgeLanes& L = M.edges[e];
        if (!L.valid) continue;
        ++roads;
        const StreetEdge& E = city.streets.edges[e];
        if (E.lanesForward < 0 && E.lanesBackward < 0) {
            EXPECT_EQ(L.right + L.left, std::max<int>(E.lanes, 2)) << "edge " << e;
        }
        EXPECT_NEAR(L.laneWidth * (L.right + L.left), carriagewayWidth(city.streets.edges[e]), 1e-9);
        const std::string rid = std::to_string(e);
        if (L.right > 0) {
            ASSERT_TRUE(netLanes.count("-" + rid)) << label << ": no net edge for road " << rid;
            EXPECT_EQ(netLanes["-" + rid], L.right) << label << " road " << rid;
        }
        if (L.left > 0) {
            ASSERT_TRUE(netLanes.count(rid)) << label << ": no net edge for road " << rid;
            EXPECT_EQ(netLanes[rid], L.left) << label << " road " << rid;
        }
        lanes += size_t(L.right + L.left);
    }
    EXPECT_EQ(n.roads, roads);
    EXPECT_EQ(n.drivingLanes, lanes);
    std::printf(
        "[ %s ] roads %zu, transitions %zu, junctions %zu (netconvert %zu), connecting roads %zu, driving lanes %zu, "
        "traffic lights %zu at %zu junctions (netconvert programs %zu), signs %zu, crosswalks %zu, "
        "netconvert errors %d, lanes not connected %d at junctions, %d at transitions (%d lanes taper in)\n",
        label.c_str(), n.roads, n.transitions, n.junctions, netJunctions, n.connectingRoads, n.drivingLanes,
        n.trafficLights, lit.size(), r.net->all("tlLogic").size(), n.signs, n.crosswalks, r.errors,
        r.notConnectedAtJunctions, r.notConnectedElsewhere, tapersIn);
}

}  // namespace

TEST(OpenDrive, NetconvertReadsGeneratedCity) { checkNet(generated(smallParams(3, 600, 0)), "generated 600 m seed 3"); }

TEST(OpenDrive, NetconvertReadsHillyCity) {
    checkNet(generated(smallParams(7, 500, 25)), "generated 500 m seed 7, hills 25 m");
}

TEST(OpenDrive, NetconvertReadsOddLaneCounts) {
    checkNet(oddLanes(smallParams(5, 400, 0)), "generated 400 m seed 5, odd lane counts");
}

TEST(OpenDrive, NetconvertReadsOsmImport) { checkNet(osmCity("hard_cases.osm"), "osm hard_cases.osm"); }

// The synthetic town (tests/data/osm/town.osm: a 7 x 7 street grid with
// building footprints): many junctions, blocks with sidewalks on both sides.
TEST(OpenDrive, NetconvertReadsOsmTown) { checkNet(osmCity("town.osm"), "osm town.osm"); }

// The OSM lane-tag fixture (tests/data/osm/lanes.osm): lanes:forward/backward,
// one-way and turn-lane tags give arms of unequal lane counts at junctions.
TEST(OpenDrive, NetconvertReadsOsmLanes) { checkNet(osmCity("lanes.osm"), "osm lanes.osm"); }

// A dual carriageway of two one-way ways 10 m apart, crossed by side streets
// (tests/data/osm/dual_carriageway.osm): one-way roads with lanes on one side.
// A street whose lane count changes where two ways meet (tests/data/osm/lane_change.osm):
// 2 -> 4 lanes straight on, 4 -> 2 at a bend (a lane appears in each: through junctions),
// two-way -> one-way (a transition); every lane netconvert builds is fed from a lane before it.
TEST(OpenDrive, NetconvertReadsOsmLaneChanges) {
    const City city = osmCity("lane_change.osm");
    const LaneModel M = buildLaneModel(city.streets, city.params, &city.blocks);
    size_t through = 0;
    for (const Junction& J : M.junctions) through += J.through;
    EXPECT_EQ(through, 2u);  // where lanes appear; two-way -> one-way stays a transition
    checkNet(city, "osm lane_change.osm");
}

TEST(OpenDrive, NetconvertReadsOsmDualCarriageway) {
    checkNet(osmCity("dual_carriageway.osm"), "osm dual_carriageway.osm");
}
