// `hybrid` bench mode: chunked near field + FarField (see mode_hybrid.h).
#include "nodes/render/mode_hybrid.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <tuple>

#include <osg/Geode>
#include <osg/Geometry>
#include <osg/MatrixTransform>

#include "runtime/engine/far_field.h"
#include "runtime/engine/horizon.h"
#include "nodes/render/offscreen.h"
#include "runtime/engine/ray_scene.h"

namespace vista {

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }


class HybridMode : public BenchMode {
public:
    explicit HybridMode(BenchContext& ctx) : _ctx(ctx) {
        _near = buildNearFieldScene(ctx.scene, kNearChunkSize);
        _grid = HeightGrid::build(*ctx.city, ctx.rays->frameOrigin(), ctx.options.horizonGrid);
        _far = std::make_unique<FarField>(*ctx.rays, &_grid, farOptions(ctx.options.nearDistance));
        _adaptive = std::make_unique<AdaptiveSplit>(_near.objects, ctx.rays);
        _root = new osg::Group;
        if (_near.rootState) _root->setStateSet(_near.rootState.get());
    }
    std::string name() const override { return "hybrid"; }

    FarFieldOptions farOptions(double nearD) const {
        FarFieldOptions o;
        o.nearDistance = std::max(0.0, nearD);
        o.pixelBudget = _ctx.options.pixelBudget;
        o.cache = _ctx.options.cache;
        o.threads = _ctx.options.threads;
        return o;
    }

    Status renderFrame(const Camera& camera, Image& out, FrameStats& stats) override {
        auto t0 = Clock::now();
        // Cull: the near/far split.
        const bool autoSplit = _ctx.options.nearDistance < 0;
        double nearD = autoSplit ? _adaptive->choose(camera, _ctx.options.pixelBudget) : _ctx.options.nearDistance;
        std::vector<uint32_t> sel = selectNearField(_near.objects, camera.eye, nearD);
        _root->removeChildren(0, _root->getNumChildren());
        uint64_t tris = 0;
        for (uint32_t i : sel) {
            _root->addChild(_near.chunks[i].get());
            tris += _near.objects[i].triangles;
        }
        stats.stages.set(Stage::Cull, msSince(t0));
        if (autoSplit) stats.notes.push_back("near auto: " + std::to_string(int(std::lround(nearD))) + " m");
        // Near field: GL draw + colour/depth readback (sky background where uncovered).
        FrameStats ns;
        // Far plane at the near distance: straddling objects are drawn up to it,
        // the far field fills the rest seamlessly (same shading); FarField's seam
        // check covers the band between the plane and the near sphere.
        const double zFar = std::max(nearD, camera.zNear * 4.0);
        Status s = _ctx.renderer->render(_root.get(), camera, zFar, &out, &_depth, ns);
        if (!s) return s;
        stats.stages.set(Stage::Near, ns.frameMs);
        stats.cullMs = ns.cullMs;
        stats.drawMs = ns.drawMs;
        stats.triangles = ns.triangles ? ns.triangles : tris;
        stats.drawCalls = ns.drawCalls;
        // Far field on the CPU.
        FarFieldOptions fo = farOptions(nearD);
        fo.depthZFar = zFar;
        _far->setOptions(fo);
        _far->render(camera, _depth.size() == size_t(camera.width) * size_t(camera.height) ? _depth.data() : nullptr, out,
                     stats);
        stats.frameMs = msSince(t0);
        if (autoSplit) {
            _adaptive->record(tris, ns.frameMs, stats.pixels.rayHit + stats.pixels.rayMiss, stats.stages.ms(Stage::Rays));
        }
        return Status::ok();
    }
    void reset() override { _far->reset(); }

private:
    BenchContext& _ctx;
    NearFieldScene _near;
    HeightGrid _grid;
    std::unique_ptr<FarField> _far;
    std::unique_ptr<AdaptiveSplit> _adaptive;
    osg::ref_ptr<osg::Group> _root;
    std::vector<float> _depth;
};

}  // namespace

Result<std::unique_ptr<BenchMode>> makeHybridMode(BenchContext& ctx) {
    if (!ctx.rays) return Status::error("mode hybrid needs the city's ray scene, which is not available");
    if (!ctx.city) return Status::error("mode hybrid needs the loaded city (height grid), which is not available");
    if (!ctx.renderer) return Status::error("mode hybrid needs an OpenGL renderer (run under `xvfb-run -a`)");
    if (ctx.options.horizonGrid < 1 || ctx.options.horizonGrid > 8192)
        return Status::error("option horizon grid = " + std::to_string(ctx.options.horizonGrid) +
                             " is out of range [1, 8192] (cells per side)");
    return std::unique_ptr<BenchMode>(new HybridMode(ctx));
}

}  // namespace vista
