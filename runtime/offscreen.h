// OffscreenRenderer: one OpenGL context (an osgViewer window; under Xvfb +
// llvmpipe here, a real window on a GPU) that renders scene graphs from a
// Camera into an Image, with colour and optional depth read back.
//
// Contract: create() fails with a clear Status when no display is available
// (message says to use `xvfb-run -a`). render() draws the sky gradient
// (lighting.h skyColor) as background, then `scene` with the camera's view
// and projection (zFar <= 0: infinite far plane), waits for the GPU
// (glFinish) and reads back colour (RGBA8, row 0 at top) and, if `depth` is
// non-null, window-space depth in [0,1] (row 0 at top, 1 = nothing drawn).
// Fills stats.frameMs/cullMs/drawMs/triangles/drawCalls. Single-threaded:
// call from the thread that created it.
#pragma once
#include <memory>
#include <vector>

#include <osg/Node>

#include "citygen/status.h"
#include "runtime/bench_mode.h"

namespace vista {

class OffscreenRenderer {
public:
    static Result<std::unique_ptr<OffscreenRenderer>> create(int width, int height);
    ~OffscreenRenderer();
    Status render(osg::Node* scene, const Camera& camera, double zFar, Image* color, std::vector<float>* depth,
                  FrameStats& stats);
    // Draws `background` (row 0 at top; RGBA8) as a full-screen layer behind
    // `scene` instead of the sky gradient (the hybrid composite path).
    Status renderOver(osg::Node* scene, const Camera& camera, double zFar, const Image& background, Image* color,
                      std::vector<float>* depth, FrameStats& stats);
    int width() const;
    int height() const;

private:
    OffscreenRenderer();
    struct Impl;
    std::unique_ptr<Impl> _impl;
};

}  // namespace vista
