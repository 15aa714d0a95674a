// generateCity(): the whole pipeline params -> City.
//
// Stages: streets (grown, or `streets` given e.g. from OSM) -> blocks ->
// lots -> buildings (imported ones from OSM first take their land) -> trees -> (street lights) -> parked cars
// -> meshes per tile (parallel over tiles).
// Contract: params must pass validateParams() and checkSingleFileSize()
// (checked; error otherwise: larger cities go through citygen/regions.h).
// Output is byte-for-byte identical for the same params whatever
// params.threads is. Stage timings go to City::stageTimes.
#pragma once
#include <functional>
#include <optional>

#include "citygen/city.h"
#include "citygen/osm_buildings.h"
#include "foundation/progress.h"

namespace vista {

struct GenerateOptions {
    Progress* progress = nullptr;
    std::optional<StreetGraph> streets;  // use these streets instead of growing them
    // Building footprints imported from OSM (importOsm with buildings): they are completed into
    // buildings (resolveOsmBuildings), appended after the procedural ones, and every lot
    // overlapping one of them is dropped before the procedural buildings are placed.
    std::optional<std::vector<OsmFootprint>> osmBuildings;
    OsmBuildingStats osmStats;  // the import's counts, carried into City::osmBuildings
    // Called with the laid-out city (streets, blocks, lots, buildings, trees,
    // street lights; no tiles yet) before the meshes stage, the bulk of the
    // memory: an error stops generation and is returned (the --memory-budget check).
    std::function<Status(const City& layout)> beforeMeshing;
};

Result<City> generateCity(const CityParams& params, const GenerateOptions& options = {});

// The meshes-per-tile stage of generateCity on a city whose streets, blocks,
// buildings, trees (and street lights, parked cars) are set: replaces city.tiles with the
// non-empty tiles among `tiles` (indices of TileGrid(city.params), row-major;
// empty = every tile), in that order. Buildings, trees, lights, signals
// (the lane model's traffic lights, stop and yield signs: traffic_signals.h)
// and parked cars (parked_cars.h) go to the tile of their anchor (footprint
// centroid, trunk base, pole base, car centre);
// those anchored in other tiles are not meshed. Parallel over tiles; the bytes do
// not depend on the thread count. Indices out of range: VISTA_CHECK.
void meshTiles(City& city, const std::vector<int>& tiles, Progress* progress);

// Summary numbers of a city (stats file fields).
struct CityCounts {
    size_t streetNodes = 0, streetEdges = 0, blocks = 0, lots = 0, buildings = 0, trees = 0;
    size_t triangles = 0;        // rendered: tile meshes + every tree instance
    size_t storedTriangles = 0;  // stored: tile meshes + each prototype once
    size_t vertices = 0;         // rendered vertices, same convention as triangles
    size_t drawCalls = 0;        // non-empty tile meshes + one instanced draw per (tile, tree prototype)
};
CityCounts countCity(const City& city);

// Stored triangles (countCity().storedTriangles) that the meshes stage will
// make for a laid-out city, estimated by meshing a sample of its tiles
// (every k-th tile of the grid: at least 16, at most 64, all of a small city)
// and scaling by the tile count, plus the tree prototypes once. Exact when
// every tile is sampled; deterministic; costs about one eighth of the
// meshes stage on a large city.
size_t estimateStoredTriangles(const City& layout);

}  // namespace vista
