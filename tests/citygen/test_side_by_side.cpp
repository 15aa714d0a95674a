// Side-by-side street edges (side_by_side.h): the carriageways of nearly
// parallel edges that share no node are narrowed until they share no area,
// each by the factor its pairs ask for, keeping lanes at least kMinLaneWidth
// wide (dropping lanes, never a direction's last one); edges that meet at a
// node, cross, or lie apart keep their widths. The overlap is re-checked here
// from the edges alone (rectangles sampled along the centre lines), and the
// divided-highway fixture is imported through importOsm.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "citygen/lanes.h"
#include "citygen/side_by_side.h"
#include "citygen/streets.h"

using namespace vista;

namespace {

// Largest depth (metres) by which the carriageways of two parallel edges
// along x overlap across: half widths against the lateral distance.
double lateralOverlap(const StreetGraph& g, size_t e, size_t f) {
    const double d = std::abs(g.nodes[g.edges[e].a].y - g.nodes[g.edges[f].a].y);
    return 0.5 * carriagewayWidth(g.edges[e]) + 0.5 * carriagewayWidth(g.edges[f]) - d;
}

// Two edges along x, `gap` metres apart, of `lanes` one-way lanes each at
// the highway class's lane width; the second runs the other way.
StreetGraph pair(double gap, int lanes, double length = 100.0) {
    StreetGraph g;
    g.nodes = {{0.0, 0.5 * gap}, {length, 0.5 * gap}, {length, -0.5 * gap}, {0.0, -0.5 * gap}};
    for (uint32_t a : {0u, 2u}) {
        StreetEdge e;
        e.a = a;
        e.b = a + 1;
        e.cls = RoadClass::Highway;
        e.lanes = uint8_t(lanes);
        e.lanesForward = int8_t(lanes);
        e.lanesBackward = 0;
        e.width = float(lanes * roadWidth(RoadClass::Highway) / roadLanes(RoadClass::Highway));
        g.edges.push_back(e);
    }
    return g;
}

}  // namespace

TEST(SideBySide, HalvesSixMetresApartKeepTheirLanesAndPart) {
    StreetGraph g = pair(6.0, 2);
    ASSERT_GT(lateralOverlap(g, 0, 1), 0.5);  // 2 x 3.33 m lanes on each side of a 6 m gap
    const SideBySideStats st = narrowSideBySide(g);
    EXPECT_EQ(st.pairs, 1u);
    EXPECT_EQ(st.edgesNarrowed, 2u);
    EXPECT_EQ(st.lanesDropped, 0u);
    const double o = lateralOverlap(g, 0, 1);
    EXPECT_LE(o, -kSideBySideClearance + 1e-4);
    EXPECT_GE(o, -kSideBySideClearance - 1e-3);  // no narrower than it needs
    for (const StreetEdge& e : g.edges) {
        EXPECT_EQ(e.lanesForward, 2);
        EXPECT_EQ(e.lanesBackward, 0);
        EXPECT_GE(e.width / 2.0, kMinLaneWidth);
    }
}

TEST(SideBySide, TooNarrowForTwoLanesKeepsOneAndStaysOneWay) {
    StreetGraph g = pair(4.0, 2);
    g.edges[0].turnForward = "left|through";
    const SideBySideStats st = narrowSideBySide(g);
    EXPECT_EQ(st.lanesDropped, 2u);
    EXPECT_LE(lateralOverlap(g, 0, 1), -kSideBySideClearance + 1e-4);
    for (const StreetEdge& e : g.edges) {
        EXPECT_EQ(e.lanes, 1);
        EXPECT_EQ(e.lanesForward, 1);
        EXPECT_EQ(e.lanesBackward, 0);
        EXPECT_TRUE(e.turnForward.empty());  // listed two lanes
    }
}

TEST(SideBySide, TwoWayEdgeKeepsALaneEachWay) {
    StreetGraph g = pair(3.0, 2);
    g.edges[0].lanes = 4;
    g.edges[0].lanesForward = g.edges[0].lanesBackward = -1;  // derived: 2 + 2
    g.edges[0].width = 13.0f;
    narrowSideBySide(g);
    EXPECT_EQ(g.edges[0].lanesForward, 1);
    EXPECT_EQ(g.edges[0].lanesBackward, 1);
    EXPECT_EQ(g.edges[1].lanesForward, 1);
    EXPECT_EQ(g.edges[1].lanesBackward, 0);
    EXPECT_LE(lateralOverlap(g, 0, 1), -kSideBySideClearance + 1e-4);
}

TEST(SideBySide, LeavesApartCrossingAndMeetingEdgesAlone) {
    {
        StreetGraph g = pair(8.0, 2);  // 6.67 m of carriageways in 8 m: apart
        const StreetGraph before = g;
        EXPECT_EQ(narrowSideBySide(g).edgesNarrowed, 0u);
        EXPECT_EQ(g.edges[0].width, before.edges[0].width);
    }
    {
        StreetGraph g = pair(6.0, 2);
        g.nodes[1] = {100.0, -3.0};  // the first edge meets the second at its start node's line: they cross
        g.nodes[0] = {0.0, 3.0};
        g.nodes[2] = {100.0, 3.0};
        g.nodes[3] = {0.0, -3.0};
        EXPECT_EQ(narrowSideBySide(g).edgesNarrowed, 0u);
    }
    {
        StreetGraph g = pair(6.0, 2);
        g.edges[1].b = 0;  // shares node 0 with the first: a junction parts them
        g.nodes[0] = {0.0, 0.0};
        EXPECT_EQ(narrowSideBySide(g).edgesNarrowed, 0u);
    }
    {
        StreetGraph g = pair(6.0, 2);
        g.nodes[2] = {50.0, 60.0};  // 40+ degrees off parallel
        EXPECT_EQ(narrowSideBySide(g).edgesNarrowed, 0u);
    }
}

// The fixture's two halves, 6 m apart, come out of the import as one-way
// edges of two lanes whose carriageways part.
TEST(SideBySide, DividedHighwayFixture) {
    CityParams p;
    auto imp = importOsm(std::string(VISTA_TEST_DATA) + "/osm/divided_highway.osm", p);
    ASSERT_TRUE(imp.isOk()) << imp.status().message();
    const StreetGraph& g = imp->streets;
    std::vector<size_t> halves;  // the straight pieces of the halves, at |y| = 3
    for (size_t e = 0; e < g.edges.size(); ++e) {
        const glm::dvec2 a = g.nodes[g.edges[e].a], b = g.nodes[g.edges[e].b];
        if (std::abs(a.y) < 2.0 || std::abs(a.y - b.y) > 0.1 || std::abs(b.x - a.x) < 50.0) continue;
        halves.push_back(e);
        EXPECT_EQ(g.edges[e].lanesForward, 2);
        EXPECT_EQ(g.edges[e].lanesBackward, 0);
        EXPECT_GE(carriagewayWidth(g.edges[e]), 2 * kMinLaneWidth);
    }
    size_t facing = 0;  // pairs of pieces side by side across the gap
    for (size_t x : halves)
        for (size_t y : halves) {
            const glm::dvec2 a = g.nodes[g.edges[x].a], b = g.nodes[g.edges[x].b];
            const glm::dvec2 c = g.nodes[g.edges[y].a], d = g.nodes[g.edges[y].b];
            const bool overlapAlong = std::min(std::max(a.x, b.x), std::max(c.x, d.x)) >
                                      std::max(std::min(a.x, b.x), std::min(c.x, d.x)) + 1.0;
            if (!(a.y > 0 && c.y < 0) || !overlapAlong) continue;
            ++facing;
            const double gap = 0.5 * (a.y + b.y) - 0.5 * (c.y + d.y);
            EXPECT_LE(0.5 * carriagewayWidth(g.edges[x]) + 0.5 * carriagewayWidth(g.edges[y]),
                      gap - kSideBySideClearance + 1e-3);
        }
    EXPECT_EQ(facing, 2u);
    EXPECT_EQ(halves.size(), 4u);
}
