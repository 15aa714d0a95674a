// `hybrid` bench mode (issue 4, thesis ch. 4): near field rasterised through
// the OffscreenRenderer, far field filled per pixel by FarField (opacity from
// the near field's depth, horizon, panoramic cache, Embree rays), composited
// on the CPU (uncovered pixels of the read-back near image are replaced).
//
// Near field: the city re-chunked by nodes/near_field_chunks.h.
// Options (BenchOptions): nearDistance (< 0 = auto: AdaptiveSplit),
// pixelBudget, horizonGrid, cache, threads. FrameStats: pixel classes (Table
// 4.1), stages: cull, near (GL draw + readback), opacity, horizon, cache,
// rays, composite; notes: skipped stages, chosen near distance in auto mode.
// Errors: missing ray scene / renderer / city -> error Status from the factory.
#pragma once
#include <memory>
#include <vector>

#include <osg/Group>
#include <osg/Node>
#include <osg/StateSet>

#include "foundation/status.h"
#include "nodes/near_field_chunks.h"
#include "nodes/render/render_mode.h"

namespace vista {

Result<std::unique_ptr<BenchMode>> makeHybridMode(BenchContext& ctx);

}  // namespace vista
