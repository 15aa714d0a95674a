// The parts of render_mode.h that every mode shares: ModeContext (the plain
// and chunked city, built once), GraphMode's bench face, loadBakeForMode.
#include "nodes/render/render_mode.h"

#include "foundation/timing.h"
#include "nodes/baked_file.h"
#include "nodes/render/city_stream.h"
#include "nodes/render/offscreen.h"
#include "nodes/view_cell_switch.h"

namespace vista {

osg::Node* ModeContext::plainScene() {
    if (_plain) return _plain.get();
    if (auto* baked = dynamic_cast<ViewCellSwitch*>(scene)) {
        osg::ref_ptr<osg::Group> tiles = new osg::Group;
        tiles->setStateSet(baked->getStateSet());
        for (unsigned i = 0; i < baked->getTileCount() && i < baked->getNumChildren(); ++i)
            tiles->addChild(baked->getChild(i));
        _plain = tiles;
    } else {
        _plain = scene;
    }
    return _plain.get();
}

const NearFieldScene& ModeContext::nearField() {
    if (stream) {
        VISTA_CHECK(stream->nearField() != nullptr);
        return stream->nearField()->scene();
    }
    if (!_nearField) {
        Stopwatch sw;
        _nearField = std::make_shared<NearFieldScene>(
            buildNearFieldScene(plainScene(), kNearChunkSize, labels, !labels && options.nearDetailPx > 0));
        _chunkingMs = sw.ms();
    }
    return *_nearField;
}

osg::Group* ModeContext::chunkedCity() {
    if (streamedCity) return streamedCity;
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

}  // namespace vista
