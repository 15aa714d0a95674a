// `hybrid`: chunked near field + FarField (mode_hybrid.h).
#include "nodes/render/mode_hybrid.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "foundation/timing.h"
#include "nodes/far_field_node.h"
#include "nodes/near_far_split.h"
#include "nodes/render/city_stream.h"
#include "nodes/render/effects_state.h"
#include "nodes/render/offscreen.h"
#include "nodes/render/traffic_scene.h"
#include "runtime/engine/adaptive_split.h"
#include "runtime/engine/far_field.h"
#include "runtime/engine/frame_raycast.h"
#include "runtime/engine/horizon.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/engine/split_guard.h"

namespace vista {

namespace {

std::string nearAutoNote(double nearD, const char* reason) {
    const std::string by = std::string(" by ") + reason;
    if (!std::isfinite(nearD)) return "near auto: everything (no far field)" + by;
    if (nearD <= 0) return "near auto: 0 m (ray casting)" + by;
    return "near auto: " + std::to_string(int(std::lround(nearD))) + " m" + by;
}

// A count for the overlay line: 74.5k, 1.2M.
std::string shortCount(double v) {
    char buf[32];
    if (v >= 1e6) std::snprintf(buf, sizeof buf, "%.1fM", v / 1e6);
    else if (v >= 1e3) std::snprintf(buf, sizeof buf, "%.1fk", v / 1e3);
    else std::snprintf(buf, sizeof buf, "%.0f", v);
    return buf;
}

// The horizon's height grid: a streamed city's (it follows the resident
// regions); else built from the loaded city into `own`, on the paged city's
// lattice when it is one (the same cells as a streamed run of the same regions).
const HeightGrid* hybridHeightGrid(ModeContext& ctx, HeightGrid& own) {
    if (ctx.stream) return ctx.stream->nearField()->grid();
    if (ctx.paged) {
        own = pagedHeightLattice(*ctx.paged, ctx.rays->frameOrigin(), ctx.options.horizonGrid);
        own.addPatch(0, std::make_shared<const HeightPatch>(own.patch(*ctx.city)));
    } else {
        own = HeightGrid::build(*ctx.city, ctx.rays->frameOrigin(), ctx.options.horizonGrid);
    }
    return &own;
}

class HybridMode : public RenderMode {
public:
    HybridMode(ModeContext& ctx, bool fixedSplit) : _ctx(ctx), _near(ctx.nearField()), _fixedSplit(fixedSplit) {
        _setup.push_back({"chunking", ctx.chunkingMs()});
        Stopwatch sw;
        _heights = hybridHeightGrid(ctx, _grid);
        _setup.push_back({"height_grid", sw.ms()});
        _far = std::make_unique<FarField>(*ctx.rays, _heights, farOptions(ctx.options.fixedNearDistance(), 0.0));
        AdaptiveSplitOptions so;
        so.endTryEvery = 24;  // each kind of choice re-measured about every 24 frames of a walkthrough
        so.fixedDistance = ctx.options.fixedNearDistance();  // `hybrid-fixed`'s choice, a kind of its own
        // A stream whose coarse levels carry no chunks cannot draw the whole city: no "everything".
        if (ctx.stream && ctx.stream->graphLevels() != StreamGraph::EveryLevel) so.everythingNear = false;
        // A streamed city: the stream's index of the resident chunks (it follows the regions).
        _adaptive = ctx.stream ? std::make_unique<AdaptiveSplit>(ctx.stream->nearField()->index(), ctx.rays, so)
                               : std::make_unique<AdaptiveSplit>(_near.objects, ctx.rays, so);
        SplitGuardOptions go;
        go.everything = so.everythingNear;
        go.fixedDistance = so.fixedDistance;  // the near default is a yardstick too
        _guard = SplitGuard(go);
        _root = new osg::Group;
        if (_near.rootState) _root->setStateSet(_near.rootState.get());
    }
    std::string name() const override { return _fixedSplit ? "hybrid-fixed" : "hybrid"; }

    Status renderFrame(const Camera& camera, Image& out, FrameStats& stats) override {
        if (!_ctx.renderer) return Status::error("mode hybrid needs an OpenGL renderer (run under `xvfb-run -a`)");
        Stopwatch sw;
        // Cull: the near/far split.
        const double nearD = chooseNear(camera);
        // Agents: GL within the near distance, rays beyond (a triangle budget: GL alone).
        if (_ctx.traffic) VISTA_RETURN_IF_ERROR(_ctx.traffic->setSplit(byBudget() ? 1e300 : nearD));
        if (!byBudget() && (nearD <= 0 || std::isinf(nearD))) return endPointFrame(camera, nearD, sw, out, stats);
        std::vector<uint32_t> sel =
            byBudget() ? selectNearFieldByBudget(_adaptive->index(), camera.eye, _ctx.options.triangleBudget)
                       : selectNearField(_adaptive->index(), camera.eye, nearD);
        _root->removeChildren(0, _root->getNumChildren());
        const uint64_t tris = addNearChunks(camera, sel, stats);
        stats.stages.set(Stage::Cull, sw.ms());
        stats.notes.push_back(splitNote(nearD));
        if (autoSplit()) {
            stats.notes.push_back(nearAutoNote(nearD, _reason));
            char model[160];
            std::snprintf(model, sizeof model,
                          "split model: %.3g ms/k triangles, %.3g ms/k far pixels, %.2f ms far fixed",
                          1e3 * _adaptive->msPerTriangle(), 1e3 * _adaptive->msPerRay(), _adaptive->farFixedMs());
            stats.notes.push_back(model);
        }
        // Near field: GL draw + colour/depth readback (sky where uncovered).
        // Far plane at the near distance: straddling chunks are drawn up to
        // it, the far field fills the rest with the same shading; FarField's
        // seam check covers the band between the plane and the near sphere.
        const double zFar = farPlane(nearD, camera);
        _raster.chunks = sel;
        _raster.zFar = zFar;
        _raster.nearDistance = byBudget() ? 1e300 : std::max(0.0, nearD);
        // The horizon depends on the camera only: traced on another thread while the near field is drawn.
        _far->setOptions(farOptions(nearD, zFar));
        if (_far->options().overlap) _far->beginFrame(camera);
        FrameStats ns;
        if (sel.empty()) {
            // Nothing near (ray casting, or an eye far from every chunk): no GL pass, no
            // read-back; the far field fills every pixel.
            if (out.width != camera.width || out.height != camera.height || !out.valid())
                out = Image(camera.width, camera.height);
            _depth.clear();
            stats.notes.push_back("near field empty: no GL pass");
        } else {
            VISTA_RETURN_IF_ERROR(
                _ctx.renderer->render(_root.get(), camera, zFar, &out, &_depth, ns, /*skyLayer=*/false));
            stats.stages.set(Stage::Near, ns.frameMs);
            stats.stages.set(Stage::Readback, ns.stages.ms(Stage::Readback));         // part of Near
            stats.notes.insert(stats.notes.end(), ns.notes.begin(), ns.notes.end());  // e.g. fragments
        }
        stats.cullMs = ns.cullMs;
        stats.drawMs = ns.drawMs;
        stats.triangles = ns.triangles ? ns.triangles : tris;
        stats.drawCalls = ns.drawCalls;
        // Far field on the CPU (every pixel far without a depth buffer).
        const bool haveDepth = !sel.empty() && _depth.size() == size_t(camera.width) * size_t(camera.height);
        _far->render(camera, haveDepth ? _depth.data() : nullptr, out, stats);
        stats.frameMs = sw.ms();
        if (autoSplit()) {
            if (nearD == _adaptive->current()) recordCosts(_adaptive->chosenTriangles(), ns.frameMs, stats);
            _adaptive->recordFrame(nearD, stats.frameMs);
            _guard.record(nearD, stats.frameMs);
        }
        return Status::ok();
    }
    void reset() override { _far->reset(); }
    // The ray scene changed (a streamed city): nothing traced in the old one that could show a
    // changed region is served again. The near field's root state comes with the first region.
    void sceneChanged(const SceneBoxes& changed) override {
        _far->sceneChanged(changed);
        if (_farNode) _farNode->sceneChanged(changed);
        if (!_root->getStateSet() && _near.rootState) _root->setStateSet(_near.rootState.get());
        if (_viewer && !_viewer->getStateSet() && _near.rootState) _viewer->setStateSet(_near.rootState.get());
    }
    bool hazesRasterPixels() const override { return true; }  // FarFieldOptions::hazeCovered
    bool drawsSky() const override { return true; }  // the far field classifies and fills every uncovered pixel
    // Both faces split the traffic at the near distance (setSplit).
    bool splitsTraffic() const override { return true; }
    const std::vector<uint32_t>* lastTracedPixels() const override { return &_far->lastTraced(); }
    double lastRayStart() const override { return _far->lastRayStart(); }
    const RasterSelection* lastRaster() const override { return &_raster; }

    osg::Node* viewerScene() override {
        if (!_viewer) {
            HybridSceneOptions ho;
            ho.nearDistance = _ctx.options.fixedNearDistance();
            ho.triangleBudget = _ctx.options.triangleBudget;
            ho.far = farOptions(ho.nearDistance, 0.0);
            if (_ctx.stream) {
                // A streamed city: the split chooses among the stream's resident chunks at each cull.
                _viewer = buildHybridScene(NearFieldScene(), *_ctx.rays, *_heights, ho, &_split, &_farNode);
                _split->setSource(&_near.chunks, &_near.objects, &_adaptive->index());
                if (_near.rootState) _viewer->setStateSet(_near.rootState.get());
            } else {
                _viewer = buildHybridScene(_near, *_ctx.rays, *_heights, ho, &_split, &_farNode);
            }
            if (_split) _split->setNearDetail(&_near, _ctx.options.nearFrontToBack, _ctx.options.nearDetailPx);
        }
        return _viewer.get();
    }
    double beginViewerFrame(const Camera& camera) override {
        const double wallMs = _viewerClock.lap();
        if (autoSplit() && _viewerFrames++ > 0 && _farNode && _split) {
            const FrameStats fs = _farNode->lastStats();
            double farMs = 0;
            fs.stages.forEach([&](Stage, double ms) { farMs += ms; });
            if (_viewerNear == _adaptive->current())
                recordCosts(_adaptive->chosenTriangles(), std::max(0.0, wallMs - farMs), fs);
            _guard.record(_viewerNear, wallMs);
            _adaptive->recordFrame(_viewerNear, wallMs);  // the split's per-kind corrections, as in bench
        }
        _viewerNear = chooseNear(camera);
        if (_ctx.traffic) (void)_ctx.traffic->setSplit(byBudget() ? 1e300 : _viewerNear);
        if (_split) _split->setNearDistance(_viewerNear);
        if (_farNode) _farNode->setOptions(farOptions(_viewerNear, 0.0));  // live effect toggles
        return farPlane(_viewerNear, camera);
    }
    FrameStats lastViewerStats() const override {
        FrameStats s = _farNode ? _farNode->lastStats() : FrameStats();
        s.triangles = _split ? _split->lastNearTriangles() : 0;
        s.notes.push_back("near chunks drawn " + std::to_string(_split ? _split->lastNearCount() : 0u));
        s.notes.push_back(overlayLine(_viewerNear, s));
        return s;
    }

private:
    // The selected chunks into _root: nearest first (ModeOptions::nearFrontToBack: the depth
    // test then rejects hidden fragments before they are shaded), each as its flattened twin
    // where that deviates from the chunk by at most ModeOptions::nearDetailPx pixels
    // (screenDeviationPx at the chunk box's distance). Notes the triangles by kind and the
    // coarse chunks (both of the chosen chunks, before the renderer's frustum culling); `sel`
    // ends up in draw order. Returns the chosen chunks' triangles.
    uint64_t addNearChunks(const Camera& camera, std::vector<uint32_t>& sel, FrameStats& stats) {
        const std::vector<SplitObject>& objs = _adaptive->index().objects();
        std::vector<std::pair<double, uint32_t>> byDistance;
        byDistance.reserve(sel.size());
        for (uint32_t i : sel) byDistance.push_back({boxDistance(objs[i], camera.eye), i});
        if (_ctx.options.nearFrontToBack)
            std::stable_sort(byDistance.begin(), byDistance.end(),
                             [](const auto& a, const auto& b) { return a.first < b.first; });
        const bool coarse = _ctx.options.nearDetailPx > 0 && _near.coarseChunks.size() == _near.chunks.size();
        const bool kinds = _near.chunkKinds.size() == _near.chunks.size();
        NearKindCounts counts{};
        uint64_t tris = 0, coarseCount = 0, saved = 0;
        for (size_t k = 0; k < byDistance.size(); ++k) {
            const auto [d, i] = byDistance[k];
            sel[k] = i;
            osg::Node* node = _near.chunks[i].get();
            uint64_t t = objs[i].triangles;
            const bool flat = coarse && _near.coarseChunks[i] &&
                              screenDeviationPx(_near.coarseError[i], d, camera.fovY, camera.width, camera.height) <=
                                  _ctx.options.nearDetailPx;
            if (flat) {
                node = _near.coarseChunks[i].get();
                saved += t - _near.coarseTriangles[i];
                t = _near.coarseTriangles[i];
                ++coarseCount;
            }
            if (kinds) {
                for (size_t c = 0; c < kNearKindCount; ++c) counts[c] += _near.chunkKinds[i][c];
                if (flat) counts[size_t(NearKind::Recess)] -= _near.chunkKinds[i][size_t(NearKind::Recess)];
            }
            _root->addChild(node);
            tris += t;
        }
        if (kinds) {
            std::string note = "near kinds:";
            for (size_t c = 0; c < kNearKindCount; ++c)
                note += std::string(" ") + nearKindName(NearKind(c)) + "=" + std::to_string(counts[c]);
            stats.notes.push_back(note);
        }
        if (coarse)
            stats.notes.push_back("near coarse: " + std::to_string(coarseCount) + " of " + std::to_string(sel.size()) +
                                  " chunks flattened, " + std::to_string(saved) + " triangles fewer");
        return tris;
    }

    // The split's end points are the modes they stand for, at their cost: ray casting (0 m) is
    // the `raycast` frame (no GL pass, no read-back, no far-field stage: raycastFrame), and
    // everything near is the `full` frame (the chunked city in its draw order, infinite far
    // plane but for haze, sky layer, haze in the rasteriser; no read-back, no far field).
    Status endPointFrame(const Camera& camera, double nearD, Stopwatch& sw, Image& out, FrameStats& stats) {
        stats.stages.set(Stage::Cull, sw.ms());  // the split's decision
        const FrameEffects& fx = _ctx.options.effects;
        uint64_t tris = 0;
        double rasterMs = 0;
        if (nearD <= 0) {
            raycastFrame(*_ctx.rays, camera, out, stats, _ctx.options.threads, fx);
            _raster.chunks.clear();
            _raster.zFar = 0.0;
            _raster.nearDistance = 0.0;
        } else {
            if (fx.haze) _ctx.renderer->setEffects(fx, /*hazeInRaster=*/true);
            FrameStats ns;
            const Status s = _ctx.renderer->render(_ctx.chunkedCity(), camera, 0.0, &out, nullptr, ns);
            if (fx.haze) _ctx.renderer->setEffects(fx, false);
            VISTA_RETURN_IF_ERROR(s);
            ns.stages.forEach([&](Stage st, double ms) { stats.stages.set(st, ms); });
            stats.notes.insert(stats.notes.end(), ns.notes.begin(), ns.notes.end());
            stats.stages.set(Stage::Near, ns.frameMs);
            stats.cullMs = ns.cullMs;
            stats.drawMs = ns.drawMs;
            stats.drawCalls = ns.drawCalls;
            tris = autoSplit() ? _adaptive->chosenTriangles() : _adaptive->index().totalTriangles();
            stats.triangles = ns.triangles ? ns.triangles : _adaptive->index().totalTriangles();
            stats.pixels.covered = uint64_t(camera.width) * uint64_t(camera.height);
            rasterMs = ns.frameMs;
            _raster.chunks = _near.drawOrder;
            _raster.zFar = 0.0;
            _raster.nearDistance = 1e300;
        }
        stats.frameMs = sw.ms();
        stats.notes.push_back(splitNote(nearD));
        if (autoSplit()) {
            stats.notes.push_back(nearAutoNote(nearD, _reason));
            // Every whole-city frame joins the raster fit, with haze too (drawn with the haze
            // program, which the near field's draw does not run): without these frames the fit
            // sees only middle distances, its slope comes out low (0.041 against 0.069 ms per
            // thousand triangles on one path) and the split drifts to larger near distances under
            // haze than without it. The kind's correction learns the rest.
            if (rasterMs > 0 && nearD == _adaptive->current()) _adaptive->record(tris, rasterMs, 0, 0.0, 0.0);
            _adaptive->recordFrame(nearD, stats.frameMs);
            _guard.record(nearD, stats.frameMs);
        }
        return Status::ok();
    }

    // The split's note of a frame (bench: frames.csv's split_* columns, see bench-output.md):
    // "split: near_m=D reason=R [model_ms=M] [rays_predicted=P]", D "inf" for everything, empty
    // under a triangle budget; with --near auto P (the probe's far pixels at D) and, for a middle
    // distance or everything the split chose, M: the split's cost model's price of its triangles
    // in view and predicted far pixels, before the correction by measured frames (ray casting is
    // priced by the probe's timed rate, which the note leaves out).
    std::string splitNote(double nearD) const {
        char buf[200];
        std::snprintf(buf, sizeof buf, "%.2f", nearD);
        const std::string near = byBudget() ? "" : std::isinf(nearD) ? "inf" : buf;
        std::string note = "split: near_m=" + near + " reason=" +
                           (autoSplit()  ? _reason
                            : byBudget() ? "budget"
                                         : "fixed");
        if (!autoSplit()) return note;
        const double rays = std::isinf(nearD) ? 0.0 : _adaptive->predictedRays(std::max(0.0, nearD));
        if (nearD > 0 && nearD == _adaptive->current()) {
            const double tris = double(_adaptive->chosenTriangles());
            const double raster = tris > 0 ? _adaptive->rasterFixedMs() + _adaptive->msPerTriangle() * tris : 0.0;
            const double far = std::isinf(nearD) ? 0.0 : _adaptive->msPerRay() * rays + _adaptive->farFixedMs();
            std::snprintf(buf, sizeof buf, " model_ms=%.4f", raster + far);
            note += buf;
        }
        std::snprintf(buf, sizeof buf, " rays_predicted=%.0f", rays);
        return note + buf;
    }
    // The viewer's overlay line: the split's choice, why, the near field's triangles drawn and
    // the frame's rays.
    std::string overlayLine(double nearD, const FrameStats& s) const {
        const std::string near = byBudget()          ? "budget"
                                 : std::isinf(nearD) ? "everything"
                                 : nearD <= 0        ? "0 m"
                                                     : std::to_string(int(std::lround(nearD))) + " m";
        const char* why = autoSplit() ? _reason : byBudget() ? "budget" : "fixed";
        return "split " + near + " (" + why + "): " + shortCount(double(s.triangles)) + " tris, " +
               shortCount(double(s.raysCast)) + " rays";
    }

    // The adaptive split's cost model: far pixels (cached or traced) against the stages that
    // scale with them; the far field's other stages as its fixed cost.
    void recordCosts(uint64_t tris, double rasterMs, const FrameStats& fs) {
        // The far pixels the frame paid for after the draw: pixels whose speculative ray was cast
        // during the draw are left out, so b is the price of a pixel the frame waits for. The
        // split then prices every far pixel of a candidate at it (the overlap's capacity is not
        // modelled): measured, a b lowered by the overlap led the split to near distances whose
        // far pixels the overlap could not cover (docs/reference/far-field.md, speculative rays).
        const uint64_t farPixels = fs.pixels.cache + fs.pixels.rayHit + fs.pixels.rayMiss + fs.pixels.interpolated -
                                   std::min(fs.speculativeUsed, fs.pixels.rayHit + fs.pixels.rayMiss);
        const double farMs = fs.stages.ms(Stage::Rays) + fs.stages.ms(Stage::Cache);
        const double fixedMs = fs.stages.ms(Stage::Opacity) + fs.stages.ms(Stage::Seam) + fs.stages.ms(Stage::Horizon) +
                               fs.stages.ms(Stage::Composite);
        _adaptive->record(tris, rasterMs, farPixels, farMs, fixedMs);
    }
    bool byBudget() const { return _ctx.options.triangleBudget > 0; }
    bool autoSplit() const { return !_fixedSplit && !byBudget() && _ctx.options.nearDistance < 0; }
    double chooseNear(const Camera& camera) {
        if (byBudget()) return 0.0;
        if (autoSplit()) {
            _adaptive->setHazeFar(_ctx.options.effects.hazeFar());
            // While the guard holds a reference the split's choice is not drawn: none is made (no probe,
            // no pricing), so a held frame costs what the reference's own mode costs.
            const double chosen =
                _guard.holding() ? _adaptive->current() : _adaptive->choose(camera, _ctx.options.pixelBudget);
            const double d = _guard.filter(chosen);
            _reason = _guard.overridden() == 1 ? "guard" : _guard.overridden() == 2 ? "measure" : "model";
            return d;
        }
        return _fixedSplit ? _ctx.options.fixedNearDistance() : _ctx.options.nearDistance;
    }
    double farPlane(double nearD, const Camera& camera) const {
        return byBudget() || !std::isfinite(nearD) ? 0.0 : std::max(nearD, camera.zNear * 4.0);  // 0 = infinite
    }
    FarFieldOptions farOptions(double nearD, double zFar) const {
        FarFieldOptions o;
        o.nearDistance = std::max(0.0, nearD);
        o.nearIsDistance = !byBudget();
        o.movingHeight = _ctx.traffic ? _ctx.traffic->tallestAgent() : 0.0;
        o.pixelBudget = _ctx.options.pixelBudget;
        o.cache = _ctx.options.cache;
        o.cacheErrorPx = _ctx.options.cacheErrorPx;
        o.cacheAdaptive = _ctx.options.cacheAdaptive;
        o.horizonAdaptive = _ctx.options.horizonAdaptive;
        o.rayStep = _ctx.options.farStep;
        o.frameMsTarget = _ctx.options.frameMsTarget;
        o.threads = _ctx.options.threads;
        o.overlap = _ctx.options.overlap;
        o.effects = _ctx.options.effects;
        o.depthZFar = effectsFarPlane(zFar, o.effects);  // the projection the renderer used
        o.hazeCovered = true;
        return o;
    }

    ModeContext& _ctx;
    const NearFieldScene& _near;
    const bool _fixedSplit;                // `hybrid-fixed`: always the fixed near distance, never the adaptive split
    HeightGrid _grid;                      // built here (a loaded city)
    const HeightGrid* _heights = nullptr;  // the horizon's grid: _grid, or a streamed city's
    std::unique_ptr<FarField> _far;
    std::unique_ptr<AdaptiveSplit> _adaptive;
    SplitGuard _guard;              // keeps the split from a middle dearer than a measured reference
    const char* _reason = "model";  // why the last auto choice: "model", "guard", "measure"
    osg::ref_ptr<osg::Group> _root;
    std::vector<float> _depth;
    RasterSelection _raster;
    // Viewer face.
    osg::ref_ptr<osg::Node> _viewer;
    NearFarSplit* _split = nullptr;    // owned by _viewer
    FarFieldNode* _farNode = nullptr;  // owned by _viewer
    Stopwatch _viewerClock;
    int _viewerFrames = 0;
    double _viewerNear = 0;
};

}  // namespace

Result<std::unique_ptr<RenderMode>> makeHybridMode(ModeContext& ctx) {
    if (!ctx.rays) return Status::error("mode hybrid needs the city's ray scene, which is not available");
    if (!ctx.city && !ctx.stream)
        return Status::error("mode hybrid needs the loaded city (height grid), which is not available");
    if (!ctx.scene) return Status::error("mode hybrid needs a scene graph, none was loaded");
    if (ctx.options.horizonGrid < 0 || ctx.options.horizonGrid > 8192)
        return Status::error("option horizon grid = " + std::to_string(ctx.options.horizonGrid) +
                             " is out of range [1, 8192] (cells per side), or 0 = auto");
    return std::unique_ptr<RenderMode>(new HybridMode(ctx, false));
}

Result<std::unique_ptr<RenderMode>> makeHybridFixedMode(ModeContext& ctx) {
    auto m = makeHybridMode(ctx);
    if (!m) return m.status();
    return std::unique_ptr<RenderMode>(new HybridMode(ctx, true));
}

}  // namespace vista
