// The run-time effects wrapper of every mode (effects_mode.h).
#include "nodes/render/effects_mode.h"

#include <osg/Geode>

#include "nodes/render/effects_state.h"
#include "nodes/render/offscreen.h"
#include "nodes/render/reflection_drawable.h"
#include "nodes/render/traffic_scene.h"
#include "runtime/engine/reflections.h"

namespace vista {

namespace {

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
        if (_ctx.traffic)
            VISTA_RETURN_IF_ERROR(_ctx.traffic->setFrame(camera.time, camera.eye, _inner->splitsTraffic()));
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
    void sceneChanged(const SceneBoxes& changed) override { _inner->sceneChanged(changed); }
    const std::vector<uint32_t>* lastTracedPixels() const override { return _inner->lastTracedPixels(); }
    double lastRayStart() const override { return _inner->lastRayStart(); }
    const RasterSelection* lastRaster() const override { return _inner->lastRaster(); }
    bool hazesRasterPixels() const override { return _inner->hazesRasterPixels(); }
    bool drawsSky() const override { return _inner->drawsSky(); }
    bool splitsTraffic() const override { return _inner->splitsTraffic(); }
    osg::Node* viewerScene() override {
        if (!_viewer) {
            _viewer = new osg::Group;
            _viewer->setName("vista.effects");
            applyEffectsState(*_viewer->getOrCreateStateSet(), _ctx.options.effects, !_inner->hazesRasterPixels());
            _viewer->addChild(_inner->viewerScene());
            if (_ctx.traffic) _viewer->addChild(_ctx.traffic->node());
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
        if (_viewer)
            applyEffectsState(*_viewer->getOrCreateStateSet(), _ctx.options.effects,
                              !_inner->hazesRasterPixels());  // live toggles
        if (_ctx.traffic) (void)_ctx.traffic->setFrame(camera.time, camera.eye, _inner->splitsTraffic());
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

std::unique_ptr<RenderMode> withEffects(std::unique_ptr<RenderMode> inner, ModeContext& ctx) {
    return std::unique_ptr<RenderMode>(new EffectsMode(std::move(inner), ctx));
}

}  // namespace vista
