// `impostor` mode of `vista bench`: the walkthrough drawn from a baked file.
// In a view cell: the city tiles not replaced by the cell's impostors plus the
// cell's point impostors; outside every cell: the plain city.
//
// Contract: the baked scene comes from ctx.scene when it is a baked root
// (bench run on a baked file), else from ctx.options.bakedFile (loaded and
// checked by loadBakedFile); neither -> setup error naming the option.
// Renders through ctx.renderer (single-threaded, the bench thread).
// Stats: the renderer's timing/counters, pixels.covered = pixels drawn (not
// sky), a note "cell N" or "no cell" per frame.
#pragma once
#include <memory>

#include "foundation/status.h"
#include "nodes/render/render_mode.h"

namespace vista {

Result<std::unique_ptr<BenchMode>> makeImpostorMode(BenchContext& ctx);

}  // namespace vista
