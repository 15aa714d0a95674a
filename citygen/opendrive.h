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
//   sides that have a sidewalk mesh) with
//   constant <width>, road marks on the centre lane and lane dividers.
// - One <junction> per node of degree >= 3 (id = road count + junction
//   index) with one connecting road (junction attribute set) per ordered pair
//   of distinct arms: a paramPoly3 (cubic Hermite) from the incoming road's
//   reference end to the outgoing road's reference start, min(in, out)
//   driving lanes, <connection> + <laneLink> entries. Degree-2 nodes link the
//   two roads directly (road and lane predecessor/successor); dead ends have
//   no link.
// - <header> with <geoReference>: the OSM import's transverse Mercator when
//   params.geo is set, else a transverse Mercator at (0, 0); both with
//   +x_0/+y_0 = the world offset, so PROJ maps the written coordinates.
// - Deterministic: the bytes depend only on (graph, params).
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
    size_t drivingLanes = 0;     // over the street-edge roads (both directions)
    size_t sidewalks = 0;        // sidewalk lanes over the street-edge roads
};

// `blocks` (the city's, or extractBlocks() of the same graph and params)
// decide on which sides sidewalk lanes are written (lanes.h); null: both.
Result<std::string> openDriveXml(const StreetGraph& g, const CityParams& params, const std::vector<Block>* blocks,
                                 OpenDriveCounts* counts = nullptr);

// The PROJ string written into <geoReference> (see above).
std::string openDriveGeoReference(const CityParams& params);

}  // namespace vista
