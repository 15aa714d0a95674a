// The reflection stage in the viewer (reflection_drawable.h).
#include "nodes/render/reflection_drawable.h"

#include <osg/GL>

#include "nodes/gl_readback.h"
#include "runtime/engine/reflections.h"

namespace vista {

void ReflectionDrawable::drawFrame(osg::RenderInfo&, const Camera& c, const osg::Viewport& vp, double) const {
    if (!_fx) return;
    const int W = int(vp.width()), H = int(vp.height());
    _image = Image(W, H);
    readColorTopDown(GLint(vp.x()), GLint(vp.y()), W, H, _gl, _image.rgba.data());
    if (!hasGlassPixels(_image)) return;
    reflectionStage(_rays, c, *_fx, _image, _stats);
    drawImage(vp);
}

}  // namespace vista
