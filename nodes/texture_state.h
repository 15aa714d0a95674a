// The texture state shared by the baked far-field nodes (point impostor
// atlases, textured depth meshes): bilinear, clamped to the edge, any size,
// the image kept after upload (the nodes are written back by the serializer).
// Internal to nodes/.
#pragma once
#include <osg/Image>
#include <osg/Texture2D>

namespace vista {

inline osg::ref_ptr<osg::Texture2D> clampedLinearTexture(osg::Image* image) {
    osg::ref_ptr<osg::Texture2D> tex = new osg::Texture2D(image);
    tex->setFilter(osg::Texture::MIN_FILTER, osg::Texture::LINEAR);
    tex->setFilter(osg::Texture::MAG_FILTER, osg::Texture::LINEAR);
    tex->setWrap(osg::Texture::WRAP_S, osg::Texture::CLAMP_TO_EDGE);
    tex->setWrap(osg::Texture::WRAP_T, osg::Texture::CLAMP_TO_EDGE);
    tex->setResizeNonPowerOfTwoHint(false);
    tex->setUnRefImageDataAfterApply(false);
    return tex;
}

}  // namespace vista
