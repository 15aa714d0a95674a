// `hybrid` (thesis ch. 4): the near field rasterised by OSG, the far field
// filled per pixel by FarField on the CPU (opacity from the near field's
// depth, seam check, horizon, panoramic cache, Embree rays, composite).
//
// Near field: the city re-chunked (ModeContext::nearField, 40 m chunks).
//   By distance (default): chunks whose box comes within the near distance,
//   drawn with the far plane at max(nearD, 4 zNear); --near auto: the
//   AdaptiveSplit picks nearD per frame, and a SplitGuard (split_guard.h)
//   holds a reference (0 m, everything or the near default of `hybrid-fixed`)
//   while the middle's measured frames cost more than that reference's; the
//   split makes no choice (no probe) on held frames (note "near auto: N m by REASON",
//   REASON model, guard or measure). Every frame notes its split as
//   "split: near_m=D reason=R [model_ms=M rays_predicted=P]" (the bench's
//   frames.csv split_* columns); the viewer's HUD gets an overlay line
//   "split D (R): T tris, N rays".
//   By triangle budget (ModeOptions::triangleBudget > 0): the nearest chunks
//   up to the budget, infinite far plane, no horizon skipping.
// Near-field draw: the chosen chunks nearest first (nearFrontToBack), each
// as its flat twin (window recesses flattened, NearFieldScene::coarseChunks)
// where the twin deviates from it by at most nearDetailPx pixels on screen;
// notes "near kinds: ..." (the chosen chunks' triangles by kind) and "near
// coarse: ..." (docs/reference/far-field.md "The near field's cost").
// Options: nearDistance, triangleBudget, pixelBudget, horizonGrid, cache,
// threads, nearFrontToBack, nearDetailPx. Stats: pixel classes (Table 4.1), stages cull, near, opacity,
// seam, horizon, cache, rays, composite; notes: skipped stages, auto choice.
// Set-up: "chunking" (shared), "height_grid"; needs ctx.rays ("bvh"). The
// height grid of a paged city lies on the paged city's lattice
// (pagedHeightLattice).
// A streamed paged city (ctx.stream, bench --paged-stream): the near field,
// the split's index and the height grid are the stream's
// (StreamedNearField: they follow the resident regions, spliced between
// frames); sceneChanged() drops the far field's cache, last frame and
// speculative rays whenever regions arrived or left.
// Viewer: the same chunks under a NearFarSplit + a FarFieldNode
// (buildHybridScene); beginViewerFrame() applies the same split and far
// plane (auto: records the previous viewer frame's costs — near ms taken as
// the frame's wall time minus its far-field stages — and chooses again).
// End points of the split (--near auto picks 0 m or everything; never under a
// triangle budget): 0 m draws the `raycast` frame (raycastFrame: no GL pass,
// no read-back, no far-field stage), everything draws the `full` frame (the
// chunked city with sky layer and haze in the rasteriser, no read-back, no
// far field): the same images as those modes, at their cost.
// `hybrid-fixed`: the same mode at the fixed near distance (--near, 100 m
// under --near auto), never the adaptive split: the split's middle fixed
// choice, for side-by-side runs against `hybrid --near auto`.
// Errors: missing ray scene / city (neither loaded nor streamed), horizon grid
// out of 1 .. 8192.
#pragma once
#include <memory>

#include "nodes/render/render_mode.h"

namespace vista {

Result<std::unique_ptr<RenderMode>> makeHybridMode(ModeContext& ctx);
Result<std::unique_ptr<RenderMode>> makeHybridFixedMode(ModeContext& ctx);

}  // namespace vista
