#include "nodes/render/ground_truth_session.h"

#include "foundation/timing.h"
#include "runtime/scene/scene_graph.h"

namespace vista {

Status GroundTruthSession::setUp(const GroundTruthSetup& setup, const SceneModel& city) {
    modeName = setup.mode;
    auto r = OffscreenRenderer::create(setup.width, setup.height);
    if (!r) return r.status();
    renderer = std::move(*r);
    ctx.city = &city;
    ctx.scene = sceneRoot(city);
    ctx.renderer = renderer.get();
    ctx.options = setup.options;
    ctx.labels = setup.labels;
    const ModeInfo* info = findRenderMode(setup.mode);
    const bool needRays = (info && info->needsRays) || effectsNeedRays(setup.options.effects);
    if (setup.streamed) {
        auto st = CityStream::create(*setup.streamed, setup.stream, needRays, {}, setup.labels);
        if (!st) return Status::error("setting up the streamed city failed: " + st.status().message());
        stream = std::move(*st);
        // hybrid: the stream keeps the near field, its split index and the horizon grid too.
        if (needRays && modeStreamsNearField(setup.mode)) stream->enableNearField(setup.options.horizonGrid);
        // The label pass draws the whole streamed city; without it the mode's own levels suffice.
        if (!setup.labels) stream->setGraphLevels(streamGraphOf({setup.mode}), streamNearBand(setup.options));
        if (setup.streamReady) setup.streamReady(*stream);
        ctx.stream = stream.get();
        ctx.streamedCity = stream->graph();
        ctx.scene = stream->graph();
        ctx.rays = stream->rays();
    } else if (needRays) {
        auto rs = RayScene::build(city);
        if (!rs) return Status::error("building the Embree ray scene failed: " + rs.status().message());
        rays = std::move(rs.value());
        ctx.rays = rays.get();
    }
    if (setup.traffic) {
        traffic = std::make_unique<TrafficScene>(setup.traffic, city.params, setup.labels);
        if (RayScene* r = activeRays()) VISTA_RETURN_IF_ERROR(traffic->attachRays(r));
        VISTA_RETURN_IF_ERROR(traffic->showCitySignals(city, setup.paged));
        ctx.traffic = traffic.get();
        renderer->setOverlay(traffic->node(), traffic->labelNode());
    }
    auto m = createRenderMode(setup.mode, ctx);
    if (!m) return m.status();
    mode = std::move(*m);
    if (setup.labels && !setup.streamed) labelRoot->setStateSet(ctx.nearField().labelRootState.get());
    return Status::ok();
}

Status GroundTruthSession::renderFrame(const Camera& camera, GroundTruthBuffers& b, FrameStats& stats) {
    // Ray origins near the scene's frame origin: float precision anywhere in the city.
    if (RayScene* rs = activeRays()) VISTA_RETURN_IF_ERROR(rs->placeFrameNear(camera.eye));
    return mode->renderFrame(camera, b.img, stats);
}

Status GroundTruthSession::renderLabels(const Camera& cam, int threads, GroundTruthBuffers& b, LabelCosts& costs) {
    const RasterSelection* sel = mode->lastRaster();
    if (!sel) return Status::error("mode " + modeName + " reports no raster selection");
    osg::Group* labelScene = labelRoot.get();
    const bool castUncovered = modeName == "hybrid";
    if (stream) {
        // The stream's label twin holds every chunk of the streamed graph; the
        // ray-cast labels of a far field need the regions' models, which a
        // streamed ray scene does not keep.
        if (!sel->wholeCity || castUncovered || sel->nearDistance < 1e299)
            return Status::error("mode " + modeName +
                                 ": ground-truth labels of a streamed city need a mode that rasterises the whole "
                                 "city (full); use --channels rgb");
        labelScene = stream->labelGraph();
    } else {
        const NearFieldScene& nf = ctx.nearField();
        labelRoot->removeChildren(0, labelRoot->getNumChildren());
        for (uint32_t i : sel->chunks)
            if (i < nf.labelChunks.size()) labelRoot->addChild(nf.labelChunks[i].get());
    }
    FrameStats ls;
    VISTA_RETURN_IF_ERROR(renderer->renderLabels(labelScene, cam, sel->zFar, b.raster, ls));
    costs.rasterMs = ls.frameMs;
    Stopwatch sw;
    const RasterLabels raster{b.raster.ids.data(), b.raster.classes.data(), b.raster.depth.data()};
    costs.farPixels = mergeLabels(*ctx.city, ctx.rays, cam, raster, sel->nearDistance, castUncovered, b.gt, threads);
    costs.raysMs = sw.ms();
    return Status::ok();
}

}  // namespace vista
