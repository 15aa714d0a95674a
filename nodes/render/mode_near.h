// `near`: only the near field — the chunked city of `full` drawn with the
// far clip plane at the near distance (ModeOptions::fixedNearDistance(): --near,
// or 100 m when --near is auto; note "near distance auto -> 100 m"). Chunks
// wholly beyond the plane are culled, the rest is clipped per pixel: the
// lower bound of hybrid's frame time (its near field without the far field).
// Set-up: "chunking" (shared). Viewer: the same graph and far plane.
#pragma once
#include <memory>

#include "nodes/render/render_mode.h"

namespace vista {

Result<std::unique_ptr<RenderMode>> makeNearMode(ModeContext& ctx);

}  // namespace vista
