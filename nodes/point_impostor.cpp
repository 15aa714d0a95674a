#include "nodes/point_impostor.h"

#include <algorithm>

#include <osg/Point>
#include <osg/Program>
#include <osg/Shader>
#include <osg/Texture2D>
#include <osg/Uniform>
#include <osgDB/InputStream>
#include <osgDB/ObjectWrapper>
#include <osgDB/OutputStream>

#include "citygen/status.h"

namespace vista {
namespace {

const char* const kVertexShader = R"(#version 120
uniform vec3 vista_planeOrigin;
uniform vec3 vista_planeU;
uniform vec3 vista_planeV;
uniform vec2 vista_texels;
uniform vec2 vista_atlasSize;
uniform int vista_useTexture;
varying vec2 vUv;
varying float vTextured;
void main() {
    vec4 e4 = gl_ModelViewMatrixInverse * vec4(0.0, 0.0, 0.0, 1.0);
    vec3 eye = e4.xyz / e4.w;
    vec3 p = gl_Vertex.xyz;
    vec3 n = cross(vista_planeU, vista_planeV);
    float denom = dot(n, p - eye);
    vec2 ab = vec2(0.5);
    if (abs(denom) > 1e-9) {
        float t = dot(n, vista_planeOrigin - eye) / denom;
        vec3 d = eye + t * (p - eye) - vista_planeOrigin;
        ab = vec2(dot(d, vista_planeU) / dot(vista_planeU, vista_planeU), dot(d, vista_planeV) / dot(vista_planeV, vista_planeV));
    }
    vec2 tc = clamp(ab * vista_texels, vec2(0.5), vista_texels - vec2(0.5));
    vTextured = (vista_useTexture != 0 && gl_MultiTexCoord0.x >= 0.0) ? 1.0 : 0.0;
    vUv = (gl_MultiTexCoord0.xy + tc) / vista_atlasSize;
    gl_FrontColor = gl_Color;
    gl_Position = ftransform();
}
)";

const char* const kFragmentShader = R"(#version 120
uniform sampler2D vista_atlas;
varying vec2 vUv;
varying float vTextured;
void main() {
    gl_FragColor = vTextured > 0.5 ? vec4(texture2D(vista_atlas, vUv).rgb, 1.0) : vec4(gl_Color.rgb, 1.0);
}
)";

}  // namespace

PointImpostor::PointImpostor() {
    setUseDisplayList(false);
    setUseVertexBufferObjects(true);
}

PointImpostor::PointImpostor(const PointImpostor& o, const osg::CopyOp& op)
    : osg::Geometry(o, op), _planeOrigin(o._planeOrigin), _planeU(o._planeU), _planeV(o._planeV), _texelsX(o._texelsX),
      _texelsY(o._texelsY), _textured(o._textured) {}

size_t PointImpostor::pointCount() const {
    const osg::Array* v = getVertexArray();
    return v ? v->getNumElements() : 0;
}

osg::ref_ptr<osg::Image> PointImpostor::buildAtlas(const PointImpostorData& d, std::vector<glm::vec2>& offsets) {
    VISTA_CHECK(d.texelsX >= 1 && d.texelsY >= 1);
    const size_t blockSize = size_t(d.texelsX) * size_t(d.texelsY);
    const size_t blocks = d.texels.size() / blockSize;
    VISTA_CHECK(blocks * blockSize == d.texels.size());
    const int width = kAtlasBlocksPerRow * d.texelsX;
    const int rows = std::max<int>(1, int((blocks + kAtlasBlocksPerRow - 1) / kAtlasBlocksPerRow));
    const int height = rows * d.texelsY;
    VISTA_CHECK(height <= kMaxAtlasHeight);
    osg::ref_ptr<osg::Image> img = new osg::Image;
    img->allocateImage(width, height, 1, GL_RGBA, GL_UNSIGNED_BYTE);
    std::fill(img->data(), img->data() + img->getTotalSizeInBytes(), 0);
    for (size_t b = 0; b < blocks; ++b) {
        const int bx = int(b % kAtlasBlocksPerRow) * d.texelsX, by = int(b / kAtlasBlocksPerRow) * d.texelsY;
        for (int j = 0; j < d.texelsY; ++j)
            for (int i = 0; i < d.texelsX; ++i) {
                const glm::u8vec4 c = d.texels[b * blockSize + size_t(j) * size_t(d.texelsX) + size_t(i)];
                unsigned char* p = img->data(bx + i, by + j);
                p[0] = c.x; p[1] = c.y; p[2] = c.z; p[3] = 255;
            }
    }
    img->setWriteHint(osg::Image::STORE_INLINE);
    offsets.assign(d.positions.size(), glm::vec2(-1.0f, -1.0f));
    for (size_t k = 0; k < d.positions.size(); ++k) {
        if (k >= d.block.size() || d.block[k] < 0) continue;
        const size_t b = size_t(d.block[k]);
        VISTA_CHECK(b < blocks);
        offsets[k] = glm::vec2(float(int(b % kAtlasBlocksPerRow) * d.texelsX), float(int(b / kAtlasBlocksPerRow) * d.texelsY));
    }
    return img;
}

void PointImpostor::setData(const PointImpostorData& d) {
    VISTA_CHECK(d.colors.size() == d.positions.size());
    _planeOrigin.set(d.planeOrigin.x, d.planeOrigin.y, d.planeOrigin.z);
    _planeU.set(d.planeU.x, d.planeU.y, d.planeU.z);
    _planeV.set(d.planeV.x, d.planeV.y, d.planeV.z);
    _texelsX = d.texelsX;
    _texelsY = d.texelsY;
    std::vector<glm::vec2> offsets;
    osg::ref_ptr<osg::Image> atlas = buildAtlas(d, offsets);
    _textured = 0;
    for (const auto& o : offsets) _textured += o.x >= 0 ? 1 : 0;

    osg::ref_ptr<osg::Vec3Array> v = new osg::Vec3Array(unsigned(d.positions.size()));
    osg::ref_ptr<osg::Vec4ubArray> c = new osg::Vec4ubArray(unsigned(d.positions.size()));
    osg::ref_ptr<osg::Vec2Array> t = new osg::Vec2Array(unsigned(d.positions.size()));
    for (size_t k = 0; k < d.positions.size(); ++k) {
        (*v)[unsigned(k)].set(d.positions[k].x, d.positions[k].y, d.positions[k].z);
        (*c)[unsigned(k)].set(d.colors[k].x, d.colors[k].y, d.colors[k].z, 255);
        (*t)[unsigned(k)].set(offsets[k].x, offsets[k].y);
    }
    c->setNormalize(true);
    setVertexArray(v.get());
    setColorArray(c.get(), osg::Array::BIND_PER_VERTEX);
    setTexCoordArray(0, t.get(), osg::Array::BIND_PER_VERTEX);
    removePrimitiveSet(0, getNumPrimitiveSets());
    addPrimitiveSet(new osg::DrawArrays(GL_POINTS, 0, GLsizei(d.positions.size())));

    osg::ref_ptr<osg::StateSet> ss = new osg::StateSet;
    osg::ref_ptr<osg::Program> prog = new osg::Program;
    prog->setName("vista.point_impostor");
    prog->addShader(new osg::Shader(osg::Shader::VERTEX, kVertexShader));
    prog->addShader(new osg::Shader(osg::Shader::FRAGMENT, kFragmentShader));
    ss->setAttributeAndModes(prog.get(), osg::StateAttribute::ON);
    osg::ref_ptr<osg::Texture2D> tex = new osg::Texture2D(atlas.get());
    tex->setFilter(osg::Texture::MIN_FILTER, osg::Texture::LINEAR);
    tex->setFilter(osg::Texture::MAG_FILTER, osg::Texture::LINEAR);
    tex->setWrap(osg::Texture::WRAP_S, osg::Texture::CLAMP_TO_EDGE);
    tex->setWrap(osg::Texture::WRAP_T, osg::Texture::CLAMP_TO_EDGE);
    tex->setResizeNonPowerOfTwoHint(false);
    tex->setUnRefImageDataAfterApply(false);
    ss->setTextureAttributeAndModes(0, tex.get(), osg::StateAttribute::ON);
    ss->addUniform(new osg::Uniform("vista_atlas", 0));
    ss->addUniform(new osg::Uniform("vista_planeOrigin", _planeOrigin));
    ss->addUniform(new osg::Uniform("vista_planeU", _planeU));
    ss->addUniform(new osg::Uniform("vista_planeV", _planeV));
    ss->addUniform(new osg::Uniform("vista_texels", osg::Vec2f(float(_texelsX), float(_texelsY))));
    ss->addUniform(new osg::Uniform("vista_atlasSize", osg::Vec2f(float(atlas->s()), float(atlas->t()))));
    ss->addUniform(new osg::Uniform("vista_useTexture", 1));
    ss->setAttributeAndModes(new osg::Point(1.0f), osg::StateAttribute::ON);
    ss->setMode(GL_LIGHTING, osg::StateAttribute::OFF);
    setStateSet(ss.get());
    dirtyBound();
}

}  // namespace vista

// osgDB serializer: class "vista::PointImpostor" (arrays and state are written
// by the osg::Geometry wrapper; these are the impostor's own properties).
REGISTER_OBJECT_WRAPPER(vista_PointImpostor, new vista::PointImpostor, vista::PointImpostor,
                        "osg::Object osg::Node osg::Drawable osg::Geometry vista::PointImpostor") {
    ADD_VEC3F_SERIALIZER(PlaneOrigin, osg::Vec3f());
    ADD_VEC3F_SERIALIZER(PlaneU, osg::Vec3f());
    ADD_VEC3F_SERIALIZER(PlaneV, osg::Vec3f());
    ADD_INT_SERIALIZER(TexelsX, 8);
    ADD_INT_SERIALIZER(TexelsY, 2);
    ADD_UINT_SERIALIZER(TexturedCount, 0);
}
