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
//    they lie farther than sqrt(2) x the largest city side (kMaxPagedSizeM,
//    64 km: 90.5 km) from the median position of all way nodes, so an
//    extract the largest city could hold never loses a node.
// 2. Projection (geodesy.h): WGS84 transverse Mercator about the centre of
//    the kept roads' bounding box (found from their centroid; rounded to
//    1e-7 degrees), so the frame holds at the poles and across +-180 degrees.
// 3. A bounding box wider or taller than the largest city side
//    (kMaxPagedSizeM) is refused with an error naming both extents and the
//    limit. The city square: with OsmExtent::CitySquare the params' size_m
//    (roads beyond it are clipped, below); with OsmExtent::Extract the
//    extract's own extent, the roads' bounding box grown by kOsmExtentMargin_m
//    on every side and rounded up to whole tiles (tile_size_m), at least
//    size_m's minimum and at most kMaxPagedSizeM (OsmImport::citySize_m).
// 4. Simplification: nodes closer than min_segment_m to the previous kept
//    node, then Douglas-Peucker at 0.5 m; junction nodes and way ends stay.
// 5. Bounded planarization work: a way crossing or touching itself more than
//    16 times is dropped (counted); more than 100,000 conflicts among all
//    segments (crossings away from shared nodes) are refused; then
//    planarize(segments, snap_radius_m, min_segment_m), every one-way way
//    its own carriageway (so a dual carriageway stays two one-way ways).
// 6. Road tags (osm_road_tags.h): an edge of a one-way way's carriageway
//    takes that way's tags; every other edge the lanes, oneway, turn:lanes,
//    maxspeed and width tags of the way of its class it lies on (within
//    snap_radius_m + min_segment_m + 1 m); both in the edge's direction
//    (swapped where the edge runs against the way); counts in roadTagStats.
//    Then every one-way edge runs along its traffic (a and b swapped: its
//    lanes are forward lanes, right lanes in OpenDRIVE) and, without a width
//    tag, is as wide as its lanes at the class's lane width (roadWidth /
//    roadLanes).
// 7. Slight bends next to a junction (short_bends.h): a degree-2 node on a
//    junction arm of at most kShortBendArm where the same road turns by at
//    most kShortBendAngle is dropped when the straight edge passes within
//    kShortBendDeviation of it and of nodes dropped before.
// 8. Side-by-side edges (side_by_side.h): nearly parallel edges sharing no
//    node whose carriageways share area (a divided road's two one-way ways a
//    few metres apart) are narrowed until they part, dropping lanes that
//    would be narrower than kMinLaneWidth; one-way edges stay one-way.
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
    // The one-way carriageway the segment belongs to (e.g. one OSM way of a
    // dual carriageway), 0 = none.
    uint32_t carriageway = 0;
};
// Nodes of different carriageways this close still merge (duplicated data).
constexpr double kCarriagewayMerge_m = 2.0;
// Builds a planar graph from arbitrary (possibly crossing, overlapping,
// near-duplicate, zero-length) segments: exact intersection, snapping of
// nodes closer than `snap`, removal of edges shorter than `minSegment`
// (merging their ends), dedup keeping the highest road class.
// Carriageways stay apart: two nodes merge (snap, contraction, a node
// splitting an edge) only when the carriageways of one's edges are among the
// other's (nodes on no carriageway merge with any), or when they are closer
// than kCarriagewayMerge_m; so the two one-way ways of a dual carriageway stay
// two edges however close, and meet only where their segments share an end
// or cross. An edge joining two carriageways may therefore be shorter than
// `minSegment` (not shorter than kCarriagewayMerge_m); without carriageways
// every edge is at least `minSegment` long.
// Never crashes or produces NaN; output satisfies checkPlanarGraph() (with
// the exception above). `carriageways`, when given, receives each output
// edge's carriageway (0: none, or two carriageways overlapped there).
StreetGraph planarize(const std::vector<RawSegment>& segments, double snap, double minSegment,
                      std::vector<uint32_t>* carriageways = nullptr);

// Which square an import fills: the params' size_m (roads beyond it clipped)
// or the extract's own extent.
enum class OsmExtent : uint8_t { CitySquare, Extract };
constexpr double kOsmExtentMargin_m = 50.0;  // room beyond the outermost road node for its street and sidewalk

struct OsmImport {
    StreetGraph streets;                  // city frame: metres, x east, y north, (0,0) at `geo`
    GeoReference geo;                     // the projection's reference (store it as CityParams::geo)
    double extentX_m = 0, extentY_m = 0;  // bounding box of the kept road nodes
    double citySize_m = 0;                // side of the city square the roads lie in (store it as size_m)
    uint64_t fileHash = 0;                // hashBytes64 of the file's bytes (names the input in paged records)
    double outlierRadius_m = 0;           // nodes farther than this from the median position were dropped
    // Distinct OSM nodes / ways of highway=* ways that were dropped, by reason.
    size_t invalidNodes = 0, missingNodes = 0, outlierNodes = 0, tangledWays = 0;
    size_t simplifiedNodes = 0;  // removed by simplification (shape kept within its tolerances)
    size_t clippedSegments = 0;  // road segments cut at the city square's border or beyond it
    double clipHalf_m = 0;       // half the city side they were clipped to
    size_t roadSegments = 0;     // road segments of the kept ways before clipping
    size_t clippedWays = 0;      // kept ways with no segment inside the city square
    size_t roadWays = 0;         // kept ways before clipping
    double roadLength_m = 0;     // length of those segments
    double keptLength_m = 0;     // of which inside the city square
    // "dropped 2 nodes (1 with invalid coordinates, ...); clipped to ..."; the clip says how
    // much of the extract's roads the city square kept (ways, segments, km and percent).
    std::string dropSummary() const;
    // Building footprints (osm_buildings.h), in the streets' frame; empty unless asked for.
    std::vector<OsmFootprint> buildings;
    OsmBuildingStats buildingStats;  // the import counts (candidates, repaired, skipped by reason)
    OsmRoadTagStats roadTagStats;    // ways that used each road tag or fell back (osm_road_tags.h)
};
// `buildings`: also read the building footprints (docs/reference/buildings.md "Buildings
// from OSM"): closed ways and multipolygon relations tagged building=*,
// repaired or skipped per reason (never an error), those with a vertex outside
// the city square [-citySize_m/2, citySize_m/2]^2 skipped. Roads are clipped to the
// city square: a segment that leaves it ends at its border, one beyond it is
// dropped (counted in clippedSegments and dropSummary()), so every street
// lies inside the city the scene file describes. With OsmExtent::Extract
// nothing is clipped; the caller sets params.size_m = citySize_m (above
// kMaxSingleFileSizeM the city is generated as a paged city).
Result<OsmImport> importOsm(const std::string& path, const CityParams& params, bool buildings = false,
                            OsmExtent extent = OsmExtent::CitySquare);

}  // namespace vista
