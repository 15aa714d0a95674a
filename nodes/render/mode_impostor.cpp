// `impostor`: the baked ViewCellSwitch (mode_impostor.h).
#include "nodes/render/mode_impostor.h"

#include "foundation/timing.h"
#include "nodes/baked_file.h"
#include "nodes/point_impostor.h"

namespace vista {
namespace {

class ImpostorMode : public GraphMode {
public:
    ImpostorMode(ModeContext& ctx, osg::ref_ptr<ViewCellSwitch> root, const SetupTimes& setup)
        : GraphMode(ctx), _root(std::move(root)) {
        _setup = setup;
        setPointSplatSigma(float(ctx.options.splatSigma));
        // The near field in hybrid's 40 m chunks and at its near distance (view_cell_switch.h).
        _root->setNearChunks(ctx.nearField(), ctx.options.fixedNearDistance());
        _setup.push_back({"chunking", ctx.chunkingMs()});
        _graph = _root;
    }
    std::string name() const override { return "impostor"; }

protected:
    void describe(FrameStats& stats) const override {
        const int cell = _root->lastCell();
        stats.notes.push_back("near chunks " + std::to_string(_root->lastChunkCount()));
        stats.notes.push_back(cell >= 0 ? "cell " + std::to_string(cell) + " (" +
                                              std::to_string(_root->impostorsOf(uint32_t(cell)).size()) + " impostors)"
                                        : "no cell");
    }

private:
    osg::ref_ptr<ViewCellSwitch> _root;
};

}  // namespace

Result<std::unique_ptr<RenderMode>> makeImpostorMode(ModeContext& ctx) {
    // A mesh bake (--representation mesh) has no point impostors: use --baked then.
    osg::ref_ptr<ViewCellSwitch> root = isMeshBake(ctx.scene) ? nullptr : dynamic_cast<ViewCellSwitch*>(ctx.scene);
    SetupTimes setup;
    if (!root) {
        if (ctx.options.bakedFile.empty())
            return Status::error(
                isMeshBake(ctx.scene)
                    ? "mode impostor: the scene holds textured depth meshes (mode lodmesh); pass --baked "
                      "city.baked.osgb "
                      "(from 'vista bake') for point impostors"
                    : "mode impostor: the city is not baked; pass --baked city.baked.osgb (from 'vista bake')");
        auto bf = loadBakeForMode(ctx, ctx.options.bakedFile);
        if (!bf) return bf.status();
        if (bf->meshes)
            return Status::error("mode impostor: '" + ctx.options.bakedFile +
                                 "' holds textured depth meshes; use mode lodmesh");
        root = bf->root;
        setup.push_back({"baked_load", bf->loadMs});
    }
    return std::unique_ptr<RenderMode>(new ImpostorMode(ctx, root, setup));
}

}  // namespace vista
