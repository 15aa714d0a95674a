// City: the complete generated model, before conversion to a scene file.
//
// Contract: all 2D/3D coordinates are double metres in the city frame (city
// centre at the origin, z up); the world position is params.origin + city
// frame. Polygons are simple, counter-clockwise, without repeated closing
// vertex. Indices between the arrays (lot.block, building.lot, tree.prototype)
// are valid. Meshes are grouped per tile, tile-local in float (see Tile).
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
    Polygon2 outline;     // inset from the street centre lines by half width + sidewalk
    bool park = false;
    double density = 0;   // density map value at the centroid, 0..1
};

struct Lot {
    uint32_t block = 0;
    Polygon2 outline;     // inside its block
    bool frontage = true; // touches a street side of the block
};

enum class RoofType : uint8_t { Flat = 0, Gabled = 1, Hipped = 2 };

struct Building {
    uint32_t lot = 0;
    Polygon2 footprint;   // inside its lot, with setbacks
    double base_z = 0;    // ground height under the footprint (min of terrain)
    double height = 0;    // wall height above base_z (eaves)
    int floors = 1;
    RoofType roof = RoofType::Flat;
    double roof_height = 0;  // ridge above the eaves (0 for flat)
};

// One tree shape (species x size variant), stored once and instanced.
struct TreePrototype {
    int species = 0;
    int variant = 0;
    double height = 0;
    Mesh mesh;            // in the tree's own frame (trunk base at the origin, z up)
};

struct TreeInstance {
    glm::dvec3 position{0.0};  // trunk base, city frame
    float yaw = 0;             // radians
    float scale = 1;
    uint16_t prototype = 0;
    bool street = true;        // street tree (true) or park tree (false)
};

// A square spatial tile of the output. Geometry is float relative to `origin`
// (city frame, double); the world origin of the tile is params.origin + origin.
struct Tile {
    int ix = 0, iy = 0;
    glm::dvec3 origin{0.0};
    std::array<Mesh, kMaterialCount> meshes;  // one per material
    std::vector<uint32_t> trees;               // indices into City::trees whose base lies in this tile
    std::vector<uint32_t> streetLights;        // indices into City::streetLights in this tile
};

struct StageTime {
    std::string name;
    double seconds = 0;
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
    std::vector<Tile> tiles;        // row-major by (iy, ix); only non-empty tiles
    std::vector<StageTime> stageTimes;
};

}  // namespace vista
