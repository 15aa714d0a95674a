// Car paths in lanes: the car stays inside the lane it claims (the claimed
// OpenDRIVE position, evaluated on the lane model, gives the sample's point),
// drives through junction connecting roads, keeps the direction of traffic
// (right- and left-hand), and writes the same bytes for the same seed.
// The replay of the positions on the written .xodr, evaluated from the XML
// by an independent reader, is the ctest OpenDrive.PathReplay.* (tests/tools/xodr_positions.py).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>

#include "citygen/blocks.h"
#include "citygen/lanes.h"
#include "citygen/streets.h"
#include "foundation/units.h"
#include "runtime/scene/lane_route.h"
#include "runtime/scene/paths.h"
#include "tests/common/run_vista.h"
#include "tests/common/temp_dir.h"

using namespace vista;

namespace {

struct TestCity {
    std::string name;
    StreetGraph streets;
    CityParams params;
};

TestCity generatedCity() {
    TestCity c;
    c.name = "generated seed 7";
    c.params.seed = 7;
    c.params.size_m = 700;
    c.params.detail = 0;
    c.params.origin_x = 1000.5;  // world = city + origin
    c.params.origin_y = -2000.25;
    c.streets = growStreets(c.params, nullptr);
    return c;
}

TestCity townCity() {
    TestCity c;
    c.name = "osm town.osm";
    c.params.detail = 0;
    auto g = importOsm(std::string(VISTA_TEST_DATA) + "/osm/town.osm", c.params);
    EXPECT_TRUE(g.isOk()) << g.status().message();
    if (g.isOk()) {
        c.params.geo = g->geo;
        c.streets = std::move(g->streets);
    }
    return c;
}

// The lane model the paths drive in: built as `vista gen --xodr` builds it.
LaneModel modelOf(const TestCity& c) {
    const std::vector<Block> blocks = extractBlocks(c.streets, c.params, nullptr);
    return buildLaneModel(c.streets, c.params, &blocks);
}

// Evaluates a lane position on the lane model directly (reference line, lane
// offset and widths of lanes.h), independent of the route's projection:
// the point, the lane's half width and whether it is a driving lane.
struct Evaluated {
    glm::dvec2 point{0.0};
    double halfWidth = 0;
    bool driving = false;
    bool connecting = false;  // a junction's connecting road
    bool street = false;
    glm::dvec2 dir{0.0};  // street roads: the reference line's direction
};

Evaluated evaluate(const LaneModel& m, const LanePosition& l) {
    Evaluated r;
    const size_t streets = m.edges.size(), firstLink = streets + m.junctions.size();
    if (l.road < streets) {
        const EdgeLanes& L = m.edges[size_t(l.road)];
        r.street = true;
        r.dir = L.dir;
        r.driving =
            L.valid && l.lane != 0 && l.lane >= -L.right && l.lane <= L.left && l.s >= -1e-6 && l.s <= L.length + 1e-6;
        const double centre = L.offset + (l.lane < 0 ? (l.lane + 0.5) : (l.lane - 0.5)) * L.laneWidth;
        r.point = L.start + L.dir * l.s + L.normal() * (centre + l.tOffset);
        r.halfWidth = 0.5 * L.laneWidth;
        return r;
    }
    if (l.road < firstLink || l.road - firstLink >= m.links.size()) return r;
    const LinkRoad& k = m.links[size_t(l.road - firstLink)];
    const auto& side = l.lane < 0 ? k.right : k.left;
    const size_t n = size_t(std::abs(l.lane));
    if (l.lane == 0 || n > side.size() || l.s < -1e-6 || l.s > k.length() + 1e-6) return r;
    r.connecting = k.junction >= 0;
    r.driving = !side[n - 1].sidewalk;
    double t = k.laneOffset(l.s), sgn = l.lane < 0 ? -1.0 : 1.0;
    for (size_t i = 0; i + 1 < n; ++i) t += sgn * k.width(side[i], l.s);
    const double w = k.width(side[n - 1], l.s);
    t += sgn * 0.5 * w + l.tOffset;
    const double h = k.heading(l.s);
    r.point = k.point(l.s) + glm::dvec2(-std::sin(h), std::cos(h)) * t;
    r.halfWidth = 0.5 * w;
    return r;
}

// Checks one car path; returns the samples on connecting roads.
size_t checkInLane(const TestCity& c, const LaneModel& m, const Path& p, bool lht, const std::string& what) {
    EXPECT_EQ(p.lanes.size(), p.samples.size()) << what;
    const glm::dvec2 origin(c.params.origin_x, c.params.origin_y);
    size_t connecting = 0, failures = 0, against = 0, along = 0;
    for (size_t i = 0; i < std::min(p.lanes.size(), p.samples.size()) && failures < 5; ++i) {
        const LanePosition& l = p.lanes[i];
        const Evaluated e = evaluate(m, l);
        const glm::dvec2 xy = glm::dvec2(p.samples[i].position) - origin;
        const bool ok = e.driving && std::abs(l.tOffset) < e.halfWidth && glm::length(e.point - xy) < 1e-4;
        EXPECT_TRUE(ok) << what << " sample " << i << ": road " << l.road << " lane " << l.lane << " s " << l.s
                        << " t_offset " << l.tOffset << " (half width " << e.halfWidth << ", driving " << e.driving
                        << ") evaluates " << glm::length(e.point - xy) << " m from the eye";
        failures += !ok;
        connecting += e.connecting;
        // Direction of traffic on street roads: right-hand traffic drives the
        // right lanes (id < 0) along the reference line; left-hand, against it.
        if (e.street && i > 0) {
            const glm::dvec2 step = xy - (glm::dvec2(p.samples[i - 1].position) - origin);
            const double along_ = glm::dot(step, e.dir);
            if (std::abs(along_) > 0.2 * glm::length(step) && glm::length(step) > 1e-3) {
                const bool withS = along_ > 0;
                ((withS == (l.lane < 0)) != lht ? along : against) += 1;
            }
        }
    }
    // U-turns at dead ends cross lanes with the car across the road: a few
    // samples there move against their lane; everywhere else the car keeps
    // the direction of traffic.
    EXPECT_GT(along, 20 * against + 100) << what << ": " << along << " samples with the traffic, " << against
                                         << " against it";
    return connecting;
}

std::string tmpFile(const std::string& name) {
    return (std::filesystem::temp_directory_path() /
            ("vista_test_lane_paths_" + std::to_string(::getpid()) + "_" + name))
        .string();
}

std::string readBytes(const std::string& f) {
    std::ifstream in(f, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

}  // namespace

TEST(LanePaths, CarStaysInItsLaneThroughJunctions) {
    for (const TestCity& c : {generatedCity(), townCity()}) {
        ASSERT_FALSE(c.streets.edges.empty()) << c.name;
        const LaneModel m = modelOf(c);
        for (bool lht : {false, true}) {
            for (uint64_t seed : {1u, 2u, 3u, 4u}) {
                PathOptions o;
                o.seed = seed;
                o.duration = 90;
                o.leftHandTraffic = lht;
                auto p = generatePath(c.streets, c.params, o);
                ASSERT_TRUE(p.isOk()) << p.status().message();
                const std::string what = c.name + (lht ? " LHT" : " RHT") + " seed " + std::to_string(seed);
                const size_t connecting = checkInLane(c, m, *p, lht, what);
                EXPECT_GT(connecting, 30u) << what << " never drove through a junction";
                // The limits hold as for every path kind.
                for (size_t i = 1; i < p->samples.size(); ++i) {
                    const auto &a = p->samples[i - 1], &b = p->samples[i];
                    EXPECT_LE(glm::length(glm::dvec2(b.position - a.position)), o.maxSpeed * o.dt + 1e-9) << what;
                    EXPECT_LE(std::abs(wrapAngle(b.heading - a.heading)), o.maxYawRate * o.dt + 1e-9) << what;
                }
            }
        }
    }
}

TEST(LanePaths, DeadEndsTurnIntoTheOppositeLane) {
    // A straight street between two dead ends: the only drive is along one
    // lane, a U-turn, back along the other, forever.
    StreetGraph g;
    g.nodes = {{0.0, 0.0}, {200.0, 0.0}};
    StreetEdge e;
    e.a = 0;
    e.b = 1;
    e.width = 8.0f;
    g.edges.push_back(e);
    CityParams params;
    params.sidewalk_m = 0;
    PathOptions o;
    o.duration = 120;
    o.runUp = 0;
    auto p = generatePath(g, params, o);
    ASSERT_TRUE(p.isOk()) << p.status().message();
    std::set<int> lanes;
    double minX = 1e9, maxX = -1e9;
    for (size_t i = 0; i < p->samples.size(); ++i) {
        lanes.insert(p->lanes[i].lane);
        EXPECT_EQ(p->lanes[i].road, uint64_t(0));
        EXPECT_LT(std::abs(p->lanes[i].tOffset), 2.0) << i;
        minX = std::min(minX, p->samples[i].position.x);
        maxX = std::max(maxX, p->samples[i].position.x);
    }
    EXPECT_EQ(lanes, (std::set<int>{-1, 1}));
    // Both ends reached, neither overrun (apex kUTurnMargin before the end).
    EXPECT_LT(minX, 5.0);
    EXPECT_GT(maxX, 195.0);
    EXPECT_GE(minX, 0.0);
    EXPECT_LE(maxX, 200.0);
    // A one-way street between dead ends has no lane network to keep driving:
    // the car follows the centre line instead, and has no lane positions.
    g.edges[0].lanesForward = 1;
    g.edges[0].lanesBackward = 0;
    auto q = generatePath(g, params, o);
    ASSERT_TRUE(q.isOk()) << q.status().message();
    EXPECT_FALSE(q->samples.empty());
    EXPECT_TRUE(q->lanes.empty());
    // The centre-line drive of a walk path with the same options, at car eye height.
    PathOptions walkOptions = o;
    walkOptions.kind = PathKind::Walk;
    auto w = generatePath(g, params, walkOptions);
    ASSERT_TRUE(w.isOk());
    ASSERT_EQ(w->samples.size(), q->samples.size());
    for (size_t i = 0; i < q->samples.size(); ++i) {
        EXPECT_EQ(glm::dvec2(q->samples[i].position), glm::dvec2(w->samples[i].position)) << i;
        EXPECT_NEAR(q->samples[i].position.z - w->samples[i].position.z, 1.2 - 1.7, 1e-9) << i;
    }
}

TEST(LanePaths, SameSeedSameBytes) {
    const TestCity c = generatedCity();
    PathOptions o;
    o.seed = 3;
    o.duration = 30;
    std::vector<std::string> files;
    for (int run = 0; run < 2; ++run) {
        auto p = generatePath(c.streets, c.params, o);
        ASSERT_TRUE(p.isOk()) << p.status().message();
        files.push_back(tmpFile("path" + std::to_string(run) + ".csv"));
        ASSERT_TRUE(savePathCsv(*p, files.back()).isOk());
        files.push_back(tmpFile("lanes" + std::to_string(run) + ".csv"));
        ASSERT_TRUE(saveLanePositionsCsv(*p, files.back()).isOk());
    }
    const std::string lanes = readBytes(files[1]);
    EXPECT_EQ(readBytes(files[0]), readBytes(files[2]));
    EXPECT_EQ(lanes, readBytes(files[3]));
    EXPECT_EQ(lanes.rfind("t_s,road_id,lane_id,s_m,t_offset_m\n", 0), 0u);
    EXPECT_EQ(size_t(std::count(lanes.begin(), lanes.end(), '\n')), size_t(30 / o.dt + 1e-9) + 2);
    // Another seed, another drive.
    o.seed = 4;
    auto other = generatePath(c.streets, c.params, o);
    ASSERT_TRUE(other.isOk());
    ASSERT_TRUE(saveLanePositionsCsv(*other, files[3]).isOk());
    EXPECT_NE(lanes, readBytes(files[3]));
    // Walk paths carry no lane positions: saving them is refused.
    o.kind = PathKind::Walk;
    auto walk = generatePath(c.streets, c.params, o);
    ASSERT_TRUE(walk.isOk());
    EXPECT_TRUE(walk->lanes.empty());
    EXPECT_FALSE(saveLanePositionsCsv(*walk, files[3]).isOk());
    for (const auto& f : files) std::filesystem::remove(f);
}

TEST(LanePaths, CommandWritesPositionsForCarsOnly) {
    test::TempDir tmp("vista_lane_paths_cli");
    const std::string city = tmp.file("c.osgb");
    auto r = test::runVista("gen --seed 3 --size 400 --detail 0 -q -o " + city);
    ASSERT_EQ(r.code, 0) << r.err;
    // Walk paths do not drive in lanes: refused before anything is written.
    r = test::runVista("path " + city + " --kind walk -o " + tmp.file("w.csv") + " --xodr-positions " +
                       tmp.file("w.lanes.csv"));
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("--xodr-positions"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(tmp.file("w.csv")));
    EXPECT_FALSE(std::filesystem::exists(tmp.file("w.lanes.csv")));
    // A car path, right- and left-hand traffic: one position per sample, other drives.
    for (const char* rule : {"", " --lht"}) {
        const std::string tag = *rule ? "lht" : "rht";
        r = test::runVista("path " + city + " --seed 2 --duration 5" + rule + " -o " + tmp.file(tag + ".csv") +
                           " --xodr-positions " + tmp.file(tag + ".lanes.csv"));
        ASSERT_EQ(r.code, 0) << r.err;
        auto p = loadPathCsv(tmp.file(tag + ".csv"));
        ASSERT_TRUE(p.isOk()) << p.status().message();
        const std::string lanes = readBytes(tmp.file(tag + ".lanes.csv"));
        EXPECT_EQ(size_t(std::count(lanes.begin(), lanes.end(), '\n')), p->samples.size() + 1);
    }
    EXPECT_NE(readBytes(tmp.file("rht.lanes.csv")), readBytes(tmp.file("lht.lanes.csv")));
}
