// Ground-truth label tables (labels.h).
#include "citygen/labels.h"

namespace vista {

const char* instanceKindName(InstanceKind k) {
    static const char* kNames[] = {"none",     "building", "tree",         "road",          "junction",
                                   "sidewalk", "park",     "street_light", "traffic_light", "traffic_sign",
                                   "car",      "vehicle",  "pedestrian"};
    static_assert(sizeof(kNames) / sizeof(kNames[0]) == size_t(InstanceKind::Count));
    const uint32_t i = uint32_t(k);
    return i < sizeof(kNames) / sizeof(kNames[0]) ? kNames[i] : "unknown";
}

SemanticClass semanticClass(Material m) {
    switch (m) {
        case Material::Ground: return SemanticClass::Terrain;
        case Material::Road: return SemanticClass::Road;
        case Material::Marking: return SemanticClass::LaneMarking;
        case Material::Sidewalk: return SemanticClass::Sidewalk;
        case Material::Grass: return SemanticClass::Grass;
        case Material::Wall: return SemanticClass::BuildingWall;
        case Material::Window: return SemanticClass::Window;
        case Material::Roof: return SemanticClass::Roof;
        case Material::Trunk: return SemanticClass::TreeTrunk;
        case Material::Leaves: return SemanticClass::TreeLeaves;
        case Material::Lamp: return SemanticClass::StreetLight;
        case Material::TrafficLight: return SemanticClass::TrafficLight;
        case Material::TrafficSign: return SemanticClass::TrafficSign;
        case Material::Car: return SemanticClass::Car;
        case Material::Vehicle: return SemanticClass::Vehicle;
        case Material::Pedestrian: return SemanticClass::Pedestrian;
        case Material::Count: break;
    }
    return SemanticClass::Count;
}

const char* semanticClassName(SemanticClass c) {
    static const char* kNames[] = {
        "sky",    "terrain", "road",       "lane_marking", "sidewalk",     "grass",         "building_wall",
        "window", "roof",    "tree_trunk", "tree_leaves",  "street_light", "traffic_light", "traffic_sign",
        "car",    "vehicle", "pedestrian", "van",          "bus",          "truck",         "bicycle"};
    static_assert(sizeof(kNames) / sizeof(kNames[0]) == size_t(kSemanticClassCount));
    const int i = int(c);
    return i >= 0 && i < kSemanticClassCount ? kNames[i] : "unknown";
}

void semanticClassColor(SemanticClass c, uint8_t rgb[3]) {
    static const uint8_t kColors[kSemanticClassCount][3] = {
        {70, 130, 180}, {152, 251, 152}, {128, 64, 128}, {255, 255, 255}, {244, 35, 232}, {107, 142, 35},
        {70, 70, 70},   {0, 130, 200},   {180, 60, 50},  {120, 80, 40},   {0, 160, 0},    {250, 170, 30},
        {255, 100, 0},  {220, 220, 0},   {0, 0, 142},    {0, 60, 100},    {220, 20, 60},  {0, 0, 110},
        {0, 60, 100},   {0, 0, 70},      {119, 11, 32}};
    const int i = int(c) < kSemanticClassCount ? int(c) : 0;  // unsigned underlying type: never negative
    for (int k = 0; k < 3; ++k) rgb[k] = int(c) == i ? kColors[i][k] : 0;
}

}  // namespace vista
