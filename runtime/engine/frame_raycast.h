// The whole-frame raycast of the `raycast` render mode (and of tests that
// compare the far field with it): one primary ray per pixel centre, every
// pixel of the camera, cast as castPrimaryRays casts (far_field_rays.h: same
// directions, packets of 8, shading, sky on a miss) with one run per image
// row.
//
// castFrame(): `out` is resized to the camera when its size differs; adds
// the rays and hits to `counts`; shading.depth / shading.keys, when set,
// hold width * height entries. Deterministic for any `threads` (0 = all
// cores). Contract (VISTA_CHECK): the camera has at least one pixel.
//
// raycastFrame(): the `raycast` render mode's frame, also the hybrid's frame
// when its split picks ray casting: castFrame with the run-time effects of
// `fx` (haze clips the rays and hazes every pixel by its eye-plane depth as
// it is written), into `out` (resized to the camera), and the pixel classes
// (rayHit, rayMiss), raysCast, the rays stage and the effects that ran in
// `stats`. One implementation, so the two frames are the same bytes.
#pragma once
#include "runtime/engine/far_field_rays.h"

namespace vista {

void castFrame(const RayScene& scene, const Camera& camera, Image& out, RayCounts& counts, int threads,
               const RayShading& shading = {});

void raycastFrame(const RayScene& scene, const Camera& camera, Image& out, FrameStats& stats, int threads,
                  const FrameEffects& fx);

}  // namespace vista
