// LaneRoute: a car's route through the lane model (citygen/lanes.h): which
// lane follows which, a seeded walk over them, the lane centre line the car
// steers along, and the OpenDRIVE position (road, lane, s, t) of a point on
// the route, so a drive can be replayed on the .xodr that `vista gen --xodr`
// writes from the same lane model.
//
// Contract (metres, city frame; lane ids and s as in OpenDRIVE):
// - Lane graph: one node per driving lane of every valid street road and of
//   every link road (sidewalk lanes are not driven). Right-hand traffic (the
//   lane model's rule): right lanes (id < 0) are driven toward +s, left lanes
//   toward -s, and a lane is followed by the lanes its lane links name where
//   its traffic leaves the road (a street road's end: the junction's
//   connecting roads that start from that lane, or the transition at that
//   node; a link road's end: the street road lane it enters).
//   Left-hand traffic drives every lane against that direction (a car
//   travelling a -> b uses the left lanes): the successors are the right-hand
//   traffic predecessors. The lane model's turn assignment (right turns from
//   the outermost lane, left turns from the innermost) is then mirrored, as
//   left-hand traffic has it; lanes are not mirrored across the road, so the
//   lanes of a one-way street are driven against its one-way direction.
// - Successors whose lane narrows to width 0 where the car would leave it
//   (a taper) are dropped when another successor exists. A street lane left
//   without successors is a dead end: the route U-turns there into the
//   innermost lane of the opposite direction: a semicircle of radius R
//   between the two lane centres whose apex lies kUTurnMargin before the
//   road end, on roads at least 2 R + kUTurnMargin long (a straight run-in as
//   long as the turn's radius); on a shorter road the lane is left without a
//   successor. Only the largest strongly connected part of the lane graph
//   is driven, so the walk never enters a lane it cannot leave (a lane that
//   ends in a taper, a one-way dead end, a dead end too short to turn in).
// - Choice of lanes: Rng(seed, 0, Stream::Paths). The route starts at the
//   beginning of a random street lane of that part. Tour (the default): at
//   the end of each lane it takes the successor on the shortest path to a
//   goal lane, goals drawn far from where the route has been (tour.h; a
//   lane's position is its road's midpoint, an arc's cost the lane's length).
//   Wander: a successor is drawn with weight 3 when its link road turns less
//   than 0.5 rad, else 1, times 0.05 when the street lane after it is a dead
//   end.
// - Centre line: a polyline through the centres of the route's lanes
//   (laneOffset + the inner lanes' widths + half the lane's width), vertices
//   at most 1 m apart on street roads and 0.25 m on link roads and U-turns
//   (and at least 2 cm, so that the rounding where pieces meet makes no
//   curvature spike), extended on demand, with arc length, heading (radians clockwise from
//   north, as Camera) and curvature (dheading/ds) per vertex.
// - Road ids follow the OpenDRIVE writer (opendrive.h): street road e has id
//   e, link road k has id edges + junctions + k.
// Deterministic; not thread-safe (extends itself); the LaneModel must outlive it.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "citygen/lanes.h"
#include "foundation/rng.h"
#include "foundation/status.h"
#include "runtime/scene/tour.h"

namespace vista {

// How a route chooses its turns: toward far goals (a drive that keeps going)
// or by a seeded random walk that prefers going straight on.
enum class RouteStyle { Tour, Wander };

constexpr double kUTurnMargin = 0.5;  // metres between a U-turn's apex and the road end

// A point on an OpenDRIVE road: road id, lane id, s along the road's reference
// line and the lateral offset (left of the reference line positive, whatever
// the direction of travel) of the point from the lane's centre at s.
struct LanePosition {
    uint64_t road = 0;
    int lane = 0;
    double s = 0;
    double tOffset = 0;
};

// The OpenDRIVE road id of street road e / link road k (see the contract).
uint64_t streetRoadId(const LaneModel& m, uint32_t e);
uint64_t linkRoadId(const LaneModel& m, uint32_t k);

// Lateral offset (left positive) of the centre of lane `id` of a link road at
// s (0 for an id the road does not have).
double linkLaneCentre(const LinkRoad& r, int id, double s);
// Width of lane `id` of a link road at s (0 for an id the road does not have).
double linkLaneWidth(const LinkRoad& r, int id, double s);
// Orthogonal projection of p onto a link road's reference line: s in [0,
// length] and the signed distance t (left positive), so that p = point(s) +
// t * left normal at s. False when no foot lies on the road (p before its
// start or past its end; s is then the nearest end's).
bool projectOnLinkRoad(const LinkRoad& r, const glm::dvec2& p, double& s, double& t);

class LaneRoute {
public:
    // Errors: no lane of the model can be driven in a loop (no valid edge,
    // only one-way dead ends).
    static Result<LaneRoute> create(const LaneModel& model, uint64_t seed, bool leftHandTraffic,
                                    RouteStyle style = RouteStyle::Tour);

    // Extends the centre line to at least arc length s.
    void ensure(double s);
    size_t vertices() const { return _pts.size(); }
    size_t segments() const { return _pts.size() - 1; }
    const glm::dvec2& point(size_t i) const { return _pts[i]; }
    double cum(size_t i) const { return _cum[i]; }
    // Heading of segment i (vertex i to i + 1) and curvature at vertex i.
    double segHeading(size_t i) const { return _segHeading[i]; }
    double curvature(size_t i) const { return i < _curv.size() ? _curv[i] : 0.0; }
    // The OpenDRIVE position of p, a point near segment `seg` of the route
    // (the car there): the lane of the route piece that segment belongs to,
    // the neighbouring piece's when p lies beyond the road's end; on a
    // U-turn, the lane of the street road that holds p.
    LanePosition position(const glm::dvec2& p, size_t seg) const;
    // Goals the tour has drawn so far (0 for a wander).
    size_t legs() const { return _tour ? _tour->legs() : 0; }

private:
    struct Node {
        bool link = false;
        uint32_t index = 0;  // street edge or link road
        int lane = 0;
        bool forward = true;  // driven toward +s
        std::vector<uint32_t> next;
    };
    struct Piece {
        uint32_t node = 0;
        bool uturn = false;
        int laneTo = 0;         // U-turn: the lane it enters
        double s0 = 0, s1 = 0;  // s range driven (s0 where the car enters)
    };
    LaneRoute(const LaneModel& m, uint64_t seed) : _m(m), _rng(seed, 0, Stream::Paths) {}
    void buildGraph(bool lht);
    void keepLargestStronglyConnected();
    void makeTour();
    uint32_t pick(uint32_t node);
    bool deadEnd(uint32_t node) const;
    double laneStart(const Node& n) const;
    double laneEnd(const Node& n) const;
    double uturnCentre(uint32_t node) const;
    void extend();
    void emitPiece(const Piece& p);
    void addVertex(const glm::dvec2& q, size_t piece);
    LanePosition onPiece(const Piece& p, const glm::dvec2& q, bool* inside) const;

    const LaneModel& _m;
    Rng _rng;
    std::vector<Node> _nodes;
    std::vector<uint32_t> _uturn;  // per node: U-turn target + 1 (0 = none)
    std::vector<uint32_t> _seq;    // lane nodes of the route, in order
    size_t _emitted = 0;           // nodes of _seq whose pieces are emitted
    std::vector<Piece> _pieces;
    std::vector<glm::dvec2> _pts;
    std::vector<double> _cum, _segHeading, _curv;
    std::vector<uint32_t> _segPiece;  // per segment: the piece it belongs to
    std::shared_ptr<Tour> _tour;      // RouteStyle::Tour (shared: a LaneRoute is returned by value)
};

}  // namespace vista
