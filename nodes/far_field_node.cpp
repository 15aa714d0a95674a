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
    setUseDisplayList(false);
    setUseVertexBufferObjects(false);
    setCullingActive(false);
    setDataVariance(osg::Object::DYNAMIC);
    getOrCreateStateSet()->setRenderBinDetails(kFarFieldRenderBin, "RenderBin");
    useFixedFunction(*getOrCreateStateSet());
}

void useFixedFunction(osg::StateSet& ss) {
    // An osg::Program without shaders applies as glUseProgram(0).
    ss.setAttributeAndModes(new osg::Program, osg::StateAttribute::ON | osg::StateAttribute::OVERRIDE | osg::StateAttribute::PROTECTED);
}

FarFieldNode::FarFieldNode(const FarFieldNode& o, const osg::CopyOp& copyop)
    : osg::Drawable(o, copyop), _rays(o._rays), _grid(o._grid), _options(o._options), _split(o._split) {}

FarFieldNode::~FarFieldNode() = default;

void FarFieldNode::setOptions(const FarFieldOptions& o) {
    std::lock_guard<std::mutex> lock(_mutex);
    _options = o;
}
FarFieldOptions FarFieldNode::options() const {
    std::lock_guard<std::mutex> lock(_mutex);
    return _options;
}
FrameStats FarFieldNode::lastStats() const {
    std::lock_guard<std::mutex> lock(_mutex);
    return _stats;
}

osg::BoundingBox FarFieldNode::computeBoundingBox() const {
    // Drawn whenever its parent is: culling is off; a tiny box keeps near/far computation unaffected.
    return osg::BoundingBox();
}

// vista::Camera from OSG matrices (world frame, x east, y north, z up).
bool cameraFromOsg(const osg::Matrixd& view, const osg::Matrixd& proj, int w, int h, Camera& c, double& zFar) {
    double fovy = 0, aspect = 0, zn = 0, zf = 0;
    if (!proj.getPerspective(fovy, aspect, zn, zf)) return false;
    osg::Matrixd inv = osg::Matrixd::inverse(view);
    osg::Vec3d eye = inv.getTrans();
    osg::Vec3d f = osg::Matrixd::transform3x3(osg::Vec3d(0, 0, -1), inv);
    osg::Vec3d up = osg::Matrixd::transform3x3(osg::Vec3d(0, 1, 0), inv);
    f.normalize();
    up.normalize();
    c.eye = glm::dvec3(eye.x(), eye.y(), eye.z());
    c.heading = std::atan2(f.x(), f.y());
    c.pitch = std::asin(std::clamp(f.z(), -1.0, 1.0));
    glm::dvec3 fg(f.x(), f.y(), f.z()), ug(up.x(), up.y(), up.z());
    glm::dvec3 r0(std::cos(c.heading), -std::sin(c.heading), 0.0);
    glm::dvec3 u0 = glm::cross(r0, fg);
    glm::dvec3 right = glm::cross(fg, ug);
    c.roll = std::atan2(-glm::dot(right, u0), glm::dot(right, r0));
    if (std::abs(c.roll) < 1e-9) c.roll = 0;
    c.fovY = fovy * kPi / 180.0;
    c.width = w;
    c.height = h;
    c.zNear = zn;
    zFar = std::isfinite(zf) && zf > zn ? zf : 0.0;  // infinite far plane
    return std::isfinite(c.eye.x) && c.fovY > 0;
}

void drawImageOverViewport(const osg::Viewport& vp, const Image& image, const std::vector<uint8_t>* mask,
                           std::vector<uint8_t>& upload) {
    const int W = image.width, H = image.height;
    if (W != int(vp.width()) || H != int(vp.height()) || !image.valid()) return;
    // GL rows bottom-up; pixels to keep get alpha 0 and are alpha-tested away.
    upload.resize(size_t(W) * size_t(H) * 4);
    for (int y = 0; y < H; ++y) {
        const size_t src = size_t(y) * size_t(W), dst = size_t(H - 1 - y) * size_t(W);
        for (int x = 0; x < W; ++x) {
            const uint8_t* p = &image.rgba[(src + size_t(x)) * 4];
            uint8_t* q = &upload[(dst + size_t(x)) * 4];
            q[0] = p[0];
            q[1] = p[1];
            q[2] = p[2];
            // Kept pixels keep their alpha (glass marks >= kGlassAlpha pass the alpha test).
            q[3] = mask && (*mask)[src + size_t(x)] == 0 ? 0 : std::max<uint8_t>(p[3], 129);
        }
    }
    glPushAttrib(GL_ALL_ATTRIB_BITS);
    glPushClientAttrib(GL_CLIENT_PIXEL_STORE_BIT);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_LIGHTING);
    glDisable(GL_TEXTURE_2D);
    glDisable(GL_BLEND);
    glDisable(GL_FOG);  // the far-field image is hazed already
    glEnable(GL_ALPHA_TEST);
    glAlphaFunc(GL_GREATER, 0.5f);
    glDepthMask(GL_FALSE);
    glWindowPos2i(GLint(vp.x()), GLint(vp.y()));
    glDrawPixels(W, H, GL_RGBA, GL_UNSIGNED_BYTE, upload.data());
    glPopClientAttrib();
    glPopAttrib();
}

bool currentView(osg::RenderInfo& ri, Camera& camera, const osg::Viewport*& vp, double& zFar) {
    const osg::Camera* cam = ri.getCurrentCamera();
    vp = cam ? cam->getViewport() : nullptr;
    if (!vp || vp->width() < 1 || vp->height() < 1) return false;
    return cameraFromOsg(cam->getViewMatrix(), cam->getProjectionMatrix(), int(vp->width()), int(vp->height()), camera, zFar);
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

void FarFieldNode::drawImplementation(osg::RenderInfo& ri) const {
    std::lock_guard<std::mutex> lock(_mutex);
    Camera c;
    const osg::Viewport* vp = nullptr;
    double zFar = 0;
    if (!currentView(ri, c, vp, zFar)) return;
    const int W = int(vp->width()), H = int(vp->height());
    if (!_far) _far = std::make_unique<FarField>(_rays, _grid, _options);
    const FarFieldOptions o = frameOptions(zFar);
    _far->setOptions(o);

    // Opacity buffer: the near field's depth (GL rows bottom-up -> row 0 at top).
    readDepthTopDown(GLint(vp->x()), GLint(vp->y()), W, H, _depthBits, _depth);

    _stats = FrameStats();
    if (_image.width != W || _image.height != H) _image = Image(W, H);
    // Near-field haze done by the far field (FarFieldOptions::hazeCovered):
    // it needs the drawn colours, and then every pixel is drawn back.
    const bool hazeCovered = o.hazeCovered && o.effects.haze;
    if (hazeCovered) {
        readColorTopDown(GLint(vp->x()), GLint(vp->y()), W, H, _colorBits, _image.rgba.data());
    }
    _far->render(c, _depth.data(), _image, _stats);

    // Far-field pixels drawn, covered pixels (class 0) kept unless hazed here.
    drawImageOverViewport(*vp, _image, hazeCovered ? nullptr : &_far->classification(), _upload);
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
