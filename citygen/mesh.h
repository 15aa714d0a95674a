// Mesh: indexed triangles with prelit per-vertex colours, in a local frame.
//
// Contract: positions are float metres relative to an origin held by the
// owner (a tile origin in double precision), so floats stay small anywhere on
// Earth. Colours are final prelit sRGB (see lighting.h): the rasteriser and the
// ray caster both show them unlit, so their images match. Triangles are
// counter-clockwise seen from outside. indices.size() is a multiple of 3 and
// every index < positions.size(); colors.size() == positions.size().
// ids: the ground-truth label of each vertex (citygen/labels.h: the entity's
// instance id in tile meshes, the part's Material in tree prototypes), either
// empty (untagged: every id 0) or ids.size() == positions.size().
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace vista {

// Surface materials; one output Geometry per tile and material.
// Lamp: street lights of the `night` effect (pole and emissive head); absent otherwise.
// TrafficLight, TrafficSign: the lane model's signals (traffic_signals.h), pole and head.
// Car: parked cars (parked_cars.h), every part of the car.
// Vehicle, Pedestrian: the moving agents of a traffic run (drawn at run time, never in a tile).
// Values are stable (tree prototypes store Trunk and Leaves by value): new ones go last.
enum class Material : uint8_t {
    Ground,
    Road,
    Marking,
    Sidewalk,
    Grass,
    Wall,
    Window,
    Roof,
    Trunk,
    Leaves,
    Lamp,
    TrafficLight,
    TrafficSign,
    Car,
    Vehicle,
    Pedestrian,
    Count
};
constexpr int kMaterialCount = int(Material::Count);
const char* materialName(Material m);
// The Material named `name` (materialName's inverse); Material::Count if none.
Material materialFromName(const char* name);

struct Mesh {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;   // per vertex, unit length (used for prelighting and export)
    std::vector<glm::u8vec4> colors;  // prelit
    std::vector<uint32_t> indices;
    std::vector<uint32_t> ids;  // per vertex label id (labels.h), or empty

    size_t triangleCount() const { return indices.size() / 3; }
    bool empty() const { return indices.empty(); }
    void append(const Mesh& other);  // concatenates, offsetting indices
};

}  // namespace vista
