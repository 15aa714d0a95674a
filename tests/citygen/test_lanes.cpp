// The lane model (citygen/lanes.h) on hand-made graphs: lane split and widths,
// laneOffset for odd counts, junction radius and trims (clamped on short
// edges), arm order, sidewalk sides from blocks.
#include <gtest/gtest.h>

#include <cmath>

#include "citygen/lanes.h"

using namespace vista;

namespace {

// A T junction at node 0: east arm 100 m (arterial, 4 lanes, 13 m), west arm
// 100 m (local, 2 lanes, 7.5 m), north arm 6 m (local, 3 lanes, 9 m) ending in
// node 3 of degree 2 that continues north-east to a dead end.
StreetGraph tee() {
    StreetGraph g;
    g.nodes = {{0, 0}, {100, 0}, {-100, 0}, {0, 6}, {30, 36}};
    g.edges = {{0, 1, RoadClass::Arterial, 13.0f, 4}, {2, 0, RoadClass::Local, 7.5f, 2},
               {0, 3, RoadClass::Local, 9.0f, 3}, {3, 4, RoadClass::Local, 7.5f, 1}};
    return g;
}

}  // namespace

TEST(Lanes, SplitWidthsAndOffsets) {
    CityParams p;
    p.sidewalk_m = 3.0;
    const LaneModel m = buildLaneModel(tee(), p);
    ASSERT_EQ(m.edges.size(), 4u);
    const EdgeLanes& east = m.edges[0];
    EXPECT_EQ(east.right, 2);
    EXPECT_EQ(east.left, 2);
    EXPECT_DOUBLE_EQ(east.laneWidth, 13.0 / 4);
    EXPECT_DOUBLE_EQ(east.offset, 0.0);
    EXPECT_DOUBLE_EQ(east.laneCentre(-1), -13.0 / 8);
    EXPECT_DOUBLE_EQ(east.laneCentre(2), 3 * 13.0 / 8);
    // 3 lanes: 2 right, 1 left, centred on the 9 m carriageway.
    const EdgeLanes& north = m.edges[2];
    EXPECT_EQ(north.right, 2);
    EXPECT_EQ(north.left, 1);
    EXPECT_DOUBLE_EQ(north.laneWidth, 3.0);
    EXPECT_DOUBLE_EQ(north.offset, 1.5);
    EXPECT_DOUBLE_EQ(north.offset - north.right * north.laneWidth, -4.5);  // right carriageway edge
    EXPECT_DOUBLE_EQ(north.offset + north.left * north.laneWidth, 4.5);    // left carriageway edge
    // 1 lane: one per direction over the same width.
    EXPECT_EQ(m.edges[3].right, 1);
    EXPECT_EQ(m.edges[3].left, 1);
    EXPECT_DOUBLE_EQ(m.edges[3].laneWidth, 3.75);
}

TEST(Lanes, JunctionsAndTrims) {
    CityParams p;
    p.sidewalk_m = 3.0;
    const LaneModel m = buildLaneModel(tee(), p);
    ASSERT_EQ(m.junctions.size(), 1u);
    const Junction& j = m.junctions[0];
    EXPECT_EQ(j.node, 0u);
    EXPECT_DOUBLE_EQ(j.radius, 6.5 + 3.0);  // widest arm: 13 m / 2 + sidewalk
    // Arms counter-clockwise by angle in (-pi, pi]: east (0), north (pi/2), west (pi).
    ASSERT_EQ(j.arms.size(), 3u);
    EXPECT_EQ(j.arms[0], 0u);
    EXPECT_EQ(j.arms[1], 2u);
    EXPECT_EQ(j.arms[2], 1u);
    EXPECT_EQ(m.degree[3], 2);
    EXPECT_EQ(m.nodeJunction[3], -1);
    // East arm starts at the junction: trimmed at a only.
    EXPECT_DOUBLE_EQ(m.edges[0].trimA, 9.5);
    EXPECT_DOUBLE_EQ(m.edges[0].trimB, 0.0);
    EXPECT_NEAR(m.edges[0].start.x, 9.5, 1e-12);
    EXPECT_NEAR(m.edges[0].length, 90.5, 1e-12);
    EXPECT_EQ(m.edges[0].junctionA, 0);
    // West arm ends at the junction.
    EXPECT_DOUBLE_EQ(m.edges[1].trimB, 9.5);
    EXPECT_NEAR(m.edges[1].end.x, -9.5, 1e-12);
    // The 6 m north arm: the trim is clamped so that kMinRoadLength remains.
    EXPECT_NEAR(m.edges[2].length, kMinRoadLength, 1e-12);
    EXPECT_NEAR(m.edges[2].trimA, 6.0 - kMinRoadLength, 1e-12);
    // Without a junction at either end nothing is trimmed.
    EXPECT_NEAR(m.edges[3].length, std::sqrt(30.0 * 30 + 30 * 30), 1e-12);
}

TEST(Lanes, SidewalkSidesFromBlocks) {
    CityParams p;
    p.sidewalk_m = 3.0;
    // A block north of the east arm only (inset by half width + sidewalk).
    Block b;
    b.outline = {{20, 9.5}, {90, 9.5}, {90, 60}, {20, 60}};
    const std::vector<Block> blocks{b};
    const LaneModel m = buildLaneModel(tee(), p, &blocks);
    EXPECT_TRUE(m.edges[0].hasWalk(1));    // left of a -> b (east) is north
    EXPECT_FALSE(m.edges[0].hasWalk(-1));
    EXPECT_FALSE(m.edges[1].hasWalk(1));
    const LaneModel all = buildLaneModel(tee(), p);
    EXPECT_TRUE(all.edges[0].hasWalk(1) && all.edges[0].hasWalk(-1));
    p.sidewalk_m = 0;
    EXPECT_FALSE(buildLaneModel(tee(), p).edges[0].hasWalk(1));
}

TEST(Lanes, InvalidEdgesAreKeptInvalid) {
    StreetGraph g;
    g.nodes = {{0, 0}, {0, 0}, {std::nan(""), 1}};
    g.edges = {{0, 1, RoadClass::Local, 7.5f, 2}, {0, 2, RoadClass::Local, 7.5f, 2}, {0, 7, RoadClass::Local, 7.5f, 2}};
    const LaneModel m = buildLaneModel(g, CityParams());
    ASSERT_EQ(m.edges.size(), 3u);
    for (const auto& e : m.edges) EXPECT_FALSE(e.valid);
    EXPECT_TRUE(m.junctions.empty());
}
