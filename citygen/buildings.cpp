// STUB
#include "citygen/buildings.h"
namespace vista {
std::vector<Building> placeBuildings(const std::vector<Lot>&, const std::vector<Block>&, const CityParams&, Progress*) { return {}; }
void meshBuilding(const Building&, uint32_t, const CityParams&, const Lighting&, const glm::dvec3&, BuildingMeshes) {}
}
