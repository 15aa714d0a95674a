// `near`: the chunked city clipped at the near distance (mode_near.h).
#include "nodes/render/mode_near.h"

#include <algorithm>

namespace vista {
namespace {

class NearMode : public GraphMode {
public:
    explicit NearMode(ModeContext& ctx) : GraphMode(ctx) {
        _graph = ctx.chunkedCity();  // full's graph: only the far plane differs
        _setup.push_back({"chunking", ctx.chunkingMs()});
    }
    std::string name() const override { return "near"; }

protected:
    double prepare(const Camera& camera) override {
        return std::max(_ctx.options.fixedNearDistance(), camera.zNear * 2.0);
    }
    void describe(FrameStats& stats) const override {
        if (_ctx.options.nearDistance <= 0) stats.notes.push_back("near distance auto -> 100 m");
    }
};

}  // namespace

Result<std::unique_ptr<RenderMode>> makeNearMode(ModeContext& ctx) {
    return std::unique_ptr<RenderMode>(new NearMode(ctx));
}

}  // namespace vista
