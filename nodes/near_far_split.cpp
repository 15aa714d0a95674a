// NearFarSplit cull node (see near_far_split.h).
#include "nodes/near_far_split.h"

#include <algorithm>
#include <cmath>

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
    std::vector<double> dist(sel.size());
    for (size_t k = 0; k < sel.size(); ++k) dist[k] = boxDistance(objs[sel[k]], eye);
    std::vector<size_t> order(sel.size());
    for (size_t k = 0; k < order.size(); ++k) order[k] = k;
    if (_frontToBack)
        std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return dist[a] < dist[b]; });
    // Flat twins: the bench face's rule with this cull's projection and viewport.
    const NearFieldScene* ds = _detailScene;
    const bool twins = ds && _detailPx > 0 && ds->coarseChunks.size() == objs.size() && cv->getViewport();
    double fovY = 0;
    int w = 0, h = 0;
    if (twins) {
        fovY = 2.0 * std::atan(1.0 / cv->getProjectionMatrix()->operator()(1, 1));
        w = int(cv->getViewport()->width());
        h = int(cv->getViewport()->height());
    }
    uint64_t tris = 0;
    for (size_t k : order) {
        const uint32_t i = sel[k];
        osg::Node* n = _srcChunks ? (*_srcChunks)[i].get() : _children[i].get();
        if (!n) continue;
        uint64_t t = objs[i].triangles;
        if (twins && ds->coarseChunks[i] && screenDeviationPx(ds->coarseError[i], dist[k], fovY, w, h) <= _detailPx) {
            n = ds->coarseChunks[i].get();
            t = ds->coarseTriangles[i];
        }
        n->accept(nv);
        tris += t;
    }
    _lastCount = unsigned(sel.size());
    _lastTriangles = tris;
}

}  // namespace vista
