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

namespace vista {

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
