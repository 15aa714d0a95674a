// `raycast`: every pixel ray cast with Embree (mode_raycast.h).
#include "nodes/render/mode_raycast.h"

#include <algorithm>
#include <cmath>
#include <mutex>

#include <osg/Geode>
#include <osg/RenderInfo>

#include "foundation/timing.h"
#include "nodes/readback_drawable.h"
#include "nodes/render/traffic_scene.h"
#include "runtime/engine/frame_raycast.h"
#include "runtime/engine/ray_scene.h"

namespace vista {
namespace {

// One primary ray per pixel centre into `rays`: the engine's raycastFrame
// (the same packets and colours as the far field's ray stage, and the frame
// the hybrid draws when its split picks ray casting).
void castEveryPixel(const RayScene& rays, const Camera& camera, Image& out, FrameStats& stats, int threads,
                    const FrameEffects& fx) {
    raycastFrame(rays, camera, out, stats, threads, fx);
}

// Viewer face: casts the OSG camera's frame and draws it over the viewport.
class RaycastDrawable : public ReadbackDrawable {
public:
    RaycastDrawable(const RayScene& rays, const FrameEffects* fx) : _rays(rays), _fx(fx) {}
    RaycastDrawable(const RaycastDrawable& o, const osg::CopyOp& op)
        : ReadbackDrawable(o, op), _rays(o._rays), _fx(o._fx) {}
    osg::Object* cloneType() const override { return new RaycastDrawable(_rays, _fx); }
    osg::Object* clone(const osg::CopyOp& op) const override { return new RaycastDrawable(*this, op); }
    bool isSameKindAs(const osg::Object* o) const override {
        return dynamic_cast<const RaycastDrawable*>(o) != nullptr;
    }
    const char* libraryName() const override { return "vista"; }
    const char* className() const override { return "RaycastDrawable"; }

protected:
    void drawFrame(osg::RenderInfo&, const Camera& c, const osg::Viewport& vp, double) const override {
        static const FrameEffects kNone;
        castEveryPixel(_rays, c, _image, _stats, 0, _fx ? *_fx : kNone);
        drawImage(vp);
    }

private:
    const RayScene& _rays;
    const FrameEffects* _fx;
};

class RaycastMode : public RenderMode {
public:
    explicit RaycastMode(ModeContext& ctx) : _ctx(ctx) {}
    std::string name() const override { return "raycast"; }
    Status renderFrame(const Camera& camera, Image& out, FrameStats& stats) override {
        Stopwatch sw;
        if (_ctx.traffic) VISTA_RETURN_IF_ERROR(_ctx.traffic->setSplit(0.0));  // every agent ray-cast
        castEveryPixel(*_ctx.rays, camera, out, stats, _ctx.options.threads, _ctx.options.effects);
        stats.frameMs = sw.ms();
        stats.drawMs = stats.frameMs;
        return Status::ok();
    }
    osg::Node* viewerScene() override {
        if (!_viewer) {
            _drawable = new RaycastDrawable(*_ctx.rays, &_ctx.options.effects);
            osg::ref_ptr<osg::Geode> geode = new osg::Geode;
            geode->setCullingActive(false);
            geode->addDrawable(_drawable.get());
            _viewer = geode;
        }
        return _viewer.get();
    }
    double beginViewerFrame(const Camera& camera) override {
        (void)camera;
        if (_ctx.traffic) (void)_ctx.traffic->setSplit(0.0);
        return 0.0;
    }
    FrameStats lastViewerStats() const override { return _drawable ? _drawable->lastStats() : FrameStats(); }
    bool splitsTraffic() const override { return true; }  // setSplit in both faces

private:
    ModeContext& _ctx;
    osg::ref_ptr<osg::Node> _viewer;
    osg::ref_ptr<RaycastDrawable> _drawable;
};

}  // namespace

Result<std::unique_ptr<RenderMode>> makeRaycastMode(ModeContext& ctx) {
    if (!ctx.rays) return Status::error("mode raycast needs the city's ray scene, which is not available");
    return std::unique_ptr<RenderMode>(new RaycastMode(ctx));
}

}  // namespace vista
