#include "nodes/point_impostor.h"
#include "nodes/point_splat.h"
#include "nodes/texture_state.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

#include <osg/Point>
#include <osg/Program>
#include <osg/Shader>
#include <osg/Texture2D>
#include <osg/Uniform>
#include <osgDB/InputStream>
#include <osgDB/ObjectWrapper>
#include <osgDB/OutputStream>

#include "foundation/status.h"

namespace vista {
namespace {

const char* const kVertexMain = R"(
void main() {
    gl_Position = gl_ModelViewProjectionMatrix * vec4(vista_impostorVertex(), 1.0);
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

std::atomic<float> gSplatSigma{kDefaultSplatSigma};

}  // namespace

void setPointSplatSigma(float sigmaPx) { gSplatSigma.store(sigmaPx > 0 ? sigmaPx : 0.0f); }
float pointSplatSigma() { return gSplatSigma.load(); }

void PointImpostor::drawImplementation(osg::RenderInfo& ri) const {
    const float sigma = gSplatSigma.load();
    if (sigma > 0) {
        SplatParams p;
        p.sigmaPx = sigma;
        if (drawSplats(*this, ri, p)) return;
    }
    osg::Geometry::drawImplementation(ri);
}

PointImpostor::PointImpostor() {
    setUseDisplayList(false);
    setUseVertexBufferObjects(true);
}

PointImpostor::PointImpostor(const PointImpostor& o, const osg::CopyOp& op)
    : osg::Geometry(o, op),
      _planeOrigin(o._planeOrigin),
      _planeU(o._planeU),
      _planeV(o._planeV),
      _dequant(o._dequant),
      _texelsX(o._texelsX),
      _texelsY(o._texelsY),
      _textured(o._textured) {}

size_t PointImpostor::pointCount() const {
    const osg::Array* v = getVertexArray();
    return v ? v->getNumElements() : 0;
}

osg::Vec3f PointImpostor::dequantize(const osg::Vec3s& q) const {
    return osg::Vec3f(_dequant.x(), _dequant.y(), _dequant.z()) + osg::Vec3f(q.x(), q.y(), q.z()) * _dequant.w();
}

osg::Vec3f PointImpostor::position(size_t k) const {
    const auto* v = dynamic_cast<const osg::Vec3sArray*>(getVertexArray());
    VISTA_CHECK(v && k < v->size());
    return dequantize((*v)[unsigned(k)]);
}

osg::BoundingBox PointImpostor::computeBoundingBox() const {
    osg::BoundingBox bb;
    const auto* v = dynamic_cast<const osg::Vec3sArray*>(getVertexArray());
    if (!v) return bb;
    for (const osg::Vec3s& q : *v) bb.expandBy(dequantize(q));
    return bb;
}

std::string PointImpostor::validate() const {
    const auto* v = dynamic_cast<const osg::Vec3sArray*>(getVertexArray());
    if (!v) return "impostor without 16-bit positions";
    const size_t n = v->size();
    const osg::Array* c = getColorArray();
    const auto* t = dynamic_cast<const osg::Vec2sArray*>(getTexCoordArray(0));
    if (!c || c->getNumElements() != n || c->getBinding() != osg::Array::BIND_PER_VERTEX)
        return "impostor colour array missing or not one per point";
    if (!t || t->size() != n) return "impostor atlas offsets missing or not one per point";
    if (getNumPrimitiveSets() != 1) return "impostor without exactly one point set";
    const auto* da = dynamic_cast<const osg::DrawArrays*>(getPrimitiveSet(0));
    if (!da || da->getMode() != GL_POINTS || da->getFirst() != 0 || size_t(da->getCount()) != n)
        return "impostor point set does not cover its points";
    if (!(_dequant.w() > 0) || !std::isfinite(_dequant.w()) || _dequant.isNaN())
        return "impostor dequantization invalid";
    if (_texelsX < 1 || _texelsY < 1 || _texelsX > 32 || _texelsY > 32) return "impostor texel layout out of range";
    const osg::StateSet* ss = getStateSet();
    const auto* tex =
        ss ? dynamic_cast<const osg::Texture2D*>(ss->getTextureAttribute(0, osg::StateAttribute::TEXTURE)) : nullptr;
    const osg::Image* img = tex ? tex->getImage() : nullptr;
    if (!img || img->s() < _texelsX || img->t() < _texelsY) return "impostor atlas missing";
    size_t textured = 0;
    for (const auto& o : *t) {
        if (o.x() < 0) continue;
        ++textured;
        if (o.x() + _texelsX > img->s() || o.y() < 0 || o.y() + _texelsY > img->t())
            return "impostor atlas offset outside the atlas";
    }
    if (textured != _textured) return "impostor textured count does not match its offsets";
    return "";
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
                p[0] = c.x;
                p[1] = c.y;
                p[2] = c.z;
                p[3] = 255;
            }
    }
    img->setWriteHint(osg::Image::STORE_INLINE);
    offsets.assign(d.positions.size(), glm::vec2(-1.0f, -1.0f));
    for (size_t k = 0; k < d.positions.size(); ++k) {
        if (k >= d.block.size() || d.block[k] < 0) continue;
        const size_t b = size_t(d.block[k]);
        VISTA_CHECK(b < blocks);
        offsets[k] =
            glm::vec2(float(int(b % kAtlasBlocksPerRow) * d.texelsX), float(int(b / kAtlasBlocksPerRow) * d.texelsY));
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
    // Quantization: centre of the bounding box, one step for all axes.
    glm::vec3 lo(0.0f), hi(0.0f);
    if (!d.positions.empty()) {
        lo = hi = d.positions[0];
        for (const auto& q : d.positions) {
            lo = glm::min(lo, q);
            hi = glm::max(hi, q);
        }
    }
    const glm::vec3 mid = 0.5f * (lo + hi), half = 0.5f * (hi - lo);
    const float step = std::max(std::max(half.x, std::max(half.y, half.z)) / 32767.0f, 1e-6f);
    _dequant.set(mid.x, mid.y, mid.z, step);

    osg::ref_ptr<osg::Vec3sArray> v = new osg::Vec3sArray(unsigned(d.positions.size()));
    osg::ref_ptr<osg::Vec4ubArray> c = new osg::Vec4ubArray(unsigned(d.positions.size()));
    osg::ref_ptr<osg::Vec2sArray> t = new osg::Vec2sArray(unsigned(d.positions.size()));
    auto quant = [&](float x, float m) { return short(std::clamp(std::lround((x - m) / step), -32767L, 32767L)); };
    for (size_t k = 0; k < d.positions.size(); ++k) {
        (*v)[unsigned(k)].set(quant(d.positions[k].x, mid.x), quant(d.positions[k].y, mid.y),
                              quant(d.positions[k].z, mid.z));
        (*c)[unsigned(k)].set(d.colors[k].x, d.colors[k].y, d.colors[k].z, 255);
        (*t)[unsigned(k)].set(short(offsets[k].x), short(offsets[k].y));
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
    prog->addShader(
        new osg::Shader(osg::Shader::VERTEX, std::string("#version 120\n") + impostorVertexLibrary() + kVertexMain));
    prog->addShader(new osg::Shader(osg::Shader::FRAGMENT, kFragmentShader));
    ss->setAttributeAndModes(prog.get(), osg::StateAttribute::ON);
    osg::ref_ptr<osg::Texture2D> tex = clampedLinearTexture(atlas.get());
    ss->setTextureAttributeAndModes(0, tex.get(), osg::StateAttribute::ON);
    ss->addUniform(new osg::Uniform("vista_atlas", 0));
    ss->addUniform(new osg::Uniform("vista_planeOrigin", _planeOrigin));
    ss->addUniform(new osg::Uniform("vista_planeU", _planeU));
    ss->addUniform(new osg::Uniform("vista_planeV", _planeV));
    ss->addUniform(new osg::Uniform("vista_texels", osg::Vec2f(float(_texelsX), float(_texelsY))));
    ss->addUniform(new osg::Uniform("vista_atlasSize", osg::Vec2f(float(atlas->s()), float(atlas->t()))));
    ss->addUniform(new osg::Uniform("vista_useTexture", 1));
    ss->addUniform(new osg::Uniform("vista_dequant", _dequant));
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
    ADD_VEC4F_SERIALIZER(Dequant, osg::Vec4f(0, 0, 0, 1));
    ADD_INT_SERIALIZER(TexelsX, 8);
    ADD_INT_SERIALIZER(TexelsY, 2);
    ADD_UINT_SERIALIZER(TexturedCount, 0);
}
