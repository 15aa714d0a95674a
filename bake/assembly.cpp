#include "bake/assembly.h"

#include <algorithm>

#include <osg/Geode>
#include <osg/MatrixTransform>
#include <osg/UserDataContainer>

#include "nodes/point_impostor.h"
#include "nodes/textured_depth_mesh.h"
#include "runtime/scene/scene_graph.h"

namespace vista {

osg::ref_ptr<ViewCellSwitch> assembleBakedScene(const SceneModel& city, const std::vector<ViewCell>& cells,
                                                const std::vector<CellResult>& results, const std::string& paramsText,
                                                BakeRepresentation representation, const std::string& sourceCityHash) {
    osg::ref_ptr<ViewCellSwitch> root = new ViewCellSwitch;
    root->setName("vista.city");
    osg::Group* cityRoot = sceneRoot(city) ? sceneRoot(city)->asGroup() : nullptr;
    if (cityRoot) {
        if (cityRoot->getUserDataContainer())
            root->setUserDataContainer(osg::clone(cityRoot->getUserDataContainer(), osg::CopyOp::DEEP_COPY_ALL));
        root->setStateSet(cityRoot->getStateSet());
        for (unsigned i = 0; i < cityRoot->getNumChildren(); ++i) root->addChild(cityRoot->getChild(i));
    }
    root->setTileCount(root->getNumChildren());
    root->setUserValue("vista.baked", 1);
    root->setUserValue("vista.bake_params", paramsText);
    if (representation == BakeRepresentation::Mesh)
        root->setUserValue("vista.bake_representation", std::string("mesh"));
    if (!sourceCityHash.empty()) root->setUserValue("vista.source_city_hash", sourceCityHash);
    // Cell ids are edge ids; the switch is indexed by edge id (absent edges get empty boxes).
    uint32_t maxId = 0;
    for (const auto& c : cells) maxId = std::max(maxId, c.id + 1);
    std::vector<ViewCellBox> boxes(maxId);
    for (const auto& c : cells) boxes[c.id] = c.box;
    root->setCells(boxes);
    std::vector<std::vector<uint32_t>> hidden(maxId), imps(maxId);
    for (const CellResult& cr : results) {
        for (const ImpostorResult& im : cr.impostors) {
            if (im.cell >= maxId) continue;
            osg::ref_ptr<osg::MatrixTransform> xf = new osg::MatrixTransform;
            xf->setName("impostor_" + std::to_string(im.cell) + "_" + std::to_string(int(im.end)));
            xf->setDataVariance(osg::Object::DYNAMIC);
            const ImpostorFrame& f = im.frame;
            const osg::Matrixd m(f.x.x, f.x.y, 0, 0, -f.x.y, f.x.x, 0, 0, 0, 0, 1, 0, f.origin.x, f.origin.y,
                                 f.origin.z, 1);
            xf->setMatrix(m);
            osg::ref_ptr<osg::Geode> geode = new osg::Geode;
            osg::ref_ptr<PointImpostor> pi = new PointImpostor;
            pi->setName(xf->getName());
            pi->setData(im.data);
            geode->addDrawable(pi.get());
            xf->addChild(geode.get());
            imps[im.cell].push_back(root->getNumChildren());
            root->addChild(xf.get());
            hidden[im.cell].insert(hidden[im.cell].end(), im.hiddenTiles.begin(), im.hiddenTiles.end());
        }
        for (const MeshResult& mr : cr.meshes) {
            if (mr.cell >= maxId) continue;
            osg::ref_ptr<osg::MatrixTransform> xf = new osg::MatrixTransform;
            xf->setName("lodmesh_" + std::to_string(mr.cell) + "_" + std::to_string(int(mr.end)));
            xf->setDataVariance(osg::Object::DYNAMIC);
            const ImpostorFrame& f = mr.frame;
            xf->setMatrix(osg::Matrixd(f.x.x, f.x.y, 0, 0, -f.x.y, f.x.x, 0, 0, 0, 0, 1, 0, f.origin.x, f.origin.y,
                                       f.origin.z, 1));
            osg::ref_ptr<osg::Geode> geode = new osg::Geode;
            osg::ref_ptr<TexturedDepthMesh> tm = new TexturedDepthMesh;
            tm->setName(xf->getName());
            tm->setCellId(mr.cell);
            tm->setEnd(int(mr.end));
            tm->setData(mr.mesh);
            geode->addDrawable(tm.get());
            xf->addChild(geode.get());
            imps[mr.cell].push_back(root->getNumChildren());
            root->addChild(xf.get());
            hidden[mr.cell].insert(hidden[mr.cell].end(), mr.hiddenTiles.begin(), mr.hiddenTiles.end());
        }
    }
    for (uint32_t c = 0; c < maxId; ++c) {
        std::sort(hidden[c].begin(), hidden[c].end());
        hidden[c].erase(std::unique(hidden[c].begin(), hidden[c].end()), hidden[c].end());
    }
    // Build the CSR lists in one go (setCellChildren per cell would be quadratic).
    osg::ref_ptr<osg::UIntArray> hs = new osg::UIntArray, hi = new osg::UIntArray, is = new osg::UIntArray,
                                 ii = new osg::UIntArray;
    hs->push_back(0);
    is->push_back(0);
    for (uint32_t c = 0; c < maxId; ++c) {
        hi->insert(hi->end(), hidden[c].begin(), hidden[c].end());
        ii->insert(ii->end(), imps[c].begin(), imps[c].end());
        hs->push_back(unsigned(hi->size()));
        is->push_back(unsigned(ii->size()));
    }
    root->setHiddenStart(hs.get());
    root->setHiddenItems(hi.get());
    root->setImpostorStart(is.get());
    root->setImpostorItems(ii.get());
    return root;
}

}  // namespace vista
