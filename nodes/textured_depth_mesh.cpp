#include "nodes/textured_depth_mesh.h"
#include "nodes/texture_state.h"

#include <algorithm>
#include <cmath>

#include <osg/AlphaFunc>
#include <osg/TexEnv>
#include <osg/Texture2D>
#include <osgDB/InputStream>
#include <osgDB/ObjectWrapper>
#include <osgDB/OutputStream>

#include "foundation/status.h"

namespace vista {

size_t depthMeshBytes(const TexturedDepthMeshData& d) {
    return d.positions.size() * (12 + 16) + d.indices.size() * 4 + d.image.size() * 4;
}

TexturedDepthMesh::TexturedDepthMesh() {
    setUseDisplayList(false);
    setUseVertexBufferObjects(true);
}

TexturedDepthMesh::TexturedDepthMesh(const TexturedDepthMesh& o, const osg::CopyOp& op)
    : osg::Geometry(o, op), _cellId(o._cellId), _end(o._end), _eye(o._eye) {}

size_t TexturedDepthMesh::vertexCount() const {
    const osg::Array* v = getVertexArray();
    return v ? v->getNumElements() : 0;
}

size_t TexturedDepthMesh::triangleCount() const {
    const osg::PrimitiveSet* p = getNumPrimitiveSets() == 1 ? getPrimitiveSet(0) : nullptr;
    return p ? p->getNumIndices() / 3 : 0;
}

std::string TexturedDepthMesh::validate() const {
    const auto* v = dynamic_cast<const osg::Vec3Array*>(getVertexArray());
    if (!v) return "depth mesh without float positions";
    const size_t n = v->size();
    const auto* t = dynamic_cast<const osg::Vec4Array*>(getTexCoordArray(0));
    if (!t || t->size() != n || t->getBinding() != osg::Array::BIND_PER_VERTEX)
        return "depth mesh projective texcoords missing or not one per vertex";
    for (size_t k = 0; k < n; ++k) {
        const osg::Vec3f& p = (*v)[unsigned(k)];
        const osg::Vec4f& q = (*t)[unsigned(k)];
        if (!p.valid() || !q.valid()) return "depth mesh vertex " + std::to_string(k) + " not finite";
        if (!(q.w() > 0)) return "depth mesh vertex " + std::to_string(k) + " has texture depth q <= 0";
    }
    if (getNumPrimitiveSets() != 1) return "depth mesh without exactly one triangle set";
    const auto* de = dynamic_cast<const osg::DrawElementsUInt*>(getPrimitiveSet(0));
    if (!de || de->getMode() != GL_TRIANGLES || de->size() % 3 != 0)
        return "depth mesh primitive set is not an indexed triangle list";
    for (unsigned i : *de)
        if (i >= n)
            return "depth mesh index " + std::to_string(i) + " out of range (" + std::to_string(n) + " vertices)";
    if (!std::isfinite(_eye.x()) || !std::isfinite(_eye.y()) || !std::isfinite(_eye.z()))
        return "depth mesh eye not finite";
    if (_end < 0 || _end > 1) return "depth mesh street end " + std::to_string(_end) + " (must be 0 or 1)";
    const osg::StateSet* ss = getStateSet();
    const auto* tex =
        ss ? dynamic_cast<const osg::Texture2D*>(ss->getTextureAttribute(0, osg::StateAttribute::TEXTURE)) : nullptr;
    const osg::Image* img = tex ? tex->getImage() : nullptr;
    if (!img || img->s() < 1 || img->t() < 1 || !img->data()) return "depth mesh texture image missing";
    return "";
}

void TexturedDepthMesh::setData(const TexturedDepthMeshData& d) {
    VISTA_CHECK(d.texcoords.size() == d.positions.size());
    VISTA_CHECK(d.width >= 1 && d.height >= 1 && d.image.size() == size_t(d.width) * size_t(d.height));
    VISTA_CHECK(d.indices.size() % 3 == 0);
    _eye.set(d.eye.x, d.eye.y, d.eye.z);
    osg::ref_ptr<osg::Vec3Array> v = new osg::Vec3Array(unsigned(d.positions.size()));
    osg::ref_ptr<osg::Vec4Array> t = new osg::Vec4Array(unsigned(d.positions.size()));
    for (size_t k = 0; k < d.positions.size(); ++k) {
        (*v)[unsigned(k)].set(d.positions[k].x, d.positions[k].y, d.positions[k].z);
        (*t)[unsigned(k)].set(d.texcoords[k].x, d.texcoords[k].y, d.texcoords[k].z, d.texcoords[k].w);
    }
    osg::ref_ptr<osg::DrawElementsUInt> de = new osg::DrawElementsUInt(GL_TRIANGLES);
    de->reserve(d.indices.size());
    for (uint32_t i : d.indices) {
        VISTA_CHECK(i < d.positions.size());
        de->push_back(i);
    }
    setVertexArray(v.get());
    setTexCoordArray(0, t.get(), osg::Array::BIND_PER_VERTEX);
    osg::ref_ptr<osg::Vec4Array> white = new osg::Vec4Array(1);
    (*white)[0].set(1, 1, 1, 1);
    setColorArray(white.get(), osg::Array::BIND_OVERALL);
    removePrimitiveSet(0, getNumPrimitiveSets());
    addPrimitiveSet(de.get());

    osg::ref_ptr<osg::Image> img = new osg::Image;
    img->allocateImage(d.width, d.height, 1, GL_RGBA, GL_UNSIGNED_BYTE);
    for (int j = 0; j < d.height; ++j)
        for (int i = 0; i < d.width; ++i) {
            const glm::u8vec4 c = d.image[size_t(j) * size_t(d.width) + size_t(i)];
            unsigned char* p = img->data(i, j);
            p[0] = c.x;
            p[1] = c.y;
            p[2] = c.z;
            p[3] = c.w;
        }
    img->setWriteHint(osg::Image::STORE_INLINE);
    osg::ref_ptr<osg::StateSet> ss = new osg::StateSet;
    osg::ref_ptr<osg::Texture2D> tex = clampedLinearTexture(img.get());
    ss->setTextureAttributeAndModes(0, tex.get(), osg::StateAttribute::ON);
    ss->setTextureAttribute(0, new osg::TexEnv(osg::TexEnv::REPLACE));
    ss->setMode(GL_LIGHTING, osg::StateAttribute::OFF);
    ss->setAttributeAndModes(new osg::AlphaFunc(osg::AlphaFunc::GREATER, 0.5f), osg::StateAttribute::ON);
    setStateSet(ss.get());
    dirtyBound();
}

}  // namespace vista

// osgDB serializer: class "vista::TexturedDepthMesh" (arrays and state are
// written by the osg::Geometry wrapper; these are the mesh's own properties).
REGISTER_OBJECT_WRAPPER(vista_TexturedDepthMesh, new vista::TexturedDepthMesh, vista::TexturedDepthMesh,
                        "osg::Object osg::Node osg::Drawable osg::Geometry vista::TexturedDepthMesh") {
    ADD_UINT_SERIALIZER(CellId, 0);
    ADD_INT_SERIALIZER(End, 0);
    ADD_VEC3F_SERIALIZER(Eye, osg::Vec3f());
}
