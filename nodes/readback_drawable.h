// ReadbackDrawable: the base of the drawables that finish a frame on the CPU
// after OSG drew the rest of it: the far field (FarFieldNode), the viewer
// face of the `raycast` mode and the reflection stage of the effects. Each
// frame it takes the camera being drawn and its viewport (currentView),
// resets the frame's statistics and calls drawFrame(), which reads back what
// it needs (gl_readback.h), computes the viewport's image and draws it over
// the viewport (drawImage: glDrawPixels, optionally masked).
//
// State: fixed-function GL (useFixedFunction), no display list, no VBO,
// culling off, dynamic data; the bounding box is empty so near/far
// computation ignores it. Thread safety: drawImplementation() and
// lastStats() serialise on _mutex (a subclass's own setters take it too);
// drawing is single-threaded per context. Nothing throws. A camera without a
// viewport of at least 1x1 or without a perspective projection draws nothing.
#pragma once
#include <cstdint>
#include <mutex>
#include <vector>

#include <osg/Drawable>
#include <osg/Matrixd>
#include <osg/RenderInfo>
#include <osg/StateSet>
#include <osg/Viewport>

#include "runtime/engine/frame_stats.h"
#include "runtime/engine/image.h"
#include "runtime/scene/camera.h"

namespace vista {

// Makes drawables under `ss` draw with the fixed-function pipeline whatever
// program the graph above sets (images drawn with glDrawPixels are final).
void useFixedFunction(osg::StateSet& ss);
// The vista::Camera of an OSG camera's view and projection matrices (world
// frame, x east, y north, z up) for a width x height viewport. zFar = the
// projection's far plane (0 = infinite). False for a non-perspective
// projection or a non-finite eye.
bool cameraFromOsg(const osg::Matrixd& view, const osg::Matrixd& proj, int width, int height, Camera& camera,
                   double& zFar);
// The vista::Camera and the viewport of the camera being drawn (for a
// drawable's drawImplementation). False without a camera, a viewport of at
// least 1x1 or a perspective projection.
bool currentView(osg::RenderInfo& ri, Camera& camera, const osg::Viewport*& viewport, double& zFar);
// Draws `image` (row 0 at top, the viewport's size) into the current frame
// buffer over `vp`, leaving pixels with mask[i] == 0 untouched (mask null:
// every pixel drawn). Fixed-function GL (glDrawPixels, alpha test), state
// saved and restored; `scratch` is reused between calls. GL thread only.
void drawImageOverViewport(const osg::Viewport& vp, const Image& image, const std::vector<uint8_t>* mask,
                           std::vector<uint8_t>& scratch);

class ReadbackDrawable : public osg::Drawable {
public:
    // Statistics of the last drawn frame (copy; thread-safe).
    FrameStats lastStats() const;
    void drawImplementation(osg::RenderInfo& renderInfo) const final;
    osg::BoundingBox computeBoundingBox() const override { return osg::BoundingBox(); }

protected:
    ReadbackDrawable();
    ReadbackDrawable(const ReadbackDrawable& o, const osg::CopyOp& copyop);
    // One frame, with _mutex held and _stats reset: `camera` and `viewport`
    // are those being drawn, zFar the projection's far plane (0 = infinite).
    virtual void drawFrame(osg::RenderInfo& renderInfo, const Camera& camera, const osg::Viewport& viewport,
                           double zFar) const = 0;
    // Draws _image over the viewport (mask: drawImageOverViewport).
    void drawImage(const osg::Viewport& viewport, const std::vector<uint8_t>* mask = nullptr) const;

    mutable Image _image;
    mutable FrameStats _stats;
    mutable std::mutex _mutex;

private:
    mutable std::vector<uint8_t> _upload;  // scratch of drawImageOverViewport
};

}  // namespace vista
