// `full`: every triangle of the city, far plane at infinity — the exact
// reference of every bench frame and the timing baseline.
//
// Drawn from the city re-chunked into kNearChunkSize (40 m) chunks, the same
// chunks as hybrid's near field (ModeContext::chunkedCity): OSG frustum-culls
// per chunk, so this is the best lossless conventional draw (one draw call
// per chunk). The chunks keep the loaded graph's vertex floats, colours and
// state, so the picture is the unchunked city's (tested: identical from the
// street; depth ties of far coplanar surfaces may resolve otherwise, >= 50 dB
// from 500 m above; see near_field_chunks.h).
// Set-up: "chunking" (shared with near, osglod and hybrid). Viewer: the same
// graph and far plane.
#pragma once
#include <memory>

#include "nodes/render/render_mode.h"

namespace vista {

Result<std::unique_ptr<RenderMode>> makeFullMode(ModeContext& ctx);

}  // namespace vista
