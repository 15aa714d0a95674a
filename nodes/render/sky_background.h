// SkyBackground: the sky every GL picture of vista is drawn over — a
// screen-filling textured quad under a nested osg::Camera, in render bin
// -1000, no depth test or write, so it is drawn first and never occludes.
// It shows the sky of a Camera (renderSky) or any image of the same size.
// Used by the OffscreenRenderer (bench) and by `vista view`, so both show the
// same sky pixels.
//
// Contract: node() goes anywhere in the drawn graph (absolute reference
// frame, culling off). showSky() re-renders and re-uploads only when the
// sky changes (pitch, roll, fov, size or jitter); a camera of another size
// resizes the layer. showImage() needs an image of the layer's size (else an
// error Status). Single-threaded: call from the frame loop, between frames.
#pragma once
#include <osg/Camera>
#include <osg/Geometry>
#include <osg/Image>
#include <osg/Texture2D>
#include <osg/ref_ptr>

#include "foundation/status.h"
#include "runtime/engine/image.h"
#include "runtime/scene/camera.h"

namespace vista {

// Sky of `camera` (camera.width x camera.height, row 0 at top): skyColor of
// the elevation of the ray through each pixel centre + (jx, jy). Shared by
// the GL modes and the ray caster so sky pixels agree exactly.
// night: the night sky (skyColor(elev, true)).
void renderSky(const Camera& camera, Image& out, double jx = 0.0, double jy = 0.0, bool night = false);

class SkyBackground {
public:
    SkyBackground(int width, int height);
    osg::Node* node() const { return _camera.get(); }
    // The quad's drawable (excluded from triangle counts).
    const osg::Drawable* drawable() const { return _quad.get(); }
    void showSky(const Camera& camera, double jx = 0.0, double jy = 0.0);
    // Day or night sky for the following showSky() calls.
    void setNight(bool night) { _night = night; }
    Status showImage(const Image& image);

private:
    void resize(int width, int height);
    void upload(const Image& image);
    osg::ref_ptr<osg::Camera> _camera;
    osg::ref_ptr<osg::Geometry> _quad;
    osg::ref_ptr<osg::Image> _image;
    osg::ref_ptr<osg::Texture2D> _texture;
    Image _sky;
    bool _skyShown = false;
    bool _night = false, _shownNight = false;
    double _key[5] = {0, 0, 0, 0, 0};  // pitch, roll, fov, jx, jy of the sky shown
};

}  // namespace vista
