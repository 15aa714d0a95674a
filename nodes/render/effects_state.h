// The GL side of the run-time effects (frame_effects.h), one implementation
// for the bench's renderer and the viewer:
//   applyEffectsState(): haze on `ss`: the uniforms of scene_graph.h
//     (density = fx.extinction(), colour = fx.hazeColor(); 0 = none) and, while
//     haze is on, a GLSL program that hazes per fragment at the eye-plane
//     depth exactly as FrameEffects::applyHaze does (fixed-function fog is
//     interpolated per vertex on some drivers, which the ray caster cannot
//     match); haze off = no program (fixed function, as without effects).
//     Idempotent. Programs below `ss` (the instanced trees) read the same uniforms.
//     hazeInRaster = false: the drawn scene stays unhazed (no program,
//     density uniform 0) because a later pass hazes the read-back pixels
//     (hybrid: FarFieldOptions::hazeCovered); the far plane still applies.
//   effectsFarPlane(): the projection's far plane with haze: nothing beyond
//     fx.hazeFar() is drawn (zFar <= 0 means infinite).
#pragma once
#include <osg/StateSet>

#include "runtime/engine/frame_effects.h"

namespace vista {

void applyEffectsState(osg::StateSet& ss, const FrameEffects& fx, bool hazeInRaster = true);
double effectsFarPlane(double zFar, const FrameEffects& fx);

}  // namespace vista
