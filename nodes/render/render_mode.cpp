// The render-mode registry and the shared parts of ModeContext (render_mode.h).
#include "nodes/render/render_mode.h"

#include <algorithm>
#include <mutex>

#include <osg/Geode>
#include <osg/RenderInfo>

#include "foundation/timing.h"
#include "nodes/baked_file.h"
#include "nodes/far_field_node.h"
#include "nodes/gl_readback.h"
#include "nodes/render/effects_state.h"
#include "runtime/engine/reflections.h"
#include "nodes/render/offscreen.h"
#include "nodes/render/mode_full.h"
#include "nodes/render/mode_hybrid.h"
#include "nodes/render/mode_impostor.h"
#include "nodes/render/mode_lodmesh.h"
#include "nodes/render/mode_near.h"
#include "nodes/render/mode_osgimpostor.h"
#include "nodes/render/mode_osglod.h"
#include "nodes/render/mode_raycast.h"
#include "nodes/view_cell_switch.h"

namespace vista {

osg::Node* ModeContext::plainScene() {
    if (_plain) return _plain.get();
    if (auto* baked = dynamic_cast<ViewCellSwitch*>(scene)) {
        osg::ref_ptr<osg::Group> tiles = new osg::Group;
        tiles->setStateSet(baked->getStateSet());
        for (unsigned i = 0; i < baked->getTileCount() && i < baked->getNumChildren(); ++i) tiles->addChild(baked->getChild(i));
        _plain = tiles;
    } else {
        _plain = scene;
    }
    return _plain.get();
}

const NearFieldScene& ModeContext::nearField() {
    if (!_nearField) {
        Stopwatch sw;
        _nearField = std::make_shared<NearFieldScene>(buildNearFieldScene(plainScene(), kNearChunkSize, labels));
        _chunkingMs = sw.ms();
    }
    return *_nearField;
}

osg::Group* ModeContext::chunkedCity() {
    if (!_chunked) {
        const NearFieldScene& nf = nearField();
        _chunked = new osg::Group;
        _chunked->setName("vista.chunked_city");
        if (nf.rootState) _chunked->setStateSet(nf.rootState.get());
        for (uint32_t i : nf.drawOrder) _chunked->addChild(nf.chunks[i].get());
    }
    return _chunked.get();
}

Status GraphMode::renderFrame(const Camera& camera, Image& out, FrameStats& stats) {
    if (!_ctx.renderer) return Status::error("mode " + name() + " needs an OpenGL renderer (run under `xvfb-run -a`)");
    const double zFar = prepare(camera);
    VISTA_RETURN_IF_ERROR(_ctx.renderer->render(_graph.get(), camera, zFar, &out, nullptr, stats));
    describe(stats);
    return Status::ok();
}

Result<ModeBake> loadBakeForMode(const ModeContext& ctx, const std::string& file) {
    ModeBake b;
    if (auto it = ctx.options.loadedBakes.find(file); it != ctx.options.loadedBakes.end() && it->second.root) {
        b.root = it->second.root;
        b.loadMs = it->second.loadMs;
    } else {
        Stopwatch sw;
        auto bf = loadBakedFile(file);
        if (!bf) return bf.status();
        b.root = bf->root;
        b.loadMs = sw.ms();
    }
    b.meshes = isMeshBake(b.root.get());
    return b;
}

const std::vector<ModeInfo>& renderModes() {
    static const std::vector<ModeInfo> kModes = {
        {"full", "all geometry in 40 m chunks, far plane at infinity (the exact reference)", false, false, makeFullMode},
        {"near", "only the near field: the chunked city clipped at --near metres", false, false, makeNearMode},
        {"raycast", "every pixel ray cast with Embree, prelit colours", true, false, makeRaycastMode},
        {"osgimpostor", "stock osgSim::Impostor on every tile beyond --near + tile radius", false, false, makeOsgImpostorMode},
        {"osglod", "stock osg::LOD per chunk with osgUtil::Simplifier far versions + small-feature culling", false, false,
         makeOsgLodMode},
        {"hybrid", "near field rasterised + ray-cast far field (horizon, cache, Embree)", true, false, makeHybridMode},
        {"impostor", "near field + baked point impostors (needs a baked file: --baked)", false, true, makeImpostorMode},
        {"lodmesh", "near field + the cell's textured depth meshes (a file from 'vista bake --representation mesh')", false, false,
         makeLodMeshMode},
    };
    return kModes;
}

const ModeInfo* findRenderMode(const std::string& name) {
    for (const auto& m : renderModes())
        if (name == m.name) return &m;
    return nullptr;
}

std::string renderModeNames() {
    std::string s;
    for (const auto& m : renderModes()) s += (s.empty() ? "" : ", ") + std::string(m.name);
    return s;
}

bool effectsNeedRays(const FrameEffects& fx) { return fx.glass && fx.glassMarked && fx.rayBudget > 0; }

namespace {

// Viewer face of the reflection stage: after everything else is drawn, reads
// the frame back, runs reflectionStage() on it and draws it over the viewport.
class ReflectionDrawable : public osg::Drawable {
public:
    ReflectionDrawable(const RayScene* rays, const FrameEffects* fx) : _rays(rays), _fx(fx) {
        useFixedFunction(*getOrCreateStateSet());
        setUseDisplayList(false);
        setUseVertexBufferObjects(false);
        setCullingActive(false);
        setDataVariance(osg::Object::DYNAMIC);
    }
    ReflectionDrawable(const ReflectionDrawable& o, const osg::CopyOp& op)
        : osg::Drawable(o, op), _rays(o._rays), _fx(o._fx) {}
    META_Object(vista, ReflectionDrawable);
    FrameStats lastStats() const {
        std::lock_guard<std::mutex> lock(_mutex);
        return _stats;
    }
    void drawImplementation(osg::RenderInfo& ri) const override {
        std::lock_guard<std::mutex> lock(_mutex);
        Camera c;
        const osg::Viewport* vpp = nullptr;
        double zFar = 0;
        if (!_fx || !currentView(ri, c, vpp, zFar)) return;
        const osg::Viewport& vp = *vpp;
        const int W = int(vp.width()), H = int(vp.height());
        _image = Image(W, H);
        readColorTopDown(GLint(vp.x()), GLint(vp.y()), W, H, _gl, _image.rgba.data());
        _stats = FrameStats();
        if (!hasGlassPixels(_image)) return;
        reflectionStage(_rays, c, *_fx, _image, _stats);
        drawImageOverViewport(vp, _image, nullptr, _upload);
    }
    osg::BoundingBox computeBoundingBox() const override { return osg::BoundingBox(); }

private:
    ReflectionDrawable() = default;
    const RayScene* _rays = nullptr;
    const FrameEffects* _fx = nullptr;
    mutable Image _image;
    mutable std::vector<uint32_t> _gl;  // scratch of the colour read (gl_readback.h)
    mutable std::vector<uint8_t> _upload;
    mutable FrameStats _stats;
    mutable std::mutex _mutex;
};

// Every mode wrapped with the run-time effects (render_mode.h).
class EffectsMode : public RenderMode {
public:
    EffectsMode(std::unique_ptr<RenderMode> inner, ModeContext& ctx) : _inner(std::move(inner)), _ctx(ctx) {
        _setup = _inner->setupMs();
    }
    std::string name() const override { return _inner->name(); }
    Status renderFrame(const Camera& camera, Image& out, FrameStats& stats) override {
        const FrameEffects& fx = _ctx.options.effects;
        if (_ctx.renderer) _ctx.renderer->setEffects(fx, !_inner->hazesRasterPixels());
        VISTA_RETURN_IF_ERROR(_inner->renderFrame(camera, out, stats));
        if (fx.haze && !stats.effects.ran(EffectId::Haze)) {
            stats.effects.add(EffectId::Haze, 0.0);  // fog inside the rasteriser's draw
        }
        if (fx.glassMarked) {
            const double before = stats.stages.ms(Stage::Reflect);
            reflectionStage(_ctx.rays, camera, fx, out, stats);
            stats.frameMs += stats.stages.ms(Stage::Reflect) - before;
        }
        return Status::ok();
    }
    void reset() override { _inner->reset(); }
    const std::vector<uint32_t>* lastTracedPixels() const override { return _inner->lastTracedPixels(); }
    double lastRayStart() const override { return _inner->lastRayStart(); }
    const RasterSelection* lastRaster() const override { return _inner->lastRaster(); }
    bool hazesRasterPixels() const override { return _inner->hazesRasterPixels(); }
    bool drawsSky() const override { return _inner->drawsSky(); }
    osg::Node* viewerScene() override {
        if (!_viewer) {
            _viewer = new osg::Group;
            _viewer->setName("vista.effects");
            applyEffectsState(*_viewer->getOrCreateStateSet(), _ctx.options.effects, !_inner->hazesRasterPixels());
            _viewer->addChild(_inner->viewerScene());
            if (_ctx.options.effects.glassMarked) {
                _reflect = new ReflectionDrawable(_ctx.rays, &_ctx.options.effects);
                osg::ref_ptr<osg::Geode> g = new osg::Geode;
                g->addDrawable(_reflect.get());
                g->getOrCreateStateSet()->setRenderBinDetails(100000, "RenderBin");
                g->setCullingActive(false);
                _viewer->addChild(g.get());
            }
        }
        return _viewer.get();
    }
    double beginViewerFrame(const Camera& camera) override {
        if (_viewer) applyEffectsState(*_viewer->getOrCreateStateSet(), _ctx.options.effects, !_inner->hazesRasterPixels());  // live toggles
        return effectsFarPlane(_inner->beginViewerFrame(camera), _ctx.options.effects);
    }
    FrameStats lastViewerStats() const override {
        FrameStats s = _inner->lastViewerStats();
        if (_reflect) {
            const FrameStats r = _reflect->lastStats();
            r.stages.forEach([&](Stage st, double ms) { s.stages.add(st, ms); });
            r.effects.forEach([&](EffectId e, double ms) { s.effects.add(e, ms); });
            s.glassPixels += r.glassPixels;
            s.reflectionRays += r.reflectionRays;
        }
        if (_ctx.options.effects.haze) s.effects.add(EffectId::Haze, 0.0);
        return s;
    }

private:
    std::unique_ptr<RenderMode> _inner;
    ModeContext& _ctx;
    osg::ref_ptr<osg::Group> _viewer;
    osg::ref_ptr<ReflectionDrawable> _reflect;
};

}  // namespace

Result<std::unique_ptr<RenderMode>> createRenderMode(const std::string& name, ModeContext& ctx) {
    const ModeInfo* m = findRenderMode(name);
    if (!m) return Status::error("unknown mode '" + name + "'; available modes: " + renderModeNames());
    if (!ctx.scene) return Status::error("mode " + name + " needs a scene graph, none was loaded");
    if (m->needsRays && !ctx.rays) return Status::error("mode " + name + " needs the city's ray scene, which is not available");
    if (effectsNeedRays(ctx.options.effects) && !ctx.rays)
        return Status::error("mode " + name + ": glass reflections need the city's ray scene, which is not available");
    auto inner = m->make(ctx);
    if (!inner) return inner.status();
    return std::unique_ptr<RenderMode>(new EffectsMode(std::move(*inner), ctx));
}

}  // namespace vista
