// ReadbackDrawable and the view helpers of the drawables that finish a frame
// on the CPU (readback_drawable.h).
#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include "nodes/readback_drawable.h"

#include <algorithm>
#include <cmath>

#include <osg/Camera>
#include <osg/GL>
#include <osg/Program>
#include <GL/glext.h>

#include "foundation/units.h"

namespace vista {

void useFixedFunction(osg::StateSet& ss) {
    // An osg::Program without shaders applies as glUseProgram(0).
    ss.setAttributeAndModes(new osg::Program,
                            osg::StateAttribute::ON | osg::StateAttribute::OVERRIDE | osg::StateAttribute::PROTECTED);
}

// vista::Camera from OSG matrices (world frame, x east, y north, z up).
bool cameraFromOsg(const osg::Matrixd& view, const osg::Matrixd& proj, int w, int h, Camera& c, double& zFar) {
    double fovy = 0, aspect = 0, zn = 0, zf = 0;
    if (!proj.getPerspective(fovy, aspect, zn, zf)) return false;
    osg::Matrixd inv = osg::Matrixd::inverse(view);
    osg::Vec3d eye = inv.getTrans();
    osg::Vec3d f = osg::Matrixd::transform3x3(osg::Vec3d(0, 0, -1), inv);
    osg::Vec3d up = osg::Matrixd::transform3x3(osg::Vec3d(0, 1, 0), inv);
    f.normalize();
    up.normalize();
    c.eye = glm::dvec3(eye.x(), eye.y(), eye.z());
    c.heading = std::atan2(f.x(), f.y());
    c.pitch = std::asin(std::clamp(f.z(), -1.0, 1.0));
    glm::dvec3 fg(f.x(), f.y(), f.z()), ug(up.x(), up.y(), up.z());
    glm::dvec3 r0(std::cos(c.heading), -std::sin(c.heading), 0.0);
    glm::dvec3 u0 = glm::cross(r0, fg);
    glm::dvec3 right = glm::cross(fg, ug);
    c.roll = std::atan2(-glm::dot(right, u0), glm::dot(right, r0));
    if (std::abs(c.roll) < 1e-9) c.roll = 0;
    c.fovY = fovy * kPi / 180.0;
    c.width = w;
    c.height = h;
    c.zNear = zn;
    zFar = std::isfinite(zf) && zf > zn ? zf : 0.0;  // infinite far plane
    return std::isfinite(c.eye.x) && c.fovY > 0;
}

void drawImageOverViewport(const osg::Viewport& vp, const Image& image, const std::vector<uint8_t>* mask,
                           std::vector<uint8_t>& upload) {
    const int W = image.width, H = image.height;
    if (W != int(vp.width()) || H != int(vp.height()) || !image.valid()) return;
    // GL rows bottom-up; pixels to keep get alpha 0 and are alpha-tested away.
    upload.resize(size_t(W) * size_t(H) * 4);
    for (int y = 0; y < H; ++y) {
        const size_t src = size_t(y) * size_t(W), dst = size_t(H - 1 - y) * size_t(W);
        for (int x = 0; x < W; ++x) {
            const uint8_t* p = &image.rgba[(src + size_t(x)) * 4];
            uint8_t* q = &upload[(dst + size_t(x)) * 4];
            q[0] = p[0];
            q[1] = p[1];
            q[2] = p[2];
            // Kept pixels keep their alpha (glass marks >= kGlassAlpha pass the alpha test).
            q[3] = mask && (*mask)[src + size_t(x)] == 0 ? 0 : std::max<uint8_t>(p[3], 129);
        }
    }
    glPushAttrib(GL_ALL_ATTRIB_BITS);
    glPushClientAttrib(GL_CLIENT_PIXEL_STORE_BIT);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_LIGHTING);
    glDisable(GL_TEXTURE_2D);
    glDisable(GL_BLEND);
    glDisable(GL_FOG);  // the far-field image is hazed already
    glEnable(GL_ALPHA_TEST);
    glAlphaFunc(GL_GREATER, 0.5f);
    glDepthMask(GL_FALSE);
    glWindowPos2i(GLint(vp.x()), GLint(vp.y()));
    glDrawPixels(W, H, GL_RGBA, GL_UNSIGNED_BYTE, upload.data());
    glPopClientAttrib();
    glPopAttrib();
}

bool currentView(osg::RenderInfo& ri, Camera& camera, const osg::Viewport*& vp, double& zFar) {
    const osg::Camera* cam = ri.getCurrentCamera();
    vp = cam ? cam->getViewport() : nullptr;
    if (!vp || vp->width() < 1 || vp->height() < 1) return false;
    return cameraFromOsg(cam->getViewMatrix(), cam->getProjectionMatrix(), int(vp->width()), int(vp->height()), camera,
                         zFar);
}

ReadbackDrawable::ReadbackDrawable() {
    useFixedFunction(*getOrCreateStateSet());
    setUseDisplayList(false);
    setUseVertexBufferObjects(false);
    setCullingActive(false);
    setDataVariance(osg::Object::DYNAMIC);
}

ReadbackDrawable::ReadbackDrawable(const ReadbackDrawable& o, const osg::CopyOp& copyop) : osg::Drawable(o, copyop) {}

FrameStats ReadbackDrawable::lastStats() const {
    std::lock_guard<std::mutex> lock(_mutex);
    return _stats;
}

void ReadbackDrawable::drawImplementation(osg::RenderInfo& ri) const {
    std::lock_guard<std::mutex> lock(_mutex);
    Camera c;
    const osg::Viewport* vp = nullptr;
    double zFar = 0;
    if (!currentView(ri, c, vp, zFar)) return;
    _stats = FrameStats();
    drawFrame(ri, c, *vp, zFar);
}

void ReadbackDrawable::drawImage(const osg::Viewport& vp, const std::vector<uint8_t>* mask) const {
    drawImageOverViewport(vp, _image, mask, _upload);
}

}  // namespace vista
