// City: the complete generated model, before conversion to a scene file.
//
// Contract: all 2D/3D coordinates are double metres in the city frame (city
// centre at the origin, z up); the world position is params.origin + city
// frame. Polygons are simple, counter-clockwise, without repeated closing
// vertex. Indices between the arrays (lot.block, building.lot, tree.prototype)
// are valid (building.lot may be kNoLot for imported buildings). Meshes are grouped per tile, tile-local in float (see
// Tile).
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "citygen/mesh.h"
#include "citygen/params.h"
#include "citygen/street_graph.h"

namespace vista {

using Polygon2 = std::vector<glm::dvec2>;

struct Block {
    Polygon2 outline;  // inset from the street centre lines by half width + sidewalk
    bool park = false;
    double density = 0;  // density map value at the centroid, 0..1
};

struct Lot {
    uint32_t block = 0;
    Polygon2 outline;      // inside its block
    bool frontage = true;  // touches a street side of the block
};

enum class RoofType : uint8_t { Flat = 0, Gabled = 1, Hipped = 2 };

// Where a building comes from: placed on a lot, or imported from OpenStreetMap
// (a closed way or a multipolygon relation tagged building=*; osm_buildings.h).
enum class BuildingSource : uint8_t { Procedural = 0, OsmWay = 1, OsmRelation = 2 };

constexpr uint32_t kNoLot = 0xFFFFFFFFu;  // Building::lot of imported buildings

struct Building {
    uint32_t lot = 0;             // index into City::lots; kNoLot for imported buildings
    Polygon2 footprint;           // outer ring, counter-clockwise; procedural: inside its lot, with setbacks
    std::vector<Polygon2> holes;  // inner rings (courtyards), clockwise, strictly inside the footprint,
                                  // pairwise disjoint; only imported buildings have them
    double base_z = 0;            // ground height under the footprint (min of terrain)
    double height = 0;            // wall top above base_z (eaves)
    double min_height = 0;        // wall bottom above base_z (OSM min_height; 0 = on the ground), < height
    int floors = 1;               // storeys between min_height and height (window rows)
    RoofType roof = RoofType::Flat;
    double roof_height = 0;  // ridge above the eaves (0 for flat)
    BuildingSource source = BuildingSource::Procedural;
    int64_t osm_id = 0;  // OSM way or relation id (source says which); 0 for procedural buildings
};

// One tree shape (species x size variant), stored once and instanced.
struct TreePrototype {
    int species = 0;
    int variant = 0;
    double height = 0;
    Mesh mesh;  // in the tree's own frame (trunk base at the origin, z up)
};

struct TreeInstance {
    glm::dvec3 position{0.0};  // trunk base, city frame
    float yaw = 0;             // radians
    float scale = 1;
    uint16_t prototype = 0;
    bool street = true;  // street tree (true) or park tree (false)
};

// A parked car (parked_cars.h): one of the procedural car models, standing
// on the ground (or on the sidewalk) along a curb or in a lot.
struct ParkedCar {
    glm::dvec3 position{0.0};  // centre of the car's footprint at ground level (wheel contact), city frame
    double yaw = 0;            // heading of the car's front, radians counter-clockwise from east
    uint8_t model = 0;         // index into carModels()
    uint8_t colour = 0;        // index into the body colour palette (kCarColourCount)
    bool curb = true;          // along a curb (true) or in a lot (false)
};

// A square spatial tile of the output. Geometry is float relative to `origin`
// (city frame, double); the world origin of the tile is params.origin + origin.
struct Tile {
    int ix = 0, iy = 0;
    glm::dvec3 origin{0.0};
    std::array<Mesh, kMaterialCount> meshes;  // one per material
    std::vector<uint32_t> trees;              // indices into City::trees whose base lies in this tile
    std::vector<uint32_t> streetLights;       // indices into City::streetLights in this tile
};

struct StageTime {
    std::string name;
    double seconds = 0;
};

// Buildings from OSM (vista gen --osm): what was read, repaired, skipped and how the
// buildings were completed (osm_buildings.h, docs/reference/buildings.md "Buildings from OSM").
// Counts are per footprint candidate: a building way is one, a multipolygon relation one
// per outer ring it assembles to (or one, skipped as no_outer_ring, when it has none).
struct OsmBuildingStats {
    bool enabled = false;            // OSM buildings were read (vista gen --osm, --osm-buildings on)
    size_t ways = 0, relations = 0;  // building=* ways / multipolygon relations read
    size_t candidates = 0;           // footprint candidates (see above)
    size_t imported = 0;             // candidates that became buildings
    // Repaired (a footprint may count under several; repaired footprints are imported).
    size_t duplicateNodes = 0;     // rings with repeated consecutive nodes, removed
    size_t unclosedRings = 0;      // rings whose ends did not meet, closed
    size_t selfIntersections = 0;  // rings split at their self-intersections, largest piece kept
    size_t innerRingsDropped = 0;  // inner rings not strictly inside their outer ring (or broken), dropped
    // Skipped, by reason (each skipped candidate counts once).
    size_t missingNodes = 0;      // a node absent from the extract or with invalid coordinates
    size_t tooFewNodes = 0;       // fewer than 3 distinct nodes
    size_t tooSmall = 0;          // area below the minimum (zero-area rings included)
    size_t selfIntersecting = 0;  // no simple piece after splitting (or too many nodes to split)
    size_t outsideCity = 0;       // a vertex outside the city square (or an outlier node)
    size_t noOuterRing = 0;       // a relation without any outer ring
    // Completion of the imported buildings (generateCity).
    size_t heightFromTag = 0, heightFromLevels = 0, heightProcedural = 0;
    size_t roofFromTag = 0, roofProcedural = 0;
    size_t roofFallbackFlat = 0;  // gabled/hipped asked for, flat built (holes, or the roof code failed)
    size_t lotsDropped = 0;       // procedural lots overlapping an imported footprint
    size_t onCarriageway = 0;     // imported footprints reaching onto a street's carriageway (kept)
};

struct City {
    CityParams params;
    StreetGraph streets;
    std::vector<Block> blocks;
    std::vector<Lot> lots;
    std::vector<Building> buildings;
    std::vector<TreePrototype> treePrototypes;
    std::vector<TreeInstance> trees;
    std::vector<glm::dvec3> streetLights;  // night effect: lamp pole bases, city frame (empty otherwise)
    std::vector<ParkedCar> cars;           // parked cars (params.parked_car_share; parked_cars.h)
    std::vector<Tile> tiles;               // row-major by (iy, ix); only non-empty tiles
    std::vector<StageTime> stageTimes;
    OsmBuildingStats osmBuildings;  // all zero unless buildings came from OSM
    // The trees are written as impostors (citygen/tree_impostor.h: cross
    // billboards with a baked atlas) instead of their prototype meshes: the
    // coarse level of a paged city (RegionalCity::coarse).
    bool treeImpostors = false;
};

}  // namespace vista
