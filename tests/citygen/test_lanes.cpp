// The lane model (citygen/lanes.h) on hand-made graphs: lane split and widths,
// laneOffset for odd counts, junction radius and trims (on short edges the
// junction's first, the transition's least kept), arm order, sidewalk sides from blocks, link roads tangent to their
// roads, turning lanes, directional lane counts; lane centres of every turn at
// least the class's turning radius from the arc's centre. Junction connections
// and surfaces: test_lane_junctions.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "citygen/lanes.h"

using namespace vista;

namespace {

// A T junction at node 0: east arm 100 m (arterial, 4 lanes, 13 m), west arm
// 100 m (local, 2 lanes, 7.5 m), north arm 6 m (local, 3 lanes, 9 m) ending in
// node 3 of degree 2 that continues north-east to a dead end.
StreetGraph tee() {
    StreetGraph g;
    g.nodes = {{0, 0}, {100, 0}, {-100, 0}, {0, 6}, {30, 36}};
    g.edges = {{0, 1, RoadClass::Arterial, 13.0f, 4},
               {2, 0, RoadClass::Local, 7.5f, 2},
               {0, 3, RoadClass::Local, 9.0f, 3},
               {3, 4, RoadClass::Local, 7.5f, 1}};
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
    // The right turn east -> north keeps the local class's turning radius:
    // its lane centre reaches 1.5 lanes of 3.25 m toward the centre.
    // Each arm is trimmed kCrossingLeadIn further, the turn's straight start.
    const double radius = (1.5 * 3.25 + kMinTurnRadiusLocal + 1e-3) * std::tan(0.25 * 3.14159265358979323846);
    const double trim = radius + kCrossingLeadIn;
    EXPECT_NEAR(j.radius, trim, 1e-9);
    EXPECT_GT(j.radius, 6.5 + 3.0);  // more than the widest arm: 13 m / 2 + sidewalk
    // Arms counter-clockwise by angle in (-pi, pi]: east (0), north (pi/2), west (pi).
    ASSERT_EQ(j.arms.size(), 3u);
    EXPECT_EQ(j.arms[0], 0u);
    EXPECT_EQ(j.arms[1], 2u);
    EXPECT_EQ(j.arms[2], 1u);
    EXPECT_EQ(m.degree[3], 2);
    EXPECT_EQ(m.nodeJunction[3], -1);
    // East arm starts at the junction: trimmed at a only.
    EXPECT_NEAR(m.edges[0].trimA, trim, 1e-9);
    EXPECT_DOUBLE_EQ(m.edges[0].trimB, 0.0);
    EXPECT_NEAR(m.edges[0].start.x, trim, 1e-9);
    EXPECT_NEAR(m.edges[0].length, 100 - trim, 1e-9);
    EXPECT_EQ(m.edges[0].junctionA, 0);
    // West arm ends at the junction.
    EXPECT_NEAR(m.edges[1].trimB, trim, 1e-9);
    EXPECT_NEAR(m.edges[1].end.x, -trim, 1e-9);
    // The 6 m north arm (junction at a, transition at b) is too short for
    // both trims: kMinRoadLength remains, the transition at b keeps at least
    // the tangent of its 45 degree fillet that holds its lanes kCurvatureMargin
    // from the centre of curvature (they reach 7.5 m toward it: the 1.5 m lane
    // offset, two 3 m lanes and the 3 m sidewalk), less than the taper it
    // would like, and the junction gets the rest.
    EXPECT_NEAR(m.edges[2].length, kMinRoadLength, 1e-12);
    EXPECT_NEAR(m.edges[2].trimA + m.edges[2].trimB, 6.0 - kMinRoadLength, 1e-12);
    const double least = (7.5 + kCurvatureMargin) * std::tan(0.125 * 3.14159265358979323846);
    EXPECT_GE(m.edges[2].trimB, least - 1e-9);
    EXPECT_LT(m.edges[2].trimB, 0.5 * kTaperLength);
    EXPECT_GT(m.edges[2].trimA, 0.0);
    // So the transition is built, its fillet clear of folding.
    const LinkRoad* bend = nullptr;
    for (const LinkRoad& r : m.links)
        if (r.junction < 0 && r.node == 3) bend = &r;
    ASSERT_NE(bend, nullptr);
    ASSERT_GT(bend->arcLength, 0.0);
    EXPECT_GE(1.0 / std::abs(bend->curvature), 7.5 + kCurvatureMargin - 1e-6);
    EXPECT_EQ(m.sharpCorners, 0u);
    // Turns into or out of the shortened arm cannot keep their radius: the
    // ones whose lanes another turn takes are dropped, none is left unlinked.
    EXPECT_GT(m.tightTurns + m.tightTurnsKept, 0u);
    EXPECT_EQ(m.unlinkedLanes, 0u);
    // The degree-2 node 3 (north arm to the north-east edge) is a transition:
    // the edge is trimmed there, a dead end is not.
    EXPECT_EQ(m.edges[3].trimB, 0.0);
    EXPECT_GT(m.edges[3].trimA, 0.0);
    EXPECT_NEAR(m.edges[3].length + m.edges[3].trimA, std::sqrt(30.0 * 30 + 30 * 30), 1e-12);
}

TEST(Lanes, SidewalkSidesFromBlocks) {
    CityParams p;
    p.sidewalk_m = 3.0;
    // A block north of the east arm only (inset by half width + sidewalk).
    Block b;
    b.outline = {{20, 9.5}, {90, 9.5}, {90, 60}, {20, 60}};
    const std::vector<Block> blocks{b};
    const LaneModel m = buildLaneModel(tee(), p, &blocks);
    EXPECT_TRUE(m.edges[0].hasWalk(1));  // left of a -> b (east) is north
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

namespace {

// A plus-shaped junction at the origin with four 80 m arms whose far ends
// continue through a degree-2 corner (turning by `corner` radians) into a
// 60 m edge; arm k has `lanes[k]` lanes (total) and carriageway `width[k]`.
StreetGraph plus(const int lanes[4], const double width[4], double corner) {
    StreetGraph g;
    g.nodes.push_back({0, 0});
    for (int k = 0; k < 4; ++k) {
        const double a = k * 0.5 * 3.14159265358979323846;
        const glm::dvec2 d(std::cos(a), std::sin(a)), e(std::cos(a + corner), std::sin(a + corner));
        g.nodes.push_back(80.0 * d);
        g.nodes.push_back(80.0 * d + 60.0 * e);
        const uint32_t mid = uint32_t(1 + 2 * k);
        g.edges.push_back({0, mid, RoadClass::Local, float(width[k]), uint8_t(lanes[k])});
        g.edges.push_back({mid, mid + 1, RoadClass::Local, float(width[k]), uint8_t(lanes[k])});
    }
    return g;
}

glm::dvec2 unit(double h) { return {std::cos(h), std::sin(h)}; }

}  // namespace

// Every link road starts on the trimmed end of the road it leaves and ends on
// the trimmed start of the road it enters, tangent to both (G1), computed
// here from the edge geometry alone; its lane borders stay on the near side
// of the centre of curvature.
TEST(Lanes, LinkRoadsAreTangentToBothRoads) {
    const int lanes[4] = {2, 4, 2, 3};
    const double width[4] = {7.5, 13.0, 7.0, 9.0};
    for (double corner : {0.0, 0.3, -0.9, 1.4, -2.0}) {
        CityParams p;
        p.sidewalk_m = 2.5;
        const StreetGraph g = plus(lanes, width, corner);
        const LaneModel m = buildLaneModel(g, p);
        ASSERT_EQ(m.junctions.size(), 1u);
        EXPECT_EQ(m.sharpCorners, 0u) << corner;
        EXPECT_EQ(m.unlinkedLanes, 0u) << corner;
        size_t transitions = 0;
        for (const LinkRoad& r : m.links) {
            transitions += r.junction < 0;
            const EdgeLanes &in = m.edges[r.in], &out = m.edges[r.out];
            // Contact points from the graph: the trimmed end of `in` at the node, the trimmed start of `out`.
            const glm::dvec2 p0 = r.inEnd ? in.end : in.start, p1 = r.outStart ? out.start : out.end;
            const glm::dvec2 d0 = r.inEnd ? in.dir : -in.dir, d1 = r.outStart ? out.dir : -out.dir;
            EXPECT_LT(glm::length(r.point(0) - p0), 1e-9) << corner;
            EXPECT_LT(glm::length(r.point(r.length()) - p1), 1e-6) << corner << " link " << r.in << "->" << r.out;
            EXPECT_LT(glm::length(unit(r.heading(0)) - d0), 1e-9);
            EXPECT_LT(glm::length(unit(r.heading(r.length())) - d1), 1e-9);
            // The arc's centre lies 1/|k| from the reference line; no border reaches it.
            if (r.arcLength > 0) {
                const double R = 1.0 / std::abs(r.curvature);
                for (double s = 0; s <= r.length(); s += 0.25) {
                    if (r.curvature > 0) {
                        EXPECT_LT(r.leftBorder(s), R) << s;
                    } else {
                        EXPECT_GT(r.rightBorder(s), -R) << s;
                    }
                }
            }
        }
        EXPECT_EQ(transitions, 4u) << corner;
    }
}

// Lane borders meet where a link road joins a street road: at s = 0 the
// link's lanes have the incoming road's widths at its lane offset, at the
// end the outgoing road's; a lane that exists on one side only has width 0
// on the other and no link there.
TEST(Lanes, LinkRoadLanesContinueTheRoadsLanes) {
    const int lanes[4] = {2, 4, 1, 3};
    const double width[4] = {7.5, 13.0, 6.0, 9.0};
    CityParams p;
    const LaneModel m = buildLaneModel(plus(lanes, width, 0.5), p);
    ASSERT_FALSE(m.links.empty());
    for (const LinkRoad& r : m.links) {
        const EdgeLanes &in = m.edges[r.in], &out = m.edges[r.out];
        // Lane k of a street road (id sign by side) in the link's frame at the node.
        auto laneBorders = [](const EdgeLanes& L, int id, bool flip) {
            const double inner = L.laneCentre(id) - (id < 0 ? -0.5 : 0.5) * L.laneWidth;
            const double outer = L.laneCentre(id) + (id < 0 ? -0.5 : 0.5) * L.laneWidth;
            return flip ? glm::dvec2(-inner, -outer) : glm::dvec2(inner, outer);
        };
        for (int side : {-1, 1}) {
            const auto& list = side < 0 ? r.right : r.left;
            double t0 = r.laneOffset(0), t1 = r.laneOffset(r.length());
            for (const LinkRoad::Lane& l : list) {
                if (l.sidewalk) continue;
                const double n0 = t0 + side * l.w0, n1 = t1 + side * l.w1;
                if (l.from) {
                    const glm::dvec2 b = laneBorders(in, l.from, !r.inEnd);
                    EXPECT_NEAR(t0, b.x, 1e-9);
                    EXPECT_NEAR(n0, b.y, 1e-9);
                } else {
                    EXPECT_EQ(l.w0, 0.0);
                }
                if (l.to) {
                    const glm::dvec2 b = laneBorders(out, l.to, !r.outStart);
                    EXPECT_NEAR(t1, b.x, 1e-9);
                    EXPECT_NEAR(n1, b.y, 1e-9);
                } else {
                    EXPECT_EQ(l.w1, 0.0);
                }
                t0 = n0, t1 = n1;
            }
        }
    }
}

// Turning lanes of right-hand traffic at a 4-arm junction with 2 lanes in
// each direction: straight on takes both lanes, the right turn the outer
// lane (-2 of a road ending at the junction), the left turn the inner one.
TEST(Lanes, TurningLanesGoWhereADriverExpects) {
    const int lanes[4] = {4, 4, 4, 4};
    const double width[4] = {14, 14, 14, 14};
    CityParams p;
    const StreetGraph g = plus(lanes, width, 0.0);
    const LaneModel m = buildLaneModel(g, p);
    std::set<int> fromEast[3];  // by turn: right, straight, left
    for (const LinkRoad& r : m.links) {
        if (r.junction < 0 || r.in != 2) continue;  // edge 2 = arm 1 (north), starts at the junction
        const int idx = r.turn == LinkRoad::Turn::Right ? 0 : r.turn == LinkRoad::Turn::Straight ? 1 : 2;
        for (const LinkRoad::Lane& l : r.right)
            if (l.from) fromEast[idx].insert(l.from);
    }
    // The north arm starts at the junction: its lanes toward it are its left lanes (+1 inner, +2 outer).
    EXPECT_EQ(fromEast[0], (std::set<int>{2}));
    EXPECT_EQ(fromEast[1], (std::set<int>{1, 2}));
    EXPECT_EQ(fromEast[2], (std::set<int>{1}));
    EXPECT_EQ(m.unlinkedLanes, 0u);
}

// A hairpin sharper than kMaxTurn cannot be turned inside the edges' lanes:
// no transition, both roads end there.
TEST(Lanes, HairpinsAreLeftUnlinked) {
    StreetGraph g;
    g.nodes = {{0, 0}, {100, 0}, {0, 10}};
    g.edges = {{0, 1, RoadClass::Local, 7.5f, 2}, {1, 2, RoadClass::Local, 7.5f, 2}};
    const LaneModel m = buildLaneModel(g, CityParams());
    EXPECT_EQ(m.sharpCorners, 1u);
    EXPECT_TRUE(m.links.empty());
    EXPECT_EQ(m.edges[0].linkB, -1);
    EXPECT_EQ(m.edges[1].linkA, -1);
}

// One-way edges (lanesBackward = 0) and lane tags change the lane counts.
TEST(Lanes, DirectionalLaneCounts) {
    StreetGraph g;
    g.nodes = {{0, 0}, {100, 0}};
    g.edges = {{0, 1, RoadClass::Arterial, 10.5f, 3}};
    g.edges[0].lanesForward = 3;
    g.edges[0].lanesBackward = 0;
    g.edges[0].maxspeedKmh = 70;
    const LaneModel m = buildLaneModel(g, CityParams());
    EXPECT_EQ(m.edges[0].right, 3);
    EXPECT_EQ(m.edges[0].left, 0);
    EXPECT_DOUBLE_EQ(m.edges[0].laneWidth, 3.5);
    EXPECT_DOUBLE_EQ(m.edges[0].offset, 5.25);
    EXPECT_DOUBLE_EQ(m.edges[0].speedKmh, 70.0);
    g.edges[0].maxspeedKmh = 0;
    EXPECT_DOUBLE_EQ(buildLaneModel(g, CityParams()).edges[0].speedKmh, classSpeedKmh(RoadClass::Arterial));
}

TEST(Lanes, TurnsKeepTheClassTurningRadius) {
    EXPECT_EQ(minTurnRadius(RoadClass::Local), kMinTurnRadiusLocal);
    EXPECT_GE(kMinTurnRadiusLocal, 5.0);  // a car's kerb-to-kerb turning radius is the floor
    EXPECT_GE(minTurnRadius(RoadClass::Arterial), minTurnRadius(RoadClass::Local));
    EXPECT_GE(minTurnRadius(RoadClass::Highway), minTurnRadius(RoadClass::Arterial));
    const int lanes[4] = {2, 4, 2, 3};
    const double width[4] = {7.5, 13.0, 7.0, 9.0};
    for (double corner : {0.0, 0.3, -0.9}) {
        CityParams p;
        p.sidewalk_m = 0;
        const LaneModel m = buildLaneModel(plus(lanes, width, corner), p);
        size_t arcs = 0;
        double smallest = 1e300;
        for (const LinkRoad& r : m.links) {
            if (r.junction < 0 || r.arcLength <= 0) continue;
            ++arcs;
            for (double s = r.line0; s <= r.line0 + r.arcLength; s += 0.1) {
                double t = r.laneOffset(s);
                for (const LinkRoad::Lane& l : r.right) {
                    const double w = r.width(l, s);
                    if (w > 0.01) smallest = std::min(smallest, std::abs(1.0 / r.curvature - (t - 0.5 * w)));
                    t -= w;
                }
            }
        }
        EXPECT_GT(arcs, 0u);
        EXPECT_GE(smallest, kMinTurnRadiusLocal - 1e-9) << corner;
        EXPECT_EQ(m.unlinkedLanes, 0u);
        EXPECT_EQ(m.tightTurns + m.tightTurnsKept, 0u);  // 80 m arms leave room for every turn
    }
}
