// `impostor` (thesis ch. 5): the walkthrough drawn from a baked file. In a
// view cell: the city tiles the cell's impostors do not replace plus the
// cell's point impostors; outside every cell: the plain city.
//
// Contract: the baked scene is ctx.scene when that is a baked root of point
// impostors (a baked file was loaded; a mesh bake is left to mode lodmesh),
// else ctx.options.bakedFile (a point bake) (loaded and checked by
// loadBakedFile; its cost is set-up "baked_load"); neither -> error naming
// --baked. Notes per frame: "cell N (K impostors)" or "no cell".
// Viewer: the same ViewCellSwitch, infinite far plane.
#pragma once
#include <memory>

#include "nodes/render/render_mode.h"

namespace vista {

Result<std::unique_ptr<RenderMode>> makeImpostorMode(ModeContext& ctx);

}  // namespace vista
