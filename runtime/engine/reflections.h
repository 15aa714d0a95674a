// Reflection stage: glass reflections of the `glass` effect, one pass over a
// finished frame, shared by every render mode (thesis §4.8.4: partly
// reflective surfaces with few rays).
//
// Input: the frame with glass pixels marked by alpha (kGlassAlpha for a pixel
// wholly covered by glass; between kGlassAlpha and 255 for partial coverage,
// e.g. after supersampling: weight (255 - a) / (255 - kGlassAlpha)).
// Glass pixels are grouped in s x s blocks, s the smallest stride (1..64)
// with at most fx.rayBudget blocks; per block one sample pixel (the marked
// pixel nearest the block centre) casts a primary ray to find the glass
// point and its normal, then one reflection ray; miss = sky (night aware),
// hit = its prelit colour hazed by the reflected distance. Every marked pixel
// of the block blends: c = c (1 - wF) + wF haze(z, reflection), with Schlick's
// F = F0 + (1 - F0)(1 - cos)^5 (F0 = fx.reflectance) and z the pixel's
// eye-plane depth. Grazing and parallel rays are handled (reflection of a ray
// parallel to the pane continues along it; origins are offset off the pane).
// Afterwards every pixel's alpha is 255.
// Runs only when called for: no marked pixel -> nothing but the scan (no
// stage recorded, no ray); fx.glass off or a budget of 0 -> marks cleared,
// no ray. Records Stage::Reflect and EffectId::Glass, glassPixels,
// reflectionRays (also added to raysCast: primary + reflection rays).
// Deterministic (blocks are independent; any thread count); nothing throws.
#pragma once
#include "runtime/engine/frame_effects.h"
#include "runtime/engine/frame_stats.h"
#include "runtime/engine/image.h"
#include "runtime/scene/camera.h"

namespace vista {

class RayScene;

// True if any pixel of `img` carries a glass mark.
bool hasGlassPixels(const Image& img);
// rays may be null only when fx.glass is off (marks are then just cleared).
void reflectionStage(const RayScene* rays, const Camera& camera, const FrameEffects& fx, Image& img, FrameStats& stats);

}  // namespace vista
