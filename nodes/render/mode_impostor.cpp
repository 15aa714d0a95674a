#include "nodes/render/mode_impostor.h"

#include "nodes/baked_file.h"
#include "nodes/render/offscreen.h"

namespace vista {
namespace {

class ImpostorMode : public BenchMode {
public:
    ImpostorMode(BenchContext& ctx, osg::ref_ptr<ViewCellSwitch> root) : _ctx(ctx), _root(std::move(root)) {}
    std::string name() const override { return "impostor"; }
    Status renderFrame(const Camera& camera, Image& out, FrameStats& stats) override {
        if (!_ctx.renderer) return Status::error("mode impostor needs an OpenGL renderer");
        Status s = _ctx.renderer->render(_root.get(), camera, 0.0, &out, nullptr, stats);
        if (!s) return s;
        const int cell = _root->lastCell();
        stats.notes.push_back(cell >= 0 ? "cell " + std::to_string(cell) + " (" + std::to_string(_root->impostorsOf(uint32_t(cell)).size()) +
                                              " impostors)"
                                        : "no cell");
        return Status::ok();
    }

private:
    BenchContext& _ctx;
    osg::ref_ptr<ViewCellSwitch> _root;
};

}  // namespace

Result<std::unique_ptr<BenchMode>> makeImpostorMode(BenchContext& ctx) {
    osg::ref_ptr<ViewCellSwitch> root = dynamic_cast<ViewCellSwitch*>(ctx.scene);
    if (!root) {
        if (ctx.options.bakedFile.empty())
            return Status::error("mode impostor: the city is not baked; pass --baked city.baked.osgb (from 'vista bake')");
        auto bf = loadBakedFile(ctx.options.bakedFile);
        if (!bf) return bf.status();
        root = bf->root;
    }
    return std::unique_ptr<BenchMode>(new ImpostorMode(ctx, root));
}

}  // namespace vista
