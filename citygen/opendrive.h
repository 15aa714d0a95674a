// OpenDRIVE export: the street graph and its lane model (lanes.h) as an ASAM
// OpenDRIVE 1.6 road network (.xodr), for driving simulators (esmini, CARLA,
// SUMO netconvert). docs/formats.md "OpenDRIVE" describes the mapping.
//
// Contract:
// - One road per valid street edge (id = edge index): a single <line>
//   geometry along the trimmed reference line of the lane model, in world
//   metres (city frame + params.origin_x/origin_y); an <elevationProfile> of
//   cubic pieces (<= 10 m) through the road surface height (terrainHeight +
//   2 cm, as the road mesh) and a <lateralProfile> superelevation for the
//   cross slope of the terrain (positive = road falls to the right); one
//   laneSection: left/right driving lanes and type="sidewalk" lanes (on the
//   sides that have a sidewalk mesh) with constant <width>, road marks on the
//   centre lane and lane dividers, the speed limit on the road <type> and on
//   every driving lane; <signal>s at junction ends (traffic lights where
//   three or more arms are highways or arterials: country "OpenDRIVE", type
//   1000001; else stop signs, DE 206, at 4+ arms and yield signs, DE 205, at
//   3 arms on the local approaches of junctions with a major arm), each
//   with a <validity> fromLane <= toLane over the lanes it controls.
// - One road per link road of the lane model (lanes.h LinkRoad; ids follow
//   the street roads and junctions): line, arc and line geometry, G1 with both
//   roads; lane widths and laneOffset as smoothstep cubics; elevation a cubic
//   Hermite continuing both roads' heights and slopes, superelevation linear
//   between theirs. Transitions at degree-2 nodes are linked road to road
//   (both directions' lanes); connecting roads belong to one <junction> per
//   node of degree >= 3 (id = road count + junction index) with a
//   <connection> and <laneLink>s per turn, and a <controller> per approach
//   group (lanes.h SignalPlacement::group) at signalised junctions; crosswalk
//   <object>s where the meshes draw zebra crossings, on a connecting road of
//   the junction (the band lies in the junction, within that road's s-range).
// - <header> with <geoReference>: the OSM import's transverse Mercator when
//   params.geo is set, else a transverse Mercator at (0, 0); both with
//   +x_0/+y_0 = the world offset, so PROJ maps the written coordinates.
// - Valid against the ASAM OpenDRIVE 1.6 schema; deterministic: the bytes
//   depend only on (graph, params, blocks).
// Returns an error when the graph has no valid edge. Pure, thread-safe.
#pragma once
#include <cstddef>
#include <string>

#include <vector>

#include "citygen/city.h"
#include "foundation/status.h"

namespace vista {

struct OpenDriveCounts {
    size_t roads = 0;            // roads of street edges
    size_t connectingRoads = 0;  // roads inside junctions
    size_t junctions = 0;
    size_t drivingLanes = 0;       // over the street-edge roads (both directions)
    size_t sidewalks = 0;          // sidewalk lanes over the street-edge roads
    size_t transitions = 0;        // link roads at degree-2 nodes
    size_t trafficLights = 0;      // signals of type traffic light
    size_t signs = 0;              // stop and yield signs
    size_t crosswalks = 0;         // crosswalk objects
    size_t sharpCorners = 0;       // degree-2 nodes left unlinked (LaneModel::sharpCorners)
    size_t droppedTurns = 0;       // LaneModel::droppedTurns
    size_t tightTurns = 0;         // LaneModel::tightTurns
    size_t overlappingArms = 0;    // LaneModel::overlappingArms
    size_t crossingTurns = 0;      // LaneModel::crossingTurns
    size_t tightTurnsKept = 0;     // LaneModel::tightTurnsKept
    size_t crossingTurnsKept = 0;  // LaneModel::crossingTurnsKept
    size_t joinedEdges = 0;        // LaneModel::joinedEdges
    size_t unlinkedLanes = 0;      // LaneModel::unlinkedLanes
    size_t unfedLanes = 0;         // LaneModel::unfedLanes
    size_t taperedLanes = 0;       // driving lanes of link roads that start or end with width 0 inside them
    double minTurnRadius = 0;      // smallest lane-centre radius over the connecting roads' arcs (m; 0: no arc)
};

// The counts as a JSON object (the "opendrive" section of `vista gen
// --stats` and the stats of `vista export`; docs/formats.md).
std::string openDriveCountsJson(const OpenDriveCounts& n);

// `blocks` (the city's, or extractBlocks() of the same graph and params)
// decide on which sides sidewalk lanes are written (lanes.h); null: both.
Result<std::string> openDriveXml(const StreetGraph& g, const CityParams& params, const std::vector<Block>* blocks,
                                 OpenDriveCounts* counts = nullptr);

// The counts as a JSON object (keys in snake_case: roads, connecting_roads,
// junctions, transitions, driving_lanes, sidewalks, traffic_lights, signs,
// crosswalks, sharp_corners, dropped_turns, unlinked_lanes, unfed_lanes,
// tapered_lanes).
std::string openDriveCountsJson(const OpenDriveCounts& counts);

// The PROJ string written into <geoReference> (see above).
std::string openDriveGeoReference(const CityParams& params);

}  // namespace vista
