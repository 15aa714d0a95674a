// SkyBackground: the CPU sky as a first-drawn screen layer (sky_background.h).
#include "nodes/render/sky_background.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <osg/Depth>

#include "citygen/lighting.h"

namespace vista {

void renderSky(const Camera& camera, Image& out, double jx, double jy, bool night) {
    if (out.width != camera.width || out.height != camera.height) out = Image(camera.width, camera.height);
    // Elevation depends only on the row/column, pitch, roll and fov: one
    // skyColor per pixel, no world position involved.
    for (int y = 0; y < camera.height; ++y)
        for (int x = 0; x < camera.width; ++x) {
            glm::dvec3 d = camera.rayDirection(x + 0.5 + jx, y + 0.5 + jy);
            out.set(x, y, skyColor(std::asin(std::clamp(d.z, -1.0, 1.0)), night));
        }
}

SkyBackground::SkyBackground(int width, int height) {
    _quad = new osg::Geometry;
    osg::ref_ptr<osg::Vec3Array> v = new osg::Vec3Array;
    v->push_back({0, 0, 0});
    v->push_back({1, 0, 0});
    v->push_back({1, 1, 0});
    v->push_back({0, 1, 0});
    // Image row 0 (top) is texture row 0: the quad maps t = 0 to the top.
    osg::ref_ptr<osg::Vec2Array> tc = new osg::Vec2Array;
    tc->push_back({0, 1});
    tc->push_back({1, 1});
    tc->push_back({1, 0});
    tc->push_back({0, 0});
    osg::ref_ptr<osg::Vec4Array> c = new osg::Vec4Array;
    c->push_back({1, 1, 1, 1});
    _quad->setVertexArray(v.get());
    _quad->setTexCoordArray(0, tc.get());
    _quad->setColorArray(c.get(), osg::Array::BIND_OVERALL);
    _quad->addPrimitiveSet(new osg::DrawArrays(GL_QUADS, 0, 4));
    _quad->setCullingActive(false);
    _quad->setUseDisplayList(false);
    _quad->setUseVertexBufferObjects(true);
    osg::StateSet* ss = _quad->getOrCreateStateSet();
    ss->setMode(GL_LIGHTING, osg::StateAttribute::OFF | osg::StateAttribute::PROTECTED);
    ss->setMode(GL_DEPTH_TEST, osg::StateAttribute::OFF | osg::StateAttribute::PROTECTED);
    ss->setMode(GL_BLEND, osg::StateAttribute::OFF);
    ss->setMode(GL_FOG, osg::StateAttribute::OFF | osg::StateAttribute::PROTECTED);
    ss->setAttributeAndModes(new osg::Depth(osg::Depth::ALWAYS, 0, 1, false));
    ss->setRenderBinDetails(-1000, "RenderBin");
    _camera = new osg::Camera;
    _camera->setName("vista.sky");
    _camera->setReferenceFrame(osg::Transform::ABSOLUTE_RF);
    _camera->setProjectionMatrixAsOrtho2D(0, 1, 0, 1);
    _camera->setViewMatrix(osg::Matrixd::identity());
    _camera->setRenderOrder(osg::Camera::NESTED_RENDER);
    _camera->setClearMask(0);
    _camera->setComputeNearFarMode(osg::CullSettings::DO_NOT_COMPUTE_NEAR_FAR);
    _camera->setCullingActive(false);
    _camera->addChild(_quad.get());
    resize(width, height);
}

void SkyBackground::resize(int width, int height) {
    width = std::max(1, width);
    height = std::max(1, height);
    if (_image && _image->s() == width && _image->t() == height) return;
    _image = new osg::Image;
    _image->allocateImage(width, height, 1, GL_RGBA, GL_UNSIGNED_BYTE);
    _image->setInternalTextureFormat(GL_RGBA8);
    std::memset(_image->data(), 0, size_t(width) * size_t(height) * 4);
    _texture = new osg::Texture2D(_image.get());
    _texture->setFilter(osg::Texture::MIN_FILTER, osg::Texture::NEAREST);
    _texture->setFilter(osg::Texture::MAG_FILTER, osg::Texture::NEAREST);
    _texture->setWrap(osg::Texture::WRAP_S, osg::Texture::CLAMP_TO_EDGE);
    _texture->setWrap(osg::Texture::WRAP_T, osg::Texture::CLAMP_TO_EDGE);
    _texture->setResizeNonPowerOfTwoHint(false);
    _texture->setUnRefImageDataAfterApply(false);
    _texture->setDataVariance(osg::Object::DYNAMIC);
    _quad->getOrCreateStateSet()->setTextureAttributeAndModes(0, _texture.get(), osg::StateAttribute::ON);
    _skyShown = false;
}

void SkyBackground::upload(const Image& image) {
    std::memcpy(_image->data(), image.rgba.data(), image.rgba.size());
    _image->dirty();
}

void SkyBackground::showSky(const Camera& camera, double jx, double jy) {
    resize(camera.width, camera.height);
    const double key[5] = {camera.pitch, camera.roll, camera.fovY, jx, jy};
    if (_skyShown && _shownNight == _night && std::equal(key, key + 5, _key) && _sky.width == camera.width &&
        _sky.height == camera.height)
        return;
    renderSky(camera, _sky, jx, jy, _night);
    _shownNight = _night;
    upload(_sky);
    std::copy(key, key + 5, _key);
    _skyShown = true;
}

Status SkyBackground::showImage(const Image& image) {
    if (!image.valid() || image.width != _image->s() || image.height != _image->t())
        return Status::error("background image " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                             " differs from the layer's " + std::to_string(_image->s()) + "x" +
                             std::to_string(_image->t()));
    upload(image);
    _skyShown = false;
    return Status::ok();
}

}  // namespace vista
