// Buildings from OpenStreetMap: the footprints importOsm() reads and their
// completion into City::buildings (docs/reference/buildings.md "Buildings from OSM").
//
// importOsm() (streets.h) reads closed ways tagged building=* (not "no") and
// multipolygon relations (type=multipolygon + building=*) with their outer
// and inner member ways, projects them with the streets' projection, repairs
// or skips broken rings (counts in OsmBuildingStats, city.h) and returns them
// as OsmFootprint records with their height and roof tags parsed.
// resolveOsmBuildings() turns the records into Buildings: ground height from
// the terrain, heights from the tags (height, else building:levels x storey,
// else procedural), roof shape from roof:shape (else procedural), flat where
// the shape cannot be built. dropCoveredLots() removes the procedural lots
// that overlap an imported footprint, so no procedural building overlaps an
// imported one. All functions are deterministic (random choices keyed by the
// OSM id), thread-safe and never throw; bad tag values count as absent.
#pragma once
#include <cmath>
#include <cstdint>
#include <limits>
#include <string_view>
#include <vector>

#include "citygen/city.h"

namespace vista {

constexpr double kOsmMinFootprintArea_m2 = 4.0;  // smaller imported footprints are skipped (too_small)
constexpr double kOsmMaxHeight_m = 1000.0;       // height / min_height / roof:height above this count as absent
constexpr double kOsmMaxLevels = 250.0;          // building:levels and the like above this count as absent

// roof:shape, mapped to the shapes vista builds: Absent = no (or empty) tag.
enum class OsmRoofShape : uint8_t { Absent = 0, Flat, Gabled, Hipped };

struct OsmFootprint {
    Polygon2 outer;               // counter-clockwise, simple, city frame (metres)
    std::vector<Polygon2> holes;  // clockwise, simple, strictly inside outer, pairwise disjoint
    BuildingSource source = BuildingSource::OsmWay;
    int64_t osm_id = 0;  // way or relation id
    uint32_t ring = 0;   // index of the outer ring within its relation (0 for ways)
    // Parsed tags; NaN = absent or unparsable.
    double height_m = std::numeric_limits<double>::quiet_NaN();       // height
    double min_height_m = std::numeric_limits<double>::quiet_NaN();   // min_height
    double roof_height_m = std::numeric_limits<double>::quiet_NaN();  // roof:height
    double levels = std::numeric_limits<double>::quiet_NaN();         // building:levels
    double min_level = std::numeric_limits<double>::quiet_NaN();      // building:min_level
    double roof_levels = std::numeric_limits<double>::quiet_NaN();    // roof:levels
    OsmRoofShape roof = OsmRoofShape::Absent;                         // roof:shape
};

// A length in metres from an OSM value: "12", "12.5", "12 m", "12.5m", "12,5"
// (decimal comma), feet "40'", "40 ft", feet and inches "12'6\"". Returns NaN
// for anything else, negative or non-finite values and values above kOsmMaxHeight_m.
double parseOsmLength(std::string_view text);
// A non-negative count ("3", "2.5"); NaN for anything else or above kOsmMaxLevels.
double parseOsmLevels(std::string_view text);
// flat, skillion (one slope, built flat) -> Flat; gabled, gambrel, saltbox,
// round -> Gabled; hipped, half-hipped, side_hipped, mansard, pyramidal, dome,
// onion, cone -> Hipped; other values -> Flat; empty -> Absent.
OsmRoofShape parseOsmRoofShape(std::string_view text);

// Completes the footprints into buildings (in input order). Heights (storey =
// params.floor_height_m): `height` is the total height to the roof top and
// the eaves lie roof:height (else roof:levels storeys, else a seeded pitch)
// below it; else building:levels storeys (+ roof:levels as the roof height of
// pitched roofs, as wall height of flat ones); else procedural floors from
// the density (no towers: 4-8 downtown, 2-5 in between, 1-3 in the suburbs,
// at most ~4 x the narrow side). min_height, else building:min_level storeys, lifts
// the wall bottom (ignored when not below the eaves). Roof: roof:shape, else
// procedural (houses gabled or hipped, larger buildings flat). Footprints with
// holes, and shapes the roof code cannot build, get a flat roof at the top
// height (counted as roof_fallback_flat). Updates the completion counts of `stats`.
std::vector<Building> resolveOsmBuildings(const std::vector<OsmFootprint>& footprints, const CityParams& params,
                                          OsmBuildingStats& stats);

// Removes every lot whose outline overlaps the outer ring of an imported
// building (interiors overlapping by more than 1e-6 m; touching is allowed);
// the kept lots stay in order. Returns the number removed.
size_t dropCoveredLots(std::vector<Lot>& lots, const std::vector<Building>& imported);

// Number of imported footprints whose outer ring comes closer to a street
// centre line than half its carriageway width (they are kept: OSM is the truth).
size_t countOnCarriageway(const std::vector<Building>& imported, const StreetGraph& streets);

}  // namespace vista
