// Ground, road and sidewalk surfaces, per tile.
//
// meshSurfaces(): for tile `tile` of `grid`, the ground (a grid following the
// terrain, Grass inside parks), road carriageways with their width (pieces of
// at most ~50 m assigned to the tile of their midpoint, joined at
// intersections by node discs), lane markings, and
// sidewalks along each block outline. Lane markings follow the lane model
// (lanes.h, the one the OpenDRIVE export writes): centre lines, dashed lane
// dividers, stop lines and zebra crossings at junctions. Heights follow terrainHeight(); roads
// sit 2 cm above the ground, sidewalks 12 cm, to avoid z-fighting.
// Writes into the tile's meshes (tile-local). Thread-safe per tile.
#pragma once
#include "citygen/city.h"
#include "citygen/lanes.h"
#include "citygen/lighting.h"
#include "citygen/mesh_builder.h"

#include <cstdint>
#include <vector>

namespace vista {

void meshSurfaces(const City& city, const TileGrid& grid, int tile, const Lighting& light, Tile& out);

// Per-tile candidate lists of the street edges, blocks and parks a tile may
// draw, built once per city (linear time) so that meshSurfaces does not scan
// the whole city for every tile. Output is identical with or without it.
struct SurfaceIndex {
    int tiles = 0;
    std::vector<std::vector<uint32_t>> edges, blocks, parks;
    LaneModel lanes;  // of the whole city (markings)
};
SurfaceIndex buildSurfaceIndex(const City& city, const TileGrid& grid);
void meshSurfaces(const City& city, const TileGrid& grid, int tile, const Lighting& light, Tile& out,
                  const SurfaceIndex* index);

}  // namespace vista
