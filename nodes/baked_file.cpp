// Loading and checking a baked city file (baked_file.h).
#include "nodes/baked_file.h"

#include <osg/Geode>
#include <osg/MatrixTransform>

#include "nodes/point_impostor.h"
#include "nodes/textured_depth_mesh.h"
#include "runtime/scene/city_file.h"
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
    auto bad = [&](const std::string& why) { return Status::error("'" + path + "' is not a vista baked file: " + why); };
    auto* root = dynamic_cast<ViewCellSwitch*>(sceneRoot(bf.city));
    if (!root) return bad("the root is a plain city (run 'vista bake' first)");
    int baked = 0;
    if (!root->getUserValue("vista.baked", baked) || baked != 1) return bad("missing or unsupported user value vista.baked");
    const std::string why = root->validate();
    if (!why.empty()) return bad(why);
    bf.meshes = isMeshBake(root);
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

}  // namespace vista
