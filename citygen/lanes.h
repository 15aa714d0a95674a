// LaneModel: the lanes of every street edge, the junctions of the street
// graph and the roads that join street roads (link roads), the one
// description that the OpenDRIVE writer (opendrive.h), the road meshes and
// their lane markings (surfaces.cpp) read, so the lanes a simulator loads and
// the road drawn agree.
//
// Contract (all lengths metres, positions city frame; lane ids and sides as
// in OpenDRIVE: right lanes -1..-n drive along the reference line in
// right-hand traffic):
// - Per edge e (index = edge index): the reference line runs from node a to
//   node b along the straight centre line, trimmed at each end that is a
//   junction (node of degree >= 3) by that junction's radius and at each
//   degree-2 node by the length its transition needs (see below); when less
//   than kMinRoadLength of the edge would remain, an edge between a junction
//   and a transition gives the junction end its trim and the transition end
//   the rest, but at least the least its transition needs (its fillet clear
//   of folding, the two edges' surfaces apart; the junction end gets what
//   that leaves when the edge is shorter still); an edge too short for that
//   least, and every other edge, shrinks both trims in proportion. Dead
//   ends (degree 1) start/end exactly at the node.
// - Driving lanes: `right` lanes drive a -> b (right of the reference line),
//   `left` lanes drive b -> a: the edge's lanesForward/lanesBackward when set
//   (OSM lanes:forward/backward, oneway), else right = ceil(n/2),
//   left = floor(n/2) with n = max(edge.lanes, 2). All driving lanes of an
//   edge have the same width laneWidth = carriageway / (right + left), so they
//   sum to the carriageway width the road mesh uses (edge.width, or the class
//   default for a non-finite or < 0.5 m width).
// - Speed limit: the edge's maxspeedKmh when set, else the class default
//   (classSpeedKmh).
// - Sidewalk: width params.sidewalk_m (0 when <= 0.01, as the sidewalk mesh),
//   directly outside the carriageway, on each side that borders a block
//   (the sidewalk mesh runs along block outlines): with `blocks` given, a side
//   has a sidewalk when the point a metre past the sidewalk at the edge's
//   midpoint lies inside a block outline; without blocks, both sides.
// - Junction: one per node of degree >= 3, and one per degree-2 node where a
//   lane appears: more lanes leave it than arrive in a direction of travel
//   that has lanes arriving, every direction with lanes leaving has lanes
//   arriving, and the corner is within kMaxTurn (a through junction,
//   Junction::through); a node whose through junction has a turn that folds
//   or misses its turning radius (below) keeps its transition instead (the
//   model is built again, at most three rounds). The lane that appears is then fed by a one-lane turn
//   of full width (below), so that every lane has a lane before it, as SUMO
//   netconvert asks (a lane tapering in inside a transition has none: ASAM's
//   road.lane.link.zero_width_at_start wants no predecessor on a lane of
//   width 0 at its start). Through junctions get no signals, stop lines or
//   crossings. Lanes that only end at a degree-2 node, and lanes that appear
//   where a through junction's turns would not fit or where one direction
//   has lanes leaving but none arriving (a two-way street going on one-way),
//   change width inside its transition. Arms are the incident edges in
//   counter-clockwise angle order (angles in (-pi, pi]). Junction joining:
//   two junction nodes whose connecting edge is shorter than their two
//   footprints need (the trims of both ends plus kMinRoadLength) form one
//   junction, as netconvert joins junctions: the joined edges carry no lanes
//   (valid = false), the junction's arms are the other edges of all its nodes
//   (each measured from its own node), and its turns run from arm to arm
//   across the joined area (line, arc and line through the point where the
//   two arms' lines meet; a pair of arms whose lines do not meet ahead of
//   both trimmed ends gets no turn). Nodes are not joined where fewer than
//   three arms would remain. Each arm's radius is that of its own node: the
//   largest of (half carriageway + sidewalk) over the node's arms and of the
//   trims the node's own turns need (below); the junction's radius is the
//   largest over its nodes. Radius = the largest
//   of (half carriageway + sidewalk) over its arms and of the trims its turns
//   need so that no lane border of a turn comes within kCurvatureMargin of
//   the turn's centre of curvature and every lane centre keeps the turn's
//   minimum turning radius (turns sharper than kMaxTurn are not built).
//   Junction footprint: each arm is trimmed by the radius, and further where
//   two arms' surfaces (carriageway and sidewalks, straight along the edge)
//   would still share area beyond it (acute arms): both arms of such a pair
//   are cut back by the same length, the shortest that leaves the two
//   surfaces apart, plus kArmClearance. Where an edge is too short for its
//   trims (shrunk, see above) the pair may still overlap: counted in
//   overlappingArms.
// - Turning radius: the lane centres of a junction turn stay at least
//   minTurnRadius() of the lower class of its two arms from the turn's centre
//   of curvature (Local 5 m, a car's kerb-to-kerb turning radius, Arterial
//   8 m, Highway 12 m); a turn whose arms could not be trimmed enough for that
//   (short edges) is not built (counted in tightTurns): its lanes join the
//   nearest turn of their arm that keeps the radius with them, and a lane no
//   such turn can take keeps its own turn below the radius (counted in
//   tightTurnsKept) rather than being left without a way on. Transitions at
//   degree-2 nodes ask for the same trims but are kept with whatever radius
//   the edges allow (their borders keep kCurvatureMargin, else the corner is
//   left unlinked and counted in sharpCorners). The two edges at a degree-2
//   node are cut back like acute junction arms, so that their surfaces part
//   whether a transition joins them or not.
// - No crossing: a junction turn whose driving lanes would share area with a
//   street road other than the two it joins, or with a turn of another
//   junction (the later of the two), is not built (counted in
//   crossingTurns), unless it is the only turn of one of its lanes (kept,
//   counted in crossingTurnsKept): road surfaces share area only inside
//   their junction. The one-lane turns that connect leftover lanes (below)
//   avoid crossings where another exit serves. Where a kept crossing turn
//   crosses an arm of its own junction, that arm is cut back past the turn
//   (kArmClearance beyond the turn's farthest point within the arm's
//   carriageway) and the model is built again; where it crosses a road or
//   turn of a junction that an edge too short for its trims joins to its
//   own, the two junctions are joined (above) and the model is built again
//   (at most four such rounds). The same joining applies where a junction
//   keeps a turn below its radius or leaves a lane without a connection and
//   one of its arms is an edge shrunk to kMinRoadLength between it and another
//   junction (a small roundabout mapped as a ring of short ways). Both kept
//   counts come from clusters of junctions joined by edges shorter than
//   their trims.
// - Link roads (LinkRoad): every junction has one per allowed turn (ordered
//   pair of distinct arms with lanes to give and take, |turn| <= kMaxTurn);
//   every other degree-2 node has one transition road joining its two edges, unless
//   the corner is too sharp for the lanes to turn inside the edges (counted
//   in sharpCorners; both ends are then dead ends). A link road's reference
//   line is a line, a circular arc and a line, tangent to both street roads
//   (G1), starting at the incoming road's trimmed end and ending at the
//   outgoing road's trimmed start. At junctions each arm is trimmed
//   kCrossingLeadIn further than its turns need, and a turn's lines are at
//   least kCrossingLeadIn long where the trims allow it with the turning
//   radius kept (else it turns as soon as the trims let it): the crosswalk at
//   the arm's end lies across the straight part, so a vehicle crosses it
//   heading along the arm, not turning (a turning vehicle's body sweeps
//   beyond its path, back over a crosswalk it has passed). Its lane widths and lane offset run from
//   the values of the road it leaves to those of the road it enters along a
//   smoothstep (zero slope at both ends), so linked lane borders meet. A lane
//   that exists on one side only appears or ends with width 0 there.
// - Turning lanes at junctions (right-hand traffic): a straight exit (turn
//   within 35 degrees) takes every incoming lane (extra lanes taper in or
//   out), a right turn the outermost lane into the outermost lane, a left
//   turn the innermost into the innermost; an incoming lane that no exit
//   would take joins the nearest turn (and tapers out where the exit has
//   fewer lanes).
// - Every full-width driving lane at a junction has a connection: an
//   incoming lane that no placed turn takes (its turn was dropped, or its
//   arm's turns leave it out) gets a one-lane turn of its own into the exit
//   its arm already turns into (else the straightest one within kMaxTurn),
//   preferably into an outgoing lane nobody feeds; an outgoing lane that no
//   incoming lane feeds gets a one-lane turn from the approach that already
//   turns into its arm (else the straightest). Such a turn is one that keeps
//   its turning radius and crosses no other road where there is one, else one
//   that crosses a road (crossingTurnsKept), else one below the radius
//   (tightTurnsKept). A lane tapering in inside a
//   turn (width 0 where it starts, no predecessor) does not count as fed.
//   What no turn can connect is counted (unlinkedLanes, unfedLanes).
// Edges with invalid node indices, non-finite coordinates or zero length are
// kept with `valid = false` (no lanes written or drawn). Deterministic; pure.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "citygen/city.h"

namespace vista {

constexpr double kMinRoadLength = 1.0;          // shortest trimmed reference line
constexpr double kMaxTurn = 2.356194490192345;  // 135 degrees: sharper turns get no link road
constexpr double kCurvatureMargin = 0.3;        // lane borders stay this far from a turn's centre of curvature
constexpr double kTaperLength = 12.0;           // transition length where lane counts or widths change
constexpr double kMinLinkLength = 1.0;          // shortest transition (straight on, same lanes)
constexpr double kArmClearance = 0.05;          // gap left between the surfaces of two acute arms
constexpr double kCrossingLeadIn = 5.0;  // straight start and end of a junction turn: a crosswalk's depth and a margin
// Smallest lane-centre radius of a junction turn by road class (metres);
// Local is a car's kerb-to-kerb turning radius, the floor of all classes.
constexpr double kMinTurnRadiusLocal = 5.0;
constexpr double kMinTurnRadiusArterial = 8.0;
constexpr double kMinTurnRadiusHighway = 12.0;

// Carriageway width the road mesh draws for an edge.
double carriagewayWidth(const StreetEdge& e);
// Default speed limit (km/h) of a road class.
double classSpeedKmh(RoadClass c);
// Smallest lane-centre turning radius (metres) of a road class (kMinTurnRadius*).
double minTurnRadius(RoadClass c);

struct EdgeLanes {
    bool valid = false;
    glm::dvec2 start{0.0}, end{0.0};  // trimmed reference line (start near node a)
    glm::dvec2 dir{1.0, 0.0};         // unit a -> b
    double trimA = 0, trimB = 0;      // distance cut off at node a / node b
    double length = 0;                // |end - start|
    int right = 1, left = 1;          // driving lanes a->b / b->a (either may be 0 on a one-way edge)
    double laneWidth = 3.5;
    double sidewalk = 0;                     // sidewalk width, 0 = none
    bool walkLeft = true, walkRight = true;  // sidewalk present on that side (when sidewalk > 0)
    double speedKmh = 50;                    // speed limit of the driving lanes
    // Lateral position of the centre lane (lane 0) relative to the street's
    // centre line (left positive): (right - left) / 2 x laneWidth, so the
    // lanes span exactly the carriageway [-w/2, w/2] for odd lane counts too
    // (OpenDRIVE <laneOffset>).
    double offset = 0;
    int junctionA = -1, junctionB = -1;       // index into LaneModel::junctions, -1 = none
    bool throughA = false, throughB = false;  // that junction is a through junction (Junction::through)
    int linkA = -1, linkB = -1;               // transition at a degree-2 node a / b: index into LaneModel::links
    glm::dvec2 normal() const { return {-dir.y, dir.x}; }  // left of a -> b
    bool hasWalk(int side) const { return sidewalk > 0 && (side > 0 ? walkLeft : walkRight); }
    double halfWidth() const { return 0.5 * laneWidth * (right + left); }
    // Lateral offset (left positive) of the centre of driving lane `id`
    // (OpenDRIVE numbering: -1..-right to the right, 1..left to the left).
    double laneCentre(int id) const { return offset + (id < 0 ? (id + 0.5) * laneWidth : (id - 0.5) * laneWidth); }
};

struct Junction {
    uint32_t node = 0;            // its node (the first of `nodes`)
    std::vector<uint32_t> nodes;  // the street nodes it joins (one unless joined), ascending
    double radius = 0;
    std::vector<uint32_t> arms;   // incident edge indices, counter-clockwise by angle
    std::vector<uint32_t> links;  // its link roads (indices into LaneModel::links)
    // A through junction: a degree-2 node where the lane count changes (see
    // the contract above); no signals, stop lines or crossings.
    bool through = false;
};

// A road between two street roads: a junction's connecting road (junction
// >= 0) or the transition at a degree-2 node (junction = -1, linked road to
// road). Its s runs from `in` to `out`.
struct LinkRoad {
    enum class Turn : uint8_t { Straight, Right, Left };
    struct Lane {
        double w0 = 0, w1 = 0;  // width at s = 0 and s = length (0: the lane appears / ends there)
        int from = 0, to = 0;   // lane id in `in` / `out` it links to (0: none)
        bool sidewalk = false;
    };
    int junction = -1;
    uint32_t node = 0;         // the degree-2 node, or the junction's node (Junction::node)
    uint32_t in = 0, out = 0;  // street edges
    bool inEnd = true;         // `in` meets the node with its end (b == node), else with its start
    bool outStart = true;      // `out` leaves the node with its start (a == node), else with its end
    Turn turn = Turn::Straight;
    double angle = 0;  // signed heading change in -> out (left positive), radians
    // Reference line: a line of length line0, an arc of length arcLength and
    // curvature `curvature` (1/m, left positive), a line of length line1,
    // starting at `start` with heading `hdg` (radians, city frame).
    glm::dvec2 start{0.0};
    double hdg = 0;
    double line0 = 0, arcLength = 0, curvature = 0, line1 = 0;
    double offset0 = 0, offset1 = 0;  // lane offset (centre lane) at s = 0 / length
    std::vector<Lane> right;          // right[k - 1] is lane -k (drives in -> out)
    std::vector<Lane> left;           // left[k - 1] is lane +k (drives out -> in; transitions only)
    double length() const { return line0 + arcLength + line1; }
    glm::dvec2 point(double s) const;  // reference line at s (clamped to [0, length])
    double heading(double s) const;
    // Smoothstep weight of the end values at s: 0 at s = 0, 1 at s = length.
    double blend(double s) const;
    double laneOffset(double s) const { return offset0 + (offset1 - offset0) * blend(s); }
    double width(const Lane& l, double s) const { return l.w0 + (l.w1 - l.w0) * blend(s); }
    // Lateral offsets (left positive) of the outermost right and left borders at s.
    double rightBorder(double s) const;
    double leftBorder(double s) const;
};

// A traffic light or sign at a junction end of a street road, facing the
// traffic that arrives there. Junctions where three or more arms are
// highways or arterials get traffic lights on every approach; junctions with
// at least one such arm get stop signs (4+ arms) or yield signs (3 arms) on
// their local approaches; junctions of local streets get none (priority to
// the right). The pole stands on the sidewalk (or 0.5 m past the
// carriageway without one) by the stop line, on the right of the traffic.
// The traffic lights of a junction form approach groups (one controller, one
// phase each): two approaches whose arms point in opposite directions within
// kOppositeArms share a group (pairs matched most-opposite first, each
// approach in at most one pair); every other approach is a group of its own.
// Groups are numbered 0.. per junction in the order of their first signal.
constexpr double kOppositeArms = 0.5235987755982988;  // 30 degrees
struct SignalPlacement {
    enum class Kind : uint8_t { TrafficLight, Stop, Yield };
    Kind kind = Kind::TrafficLight;
    uint32_t edge = 0;         // street road it stands on
    bool atB = true;           // at the road's end b (faces traffic a -> b) or its start a
    int junction = -1;         // index into LaneModel::junctions
    int lanes = 0;             // incoming lanes it controls: ids -1..-lanes (atB) or 1..lanes
    double s = 0, t = 0;       // road frame: s along the trimmed reference line from start, t left positive
    glm::dvec2 position{0.0};  // city frame
    glm::dvec2 facing{0.0};    // unit: toward the traffic it controls
    int group = -1;            // traffic lights: approach group within the junction (see above); else -1
};

struct LaneModel {
    std::vector<EdgeLanes> edges;     // one per street edge
    std::vector<Junction> junctions;  // nodes of degree >= 3, by node index
    std::vector<int> nodeJunction;    // per node: junction index or -1 (every node of a joined junction)
    std::vector<int> degree;          // per node
    std::vector<LinkRoad> links;      // junctions' connecting roads, then transitions, by node index
    std::vector<std::vector<uint32_t>>
        nodeLinks;                         // per node: its link roads (a joined junction's under each of its nodes)
    size_t joinedEdges = 0;                // edges inside joined junctions (no lanes)
    std::vector<SignalPlacement> signals;  // by edge, start before end
    size_t sharpCorners = 0;               // degree-2 nodes left unlinked: too sharp for the lanes
    size_t droppedTurns = 0;               // junction turns within kMaxTurn whose trims did not fit the edges
    size_t tightTurns = 0;                 // junction turns not built: lane-centre radius below the class floor
    size_t tightTurnsKept = 0;             // turns below the floor kept: the only way on for a lane
    size_t overlappingArms = 0;            // junction arm pairs whose surfaces still overlap (edges too short)
    size_t crossingTurns = 0;              // junction turns not built: they would cross another road (see above)
    size_t crossingTurnsKept = 0;          // crossing turns kept: the only way on for a lane
    // Smallest lane-centre radius bound over the built junction turns: arc
    // radius less the farthest reach of a lane centre toward its centre
    // (metres; 0 when no turn has an arc).
    double minTurnRadius = 0;
    size_t unlinkedLanes = 0;  // incoming driving lanes at a junction that no turn takes
    size_t unfedLanes = 0;     // outgoing driving lanes at a junction that no incoming lane feeds
};

LaneModel buildLaneModel(const StreetGraph& g, const CityParams& params, const std::vector<Block>* blocks = nullptr);

// Stop lines and zebra crossings at junction ends (metres): the stop line
// lies kStopSetback before the road's trimmed end, kStopDepth deep; the
// crossing lies in the junction, between kCrossingGap past the road end and
// the sidewalk width (or kCrossingDepth without sidewalks) into it, where the
// corner sidewalks of the neighbouring streets meet.
constexpr double kStopSetback = 0.5, kStopDepth = 0.4;
constexpr double kCrossingDepth = 3.0;
constexpr double kCrossingGap = 0.3;

// True when the road meets a junction at its end b (atB) or start that
// stops its traffic (a stop line there): any junction but a through junction.
inline bool stopLine(const EdgeLanes& L, bool atB) {
    return (atB ? L.junctionB : L.junctionA) >= 0 && !(atB ? L.throughB : L.throughA);
}

// The s range [s0, s1] (along the edge's trimmed reference line, from
// L.start; negative before it, beyond L.length after it) of the zebra
// crossing at the junction end of edge L at node b (atB) or a; false when
// that end has no crossing (no junction, or too short a road or band).
// The road meshes draw it and the OpenDRIVE writer declares it.
bool crossingBand(const EdgeLanes& L, bool atB, double& s0, double& s1);

}  // namespace vista
