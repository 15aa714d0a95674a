// Regions: a city generated region by region (the generation side of a paged
// city, bake/gen/paged_city.h), so that memory is bounded by the street
// graph, the blocks and one region, not by the city.
//
// RegionGrid: square regions of `region_size_m` (a whole number of tiles,
// kMinRegionSizeM .. kMaxRegionSizeM, checked by validateRegionSize) over the
// tile grid (TileGrid), row-major from the south-west corner; the last row and
// column are cut by the city border. Every tile belongs to exactly one region.
//
// RegionalCity: create() grows the street graph (or takes the given one, e.g.
// an OSM import) and extracts the blocks (with their parks) of the whole city
// once, exactly as generateCity does, completes the given OSM building
// footprints into buildings (resolveOsmBuildings), and makes the tree
// prototypes. region(r) then generates one region:
//   - its street graph: the edges within kRegionHaloM of the region, plus
//     every edge at their end nodes (so junctions and node degrees near the
//     region are those of the whole city), re-indexed in global order;
//   - the blocks within kRegionHaloM of the region (global order, parks kept);
//     their lots and buildings (both seeded by position, so each is the
//     building generateCity places on that lot; lots overlapping an imported
//     building within kRegionHaloM are dropped first, and those imported
//     buildings join the region's, as generateCity does), the trees (placed among the
//     halo's buildings and streets), street lights and parked cars;
//   - it keeps the buildings, trees, lights and cars anchored in the region (tile
//     of the footprint centroid / trunk base / pole base / car centre, the anchor of
//     generateCity's tiles), and meshes the region's tiles (meshTiles).
// So every building of the city is in exactly one region, the same building
// as in generateCity (its count is the unpaged count); its facade colours and
// every ground-truth id (labels.h) are numbered within the region (index in
// the region's City). Trees: the greedy spacing filter runs over the region
// and its halo, so near a region border a tree may differ from the unpaged
// city's (the region's own trees are deterministic); so may a parked car.
// coarse(): the far level of a region: the same tiles with ground, grass and
// roads, buildings as plain prisms (detail 0), the region's trees as
// impostors (City::treeImpostors: cross billboards, tree_impostor.h), no
// sidewalks, markings, lamps or cars; the coarse City's params carry detail 0.
//
// Contract: params must pass validateParams() (the single-file cap does not
// apply); bad params or region size: error Status naming the field. region()
// is deterministic (the bytes of a written region depend only on params, the
// region size and r, not on thread count or on other regions) and may be
// called in any order; r out of range: VISTA_CHECK. Not thread-safe per
// instance (region() uses TBB inside).
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "citygen/city.h"
#include "citygen/mesh_builder.h"
#include "citygen/osm_buildings.h"
#include "foundation/progress.h"
#include "foundation/status.h"

namespace vista {

constexpr double kMinRegionSizeM = 250.0;
constexpr double kMaxRegionSizeM = 16000.0;
constexpr double kDefaultRegionSizeM = 2000.0;
constexpr double kRegionHaloM = 250.0;

// region_size_m in [max(kMinRegionSizeM, tile_size_m), kMaxRegionSizeM] and a
// whole multiple of tile_size_m; the message names 'region_size_m', the value
// and the allowed range.
Status validateRegionSize(const CityParams& params, double regionSizeM);

class RegionGrid {
public:
    RegionGrid(const CityParams& params, double regionSizeM);  // validated values
    int countX() const { return _n; }
    int countY() const { return _n; }
    int count() const { return _n * _n; }
    int ix(int region) const { return region % _n; }
    int iy(int region) const { return region / _n; }
    int tilesPerRegion() const { return _k; }
    int regionOfTile(int tile) const;
    // The tile indices (TileGrid, row-major) of `region`, row-major.
    std::vector<int> tilesOf(int region) const;
    // City-frame rectangle of `region`, cut by the city border.
    void bounds(int region, glm::dvec2& lo, glm::dvec2& hi) const;

private:
    TileGrid _tiles;
    double _half, _tileSize;
    int _tileCount, _k, _n;
};

// What a regional city takes as given instead of growing it (null: grown).
struct RegionalInputs {
    const StreetGraph* streets = nullptr;
    const std::vector<OsmFootprint>* osmBuildings = nullptr;
};

class RegionalCity {
public:
    static Result<RegionalCity> create(const CityParams& params, double regionSizeM, Progress* progress,
                                       const RegionalInputs& inputs = {});
    const CityParams& params() const { return _params; }
    const RegionGrid& grid() const { return _grid; }
    const StreetGraph& streets() const { return _streets; }
    size_t blockCount() const { return _blocks.size(); }
    // The whole city's blocks (extractBlocks of streets(), as generateCity's).
    const std::vector<Block>& blocks() const { return _blocks; }
    // The completion counts of the imported buildings (enabled when given).
    const OsmBuildingStats& osmBuildingStats() const { return _osmStats; }
    City region(int r) const;
    static City coarse(const City& region);

private:
    RegionalCity(const CityParams& params, double regionSizeM) : _params(params), _grid(params, regionSizeM) {}
    CityParams _params;
    RegionGrid _grid;
    StreetGraph _streets;
    std::vector<Block> _blocks;
    std::vector<Building> _imported;  // completed OSM buildings
    OsmBuildingStats _osmStats;
    std::vector<TreePrototype> _prototypes;
    std::vector<std::vector<uint32_t>> _edgesNear, _blocksNear, _importedNear;  // per region: within the halo
    std::vector<uint32_t> _nodeEdgeStart, _nodeEdges;                           // node -> incident edges (CSR)
};

}  // namespace vista
