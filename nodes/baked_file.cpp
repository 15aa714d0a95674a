// Loading and checking a baked city file (baked_file.h).
#include "nodes/baked_file.h"

#include <osg/Geode>
#include <osg/MatrixTransform>

#include "nodes/point_impostor.h"
#include "nodes/textured_depth_mesh.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_file.h"
#include "runtime/scene/scene_graph.h"

namespace vista {

bool isMeshBake(const osg::Node* root) {
    std::string repr;
    return root && root->getUserValue("vista.bake_representation", repr) && repr == "mesh";
}

Result<BakedFile> loadBakedFile(const std::string& path) {
    auto city = loadCityFile(path);
    if (!city) return city.status();
    BakedFile bf;
    bf.city = std::move(*city);
    auto bad = [&](const std::string& why) {
        return Status::error("'" + path + "' is not a vista baked file: " + why);
    };
    auto* root = dynamic_cast<ViewCellSwitch*>(sceneRoot(bf.city));
    if (!root) return bad("the root is a plain city (run 'vista bake' first)");
    int baked = 0;
    if (!root->getUserValue("vista.baked", baked) || baked != 1)
        return bad("missing or unsupported user value vista.baked");
    const std::string why = root->validate();
    if (!why.empty()) return bad(why);
    bf.meshes = isMeshBake(root);
    root->getUserValue("vista.source_city_hash", bf.sourceCityHash);
    for (unsigned i = root->getTileCount(); i < root->getNumChildren(); ++i) {
        auto* xf = dynamic_cast<osg::MatrixTransform*>(root->getChild(i));
        osg::Geode* g = xf && xf->getNumChildren() == 1 ? xf->getChild(0)->asGeode() : nullptr;
        if (bf.meshes) {
            auto* tm = g && g->getNumDrawables() == 1 ? dynamic_cast<TexturedDepthMesh*>(g->getDrawable(0)) : nullptr;
            if (!tm) return bad("child " + std::to_string(i) + " is not a textured depth mesh node");
            if (const std::string w = tm->validate(); !w.empty()) return bad("child " + std::to_string(i) + ": " + w);
            ++bf.meshCount;
            bf.meshTriangles += tm->triangleCount();
            continue;
        }
        auto* pi = g && g->getNumDrawables() == 1 ? dynamic_cast<PointImpostor*>(g->getDrawable(0)) : nullptr;
        if (!pi) return bad("child " + std::to_string(i) + " is not an impostor node");
        if (const std::string w = pi->validate(); !w.empty()) return bad("child " + std::to_string(i) + ": " + w);
        ++bf.impostors;
        bf.points += pi->pointCount();
    }
    bf.root = root;
    return bf;
}

Result<std::string> cityIdentity(const std::string& path, const osg::Node* root) {
    int baked = 0;
    if (root && root->getUserValue("vista.baked", baked) && baked == 1) {
        std::string h;
        root->getUserValue("vista.source_city_hash", h);
        return h;
    }
    return sceneFileContentHash(path);
}

Status checkBakedFromCity(const std::string& bakedPath, const BakedFile& baked, const std::string& cityPath,
                          const osg::Node* cityRoot, std::string* warning) {
    if (warning) warning->clear();
    auto city = cityIdentity(cityPath, cityRoot);
    if (!city) return city.status();
    const std::string unchecked = baked.sourceCityHash.empty() ? bakedPath : city->empty() ? cityPath : "";
    if (!unchecked.empty()) {
        if (warning)
            *warning =
                "'" + unchecked +
                "' records no source city hash (baked before vista.source_city_hash existed): cannot check that '" +
                bakedPath + "' was baked from '" + cityPath + "'; rebake to add it";
        return Status::ok();
    }
    if (*city == baked.sourceCityHash) return Status::ok();
    return Status::error("baked from another city: '" + bakedPath + "' was baked from a city with hash " +
                         baked.sourceCityHash + ", '" + cityPath + "' has hash " + *city +
                         "; rebake with 'vista bake " + cityPath + " -o " + bakedPath +
                         (baked.meshes ? " --representation mesh" : "") +
                         "' (from the plain city file) or pass the city it was baked from");
}

}  // namespace vista
