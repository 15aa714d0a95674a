// Buildings: footprints on lots and their meshes.
//
// placeBuildings(): one building per lot (none on tiny lots): footprint = lot
// inset by a setback growing with lower density; floors from density (towers
// downtown, houses in the suburbs, seeded per lot); roof type from size and
// density (flat for large/dense, gabled or hipped for houses). Footprints lie
// inside their lot, so they never overlap roads or each other.
// meshBuilding(): walls, roof (flat; gabled; hipped via CGAL straight
// skeleton, falling back to flat on failure) and facades at params.detail:
// 0 plain prism, 1 window bands, 2 window recesses as geometry (the
// microgeometry the far-field methods must handle), 3 adds sills.
// Imported (OSM) buildings may have holes (courtyards): their walls are built
// along every inner ring too, facing into the courtyard, and their roof is flat
// over the polygon with holes (constrained triangulation, footprint_repair.h);
// a min_height > 0 lifts the walls and adds an underside.
// Geometry goes to `walls`, `windows` and `roofs` meshes relative to origin.
// Thread-safe for distinct target meshes.
#pragma once
#include <vector>

#include "citygen/city.h"
#include "citygen/lighting.h"
#include "foundation/progress.h"
#include "foundation/rng.h"

namespace vista {

// Procedural storey count of a footprint whose narrow side is `width` metres at
// population density `density` (0..1), as placeBuildings() draws it from `rng`:
// towers downtown, 2-5 floors in between, 1-3 in the suburbs; within
// [min_floors, max_floors] and at most ~7 x width tall.
int proceduralFloors(Rng& rng, double density, double width, const CityParams& params);

std::vector<Building> placeBuildings(const std::vector<Lot>& lots, const std::vector<Block>& blocks,
                                     const CityParams& params, Progress* progress);

struct BuildingMeshes {
    Mesh* walls;
    Mesh* windows;
    Mesh* roofs;
};
void meshBuilding(const Building& b, uint32_t buildingId, const CityParams& params, const Lighting& light,
                  const glm::dvec3& origin, BuildingMeshes out);

}  // namespace vista
