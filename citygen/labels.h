// Ground-truth labels: the stable instance id every mesh vertex carries and
// the semantic class table of `vista render` (docs/formats.md "Ground truth").
//
// Instance id (uint32): kind << 28 | index, index < 2^28. The index is a
// stable entity index of the generated City (the same for the same params,
// whatever the thread count): building index (City::buildings), tree index
// (City::trees), street edge index (carriageway pieces and lane markings of
// the edge), street node index (the junction polygon at the node), block
// index (sidewalk ring of the block; park lawn of a park block), street
// light index (City::streetLights), signal index (LaneModel::signals of
// lanes.h, for traffic lights and for stop and yield signs alike), parked car
// index (City::cars), moving vehicle and pedestrian: the agent's number in
// the traffic run (TrafficTracks, stable over the run). Ground
// (terrain) and sky are 0.
// Tree prototype meshes are shared by all trees: their vertices carry the
// Material of the part (Trunk, Leaves) instead; the tree's id comes from the
// instance. makeInstanceId() checks index < 2^28 (VISTA_CHECK).
//
// Semantic class (uint8): one per Material (semanticClass) plus sky = 0;
// classes whose effect a city does not declare (street_light: night) simply
// never occur; traffic_light and traffic_sign cover the whole signal, pole
// included (as street_light covers its pole). The moving agents of a traffic
// run take the class of their SUMO type (agent_models.h agentClass): car (as
// the parked cars; the instance kind tells a parked car from a moving one),
// van, bus, truck, bicycle (the bicycle with its rider) and pedestrian;
// vehicle is a moving vehicle of no other class (geometry of
// Material::Vehicle drawn without an agent's class). Pure functions;
// thread-safe.
#pragma once
#include <cstdint>

#include "citygen/mesh.h"
#include "foundation/status.h"

namespace vista {

enum class InstanceKind : uint32_t {
    None = 0,
    Building = 1,
    Tree = 2,
    Road = 3,
    Junction = 4,
    Sidewalk = 5,
    Park = 6,
    StreetLight = 7,
    TrafficLight = 8,
    TrafficSign = 9,
    Car = 10,
    Vehicle = 11,
    Pedestrian = 12,
    Count = 13  // number of kinds (not a kind)
};
constexpr uint32_t kInstanceIndexBits = 28;
constexpr uint32_t kInstanceIndexMask = (1u << kInstanceIndexBits) - 1u;

inline uint32_t makeInstanceId(InstanceKind kind, uint64_t index) {
    VISTA_CHECK(index <= kInstanceIndexMask);
    return uint32_t(kind) << kInstanceIndexBits | uint32_t(index);
}
inline InstanceKind instanceKind(uint32_t id) { return InstanceKind(id >> kInstanceIndexBits); }
inline uint32_t instanceIndex(uint32_t id) { return id & kInstanceIndexMask; }
const char* instanceKindName(InstanceKind k);  // "none", "building", ...; "unknown" out of range (Count included)

// Semantic classes (values are stable: datasets depend on them).
enum class SemanticClass : uint8_t {
    Sky = 0,
    Terrain = 1,
    Road = 2,
    LaneMarking = 3,
    Sidewalk = 4,
    Grass = 5,
    BuildingWall = 6,
    Window = 7,
    Roof = 8,
    TreeTrunk = 9,
    TreeLeaves = 10,
    StreetLight = 11,
    TrafficLight = 12,
    TrafficSign = 13,
    Car = 14,
    Vehicle = 15,
    Pedestrian = 16,
    Van = 17,
    Bus = 18,
    Truck = 19,
    Bicycle = 20,
    Count = 21
};
constexpr int kSemanticClassCount = int(SemanticClass::Count);
SemanticClass semanticClass(Material m);         // Count (invalid) for Material::Count
const char* semanticClassName(SemanticClass c);  // "sky", "terrain", ...; "unknown" out of range
// A colour per class for previews (RGB).
void semanticClassColor(SemanticClass c, uint8_t rgb[3]);

}  // namespace vista
