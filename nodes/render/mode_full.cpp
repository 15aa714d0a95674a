// `full`: the chunked city, far plane at infinity (mode_full.h).
#include "nodes/render/mode_full.h"

namespace vista {
namespace {

class FullMode : public GraphMode {
public:
    explicit FullMode(ModeContext& ctx) : GraphMode(ctx) {
        _graph = ctx.chunkedCity();
        _setup.push_back({"chunking", ctx.chunkingMs()});
        // A streamed city is chunked region by region as it arrives (no chunk list of the whole).
        if (!ctx.streamedCity) _raster.chunks = ctx.nearField().drawOrder;
        _raster.wholeCity = true;
    }
    std::string name() const override { return "full"; }
    const RasterSelection* lastRaster() const override { return &_raster; }

private:
    RasterSelection _raster;  // every chunk, infinite far plane
};

}  // namespace

Result<std::unique_ptr<RenderMode>> makeFullMode(ModeContext& ctx) {
    return std::unique_ptr<RenderMode>(new FullMode(ctx));
}

}  // namespace vista
