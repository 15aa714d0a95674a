#include "citygen/mesh.h"

namespace vista {

const char* materialName(Material m) {
    static const char* kNames[] = {"ground", "road", "marking", "sidewalk", "grass", "wall", "window", "roof", "trunk", "leaves", "lamp"};
    int i = int(m);
    return i >= 0 && i < kMaterialCount ? kNames[i] : "unknown";
}

void Mesh::append(const Mesh& o) {
    uint32_t base = uint32_t(positions.size());
    positions.insert(positions.end(), o.positions.begin(), o.positions.end());
    normals.insert(normals.end(), o.normals.begin(), o.normals.end());
    colors.insert(colors.end(), o.colors.begin(), o.colors.end());
    indices.reserve(indices.size() + o.indices.size());
    for (uint32_t i : o.indices) indices.push_back(base + i);
}

}  // namespace vista
