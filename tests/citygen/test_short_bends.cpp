// Slight bends next to a junction (short_bends.h): a degree-2 node on a short
// junction arm where the road turns slightly and goes on unchanged is dropped,
// its two edges becoming one straight edge from the junction (a one-way edge
// still along its traffic); nodes where the road changes, turns too much,
// lies too far off the straight edge, is too far from the junction, or where
// another node lies in the cut-off corner stay. The fixture
// tests/data/osm/short_arm_slight_bend.osm comes out of importOsm with its
// north arm as one edge.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "citygen/short_bends.h"
#include "citygen/streets.h"

using namespace vista;

namespace {

// A crossing at node 0 (arms west, south, east to nodes 1..3) and a north arm
// of two edges: 0 -> 4 at (0, arm) and 4 -> 5, `bend` radians east of north, 100 m on.
StreetGraph crossing(double arm, double bend) {
    StreetGraph g;
    g.nodes = {{0, 0}, {-100, 0}, {0, -100}, {100, 0}, {0, arm}, {100 * std::sin(bend), arm + 100 * std::cos(bend)}};
    for (auto [a, b] : {std::pair{0u, 1u}, {0u, 2u}, {0u, 3u}, {0u, 4u}, {4u, 5u}}) {
        StreetEdge e;
        e.a = a;
        e.b = b;
        e.cls = RoadClass::Arterial;
        e.width = 13.0f;
        e.lanes = 4;
        g.edges.push_back(e);
    }
    return g;
}

}  // namespace

TEST(ShortBends, SlightBendNextToAJunctionIsStraightened) {
    StreetGraph g = crossing(18.0, 0.05);
    ASSERT_EQ(straightenShortBends(g), 1u);
    ASSERT_EQ(g.nodes.size(), 5u);
    ASSERT_EQ(g.edges.size(), 4u);
    const StreetEdge& e = g.edges[3];  // the north arm, now from the crossing to the far node
    EXPECT_EQ(e.a, 0u);
    EXPECT_EQ(g.nodes[e.b], glm::dvec2(100 * std::sin(0.05), 18.0 + 100 * std::cos(0.05)));
    EXPECT_EQ(e.lanes, 4);
    EXPECT_TRUE(checkPlanarGraph(g, 12.0).isOk());
}

TEST(ShortBends, OneWayArmStaysAlongItsTraffic) {
    StreetGraph g = crossing(18.0, 0.05);
    for (size_t k : {3u, 4u}) {  // traffic from the far node toward the crossing
        StreetEdge& e = g.edges[k];
        std::swap(e.a, e.b);
        e.lanes = 2;
        e.lanesForward = 2;
        e.lanesBackward = 0;
        e.width = 6.5f;
    }
    ASSERT_EQ(straightenShortBends(g), 1u);
    const StreetEdge& e = g.edges[3];
    EXPECT_EQ(e.b, 0u);  // runs toward the crossing, as its traffic does
    EXPECT_EQ(e.lanesForward, 2);
    EXPECT_EQ(e.lanesBackward, 0);
}

TEST(ShortBends, KeepsNodesWhereTheRoadChangesOrTurns) {
    {
        StreetGraph g = crossing(18.0, 0.05);
        g.edges[4].lanes = 2;  // the road changes there: its transition stays
        EXPECT_EQ(straightenShortBends(g), 0u);
    }
    {
        StreetGraph g = crossing(18.0, 0.35);  // 20 degrees
        EXPECT_EQ(straightenShortBends(g), 0u);
    }
    {
        StreetGraph g = crossing(40.0, 0.05);  // farther from the crossing than kShortBendArm
        EXPECT_EQ(straightenShortBends(g), 0u);
    }
    {
        StreetGraph g = crossing(24.0, 0.2);  // 11.5 degrees: the node lies 3.9 m off the straight edge
        EXPECT_EQ(straightenShortBends(g), 0u);
    }
    {
        StreetGraph g = crossing(18.0, 0.05);
        g.nodes.push_back({0.2, 10.0});  // a node in the cut-off corner, with an edge to the east arm's end
        StreetEdge e = g.edges[0];
        e.a = 3;
        e.b = 6;
        g.edges.push_back(e);
        EXPECT_EQ(straightenShortBends(g), 0u);
    }
}

TEST(ShortBends, FixtureNorthArmIsOneEdge) {
    auto imp = importOsm(std::string(VISTA_TEST_DATA) + "/osm/short_arm_slight_bend.osm", CityParams());
    ASSERT_TRUE(imp.isOk()) << imp.status().message();
    const StreetGraph& g = imp->streets;
    const std::vector<int> deg = g.degrees();
    size_t two = 0;
    for (int d : deg) two += d == 2;
    EXPECT_EQ(two, 0u);  // no node where the two northern ways met
    EXPECT_EQ(g.edges.size(), 4u);
}
