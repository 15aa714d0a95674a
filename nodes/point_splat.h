// Splatted drawing of point impostors (thesis ch. 5 "splatting"; surface
// splatting with normalised accumulation). Internal to nodes/: called by
// PointImpostor::drawImplementation when the process-wide point style
// (point_impostor.h, setPointStyle) asks for splats.
//
// Per impostor, within the screen rectangle of its bounding box:
//   1. the depth drawn so far is copied into a private depth texture;
//   2. visibility: every point as a round sprite of radius 2 sigma pixels
//      writes its depth pushed back by `push` footprints (depth only);
//   3. accumulation: every point adds (colour * w, w) into an RGBA16F target
//      where its depth passes (LEQUAL) against step 2, with w the Gaussian of
//      the fragment's distance to the point's exact projected position;
//   4. normalisation: back in the caller's framebuffer, every pixel with
//      weight gets colour = sum(colour * w) / sum(w) and the visibility depth.
// Points within `push` footprints of the nearest surface are averaged; points
// behind it are hidden. The kernel is sigma output pixels at the bake's
// target focal length (480 pixels over 60 degrees) and grows with the
// viewer's focal length beyond it, so a larger window does not open holes.
// GL resources (an FBO with a colour and a depth texture of the viewport's
// size) are kept per graphics context. Returns false, having drawn nothing,
// when it cannot splat here (a multisampled framebuffer, an incomplete FBO);
// the caller then draws plain points.
#pragma once
#include <osg/Geometry>
#include <osg/RenderInfo>

namespace vista {

struct SplatParams {
    float sigmaPx = 0.25f;  // Gaussian sigma, output pixels (at the bake's focal length)
    float push = 2.0f;      // visibility tolerance, in kernel footprints (world size at the point's distance)
};

// `geometry` (a PointImpostor) is drawn twice with its own state (uniforms,
// atlas) under the splat program, which replaces the geometry's program.
bool drawSplats(const osg::Geometry& geometry, osg::RenderInfo& ri, const SplatParams& params);

// GLSL 1.20 shared by the impostor's point program and the splat program:
// the impostor uniforms, varyings vUv/vTextured, and
// `vec3 vista_impostorVertex()` (sets vUv, vTextured and gl_FrontColor from
// the eye's ray through the sampling plane; returns the dequantized model
// position of the point).
const char* impostorVertexLibrary();

}  // namespace vista
