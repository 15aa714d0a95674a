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
// importOsm(): ways tagged highway=* from an .osm / .osm.pbf file, projected
// to local metres (equirectangular about the centre of the data's bounding
// box) then planarized exactly like grown streets.
// Unreadable or corrupt files return an error naming the file.
#pragma once
#include <string>
#include <vector>

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

Result<StreetGraph> importOsm(const std::string& path, const CityParams& params);

}  // namespace vista
