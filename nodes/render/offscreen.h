// OffscreenRenderer: one OpenGL context (an osgViewer window; under Xvfb +
// llvmpipe here, a real window on a GPU) that renders scene graphs from a
// Camera into an Image, with colour and optional depth read back.
//
// Contract: create() fails with a clear Status when no display is available
// (message says to use `xvfb-run -a`). render() draws the sky (SkyBackground)
// as background (unless skyLayer = false), then `scene` with the camera's view
// and projection (zFar <= 0: infinite far plane), waits for the GPU
// (glFinish) and reads back colour (RGBA8, row 0 at top) and, if `depth` is
// non-null, window-space depth in [0,1] (row 0 at top, 1 = nothing drawn).
// The window is never presented (no buffer swap: a frame is the read-back
// image, as a ray-cast frame is), and deleted GL objects are released every
// kGLObjectFlushFrames frames (flushDeletedGLObjectsEvery).
// Fills stats.frameMs/cullMs/drawMs/triangles/drawCalls. Single-threaded:
// call from the thread that created it.
//
// Precision: the view matrix is camera.view() about the world origin; OSG
// multiplies it with the tiles' double MatrixTransforms in double (osg::Matrixd)
// before handing float modelview matrices to GL, so tile-local float geometry
// stays exact 1,000 km from the origin (tested at 1e6/2e6 m).
// Depth: standard 24-bit depth with the infinite far plane: resolution
// ~ d^2 / (zNear * 2^24) metres at distance d (0.3 m at 1.2 km for zNear 0.3).
// Culling: setExactCulling() (near and far planes, no small-feature culling).
// Triangles/draw calls count every leaf of OSG's render bins after cull
// (instanced primitive sets count every instance; the background is excluded).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include <osg/Node>

#include <osg/Camera>

#include "foundation/status.h"
#include "nodes/render/sky_background.h"
#include "runtime/engine/frame_effects.h"
#include "runtime/engine/frame_stats.h"
#include "runtime/engine/image.h"
#include "runtime/scene/camera.h"

namespace vista {

// The culling of every vista picture (the bench's renderer and the viewer's
// camera): exact frustum culling including the near and far planes; no
// small-feature culling (the ray caster has none). A mode that wants more
// culling adds it inside its own graph (osglod).
void setExactCulling(osg::Camera& camera);

// Deleted GL objects (buffers, textures, programs of dropped nodes) are
// released every `frames` frames instead of every frame. osgViewer's renderer
// flushes them at the start of each draw (osg::flushDeletedGLObjects), which
// walks every buffer-object set under a mutex whether anything was deleted or
// not; OSG keeps one set per buffer size, thousands in a city, so the walk
// costs 2.2 ms of CPU a frame on the 2 km city whatever was drawn (perf, llvmpipe).
// Installs a renderer on `camera` (before the viewer is realized; a viewer
// with an incremental compile operation flushes through it and is left as
// is). frames >= 1 (1 = OSG's every frame).
constexpr unsigned kGLObjectFlushFrames = 16;
void flushDeletedGLObjectsEvery(osg::Camera& camera, unsigned frames = kGLObjectFlushFrames);

// One frame of ground-truth labels (renderLabels), row 0 at the top.
struct LabelFrame {
    int width = 0, height = 0;
    std::vector<uint32_t> ids;     // instance ids (citygen/labels.h), 0 = nothing drawn
    std::vector<uint8_t> classes;  // semantic classes, 0 (sky) = nothing drawn
    std::vector<float> depth;      // eye depth (metres along the optical axis), 0 = nothing drawn
};

class OffscreenRenderer {
public:
    static Result<std::unique_ptr<OffscreenRenderer>> create(int width, int height);
    ~OffscreenRenderer();
    // skyLayer = false: no sky under the scene (the colour buffer is cleared
    // to black), for a caller that writes every uncovered pixel itself (the
    // hybrid's far field: RenderMode::drawsSky); saves the screen-filling
    // textured quad (3.7 ms of a 1280x720 frame on llvmpipe).
    Status render(osg::Node* scene, const Camera& camera, double zFar, Image* color, std::vector<float>* depth,
                  FrameStats& stats, bool skyLayer = true);
    // The label pass (nodes/label_pass.h): draws `labelScene` (label twins of
    // chunks under a group with NearFieldScene::labelRootState) into an FBO
    // (RGBA8 ids + RGBA32F depth/class + 24-bit depth test) with the camera's
    // view and projection (zFar <= 0: infinite; run-time effects do not
    // apply) and reads it back into `out`. stats.frameMs = wall time incl.
    // glFinish and read-back.
    Status renderLabels(osg::Node* labelScene, const Camera& camera, double zFar, LabelFrame& out, FrameStats& stats);
    int width() const;
    int height() const;
    // Shifts the sample point of every pixel by (dx, dy) pixels (x right,
    // y down) for the following renders (jittered supersampling); sky included.
    void setSubpixelOffset(double dx, double dy);
    // A node drawn with every render() after the scene (with the scene's
    // effects) and one drawn with every renderLabels() after the label scene:
    // what moves through every mode (a traffic run's agents,
    // traffic_scene.h); null = none. The nodes must outlive their use.
    void setOverlay(osg::Node* colour, osg::Node* labels);
    // Run-time effects of the following renders: haze (fog on the drawn
    // scene, far plane at fx.hazeFar()) and the night sky (effects_state.h);
    // hazeInRaster = false: far plane only, the caller hazes the pixels.
    void setEffects(const FrameEffects& fx, bool hazeInRaster = true);
    // Counts the fragments of the following render()s that pass the depth
    // test (a GL_SAMPLES_PASSED query around the frame; the sky layer's one
    // per pixel left out) and notes them in the frame's stats:
    // "fragments: N (F per pixel)". Off by default (the query costs time).
    void setCountFragments(bool on);
    // GL_RENDERER / GL_VERSION strings of the context (for result files).
    std::string glRenderer() const;

private:
    OffscreenRenderer();
    struct Impl;
    std::unique_ptr<Impl> _impl;
};

}  // namespace vista
