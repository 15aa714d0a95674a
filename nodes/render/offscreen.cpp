// OffscreenRenderer: osgViewer window (works under Xvfb + llvmpipe) with
// explicit view/projection, CPU sky background, glFinish timing and readback.
#include "nodes/render/offscreen.h"
#include "nodes/render/effects_state.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>

#include <osg/GL>
#include <osg/GLExtensions>
#include <osg/GLObjects>
#include <osg/Geometry>
#include <osg/Image>
#include <osg/Texture>
#include <osgUtil/RenderStage>
#include <osgUtil/SceneView>
#include <osgUtil/StateGraph>
#include <osgViewer/Renderer>
#include <osgViewer/Viewer>

#include <glm/gtc/type_ptr.hpp>

#include "foundation/timing.h"
#include "nodes/gl_readback.h"

namespace vista {

namespace {

// Final draw callback: waits for the GL, reads colour and depth back.
struct Readback : public osg::Camera::DrawCallback {
    int width = 0, height = 0;
    std::vector<uint8_t>* color = nullptr;
    std::vector<float>* depth = nullptr;
    const Stopwatch* frame = nullptr;  // started when the frame began
    mutable double finishedMs = 0;     // frame time at which the GL finished drawing
    mutable double readMs = 0;
    mutable std::string renderer;
    mutable std::vector<uint32_t> depthBits, colorBits;  // scratch of the reads
    // setCountFragments: the query FragmentQueryBegin started, its result.
    bool countFragments = false;
    mutable GLuint query = 0;
    mutable bool queryOpen = false;
    mutable uint64_t fragments = 0;
    void operator()(osg::RenderInfo& info) const override {
        if (queryOpen) {
            const osg::GLExtensions* ext = info.getState()->get<osg::GLExtensions>();
            ext->glEndQuery(GL_SAMPLES_PASSED_ARB);
            GLuint64 n = 0;
            ext->glGetQueryObjectui64v(query, GL_QUERY_RESULT_ARB, &n);
            fragments = uint64_t(n);
            queryOpen = false;
        }
        glFinish();
        finishedMs = frame ? frame->ms() : 0.0;
        Stopwatch read;
        if (renderer.empty()) {
            const char* r = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
            const char* v = reinterpret_cast<const char*>(glGetString(GL_VERSION));
            renderer = std::string(r ? r : "?") + " / OpenGL " + (v ? v : "?");
        }
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glReadBuffer(GL_BACK);
        if (color) {
            color->resize(size_t(width) * size_t(height) * 4);
            readColorTopDown(0, 0, width, height, colorBits, color->data());  // row 0 at top
        }
        if (depth) readDepthTopDown(0, 0, width, height, depthBits, *depth);  // row 0 at top
        readMs = read.ms();
    }
};

// Initial draw callback: starts the frame's samples-passed query (Readback ends it).
struct FragmentQueryBegin : public osg::Camera::DrawCallback {
    const Readback* readback = nullptr;
    void operator()(osg::RenderInfo& info) const override {
        if (!readback->countFragments) return;
        const osg::GLExtensions* ext = info.getState()->get<osg::GLExtensions>();
        if (!ext->glGenQueries || !ext->glBeginQuery || !ext->glGetQueryObjectui64v) return;
        if (!readback->query) ext->glGenQueries(1, &readback->query);
        ext->glBeginQuery(GL_SAMPLES_PASSED_ARB, readback->query);
        readback->queryOpen = true;
    }
};

// Counts triangles and draw calls of everything culled into a render stage.
struct PrimitiveCounter {
    const osg::Drawable* skip = nullptr;
    uint64_t triangles = 0, drawCalls = 0;
    void leaf(const osgUtil::RenderLeaf* l) {
        const osg::Drawable* d = l->getDrawable();
        if (!d || d == skip) return;
        const osg::Geometry* g = d->asGeometry();
        if (!g) {  // e.g. impostor sprites: one quad
            triangles += 2;
            drawCalls += 1;
            return;
        }
        for (unsigned i = 0; i < g->getNumPrimitiveSets(); ++i) {
            const osg::PrimitiveSet* ps = g->getPrimitiveSet(i);
            uint64_t n = ps->getNumIndices(), inst = uint64_t(std::max(1, ps->getNumInstances())), t = 0;
            switch (ps->getMode()) {
                case GL_TRIANGLES: t = n / 3; break;
                case GL_TRIANGLE_STRIP:
                case GL_TRIANGLE_FAN: t = n >= 3 ? n - 2 : 0; break;
                case GL_QUADS: t = n / 2; break;
                case GL_QUAD_STRIP: t = n >= 4 ? n - 2 : 0; break;
                default: t = 0;
            }
            triangles += t * inst;
            drawCalls += 1;
        }
    }
    void bin(const osgUtil::RenderBin* b) {
        if (!b) return;
        for (const auto& kv : b->getRenderBinList()) bin(kv.second.get());
        for (const auto* l : b->getRenderLeafList()) leaf(l);
        for (const auto* sg : b->getStateGraphList())
            for (const auto& l : sg->_leaves) leaf(l.get());
    }
    void stage(const osgUtil::RenderStage* s) {
        if (!s) return;
        for (const auto& p : s->getPreRenderList()) stage(p.second.get());
        bin(s);
        for (const auto& p : s->getPostRenderList()) stage(p.second.get());
    }
};

osg::Matrixd toOsg(const glm::dmat4& m) { return osg::Matrixd(glm::value_ptr(m)); }

}  // namespace

void setExactCulling(osg::Camera& cam) {
    cam.setComputeNearFarMode(osg::CullSettings::DO_NOT_COMPUTE_NEAR_FAR);
    cam.setCullingMode(
        (cam.getCullingMode() | osg::CullSettings::NEAR_PLANE_CULLING | osg::CullSettings::FAR_PLANE_CULLING) &
        ~osg::CullSettings::SMALL_FEATURE_CULLING);
}

namespace {

// osgViewer::Renderer whose scene views flush deleted GL objects every
// `frames` frames (Renderer::updateSceneView turns the automatic flush on for
// every frame; SceneView::draw flushes when the frame before had it on).
class PeriodicFlushRenderer : public osgViewer::Renderer {
public:
    PeriodicFlushRenderer(osg::Camera* camera, unsigned frames)
        : osgViewer::Renderer(camera), _frames(std::max(1u, frames)) {}

protected:
    void updateSceneView(osgUtil::SceneView* sceneView) override {
        osgViewer::Renderer::updateSceneView(sceneView);
        if (!sceneView->getAutomaticFlush()) return;  // an incremental compile operation flushes
        sceneView->setAutomaticFlush(++_count % _frames == 0);
    }

private:
    unsigned _frames;
    unsigned _count = 0;
};

// The renderer's window is never shown: its frames are read back from the
// back buffer, so swapping (under Xvfb a copy of the whole window to the X
// server, 0.6 to 0.9 ms a frame at 640x480 to 1280x720) is skipped. The
// ray-cast modes present nothing either.
struct NoPresent : public osg::GraphicsContext::SwapCallback {
    void swapBuffersImplementation(osg::GraphicsContext*) override {}
};

}  // namespace

void flushDeletedGLObjectsEvery(osg::Camera& camera, unsigned frames) {
    camera.setRenderer(new PeriodicFlushRenderer(&camera, frames));
}

struct OffscreenRenderer::Impl {
    int width = 0, height = 0;
    osg::ref_ptr<osgViewer::Viewer> viewer;
    osg::ref_ptr<osg::Group> root, slot;
    osg::ref_ptr<osg::Node> overlay, labelOverlay;  // setOverlay
    std::unique_ptr<SkyBackground> sky;
    osg::ref_ptr<Readback> readback;
    std::vector<uint8_t> colorBuf;
    double jx = 0, jy = 0;
    FrameEffects effects;
    // Label pass (created on first use): an FBO camera drawn before the main one.
    osg::ref_ptr<osg::Camera> labelCam;
    osg::ref_ptr<osg::Group> labelSlot;
    osg::ref_ptr<osg::Image> labelIds, labelDepth;

    void makeLabelCamera() {
        labelCam = new osg::Camera;
        labelCam->setName("vista.label_pass");
        labelCam->setReferenceFrame(osg::Transform::ABSOLUTE_RF);
        labelCam->setRenderOrder(osg::Camera::PRE_RENDER);
        labelCam->setRenderTargetImplementation(osg::Camera::FRAME_BUFFER_OBJECT);
        labelCam->setViewport(0, 0, width, height);
        labelCam->setClearColor(osg::Vec4(0, 0, 0, 0));
        labelCam->setClearMask(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        setExactCulling(*labelCam);
        labelIds = new osg::Image;
        labelIds->allocateImage(width, height, 1, GL_RGBA, GL_UNSIGNED_BYTE);
        labelIds->setInternalTextureFormat(GL_RGBA8);
        labelDepth = new osg::Image;
        labelDepth->allocateImage(width, height, 1, GL_RGBA, GL_FLOAT);
        labelDepth->setInternalTextureFormat(GL_RGBA32F_ARB);
        labelCam->attach(osg::Camera::COLOR_BUFFER0, labelIds.get());
        labelCam->attach(osg::Camera::COLOR_BUFFER1, labelDepth.get());
        labelCam->attach(osg::Camera::DEPTH_BUFFER, GL_DEPTH_COMPONENT24);
        labelSlot = new osg::Group;
        labelCam->addChild(labelSlot.get());
        labelCam->setNodeMask(0);
        root->addChild(labelCam.get());
    }

    Status draw(osg::Node* scene, const Camera& camera, double zFar, Image* color, std::vector<float>* depth,
                FrameStats& stats) {
        osg::Camera* cam = viewer->getCamera();
        cam->setViewMatrix(toOsg(camera.view()));
        osg::Matrixd proj = toOsg(camera.projection(effectsFarPlane(zFar, effects)));
        if (jx != 0 || jy != 0) proj = proj * osg::Matrixd::translate(-2.0 * jx / width, 2.0 * jy / height, 0.0);
        cam->setProjectionMatrix(proj);
        const unsigned want = (scene ? 1u : 0u) + (overlay ? 1u : 0u);
        if (slot->getNumChildren() != want || (scene && slot->getChild(0) != scene)) {
            slot->removeChildren(0, slot->getNumChildren());
            if (scene) slot->addChild(scene);
            if (overlay) slot->addChild(overlay.get());
        }
        readback->color = color ? &colorBuf : nullptr;
        readback->depth = depth;
        Stopwatch frame;
        readback->frame = &frame;
        viewer->frame();
        readback->frame = nullptr;
        const double frameMs = frame.ms();
        if (!readback->renderer.size()) return Status::error("offscreen render: the draw callback did not run");

        stats.frameMs = frameMs;
        double cull = 0;
        osg::Stats* st = cam->getStats();
        unsigned fn = viewer->getFrameStamp()->getFrameNumber();
        if (st && st->getAttribute(fn, "Cull traversal time taken", cull)) stats.cullMs = cull * 1000.0;
        stats.drawMs = std::max(0.0, readback->finishedMs - stats.cullMs);
        stats.stages.set(Stage::Readback, readback->readMs);

        PrimitiveCounter pc;
        pc.skip = sky->drawable();
        if (auto* r = dynamic_cast<osgViewer::Renderer*>(cam->getRenderer()))
            if (osgUtil::SceneView* sv = r->getSceneView(0)) pc.stage(sv->getRenderStage());
        stats.triangles = pc.triangles;
        stats.drawCalls = pc.drawCalls;

        if (color) {
            if (color->width != width || color->height != height) *color = Image(width, height);
            color->rgba.swap(colorBuf);  // read top-down already; the old buffer is the next frame's
        }
        return Status::ok();
    }
};

OffscreenRenderer::OffscreenRenderer() : _impl(new Impl) {}
OffscreenRenderer::~OffscreenRenderer() {
    if (_impl && _impl->viewer) {
        // The graphs drawn here outlive the renderer (a city drawn again by a later
        // renderer, whose context may get this one's id): their GL objects of this
        // context are released while it is current, so no node keeps a name of a
        // closed context.
        osg::GraphicsContext* gc = _impl->viewer->getCamera()->getGraphicsContext();
        if (gc && gc->valid() && gc->makeCurrent()) {
            osg::State* state = gc->getState();
            _impl->root->releaseGLObjects(state);
            if (_impl->labelCam) _impl->labelCam->releaseGLObjects(state);
            osg::flushAllDeletedGLObjects(state->getContextID());
            gc->releaseContext();
        }
        _impl->viewer->setSceneData(nullptr);
        _impl->viewer = nullptr;
    }
}

Result<std::unique_ptr<OffscreenRenderer>> OffscreenRenderer::create(int width, int height) {
    if (width < 1 || height < 1 || width > 8192 || height > 8192)
        return Status::error("render size " + std::to_string(width) + "x" + std::to_string(height) +
                             " out of range 1x1 .. 8192x8192");
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display)
        return Status::error(
            "no X display (DISPLAY is not set): run under `xvfb-run -a` on a machine without a screen");
    osg::ref_ptr<osg::GraphicsContext::Traits> traits = new osg::GraphicsContext::Traits;
    traits->readDISPLAY();
    traits->setUndefinedScreenDetailsToDefaultScreen();
    traits->x = 0;
    traits->y = 0;
    traits->width = width;
    traits->height = height;
    traits->windowDecoration = false;
    traits->doubleBuffer = true;
    traits->pbuffer = false;
    traits->red = traits->green = traits->blue = 8;
    traits->alpha = 8;
    traits->depth = 24;
    traits->vsync = false;
    traits->windowName = "vista offscreen";
    // Opening the window fails now and then under a busy Xvfb (the X
    // connection is refused right after another context closed): retry a few times.
    osg::ref_ptr<osg::GraphicsContext> gc;
    for (int attempt = 0; attempt < 20; ++attempt) {
        gc = osg::GraphicsContext::createGraphicsContext(traits.get());
        if (gc && gc->valid()) break;
        gc = nullptr;
        std::this_thread::sleep_for(std::chrono::milliseconds(50 + 50 * attempt));
    }
    if (!gc || !gc->valid())
        return Status::error(
            std::string("cannot create an OpenGL window on display '") + display +
            "' (no GLX visual with RGBA8 + depth24?); try `xvfb-run -a -s \"-screen 0 1920x1080x24\"`");

    std::unique_ptr<OffscreenRenderer> r(new OffscreenRenderer);
    Impl& m = *r->_impl;
    m.width = width;
    m.height = height;
    m.viewer = new osgViewer::Viewer;
    m.viewer->setThreadingModel(osgViewer::ViewerBase::SingleThreaded);
    // osgViewer pins a single-threaded viewer's main thread to core 0 by default
    // (configureAffinity); every thread it starts afterwards (TBB's ray casting,
    // the horizon's overlap thread) would then share that one core.
    m.viewer->setUseConfigureAffinity(false);
    m.viewer->setKeyEventSetsDone(0);
    m.viewer->setQuitEventSetsDone(false);
    osg::Camera* cam = m.viewer->getCamera();
    gc->setSwapCallback(new NoPresent);
    cam->setGraphicsContext(gc.get());
    flushDeletedGLObjectsEvery(*cam);
    cam->setViewport(new osg::Viewport(0, 0, width, height));
    cam->setDrawBuffer(GL_BACK);
    cam->setReadBuffer(GL_BACK);
    setExactCulling(*cam);
    cam->setClearColor(osg::Vec4(0, 0, 0, 1));
    cam->setClearMask(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    cam->setProjectionResizePolicy(osg::Camera::FIXED);
    if (cam->getStats()) cam->getStats()->collectStats("rendering", true);
    m.readback = new Readback;
    m.readback->width = width;
    m.readback->height = height;
    cam->setFinalDrawCallback(m.readback.get());
    osg::ref_ptr<FragmentQueryBegin> begin = new FragmentQueryBegin;
    begin->readback = m.readback.get();
    cam->setInitialDrawCallback(begin.get());

    m.sky = std::make_unique<SkyBackground>(width, height);

    m.root = new osg::Group;
    m.slot = new osg::Group;
    m.root->addChild(m.sky->node());
    m.root->addChild(m.slot.get());
    m.viewer->setSceneData(m.root.get());
    m.viewer->realize();
    if (!m.viewer->isRealized()) return Status::error("cannot realize the OpenGL window (display problem)");
    return r;
}

Status OffscreenRenderer::render(osg::Node* scene, const Camera& camera, double zFar, Image* color,
                                 std::vector<float>* depth, FrameStats& stats, bool skyLayer) {
    Impl& m = *_impl;
    if (camera.width != m.width || camera.height != m.height)
        return Status::error("camera size " + std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                             " differs from the renderer's " + std::to_string(m.width) + "x" +
                             std::to_string(m.height));
    Stopwatch sw;
    m.sky->node()->setNodeMask(skyLayer ? ~0u : 0u);
    if (skyLayer) m.sky->showSky(camera, m.jx, m.jy);
    const double skyMs = sw.ms();
    m.readback->fragments = 0;
    Status s = m.draw(scene, camera, zFar, color, depth, stats);
    stats.frameMs += skyMs;
    if (s.isOk() && m.readback->countFragments) {
        // The sky layer (no depth test) passes one sample per pixel: not the scene's.
        const uint64_t sky = skyLayer ? uint64_t(m.width) * uint64_t(m.height) : 0;
        const uint64_t f = m.readback->fragments > sky ? m.readback->fragments - sky : 0;
        char buf[96];
        std::snprintf(buf, sizeof buf, "fragments: %llu (%.3f per pixel)", static_cast<unsigned long long>(f),
                      double(f) / (double(m.width) * double(m.height)));
        stats.notes.push_back(buf);
    }
    return s;
}

void OffscreenRenderer::setCountFragments(bool on) { _impl->readback->countFragments = on; }

void OffscreenRenderer::setOverlay(osg::Node* colour, osg::Node* labels) {
    _impl->overlay = colour;
    _impl->labelOverlay = labels;
    _impl->slot->removeChildren(0, _impl->slot->getNumChildren());  // the next draw lays the slot out again
}

void OffscreenRenderer::setEffects(const FrameEffects& fx, bool hazeInRaster) {
    Impl& m = *_impl;
    m.effects = fx;
    applyEffectsState(*m.slot->getOrCreateStateSet(), fx, hazeInRaster);
    m.sky->setNight(fx.night);
}

Status OffscreenRenderer::renderLabels(osg::Node* labelScene, const Camera& camera, double zFar, LabelFrame& out,
                                       FrameStats& stats) {
    Impl& m = *_impl;
    if (camera.width != m.width || camera.height != m.height)
        return Status::error("camera size " + std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                             " differs from the renderer's " + std::to_string(m.width) + "x" +
                             std::to_string(m.height));
    if (!m.labelCam) m.makeLabelCamera();
    Stopwatch sw;
    m.labelCam->setViewMatrix(toOsg(camera.view()));
    m.labelCam->setProjectionMatrix(toOsg(camera.projection(zFar)));
    m.labelSlot->removeChildren(0, m.labelSlot->getNumChildren());
    if (labelScene) m.labelSlot->addChild(labelScene);
    if (m.labelOverlay) m.labelSlot->addChild(m.labelOverlay.get());
    // Only the label camera draws: sky and colour scene masked off, no colour read-back.
    m.labelCam->setNodeMask(~0u);
    m.sky->node()->setNodeMask(0);
    m.slot->setNodeMask(0);
    m.readback->color = nullptr;
    m.readback->depth = nullptr;
    m.readback->frame = &sw;
    m.viewer->frame();
    m.readback->frame = nullptr;
    m.labelCam->setNodeMask(0);
    m.sky->node()->setNodeMask(~0u);
    m.slot->setNodeMask(~0u);
    m.labelSlot->removeChildren(0, m.labelSlot->getNumChildren());
    const int W = m.width, H = m.height;
    const size_t n = size_t(W) * size_t(H);
    out.width = W;
    out.height = H;
    out.ids.resize(n);
    out.classes.resize(n);
    out.depth.resize(n);
    const uint8_t* ib = m.labelIds->data();
    const float* db = reinterpret_cast<const float*>(m.labelDepth->data());
    if (!ib || !db) return Status::error("label pass: the FBO read-back returned no data");
    for (int y = 0; y < H; ++y) {
        const size_t src = size_t(H - 1 - y) * size_t(W), dst = size_t(y) * size_t(W);
        for (int x = 0; x < W; ++x) {
            const uint8_t* p = ib + 4 * (src + size_t(x));
            out.ids[dst + size_t(x)] =
                uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
            const float* d = db + 4 * (src + size_t(x));
            out.depth[dst + size_t(x)] = d[0];
            const float c = d[1];
            out.classes[dst + size_t(x)] = c > 0.0f && c < 255.5f ? uint8_t(c + 0.5f) : 0;
        }
    }
    stats.frameMs = sw.ms();
    return Status::ok();
}

int OffscreenRenderer::width() const { return _impl->width; }
int OffscreenRenderer::height() const { return _impl->height; }
void OffscreenRenderer::setSubpixelOffset(double dx, double dy) {
    _impl->jx = dx;
    _impl->jy = dy;
}
std::string OffscreenRenderer::glRenderer() const {
    return _impl->readback ? _impl->readback->renderer : std::string();
}

}  // namespace vista
