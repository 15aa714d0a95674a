// The run-time effects around every render mode (render_mode.h:
// createRenderMode() wraps each mode with withEffects()): one implementation
// for all modes and both faces.
//   bench face: sets the renderer's fog and night sky (OffscreenRenderer::
//               setEffects; the haze program stays out of the rasteriser
//               when the mode hazes its raster pixels itself), renders the
//               inner mode, records the haze effect the rasteriser's fog
//               applied, and runs the reflection stage (reflections.h) on
//               the image when the scene marks glass (its time is added to
//               the frame);
//   viewer face: the inner mode's scene under a group with the effects'
//               state (effects_state.h, refreshed every frame for live
//               toggles), plus a ReflectionDrawable when the scene marks
//               glass; the far plane of the haze (effectsFarPlane).
// With a traffic run (ModeContext::traffic), both faces place its agents at
// the camera's time before the inner mode runs (which may split them between
// GL and rays); the viewer's group holds the agents' node.
// Everything else (reset, traced pixels, raster selection, sky) is the inner
// mode's. The effects are read from ctx.options.effects every frame; `ctx`
// must outlive the mode.
#pragma once
#include <memory>

#include "nodes/render/render_mode.h"

namespace vista {

std::unique_ptr<RenderMode> withEffects(std::unique_ptr<RenderMode> inner, ModeContext& ctx);

}  // namespace vista
