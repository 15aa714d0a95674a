// `lodmesh` (Chen et al. 2003): the walkthrough drawn from a mesh bake
// (`vista bake --representation mesh`). In a view cell: the city tiles the
// cell's textured depth meshes do not replace plus those meshes; outside
// every cell: the same for the nearest cell (ViewCellSwitch nearest
// fallback), so the far field is always a mesh.
//
// Contract: the mesh bake is ctx.scene when that is the root of a mesh bake
// (isMeshBake), else ctx.options.bakedMeshFile (--baked-mesh), else
// ctx.options.bakedFile (--baked), which must then be a mesh bake (loaded and
// checked by loadBakedFile; set-up cost "baked_load"); none or a point bake ->
// error naming --baked-mesh and --representation mesh. Notes per frame: "cell N (K meshes)".
// Viewer: the same ViewCellSwitch, infinite far plane. All meshes are
// resident once the file is loaded (no per-cell streaming or prefetch).
#pragma once
#include <memory>

#include "nodes/render/render_mode.h"

namespace vista {

Result<std::unique_ptr<RenderMode>> makeLodMeshMode(ModeContext& ctx);

}  // namespace vista
