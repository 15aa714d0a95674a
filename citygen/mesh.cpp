#include "citygen/mesh.h"

#include <cstring>

namespace vista {

const char* materialName(Material m) {
    static const char* kNames[] = {"ground",       "road", "marking", "sidewalk",  "grass", "wall",
                                   "window",       "roof", "trunk",   "leaves",    "lamp",  "traffic_light",
                                   "traffic_sign", "car",  "vehicle", "pedestrian"};
    static_assert(sizeof(kNames) / sizeof(kNames[0]) == size_t(kMaterialCount));
    int i = int(m);
    return i >= 0 && i < kMaterialCount ? kNames[i] : "unknown";
}

Material materialFromName(const char* name) {
    for (int i = 0; i < kMaterialCount && name; ++i)
        if (std::strcmp(name, materialName(Material(i))) == 0) return Material(i);
    return Material::Count;
}

void Mesh::append(const Mesh& o) {
    uint32_t base = uint32_t(positions.size());
    if (!ids.empty() || !o.ids.empty()) {
        ids.resize(positions.size(), 0u);
        if (o.ids.size() == o.positions.size()) ids.insert(ids.end(), o.ids.begin(), o.ids.end());
        else ids.resize(positions.size() + o.positions.size(), 0u);
    }
    positions.insert(positions.end(), o.positions.begin(), o.positions.end());
    normals.insert(normals.end(), o.normals.begin(), o.normals.end());
    colors.insert(colors.end(), o.colors.begin(), o.colors.end());
    indices.reserve(indices.size() + o.indices.size());
    for (uint32_t i : o.indices) indices.push_back(base + i);
}

}  // namespace vista
