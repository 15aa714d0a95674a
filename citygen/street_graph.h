// StreetGraph: the planar street network of a city.
//
// Contract: node positions are double metres in the city frame (centre of the
// city at (0,0), x east, y north). After generation or import the graph is
// planar: edges meet only at shared nodes, no edge is shorter than the
// configured minimum, no duplicate edges, no self loops, all coordinates
// finite. Edge ids and node ids are stable for a given (params, seed).
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "citygen/geodesy.h"
#include "foundation/status.h"

namespace vista {

enum class RoadClass : uint8_t { Highway = 0, Arterial = 1, Local = 2 };
const char* roadClassName(RoadClass c);
// Default carriageway width (metres) and lanes per class.
double roadWidth(RoadClass c);
int roadLanes(RoadClass c);

struct StreetEdge {
    uint32_t a = 0, b = 0;  // node indices
    RoadClass cls = RoadClass::Local;
    float width = 8.0f;  // carriageway width, metres (without sidewalks)
    uint8_t lanes = 2;
    // Driving lanes per travel direction: forward = a -> b, backward = b -> a; -1 = derived from
    // `lanes` (forward ceil(n/2), backward floor(n/2), n = max(lanes, 2)). A one-way edge has 0 backward (or 0
    // forward).
    int8_t lanesForward = -1, lanesBackward = -1;
    float maxspeedKmh = 0.0f;  // 0 = the class default
    std::string turnForward{},
        turnBackward{};  // OSM turn:lanes value for that direction ("" = none), lanes listed left to right as OSM does
};

struct StreetGraph {
    std::vector<glm::dvec2> nodes;
    std::vector<StreetEdge> edges;

    double edgeLength(size_t e) const { return glm::length(nodes[edges[e].b] - nodes[edges[e].a]); }
    // Degree of every node.
    std::vector<int> degrees() const;
};

// Checks the invariants above; returns a message naming the first violation.
// `minSegment` is the shortest allowed edge length.
Status checkPlanarGraph(const StreetGraph& g, double minSegment);

// Serialisation used inside the city file and by tools (compact JSON:
// {"nodes":[[x,y],...],"edges":[[a,b,cls,width,lanes],...]}). An edge whose
// lane directions, speed limit or turn lanes differ from the defaults (an OSM
// import) has a sixth element, an object holding only those that differ:
// "forward" / "backward" (lanesForward / lanesBackward, 0..8), "maxspeed"
// (km/h, [5, 250]), "turn_forward" / "turn_backward" (turn:lanes values as
// osm_road_tags.h accepts them, listing exactly that direction's lanes). A
// generated city has none, so its JSON is the five-element form. The reader
// refuses other keys, values out of range, and an edge without driving lanes.
std::string streetGraphToJson(const StreetGraph& g);
Result<StreetGraph> streetGraphFromJson(const std::string& text);

// GeoJSON FeatureCollection, one feature per edge; properties: id (edge
// index), class, width, lanes. Without a geo reference: LineStrings in world
// metres (the city frame offset by (originX, originY)). With one (a city
// imported from OSM): WGS84 [lon, lat] in degrees as RFC 7946 requires, of
// the city-frame positions (the origin only places the city in the rendering
// world and is not applied); an edge crossing the antimeridian becomes a
// MultiLineString cut at +-180 degrees (RFC 7946, 3.1.9).
std::string streetGraphToGeoJson(const StreetGraph& g, double originX, double originY,
                                 const std::optional<GeoReference>& geo = std::nullopt);

}  // namespace vista
