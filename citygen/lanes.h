// LaneModel: the lanes of every street edge and the junctions of the street
// graph, the one description that both the OpenDRIVE writer (opendrive.h) and
// the lane markings of the road meshes (surfaces.cpp) read, so the lanes a
// simulator loads and the lines drawn on the road agree.
//
// Contract (all lengths metres, positions city frame, right-hand traffic):
// - Per edge e (index = edge index): the reference line runs from node a to
//   node b along the straight centre line, trimmed at each end that is a
//   junction (node of degree >= 3) by that junction's radius (clamped so that
//   at least kMinRoadLength of the edge remains, both trims shrunk in
//   proportion). Untrimmed ends (degree 1 or 2) start/end exactly at the node.
// - Driving lanes: `right` lanes drive a -> b (right of the reference line),
//   `left` lanes drive b -> a. right = ceil(n/2), left = floor(n/2) with
//   n = max(edge.lanes, 2) (the graph has no one-way flag, so a 1-lane edge
//   gets one lane per direction). All driving lanes have the same width
//   laneWidth = carriageway / n, so they sum to the carriageway width the
//   road mesh uses (edge.width, or the class default for a non-finite or
//   < 0.5 m width, as surfaces.cpp does).
// - Sidewalk: width params.sidewalk_m (0 when <= 0.01, as the sidewalk mesh),
//   directly outside the carriageway, on each side that borders a block
//   (the sidewalk mesh runs along block outlines): with `blocks` given, a side
//   has a sidewalk when the point a metre past the sidewalk at the edge's
//   midpoint lies inside a block outline; without blocks, both sides.
// - Junction: one per node of degree >= 3, radius = max over its edges of
//   (half carriageway + sidewalk): the corner points of the sidewalks of
//   neighbouring streets lie inside it; its arms are the incident edges in
//   counter-clockwise angle order (angles in (-pi, pi]).
// Edges with invalid node indices, non-finite coordinates or zero length are
// kept with `valid = false` (no lanes written or drawn). Deterministic; pure.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "citygen/city.h"

namespace vista {

constexpr double kMinRoadLength = 1.0;  // shortest trimmed reference line

// Carriageway width the road mesh draws for an edge.
double carriagewayWidth(const StreetEdge& e);

struct EdgeLanes {
    bool valid = false;
    glm::dvec2 start{0.0}, end{0.0};  // trimmed reference line (start near node a)
    glm::dvec2 dir{1.0, 0.0};         // unit a -> b
    double trimA = 0, trimB = 0;      // distance cut off at node a / node b
    double length = 0;                // |end - start|
    int right = 1, left = 1;          // driving lanes a->b / b->a
    double laneWidth = 3.5;
    double sidewalk = 0;              // sidewalk width, 0 = none
    bool walkLeft = true, walkRight = true;  // sidewalk present on that side (when sidewalk > 0)
    // Lateral position of the centre lane (lane 0) relative to the street's
    // centre line (left positive): (right - left) / 2 x laneWidth, so the
    // lanes span exactly the carriageway [-w/2, w/2] for odd lane counts too
    // (OpenDRIVE <laneOffset>).
    double offset = 0;
    int junctionA = -1, junctionB = -1;  // index into LaneModel::junctions, -1 = none
    glm::dvec2 normal() const { return {-dir.y, dir.x}; }  // left of a -> b
    bool hasWalk(int side) const { return sidewalk > 0 && (side > 0 ? walkLeft : walkRight); }
    double halfWidth() const { return 0.5 * laneWidth * (right + left); }
    // Lateral offset (left positive) of the centre of driving lane `id`
    // (OpenDRIVE numbering: -1..-right to the right, 1..left to the left).
    double laneCentre(int id) const { return offset + (id < 0 ? (id + 0.5) * laneWidth : (id - 0.5) * laneWidth); }
};

struct Junction {
    uint32_t node = 0;
    double radius = 0;
    std::vector<uint32_t> arms;  // incident edge indices, counter-clockwise by angle
};

struct LaneModel {
    std::vector<EdgeLanes> edges;      // one per street edge
    std::vector<Junction> junctions;   // nodes of degree >= 3, by node index
    std::vector<int> nodeJunction;     // per node: junction index or -1
    std::vector<int> degree;           // per node
};

LaneModel buildLaneModel(const StreetGraph& g, const CityParams& params, const std::vector<Block>* blocks = nullptr);

}  // namespace vista
