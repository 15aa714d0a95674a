// NearFarSplit cull node (see near_far_split.h).
#include "nodes/near_far_split.h"

#include <osg/ComputeBoundsVisitor>
#include <osg/Geode>
#include <osg/Geometry>
#include <osgUtil/CullVisitor>

namespace vista {

namespace {

class TriangleCounter : public osg::NodeVisitor {
public:
    TriangleCounter() : osg::NodeVisitor(TRAVERSE_ALL_CHILDREN) {}
    uint64_t triangles = 0;
    void apply(osg::Drawable& d) override {
        osg::Geometry* g = d.asGeometry();
        if (!g) return;
        for (unsigned i = 0; i < g->getNumPrimitiveSets(); ++i) {
            const osg::PrimitiveSet* ps = g->getPrimitiveSet(i);
            uint64_t n = 0;
            switch (ps->getMode()) {
                case GL_TRIANGLES: n = ps->getNumIndices() / 3; break;
                case GL_TRIANGLE_STRIP:
                case GL_TRIANGLE_FAN: n = ps->getNumIndices() > 2 ? ps->getNumIndices() - 2 : 0; break;
                case GL_QUADS: n = ps->getNumIndices() / 2; break;
                default: break;
            }
            n *= uint64_t(std::max(1, ps->getNumInstances()));
            triangles += n;
        }
    }
};

}  // namespace

uint64_t countTriangles(osg::Node* node) {
    if (!node) return 0;
    TriangleCounter tc;
    node->accept(tc);
    return tc.triangles;
}

NearFarSplit::NearFarSplit() = default;

NearFarSplit::NearFarSplit(const NearFarSplit& o, const osg::CopyOp& copyop)
    : osg::Group(o, copyop), _nearDistance(o._nearDistance), _triangleBudget(o._triangleBudget) {}

bool NearFarSplit::insertChild(unsigned int index, osg::Node* child) {
    _dirty = true;
    return osg::Group::insertChild(index, child);
}
bool NearFarSplit::removeChildren(unsigned int pos, unsigned int n) {
    _dirty = true;
    return osg::Group::removeChildren(pos, n);
}
bool NearFarSplit::setChild(unsigned int i, osg::Node* node) {
    _dirty = true;
    return osg::Group::setChild(i, node);
}

void NearFarSplit::refresh() {
    _objects.assign(_children.size(), SplitObject());
    for (size_t i = 0; i < _children.size(); ++i) {
        osg::ComputeBoundsVisitor cbv;
        _children[i]->accept(cbv);
        const osg::BoundingBox& bb = cbv.getBoundingBox();
        SplitObject& o = _objects[i];
        if (bb.valid()) {
            o.lo = glm::dvec3(bb.xMin(), bb.yMin(), bb.zMin());
            o.hi = glm::dvec3(bb.xMax(), bb.yMax(), bb.zMax());
        } else {  // no geometry: a point at the bounding sphere centre
            const osg::BoundingSphere& bs = _children[i]->getBound();
            o.lo = o.hi = glm::dvec3(bs.center().x(), bs.center().y(), bs.center().z());
        }
        o.triangles = countTriangles(_children[i].get());
    }
    _index = std::make_unique<SplitIndex>(_objects);
    _dirty = false;
}

void NearFarSplit::setSource(const std::vector<osg::ref_ptr<osg::Node>>* chunks,
                             const std::vector<SplitObject>* objects, const SplitIndex* index) {
    _srcChunks = chunks;
    _srcObjects = objects;
    _srcIndex = index;
    setCullingActive(!index);  // an empty group's bound would cull the streamed chunks
}

const std::vector<SplitObject>& NearFarSplit::objects() {
    if (_srcIndex) return *_srcObjects;
    if (_dirty || _objects.size() != _children.size()) refresh();
    return _objects;
}

void NearFarSplit::traverse(osg::NodeVisitor& nv) {
    auto* cv = nv.asCullVisitor();
    if (!cv) {
        osg::Group::traverse(nv);
        return;
    }
    const std::vector<SplitObject>& objs = objects();
    osg::Vec3 e = cv->getEyePoint();
    glm::dvec3 eye(e.x(), e.y(), e.z());
    const SplitIndex& index = _srcIndex ? *_srcIndex : *_index;
    std::vector<uint32_t> sel;
    if (_triangleBudget == 0) sel = selectNearField(index, eye, _nearDistance);
    else if (_srcIndex) sel = selectNearFieldByBudget(index, eye, _triangleBudget);  // free slots are in no block
    else sel = selectNearFieldByBudget(objs, eye, _triangleBudget);
    uint64_t tris = 0;
    for (uint32_t i : sel) {
        osg::Node* n = _srcChunks ? (*_srcChunks)[i].get() : _children[i].get();
        if (!n) continue;
        n->accept(nv);
        tris += objs[i].triangles;
    }
    _lastCount = unsigned(sel.size());
    _lastTriangles = tris;
}

}  // namespace vista
