// `lodmesh`: the baked ViewCellSwitch of a mesh bake (mode_lodmesh.h).
#include "nodes/render/mode_lodmesh.h"

#include "foundation/timing.h"
#include "nodes/baked_file.h"

namespace vista {
namespace {

class LodMeshMode : public GraphMode {
public:
    LodMeshMode(ModeContext& ctx, osg::ref_ptr<ViewCellSwitch> root, const SetupTimes& setup)
        : GraphMode(ctx), _root(std::move(root)) {
        _setup = setup;
        // The near field in hybrid's 40 m chunks and at its near distance (view_cell_switch.h).
        _root->setNearChunks(ctx.nearField(), ctx.options.fixedNearDistance());
        _setup.push_back({"chunking", ctx.chunkingMs()});
        _root->setNearestFallback(true);
        _graph = _root;
    }
    std::string name() const override { return "lodmesh"; }

protected:
    void describe(FrameStats& stats) const override {
        const int cell = _root->lastCell();
        stats.notes.push_back("near chunks " + std::to_string(_root->lastChunkCount()));
        stats.notes.push_back(cell >= 0 ? "cell " + std::to_string(cell) + " (" +
                                              std::to_string(_root->impostorsOf(uint32_t(cell)).size()) + " meshes)"
                                        : "no cell");
    }

private:
    osg::ref_ptr<ViewCellSwitch> _root;
};

}  // namespace

Result<std::unique_ptr<RenderMode>> makeLodMeshMode(ModeContext& ctx) {
    osg::ref_ptr<ViewCellSwitch> root = isMeshBake(ctx.scene) ? dynamic_cast<ViewCellSwitch*>(ctx.scene) : nullptr;
    SetupTimes setup;
    if (!root) {
        const std::string file = !ctx.options.bakedMeshFile.empty() ? ctx.options.bakedMeshFile : ctx.options.bakedFile;
        if (file.empty())
            return Status::error(
                "mode lodmesh: the city has no textured depth meshes; open or pass (--baked-mesh) a file from "
                "'vista bake --representation mesh'");
        auto bf = loadBakeForMode(ctx, file);
        if (!bf) return bf.status();
        if (!bf->meshes)
            return Status::error("mode lodmesh: '" + file +
                                 "' holds point impostors; pass --baked-mesh with a file from "
                                 "'vista bake --representation mesh'");
        root = bf->root;
        setup.push_back({"baked_load", bf->loadMs});
    }
    return std::unique_ptr<RenderMode>(new LodMeshMode(ctx, root, setup));
}

}  // namespace vista
