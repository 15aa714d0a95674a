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
    // Haze: on the CPU from the read-back depth in the bench face, the haze program in the viewer.
    Status renderFrame(const Camera& camera, Image& out, FrameStats& stats) override {
        if (!_ctx.options.effects.haze || !_ctx.renderer) return GraphMode::renderFrame(camera, out, stats);
        return renderWholeCityHazed(_ctx, camera, out, _depth, stats);
    }
    bool hazesRasterPixels() const override { return true; }
    bool hazesViewerPixels() const override { return false; }

private:
    RasterSelection _raster;    // every chunk, infinite far plane
    std::vector<float> _depth;  // read-back scratch under haze
};

}  // namespace

Result<std::unique_ptr<RenderMode>> makeFullMode(ModeContext& ctx) {
    return std::unique_ptr<RenderMode>(new FullMode(ctx));
}

}  // namespace vista
