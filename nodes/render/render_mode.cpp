// The render-mode registry (render_mode.h): every mode by name, and
// createRenderMode(), which wraps each in the run-time effects.
#include "nodes/render/render_mode.h"

#include <algorithm>

#include "nodes/render/city_stream.h"
#include "nodes/render/effects_mode.h"
#include "nodes/render/mode_full.h"
#include "nodes/render/mode_hybrid.h"
#include "nodes/render/mode_impostor.h"
#include "nodes/render/mode_lodmesh.h"
#include "nodes/render/mode_near.h"
#include "nodes/render/mode_osgimpostor.h"
#include "nodes/render/mode_osglod.h"
#include "nodes/render/mode_raycast.h"
#include "runtime/engine/adaptive_split.h"

namespace vista {

const std::vector<ModeInfo>& renderModes() {
    static const std::vector<ModeInfo> kModes = {
        {"full", "all geometry in 40 m chunks, far plane at infinity (the exact reference)", false, false,
         makeFullMode},
        {"near", "only the near field: the chunked city clipped at --near metres", false, false, makeNearMode},
        {"raycast", "every pixel ray cast with Embree, prelit colours", true, false, makeRaycastMode},
        {"osgimpostor", "stock osgSim::Impostor on every tile beyond --near + tile radius", false, false,
         makeOsgImpostorMode},
        {"osglod", "stock osg::LOD per chunk with osgUtil::Simplifier far versions + small-feature culling", false,
         false, makeOsgLodMode},
        {"hybrid", "near field rasterised + ray-cast far field (horizon, cache, Embree)", true, false, makeHybridMode},
        {"hybrid-fixed", "hybrid at the fixed --near distance (100 m under --near auto), never the adaptive split",
         true, false, makeHybridFixedMode},
        {"impostor", "near field + baked point impostors (needs a baked file: --baked)", false, true, makeImpostorMode},
        {"lodmesh", "near field + the cell's textured depth meshes (a file from 'vista bake --representation mesh')",
         false, false, makeLodMeshMode},
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

bool modeStreams(const std::string& name) {
    return name == "full" || name == "near" || name == "raycast" || modeStreamsNearField(name);
}

std::string streamingModeNames() { return "full, near, raycast, hybrid, hybrid-fixed"; }

bool modeStreamsNearField(const std::string& name) { return name == "hybrid" || name == "hybrid-fixed"; }

StreamGraph streamGraphOf(const std::vector<std::string>& modes) {
    bool nearField = false;
    for (const std::string& m : modes) {
        if (modeStreamsNearField(m)) nearField = true;
        else if (m != "raycast") return StreamGraph::EveryLevel;
    }
    return nearField ? StreamGraph::NearBand : StreamGraph::None;
}

double streamNearBand(const ModeOptions& o) {
    return std::max({AdaptiveSplitOptions().maxDistance, o.fixedNearDistance(), o.nearDistance}) + kStreamBandMarginM;
}

bool modeFollowsTimings(const std::string& name, const ModeOptions& o) {
    if (name != "hybrid" && name != "hybrid-fixed") return false;
    const bool autoSplit = name == "hybrid" && o.triangleBudget == 0 && o.nearDistance < 0;
    return autoSplit || (o.cache && (o.cacheAdaptive || o.horizonAdaptive)) || o.frameMsTarget > 0;
}

bool effectsNeedRays(const FrameEffects& fx) { return fx.glass && fx.glassMarked && fx.rayBudget > 0; }

Result<std::unique_ptr<RenderMode>> createRenderMode(const std::string& name, ModeContext& ctx) {
    const ModeInfo* m = findRenderMode(name);
    if (!m) return Status::error("unknown mode '" + name + "'; available modes: " + renderModeNames());
    if (ctx.streamedCity && !modeStreams(name))
        return Status::error("mode " + name + " does not stream a paged city (modes that do: " + streamingModeNames() +
                             ")");
    if (ctx.streamedCity && modeStreamsNearField(name) && !(ctx.stream && ctx.stream->nearField()))
        return Status::error("mode " + name + " needs the streamed city's near field, which is not kept");
    if (!ctx.scene) return Status::error("mode " + name + " needs a scene graph, none was loaded");
    if (m->needsRays && !ctx.rays)
        return Status::error("mode " + name + " needs the city's ray scene, which is not available");
    if (effectsNeedRays(ctx.options.effects) && !ctx.rays)
        return Status::error("mode " + name + ": glass reflections need the city's ray scene, which is not available");
    auto inner = m->make(ctx);
    if (!inner) return inner.status();
    return withEffects(std::move(*inner), ctx);
}

}  // namespace vista
