// Binary glTF 2.0 (.glb) export of a City (see city_file.h, docs/formats.md).
//
// Layout: one buffer (the BIN chunk); per tile and non-empty material one
// mesh with one primitive (POSITION float VEC3 with min/max, NORMAL float
// VEC3, COLOR_0 normalised UNSIGNED_BYTE VEC4, indices UNSIGNED_INT); one node
// per tile (translation = tile origin in the city frame, i.e. relative to the
// city centre) whose children are the tile's material meshes and one node per
// tree instance (translation/rotation/scale relative to the tile) referencing
// the prototype's mesh. glTF is y-up: a root node rotates the z-up city frame
// (-90 degrees about x). The city's world origin is in asset.extras.vista.
// Output bytes depend only on the City.
#include <cmath>
#include <cstring>
#include <map>

#include <nlohmann/json.hpp>

#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_graph.h"
#include "foundation/atomic_file.h"

namespace vista {
namespace {

constexpr uint32_t kArrayBuffer = 34962, kElementArrayBuffer = 34963;
constexpr int kFloat = 5126, kUnsignedByte = 5121, kUnsignedInt = 5125;

class GlbBuilder {
public:
    nlohmann::ordered_json accessors = nlohmann::ordered_json::array();
    nlohmann::ordered_json views = nlohmann::ordered_json::array();
    std::string bin;

    size_t addView(const void* data, size_t bytes, uint32_t target) {
        while (bin.size() % 4) bin.push_back('\0');
        nlohmann::ordered_json v;
        v["buffer"] = 0;
        v["byteOffset"] = bin.size();
        v["byteLength"] = bytes;
        v["target"] = target;
        bin.append(static_cast<const char*>(data), bytes);
        views.push_back(v);
        return views.size() - 1;
    }
    size_t addAccessor(size_t view, int componentType, size_t count, const char* type, bool normalized = false) {
        nlohmann::ordered_json a;
        a["bufferView"] = view;
        a["componentType"] = componentType;
        if (normalized) a["normalized"] = true;
        a["count"] = count;
        a["type"] = type;
        accessors.push_back(a);
        return accessors.size() - 1;
    }
    // One primitive (attributes + indices) from a mesh.
    nlohmann::ordered_json addPrimitive(const Mesh& m) {
        const size_t n = m.positions.size();
        nlohmann::ordered_json prim;
        // POSITION with min/max.
        glm::vec3 lo(INFINITY), hi(-INFINITY);
        for (const auto& p : m.positions) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
        size_t pa = addAccessor(addView(m.positions.data(), n * sizeof(glm::vec3), kArrayBuffer), kFloat, n, "VEC3");
        accessors[pa]["min"] = {lo.x, lo.y, lo.z};
        accessors[pa]["max"] = {hi.x, hi.y, hi.z};
        prim["attributes"]["POSITION"] = pa;
        std::vector<glm::vec3> normals = m.normals;
        if (normals.size() != n) normals.assign(n, glm::vec3(0, 0, 1));
        for (auto& v : normals) {
            float l = glm::length(v);
            v = l > 0 && std::isfinite(l) ? v / l : glm::vec3(0, 0, 1);
        }
        prim["attributes"]["NORMAL"] =
            addAccessor(addView(normals.data(), n * sizeof(glm::vec3), kArrayBuffer), kFloat, n, "VEC3");
        prim["attributes"]["COLOR_0"] = addAccessor(addView(m.colors.data(), n * sizeof(glm::u8vec4), kArrayBuffer),
                                                    kUnsignedByte, n, "VEC4", true);
        prim["indices"] =
            addAccessor(addView(m.indices.data(), m.indices.size() * sizeof(uint32_t), kElementArrayBuffer),
                        kUnsignedInt, m.indices.size(), "SCALAR");
        prim["mode"] = 4;
        return prim;
    }
};

void checkMesh(const Mesh& m) {
    VISTA_CHECK(m.indices.size() % 3 == 0);
    VISTA_CHECK(m.colors.size() == m.positions.size());
    for (uint32_t i : m.indices) VISTA_CHECK(i < m.positions.size());
}

void appendLE32(std::string& s, uint32_t v) {
    for (int i = 0; i < 4; ++i) s.push_back(char((v >> (8 * i)) & 0xFF));
}

// Effects glTF can say: glass windows as a smooth dielectric material (a
// viewer with environment lighting reflects in them), street-light lamps as
// emissive. Haze, shadows and occlusion are in the colours or in
// asset.extras.vista.params.effects. No material without those effects; -1
// for a material not made.
void effectMaterials(const Effects& effects, nlohmann::ordered_json& materials, long& glass, long& lamp) {
    if (effects.glass) {
        materials.push_back(
            {{"name", "vista.glass"},
             {"pbrMetallicRoughness",
              {{"baseColorFactor", {1.0, 1.0, 1.0, 1.0}}, {"metallicFactor", 0.0}, {"roughnessFactor", 0.05}}}});
        glass = long(materials.size() - 1);
    }
    if (effects.night) {
        materials.push_back({{"name", "vista.lamp"}, {"emissiveFactor", {1.0, 0.95, 0.85}}});
        lamp = long(materials.size() - 1);
    }
}

}  // namespace

Status writeGltf(const City& city, const std::string& path) {
    static_assert(sizeof(glm::vec3) == 12 && sizeof(glm::u8vec4) == 4, "packed glm types expected");
    GlbBuilder b;
    nlohmann::ordered_json meshes = nlohmann::ordered_json::array();
    nlohmann::ordered_json nodes = nlohmann::ordered_json::array();

    // Node 0: root, turning the z-up city frame into glTF's y-up frame.
    nodes.push_back({{"name", "vista.city"},
                     {"rotation", {-std::sqrt(0.5), 0.0, 0.0, std::sqrt(0.5)}},
                     {"children", nlohmann::ordered_json::array()}});

    // Tree prototypes: one mesh each (empty prototypes get no mesh).
    std::vector<long> protoMesh(city.treePrototypes.size(), -1);
    for (size_t i = 0; i < city.treePrototypes.size(); ++i) {
        const Mesh& m = city.treePrototypes[i].mesh;
        if (m.empty()) continue;
        checkMesh(m);
        nlohmann::ordered_json mesh;
        mesh["name"] = kTreeGeometryPrefix + std::to_string(i);
        mesh["primitives"] = nlohmann::ordered_json::array({b.addPrimitive(m)});
        meshes.push_back(mesh);
        protoMesh[i] = long(meshes.size() - 1);
    }

    nlohmann::ordered_json materials = nlohmann::ordered_json::array();
    long glassMaterial = -1, lampMaterial = -1;
    effectMaterials(city.params.effects, materials, glassMaterial, lampMaterial);

    for (const Tile& tile : city.tiles) {
        const std::string tname = "tile_" + std::to_string(tile.ix) + "_" + std::to_string(tile.iy);
        nlohmann::ordered_json children = nlohmann::ordered_json::array();
        for (int mi = 0; mi < kMaterialCount; ++mi) {
            const Mesh& m = tile.meshes[size_t(mi)];
            if (m.empty()) continue;
            checkMesh(m);
            nlohmann::ordered_json mesh;
            mesh["name"] = tname + "_" + materialName(Material(mi));
            nlohmann::ordered_json prim = b.addPrimitive(m);
            if (Material(mi) == Material::Window && glassMaterial >= 0) prim["material"] = glassMaterial;
            if (Material(mi) == Material::Lamp && lampMaterial >= 0) prim["material"] = lampMaterial;
            mesh["primitives"] = nlohmann::ordered_json::array({prim});
            meshes.push_back(mesh);
            nodes.push_back({{"name", mesh["name"]}, {"mesh", meshes.size() - 1}});
            children.push_back(nodes.size() - 1);
        }
        for (uint32_t ti : tile.trees) {
            VISTA_CHECK(ti < city.trees.size());
            const TreeInstance& t = city.trees[ti];
            VISTA_CHECK(t.prototype < city.treePrototypes.size());
            if (protoMesh[t.prototype] < 0) continue;
            glm::dvec3 local = t.position - tile.origin;
            double h = 0.5 * double(t.yaw);
            nlohmann::ordered_json n;
            n["name"] = "tree_" + std::to_string(ti);
            n["mesh"] = protoMesh[t.prototype];
            n["translation"] = {float(local.x), float(local.y), float(local.z)};
            n["rotation"] = {0.0f, 0.0f, float(std::sin(h)), float(std::cos(h))};
            n["scale"] = {t.scale, t.scale, t.scale};
            nodes.push_back(n);
            children.push_back(nodes.size() - 1);
        }
        if (children.empty()) continue;
        nodes.push_back({{"name", tname},
                         {"translation", {float(tile.origin.x), float(tile.origin.y), float(tile.origin.z)}},
                         {"children", children}});
        nodes[0]["children"].push_back(nodes.size() - 1);
    }

    nlohmann::ordered_json j;
    j["asset"]["version"] = "2.0";
    j["asset"]["generator"] = "vista";
    j["asset"]["extras"]["vista"] = {
        {"origin_x", city.params.origin_x},
        {"origin_y", city.params.origin_y},
        {"tile_size_m", city.params.tile_size_m},
        {"up", "z (root node rotates to glTF y-up)"},
        {"params", nlohmann::ordered_json::parse(paramsToJson(city.params), nullptr, false)}};
    j["scene"] = 0;
    j["scenes"] = nlohmann::ordered_json::array({{{"name", "vista.city"}, {"nodes", {0}}}});
    j["nodes"] = nodes;
    if (!meshes.empty()) j["meshes"] = meshes;
    if (!materials.empty()) j["materials"] = materials;
    if (!b.accessors.empty()) j["accessors"] = b.accessors;
    if (!b.views.empty()) j["bufferViews"] = b.views;
    while (b.bin.size() % 4) b.bin.push_back('\0');
    if (!b.bin.empty()) j["buffers"] = nlohmann::ordered_json::array({{{"byteLength", b.bin.size()}}});

    std::string jsonText = j.dump();
    while (jsonText.size() % 4) jsonText.push_back(' ');
    const uint64_t total = 12 + 8 + uint64_t(jsonText.size()) + (b.bin.empty() ? 0 : 8 + uint64_t(b.bin.size()));
    if (total > 0xFFFFFFFFull)
        return Status::error("option --gltf: the city as glTF would be " + std::to_string(total) +
                             " bytes, above the 4 GiB limit of a .glb file; use a smaller --size");
    std::string out;
    out.reserve(size_t(total));
    out.append("glTF");
    appendLE32(out, 2);
    appendLE32(out, uint32_t(total));
    appendLE32(out, uint32_t(jsonText.size()));
    appendLE32(out, 0x4E4F534Au);  // "JSON"
    out.append(jsonText);
    if (!b.bin.empty()) {
        appendLE32(out, uint32_t(b.bin.size()));
        appendLE32(out, 0x004E4942u);  // "BIN\0"
        out.append(b.bin);
    }
    return writeFileAtomic(path, out);
}

}  // namespace vista
