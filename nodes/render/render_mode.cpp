// The render-mode registry and the shared parts of ModeContext (render_mode.h).
#include "nodes/render/render_mode.h"

#include "foundation/timing.h"
#include "nodes/render/offscreen.h"
#include "nodes/render/mode_full.h"
#include "nodes/render/mode_hybrid.h"
#include "nodes/render/mode_impostor.h"
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
        _nearField = std::make_shared<NearFieldScene>(buildNearFieldScene(plainScene(), kNearChunkSize));
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

Result<std::unique_ptr<RenderMode>> createRenderMode(const std::string& name, ModeContext& ctx) {
    const ModeInfo* m = findRenderMode(name);
    if (!m) return Status::error("unknown mode '" + name + "'; available modes: " + renderModeNames());
    if (!ctx.scene) return Status::error("mode " + name + " needs a scene graph, none was loaded");
    if (m->needsRays && !ctx.rays) return Status::error("mode " + name + " needs the city's ray scene, which is not available");
    return m->make(ctx);
}

}  // namespace vista
