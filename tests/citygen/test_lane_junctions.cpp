// The lane model's junctions (citygen/lanes.h) on hand-made graphs: every
// full-width lane at a junction has a connection in and out (through
// junctions where a lane appears included), acute arms cut back until their
// surfaces (intersected here with Boost.Geometry) share no area, lanes no turn
// can connect counted, junctions closer than their footprints joined, and arms
// cut back past the turns that must cross them.
#include <gtest/gtest.h>

// Boost.Geometry's rescaling code trips GCC's maybe-uninitialized warning.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#define BOOST_GEOMETRY_NO_ROBUSTNESS
#include <boost/geometry.hpp>
#include <boost/geometry/geometries/point_xy.hpp>
#include <boost/geometry/geometries/polygon.hpp>

#include <cmath>
#include <map>
#include <set>

#include "citygen/lanes.h"

using namespace vista;

namespace {

// Per junction arm, the incoming lanes (k = 1 innermost) that are the `from`
// of a link road lane and the outgoing lanes that a link road lane with a
// `from` (full width where it starts) leads into, from the link roads alone.
struct Connections {
    std::map<uint32_t, std::set<int>> in, out;  // by edge: |lane id|
};
Connections connections(const LaneModel& m) {
    Connections c;
    for (const LinkRoad& r : m.links) {
        if (r.junction < 0) continue;
        for (const LinkRoad::Lane& l : r.right) {
            if (l.from && l.w0 > 0) c.in[r.in].insert(std::abs(l.from));
            if (l.from && l.to && l.w0 > 0 && l.w1 > 0) c.out[r.out].insert(std::abs(l.to));
        }
    }
    return c;
}

// Incoming and outgoing driving lanes of edge e at node v.
int lanesToward(const LaneModel& m, const StreetGraph& g, uint32_t e, uint32_t v) {
    return g.edges[e].b == v ? m.edges[e].right : m.edges[e].left;
}
int lanesAway(const LaneModel& m, const StreetGraph& g, uint32_t e, uint32_t v) {
    return g.edges[e].b == v ? m.edges[e].left : m.edges[e].right;
}

namespace bg = boost::geometry;
using BgPoint = bg::model::d2::point_xy<double>;
using BgPolygon = bg::model::polygon<BgPoint>;

BgPolygon bgPolygon(const std::vector<glm::dvec2>& pts) {
    BgPolygon poly;
    for (const glm::dvec2& p : pts) bg::append(poly.outer(), BgPoint(p.x, p.y));
    bg::append(poly.outer(), BgPoint(pts[0].x, pts[0].y));
    bg::correct(poly);
    return poly;
}

double sharedArea(const BgPolygon& a, const BgPolygon& b) {
    std::vector<BgPolygon> out;
    bg::intersection(a, b, out);
    double area = 0;
    for (const BgPolygon& p : out) area += bg::area(p);
    return area;
}
#pragma GCC diagnostic pop

// The surface of a street road in the model: carriageway and the sidewalks
// it has, between its trimmed ends.
BgPolygon streetSurface(const EdgeLanes& L) {
    const glm::dvec2 n = L.normal();
    const double left = L.halfWidth() + (L.hasWalk(1) ? L.sidewalk : 0.0);
    const double right = L.halfWidth() + (L.hasWalk(-1) ? L.sidewalk : 0.0);
    return bgPolygon({L.start - n * right, L.end - n * right, L.end + n * left, L.start + n * left});
}

// A junction at the origin with local arms east (0), at `acute` radians and
// west, 80 m each; the middle arm an arterial.
StreetGraph fork(double acute) {
    StreetGraph g;
    g.nodes = {{0, 0}, {80, 0}, {80 * std::cos(acute), 80 * std::sin(acute)}, {-80, 0}};
    g.edges = {
        {0, 1, RoadClass::Local, 7.5f, 2}, {0, 2, RoadClass::Arterial, 13.0f, 4}, {3, 0, RoadClass::Local, 7.5f, 2}};
    return g;
}

}  // namespace

// Every full-width lane at a junction has a connection in and out: a T whose
// east arm leaves with three lanes (one lane back) gets from the west's one
// straight lane and the south's right turn only lanes 1 and 3 of the plan;
// lane 2 is fed by a one-lane turn of its own, and every incoming lane is
// taken. Counted from the link roads, independently of the model's counters.
TEST(Lanes, EveryJunctionLaneHasAConnectionInAndOut) {
    StreetGraph g;
    g.nodes = {{0, 0}, {-100, 0}, {100, 0}, {0, -100}, {0, 100}};
    g.edges = {
        {1, 0, RoadClass::Local, 7.0f, 2}, {0, 2, RoadClass::Arterial, 14.0f, 4}, {3, 0, RoadClass::Local, 7.0f, 2}};
    g.edges[1].lanesForward = 3;
    g.edges[1].lanesBackward = 1;
    for (int variant = 0; variant < 2; ++variant) {
        if (variant == 1) {  // a fourth arm, one-way toward the junction with three lanes
            g.edges.push_back({4, 0, RoadClass::Arterial, 10.5f, 3});
            g.edges.back().lanesForward = 3;
            g.edges.back().lanesBackward = 0;
        }
        const LaneModel m = buildLaneModel(g, CityParams());
        ASSERT_EQ(m.junctions.size(), 1u);
        Connections c = connections(m);
        size_t lanesIn = 0, lanesOut = 0;
        for (uint32_t e : m.junctions[0].arms) {
            for (int k = 1; k <= lanesToward(m, g, e, 0); ++k, ++lanesIn)
                EXPECT_TRUE(c.in[e].count(k)) << "variant " << variant << ": edge " << e << " incoming lane " << k;
            for (int k = 1; k <= lanesAway(m, g, e, 0); ++k, ++lanesOut)
                EXPECT_TRUE(c.out[e].count(k)) << "variant " << variant << ": edge " << e << " outgoing lane " << k;
        }
        EXPECT_EQ(lanesOut, 5u);  // east 3, west 1, south 1 (the fourth arm only arrives)
        EXPECT_EQ(m.unlinkedLanes, 0u);
        EXPECT_EQ(m.unfedLanes, 0u);
        // Every added turn is a proper link road: tangent at both ends, lanes clear of the centre of curvature.
        for (const LinkRoad& r : m.links) {
            if (r.arcLength <= 0) continue;
            const double R = 1.0 / std::abs(r.curvature);
            for (double s = 0; s <= r.length(); s += 0.25) {
                if (r.curvature > 0) EXPECT_LT(r.leftBorder(s), R - kCurvatureMargin + 1e-9);
                else EXPECT_GT(r.rightBorder(s), -R + kCurvatureMargin - 1e-9);
            }
        }
    }
}

// Where a street's lane count changes at a degree-2 node (2 -> 4 lanes
// straight on, 4 -> 2 lanes at a 30 degree bend), the node is a through
// junction: no transition road, every full-width lane in and out has a
// connecting road of full width, no signals, stop lines or crossings; where
// the counts agree the node keeps its transition.
TEST(Lanes, LaneCountChangesAtThroughJunctions) {
    const double bend = 30.0 * 3.14159265358979323846 / 180;
    StreetGraph g;
    g.nodes = {{0, 0},
               {100, 0},
               {200, 0},
               {200 + 100 * std::cos(bend), 100 * std::sin(bend)},
               {200 + 200 * std::cos(bend), 200 * std::sin(bend)}};
    g.edges = {{0, 1, RoadClass::Local, 7.0f, 2},  // a local arm: signs if it were a junction
               {1, 2, RoadClass::Arterial, 14.0f, 4},
               {2, 3, RoadClass::Arterial, 7.0f, 2},
               {3, 4, RoadClass::Arterial, 7.0f, 2}};
    CityParams p;
    p.sidewalk_m = 2.5;
    const LaneModel m = buildLaneModel(g, p);
    ASSERT_EQ(m.junctions.size(), 2u);
    Connections c = connections(m);
    for (const Junction& J : m.junctions) {
        EXPECT_TRUE(J.through);
        EXPECT_EQ(J.arms.size(), 2u);
        for (uint32_t e : J.arms) {
            for (int k = 1; k <= lanesToward(m, g, e, J.node); ++k)
                EXPECT_TRUE(c.in[e].count(k)) << "node " << J.node << " edge " << e << " incoming lane " << k;
            for (int k = 1; k <= lanesAway(m, g, e, J.node); ++k)
                EXPECT_TRUE(c.out[e].count(k)) << "node " << J.node << " edge " << e << " outgoing lane " << k;
        }
    }
    EXPECT_EQ(m.nodeJunction[1], 0);
    EXPECT_EQ(m.nodeJunction[2], 1);
    EXPECT_EQ(m.nodeJunction[3], -1);  // 2 -> 2 lanes: a transition
    size_t transitions = 0;
    for (const LinkRoad& r : m.links) {
        if (r.junction >= 0) continue;
        ++transitions;
        EXPECT_EQ(r.node, 3u);
    }
    EXPECT_EQ(transitions, 1u);
    EXPECT_TRUE(m.signals.empty());
    EXPECT_EQ(m.unlinkedLanes, 0u);
    EXPECT_EQ(m.unfedLanes, 0u);
    double s0 = 0, s1 = 0;
    EXPECT_FALSE(stopLine(m.edges[1], false));
    EXPECT_FALSE(stopLine(m.edges[1], true));
    EXPECT_FALSE(crossingBand(m.edges[1], false, s0, s1));
    EXPECT_FALSE(crossingBand(m.edges[1], true, s0, s1));
    EXPECT_EQ(m.edges[1].junctionA, 0);
    EXPECT_EQ(m.edges[1].junctionB, 1);
}

// Arms meeting at acute angles are cut back until their surfaces share no
// area outside the junction (Boost.Geometry intersection of the trimmed
// rectangles); at a right angle the junction radius alone keeps them apart.
TEST(Lanes, AcuteArmsShareNoSurface) {
    for (double deg : {12.0, 20.0, 30.0, 45.0, 90.0}) {
        CityParams p;
        p.sidewalk_m = 2.5;
        const LaneModel m = buildLaneModel(fork(deg * 3.14159265358979323846 / 180), p);
        ASSERT_EQ(m.junctions.size(), 1u);
        EXPECT_EQ(m.overlappingArms, 0u) << deg;
        for (size_t a = 0; a < 3; ++a)
            for (size_t b = a + 1; b < 3; ++b)
                EXPECT_LT(sharedArea(streetSurface(m.edges[a]), streetSurface(m.edges[b])), 1e-6)
                    << deg << " deg, edges " << a << ", " << b;
        // No turn crosses the third arm: its driving lanes (sampled) share no area with it.
        for (const LinkRoad& r : m.links) {
            for (size_t e = 0; e < 3; ++e) {
                if (e == r.in || e == r.out) continue;
                const EdgeLanes& L = m.edges[e];
                const glm::dvec2 n = L.normal();
                const BgPolygon carriageway = bgPolygon({L.start - n * L.halfWidth(), L.end - n * L.halfWidth(),
                                                         L.end + n * L.halfWidth(), L.start + n * L.halfWidth()});
                for (double s = 0; s + 0.25 <= r.length(); s += 0.25) {
                    auto corner = [&](double u, bool left) {
                        const double h = r.heading(u);
                        return r.point(u) +
                               glm::dvec2(-std::sin(h), std::cos(h)) * (left ? r.leftBorder(u) : r.rightBorder(u));
                    };
                    const BgPolygon piece =
                        bgPolygon({corner(s, false), corner(s + 0.25, false), corner(s + 0.25, true), corner(s, true)});
                    EXPECT_LT(sharedArea(piece, carriageway), 1e-3) << deg << " deg, link " << r.in << "->" << r.out;
                }
            }
        }
    }
}

// A lane that no turn can take (the only other arm is a hairpin away) is
// counted, not hidden.
TEST(Lanes, LanesNoTurnCanConnectAreCounted) {
    StreetGraph g;
    // Node 0 with a two-way arm to the west and two one-way arms leaving it:
    // one east, one back toward the west (5 degrees off the west arm). The
    // west arm's lane toward the junction goes straight on east.
    g.nodes = {{0, 0}, {-100, 0}, {100, 5}, {-100, 8}};
    g.edges = {{1, 0, RoadClass::Local, 7.0f, 2}, {0, 2, RoadClass::Local, 3.5f, 1}, {0, 3, RoadClass::Local, 3.5f, 1}};
    g.edges[1].lanesForward = 1, g.edges[1].lanesBackward = 0;
    g.edges[2].lanesForward = 1, g.edges[2].lanesBackward = 0;
    const LaneModel m = buildLaneModel(g, CityParams());
    ASSERT_EQ(m.junctions.size(), 1u);
    // Edge 2 leaves almost back along the west arm (a turn of about 175 degrees
    // from the west arm's traffic): no turn can feed it; the west arm's
    // outgoing lane can be fed from nothing either (the other arms only leave).
    EXPECT_EQ(m.unfedLanes, 2u);
    EXPECT_EQ(m.unlinkedLanes, 0u);
}

// Every lane centre of a junction turn keeps the turning radius of the
// lower class of its arms, |1/k - t| on the arc with t the lane centre's
// offset (right turns at a local plus with no sidewalk had 1.9 m).

namespace {

// Driving-lane outline of a link road as quadrilaterals 0.25 m long.
std::vector<BgPolygon> linkPieces(const LinkRoad& r) {
    std::vector<BgPolygon> out;
    auto corner = [&](double u, bool left) {
        const double h = r.heading(u);
        double t = r.laneOffset(u);
        for (const LinkRoad::Lane& l : left ? r.left : r.right)
            t += (l.sidewalk ? 0.0 : r.width(l, u)) * (left ? 1.0 : -1.0);
        return r.point(u) + glm::dvec2(-std::sin(h), std::cos(h)) * t;
    };
    const int n = std::max(1, int(std::ceil(r.length() / 0.25)));
    for (int i = 0; i < n; ++i) {
        const double s0 = r.length() * i / n, s1 = r.length() * (i + 1) / n;
        out.push_back(bgPolygon({corner(s0, false), corner(s1, false), corner(s1, true), corner(s0, true)}));
    }
    return out;
}

}  // namespace

// Three junctions of local streets joined by edges of 17 and 18 m, shorter
// than the trims both their ends want (a cluster of the default city): the
// short edges are joined into the junction, so that no road surface shares
// driving-lane area with another outside a common junction (Boost.Geometry
// on the model's outlines: street carriageways and connecting roads sampled
// every 0.25 m), and every lane entering or leaving the joined junction
// still has a connecting road, counted from the link roads.
TEST(Lanes, JunctionsCloserThanTheirFootprintsAreJoined) {
    StreetGraph g;
    g.nodes = {{-5.606, 16.073},   {0, 0},
               {15.748, 8.890},    {-100.995, 24.901},
               {-90.740, -51.226}, {-42.332, 121.376},
               {20.088, -59.565},  {22.558, 94.010},
               {73.104, 41.270}};
    const std::pair<uint32_t, uint32_t> ends[] = {{3, 0}, {4, 1}, {5, 0}, {0, 1}, {1, 2}, {1, 7}, {2, 6}, {2, 8}};
    for (const auto& [a, b] : ends) g.edges.push_back({a, b, RoadClass::Local, 7.5f, 2});
    CityParams p;
    p.sidewalk_m = 3.0;
    const LaneModel m = buildLaneModel(g, p);
    EXPECT_GT(m.joinedEdges, 0u);
    EXPECT_EQ(m.crossingTurnsKept, 0u);
    // Surfaces: street roads as carriageway rectangles, link roads as pieces.
    struct Surface {
        int junction;      // link road: its junction; street road: -1
        uint32_t in, out;  // link road: the street roads it joins; street road: itself twice
        std::vector<BgPolygon> pieces;
    };
    std::vector<Surface> roads;
    for (uint32_t e = 0; e < m.edges.size(); ++e) {
        const EdgeLanes& L = m.edges[e];
        if (!L.valid) continue;
        const glm::dvec2 n = L.normal() * L.halfWidth();
        roads.push_back({-1, e, e, {bgPolygon({L.start - n, L.end - n, L.end + n, L.start + n})}});
    }
    for (const LinkRoad& r : m.links) roads.push_back({r.junction, r.in, r.out, linkPieces(r)});
    size_t pairs = 0;
    for (size_t x = 0; x < roads.size(); ++x)
        for (size_t y = x + 1; y < roads.size(); ++y) {
            const Surface &a = roads[x], &b = roads[y];
            if (a.junction >= 0 && a.junction == b.junction) continue;  // inside their common junction
            if (a.junction < 0 && b.junction < 0) continue;             // street roads: AcuteArmsShareNoSurface
            const Surface& street = a.junction < 0 ? a : b;
            const Surface& link = a.junction < 0 ? b : a;
            if (street.junction < 0 && (street.in == link.in || street.in == link.out)) continue;  // its own ends
            double shared = 0;
            for (const BgPolygon& p : a.pieces)
                for (const BgPolygon& q : b.pieces) shared += sharedArea(p, q);
            ++pairs;
            EXPECT_LT(shared, 1e-3) << "road pair " << x << ", " << y;
        }
    EXPECT_GT(pairs, 0u);
    // Every driving lane entering or leaving a junction has a connecting road.
    for (size_t j = 0; j < m.junctions.size(); ++j)
        for (uint32_t e : m.junctions[j].arms) {
            const EdgeLanes& L = m.edges[e];
            const bool atB = L.junctionB == int(j);
            std::set<int> in, out;
            for (const LinkRoad& r : m.links) {
                if (r.junction != int(j)) continue;
                for (const LinkRoad::Lane& l : r.right) {
                    if (r.in == e && r.inEnd == atB && l.from && l.w0 > 0) in.insert(l.from);
                    if (r.out == e && r.outStart == !atB && l.from && l.to && l.w0 > 0 && l.w1 > 0) out.insert(l.to);
                }
            }
            for (int k = 1; k <= (atB ? L.right : L.left); ++k)
                EXPECT_TRUE(in.count(atB ? -k : k)) << "junction " << j << " edge " << e << " incoming lane " << k;
            for (int k = 1; k <= (atB ? L.left : L.right); ++k)
                EXPECT_TRUE(out.count(atB ? k : -k)) << "junction " << j << " edge " << e << " outgoing lane " << k;
        }
}

// A highway junction 33 m from the next one (a junction of the generated
// city, seed 11): a lane whose only turn cuts the corner across a local arm
// of its own junction gets that arm cut back past the turn, so no connecting
// road shares driving-lane area with a street road other than its two
// (Boost.Geometry on the model's outlines).
TEST(Lanes, ArmsAreCutBackPastTheTurnsThatMustCrossThem) {
    StreetGraph g;
    g.nodes = {
        {0, 0},           {31.930, 9.302}, {-61.939, 20.345}, {-47.597, -13.866}, {-13.571, 59.568}, {57.612, -80.648},
        {111.456, 32.469}};
    g.edges = {{2, 0, RoadClass::Local, 7.5f, 2}, {3, 0, RoadClass::Highway, 20.0f, 6},
               {4, 0, RoadClass::Local, 7.5f, 2}, {0, 1, RoadClass::Highway, 20.0f, 6},
               {1, 5, RoadClass::Local, 7.5f, 2}, {1, 6, RoadClass::Highway, 20.0f, 6}};
    for (double sidewalk : {0.0, 3.0}) {
        CityParams p;
        p.sidewalk_m = sidewalk;
        const LaneModel m = buildLaneModel(g, p);
        EXPECT_EQ(m.unlinkedLanes + m.unfedLanes, 0u) << sidewalk;
        size_t links = 0;
        for (const LinkRoad& r : m.links) {
            if (r.junction < 0) continue;
            ++links;
            const std::vector<BgPolygon> pieces = linkPieces(r);
            for (uint32_t e = 0; e < m.edges.size(); ++e) {
                const EdgeLanes& L = m.edges[e];
                if (!L.valid || e == r.in || e == r.out) continue;
                const glm::dvec2 n = L.normal() * L.halfWidth();
                const BgPolygon street = bgPolygon({L.start - n, L.end - n, L.end + n, L.start + n});
                double shared = 0;
                for (const BgPolygon& q : pieces) shared += sharedArea(q, street);
                EXPECT_LT(shared, 1e-2) << "sidewalk " << sidewalk << ": turn " << r.in << "->" << r.out
                                        << " of junction " << r.junction << " crosses edge " << e;
            }
        }
        EXPECT_GT(links, 0u);
    }
}
