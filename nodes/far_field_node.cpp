// FarFieldNode: depth readback + FarField + glDrawPixels composite (see far_field_node.h).
#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include "nodes/far_field_node.h"

#include <osgUtil/CullVisitor>

#include <osg/Program>
#include "foundation/units.h"

#include <algorithm>
#include <cmath>

#include <osg/Camera>
#include <osg/Geode>
#include <osg/GL>
#include <osg/RenderInfo>
#include <osg/State>
#include <osg/Viewport>
#include <GL/glext.h>

#include "nodes/gl_readback.h"
#include "nodes/near_far_split.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_graph.h"
#include "nodes/near_field_chunks.h"
#include "runtime/engine/ray_scene.h"

namespace vista {

namespace {

// At cull time, before the near field is drawn: starts the frame's horizon and speculative
// rays (FarField::beginFrame) for the camera the draw will see.
struct BeginFrameAtCull : public osg::DrawableCullCallback {
    bool cull(osg::NodeVisitor* nv, osg::Drawable* d, osg::RenderInfo*) const override {
        const osg::Camera* cam = nv && nv->asCullVisitor() ? nv->asCullVisitor()->getCurrentCamera() : nullptr;
        if (cam) static_cast<FarFieldNode*>(d)->beginFrame(*cam);
        return false;
    }
};

}  // namespace

FarFieldNode::FarFieldNode(const RayScene& rays, const HeightGrid* grid, const FarFieldOptions& options)
    : _rays(rays), _grid(grid), _options(options) {
    setCullCallback(new BeginFrameAtCull);
    getOrCreateStateSet()->setRenderBinDetails(kFarFieldRenderBin, "RenderBin");
}

FarFieldNode::FarFieldNode(const FarFieldNode& o, const osg::CopyOp& copyop)
    : ReadbackDrawable(o, copyop), _rays(o._rays), _grid(o._grid), _options(o._options), _split(o._split) {}

FarFieldNode::~FarFieldNode() = default;

void FarFieldNode::setOptions(const FarFieldOptions& o) {
    std::lock_guard<std::mutex> lock(_mutex);
    _options = o;
}
FarFieldOptions FarFieldNode::options() const {
    std::lock_guard<std::mutex> lock(_mutex);
    return _options;
}
FarFieldOptions FarFieldNode::frameOptions(double zFar) const {
    FarFieldOptions o = _options;
    if (_split.valid()) {
        osg::ref_ptr<NearFarSplit> s;
        if (_split.lock(s)) {
            o.nearDistance = s->getNearDistance();
            o.nearIsDistance = s->getTriangleBudget() == 0;
        }
    }
    o.depthZFar = zFar;
    return o;
}

void FarFieldNode::beginFrame(const osg::Camera& cam) const {
    const osg::Viewport* vp = cam.getViewport();
    Camera c;
    double zFar = 0;
    if (!vp || vp->width() < 1 || vp->height() < 1 ||
        !cameraFromOsg(cam.getViewMatrix(), cam.getProjectionMatrix(), int(vp->width()), int(vp->height()), c, zFar))
        return;
    std::lock_guard<std::mutex> lock(_mutex);
    if (!_options.overlap) return;
    if (!_far) _far = std::make_unique<FarField>(_rays, _grid, _options);
    _far->setOptions(frameOptions(zFar));
    _far->beginFrame(c);
}

void FarFieldNode::sceneChanged(const SceneBoxes& changed) {
    std::lock_guard<std::mutex> lock(_mutex);
    if (_far) _far->sceneChanged(changed);
}

void FarFieldNode::drawFrame(osg::RenderInfo& ri, const Camera& c, const osg::Viewport& vp, double zFar) const {
    const int W = int(vp.width()), H = int(vp.height());
    if (!_far) _far = std::make_unique<FarField>(_rays, _grid, _options);
    const FarFieldOptions o = frameOptions(zFar);
    _far->setOptions(o);

    // Opacity buffer: the near field's depth (GL rows bottom-up -> row 0 at top).
    readDepthTopDown(GLint(vp.x()), GLint(vp.y()), W, H, _depthBits, _depth);

    if (_image.width != W || _image.height != H) _image = Image(W, H);
    // Near-field haze done by the far field (FarFieldOptions::hazeCovered):
    // it needs the drawn colours, and then every pixel is drawn back.
    const bool hazeCovered = o.hazeCovered && o.effects.haze;
    if (hazeCovered) { readColorTopDown(GLint(vp.x()), GLint(vp.y()), W, H, _colorBits, _image.rgba.data()); }
    _far->render(c, _depth.data(), _image, _stats);

    // Far-field pixels drawn, covered pixels (class 0) kept unless hazed here.
    drawImage(vp, hazeCovered ? nullptr : &_far->classification());
    // Anything OSG believes about bound programs/textures is unchanged (fixed function only used here).
    (void)ri.getState();
}

osg::ref_ptr<osg::Group> buildHybridScene(const SceneModel& city, const RayScene& rays, const HeightGrid& grid,
                                          const HybridSceneOptions& options, NearFarSplit** splitOut,
                                          FarFieldNode** farOut) {
    return buildHybridScene(buildNearFieldScene(sceneRoot(city)), rays, grid, options, splitOut, farOut);
}

osg::ref_ptr<osg::Group> buildHybridScene(const NearFieldScene& nf, const RayScene& rays, const HeightGrid& grid,
                                          const HybridSceneOptions& options, NearFarSplit** splitOut,
                                          FarFieldNode** farOut) {
    osg::ref_ptr<osg::Group> root = new osg::Group;
    root->setName("vista.hybrid");
    if (nf.rootState) root->setStateSet(nf.rootState.get());
    osg::ref_ptr<NearFarSplit> split = new NearFarSplit;
    split->setNearDistance(options.nearDistance);
    split->setTriangleBudget(options.triangleBudget);
    for (const auto& n : nf.chunks) split->addChild(n.get());
    root->addChild(split.get());
    osg::ref_ptr<FarFieldNode> far = new FarFieldNode(rays, &grid, options.far);
    far->setSplit(split.get());
    osg::ref_ptr<osg::Geode> geode = new osg::Geode;
    geode->setCullingActive(false);
    geode->addDrawable(far.get());
    root->addChild(geode.get());
    if (splitOut) *splitOut = split.get();
    if (farOut) *farOut = far.get();
    return root;
}

}  // namespace vista
