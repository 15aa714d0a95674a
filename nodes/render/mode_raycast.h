// `raycast`: every pixel ray cast with Embree into the city's RayScene (one
// primary ray through each pixel centre, prelit colour of the hit, sky colour
// on a miss — the same sky as the GL modes). Both cores via TBB.
// Stats: pixels.rayHit / rayMiss (they add up to the frame), raysCast = one
// per pixel, stage "rays". Needs ctx.rays (the program builds it: "bvh").
// Viewer: a drawable that casts the viewer camera's frame the same way and
// draws it over the viewport (infinite far plane, nothing rasterised).
#pragma once
#include <memory>

#include "nodes/render/render_mode.h"

namespace vista {

Result<std::unique_ptr<RenderMode>> makeRaycastMode(ModeContext& ctx);

}  // namespace vista
