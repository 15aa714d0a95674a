// Street network: procedural growth (Parish & Mueller style) and OSM import.
//
// growStreets(): highways, then arterials, then local streets grow from seeds
// guided by global goals (population density, the regional mix of grid /
// radial / organic patterns from terrain.h) and local constraints: snap to
// intersections within snap_radius_m, trim at crossings, reject edges below
// min_segment_m or meeting others at less than min_angle_deg. Every proposed
// segment goes through planarization with exact predicates (CGAL), so the
// result satisfies checkPlanarGraph() for any params. Deterministic for a
// given params (random streams keyed by seed and stable ids); the centre of a
// larger city matches a smaller one with the same seed as far as possible.
// Progress is reported through `progress` (may be null).
//
// importOsm(): ways tagged highway=* from an OpenStreetMap extract (.osm XML,
// also .osm.gz / .osm.bz2, or .osm.pbf) as a planar street graph in a local
// metric frame. Steps (docs/reference/streets.md):
// 1. Nodes are dropped, and their ways split there, when their coordinates
//    are invalid (unparsable, non-finite, lat outside [-90, 90], lon outside
//    [-180, 180]; XML coordinates are checked as text before libosmium parses
//    them, see osm_import.cpp), when they are missing from the file, or when
//    they lie farther than sqrt(2) x the largest city side (size_m's maximum
//    in paramSpecs(), 16 km: 22.6 km) from the median position of all way
//    nodes, so an extract the largest city could hold never loses a node.
// 2. Projection (geodesy.h): WGS84 transverse Mercator about the centre of
//    the kept roads' bounding box (found from their centroid; rounded to
//    1e-7 degrees), so the frame holds at the poles and across +-180 degrees.
// 3. A bounding box wider or taller than the largest city side is refused
//    with an error naming both extents and the limit.
// 4. Simplification: nodes closer than min_segment_m to the previous kept
//    node, then Douglas-Peucker at 0.5 m; junction nodes and way ends stay.
// 5. Bounded planarization work: a way crossing or touching itself more than
//    16 times is dropped (counted); more than 100,000 conflicts among all
//    segments (crossings away from shared nodes) are refused; then
//    planarize(segments, snap_radius_m, min_segment_m).
// 6. Road tags (osm_road_tags.h): every edge takes the lanes, oneway,
//    turn:lanes, maxspeed and width tags of the way of its class it lies on
//    (within snap_radius_m + min_segment_m + 1 m), in the edge's direction
//    (swapped where the edge runs against the way); counts in roadTagStats.
// Unreadable, corrupt, unsupported (DOCTYPE, UTF-16, other formats) or
// road-less files return an error naming the file. Every drop is counted in
// the result; dropSummary() words them ("" when nothing was dropped).
// Deterministic: the same file and params give the same bytes.
#pragma once
#include <string>
#include <vector>

#include "citygen/osm_buildings.h"
#include "citygen/osm_road_tags.h"
#include "citygen/params.h"
#include "foundation/progress.h"
#include "foundation/status.h"
#include "citygen/street_graph.h"

namespace vista {

StreetGraph growStreets(const CityParams& params, Progress* progress);

struct RawSegment {
    glm::dvec2 a, b;
    RoadClass cls = RoadClass::Local;
};
// Builds a planar graph from arbitrary (possibly crossing, overlapping,
// near-duplicate, zero-length) segments: exact intersection, snapping of
// nodes closer than `snap`, removal of edges shorter than `minSegment`
// (merging their ends), dedup keeping the highest road class.
// Never crashes or produces NaN; output satisfies checkPlanarGraph().
StreetGraph planarize(const std::vector<RawSegment>& segments, double snap, double minSegment);

struct OsmImport {
    StreetGraph streets;                  // city frame: metres, x east, y north, (0,0) at `geo`
    GeoReference geo;                     // the projection's reference (store it as CityParams::geo)
    double extentX_m = 0, extentY_m = 0;  // bounding box of the kept road nodes
    double outlierRadius_m = 0;           // nodes farther than this from the median position were dropped
    // Distinct OSM nodes / ways of highway=* ways that were dropped, by reason.
    size_t invalidNodes = 0, missingNodes = 0, outlierNodes = 0, tangledWays = 0;
    size_t simplifiedNodes = 0;       // removed by simplification (shape kept within its tolerances)
    size_t clippedSegments = 0;       // road segments cut at the city square's border or beyond it
    double clipHalf_m = 0;            // half the city side they were clipped to
    std::string dropSummary() const;  // "dropped 2 nodes (1 with invalid coordinates, ...)"
    // Building footprints (osm_buildings.h), in the streets' frame; empty unless asked for.
    std::vector<OsmFootprint> buildings;
    OsmBuildingStats buildingStats;  // the import counts (candidates, repaired, skipped by reason)
    OsmRoadTagStats roadTagStats;    // ways that used each road tag or fell back (osm_road_tags.h)
};
// `buildings`: also read the building footprints (docs/reference/buildings.md "Buildings
// from OSM"): closed ways and multipolygon relations tagged building=*,
// repaired or skipped per reason (never an error), those with a vertex outside
// the city square [-size_m/2, size_m/2]^2 skipped. Roads are clipped to the
// city square: a segment that leaves it ends at its border, one beyond it is
// dropped (counted in clippedSegments and dropSummary()), so every street
// lies inside the city the scene file describes.
Result<OsmImport> importOsm(const std::string& path, const CityParams& params, bool buildings = false);

}  // namespace vista
