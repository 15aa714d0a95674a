// The OSG side of tree impostors (tree_impostor_graph.h).
#include "runtime/scene/tree_impostor_graph.h"

#include <cstdlib>
#include <cstring>
#include <string>

#include <osg/CullFace>
#include <osg/Image>
#include <osg/Program>
#include <osg/Shader>
#include <osg/Texture2D>
#include <osg/Uniform>
#include <osg/VertexAttribDivisor>

#include "runtime/scene/scene_graph.h"

namespace vista {
namespace {

std::string vertexShader() {
    return std::string(kInstancedVertexHead) + "    gl_TexCoord[0] = gl_MultiTexCoord0;\n}\n";
}

std::string fragmentShader() {
    return std::string(kHazeGlsl) +
           "uniform sampler2D vista_impostor_atlas;\n"
           "void main() {\n"
           "    vec4 c = texture2D(vista_impostor_atlas, gl_TexCoord[0].st);\n"
           "    if (c.a < " +
           std::to_string(kImpostorAlphaRef) +
           ".0 / 255.0) discard;\n"
           "    gl_FragColor = vistaHaze(vec4(c.rgb, 1.0));\n"
           "}\n";
}

// Shared by every impostor state (one program object per process).
osg::Program* impostorProgram() {
    static osg::ref_ptr<osg::Program> prog = [] {
        osg::ref_ptr<osg::Program> p = new osg::Program;
        p->setName(kTreeImpostorProgramName);
        p->addShader(new osg::Shader(osg::Shader::VERTEX, vertexShader()));
        p->addShader(new osg::Shader(osg::Shader::FRAGMENT, fragmentShader()));
        for (unsigned c = 0; c < 4; ++c)
            p->addBindAttribLocation("vista_instance" + std::to_string(c), kInstanceAttrib0 + c);
        return p;
    }();
    return prog.get();
}

}  // namespace

TreeImpostorArrays makeTreeImpostorArrays(const TreeImpostor& imp) {
    TreeImpostorArrays a;
    a.verts = new osg::Vec3Array;
    a.normals = new osg::Vec3Array;
    a.texcoords = new osg::Vec2Array;
    a.colors = new osg::Vec4ubArray;
    a.colors->setNormalize(true);
    a.triangles = new osg::DrawElementsUInt(GL_TRIANGLES, imp.indices.begin(), imp.indices.end());
    for (size_t i = 0; i < imp.positions.size(); ++i) {
        const glm::vec3 &p = imp.positions[i], &n = imp.normals[i];
        a.verts->push_back(osg::Vec3(p.x, p.y, p.z));
        a.normals->push_back(osg::Vec3(n.x, n.y, n.z));
        a.texcoords->push_back(osg::Vec2(imp.texcoords[i].x, imp.texcoords[i].y));
        a.colors->push_back(osg::Vec4ub(255, 255, 255, 255));
        a.bounds.expandBy(a.verts->back());
    }
    if (imp.empty()) return a;
    osg::ref_ptr<osg::Image> img = new osg::Image;
    img->allocateImage(imp.atlasWidth, imp.atlasHeight, 1, GL_RGBA, GL_UNSIGNED_BYTE);
    std::memcpy(img->data(), imp.atlas.data(), imp.atlas.size());
    img->setInternalTextureFormat(GL_RGBA8);
    img->setWriteHint(osg::Image::STORE_INLINE);
    osg::ref_ptr<osg::Texture2D> tex = new osg::Texture2D(img.get());
    tex->setFilter(osg::Texture::MIN_FILTER, osg::Texture::LINEAR_MIPMAP_LINEAR);
    tex->setFilter(osg::Texture::MAG_FILTER, osg::Texture::LINEAR);
    tex->setWrap(osg::Texture::WRAP_S, osg::Texture::CLAMP_TO_EDGE);
    tex->setWrap(osg::Texture::WRAP_T, osg::Texture::CLAMP_TO_EDGE);
    tex->setUnRefImageDataAfterApply(false);
    a.state = new osg::StateSet;
    a.state->setAttributeAndModes(impostorProgram(), osg::StateAttribute::ON);
    a.state->setTextureAttributeAndModes(0, tex.get(), osg::StateAttribute::ON);
    a.state->addUniform(new osg::Uniform("vista_impostor_atlas", 0));
    a.state->setMode(GL_CULL_FACE, osg::StateAttribute::OFF | osg::StateAttribute::OVERRIDE);
    for (unsigned c = 0; c < 4; ++c) a.state->setAttribute(new osg::VertexAttribDivisor(kInstanceAttrib0 + c, 1));
    return a;
}

osg::ref_ptr<osg::Geometry> instancedTreeImpostor(const TreeImpostorArrays& a, unsigned prototype,
                                                  osg::Array* const cols[4], unsigned instances,
                                                  const osg::BoundingBox& bound) {
    if (a.empty() || instances == 0) return nullptr;
    osg::ref_ptr<osg::Geometry> g = new osg::Geometry;
    g->setName(kTreeImpostorGeometryPrefix + std::to_string(prototype));
    g->setUseDisplayList(false);
    g->setUseVertexBufferObjects(true);
    g->setVertexArray(a.verts.get());
    g->setNormalArray(a.normals.get(), osg::Array::BIND_PER_VERTEX);
    g->setColorArray(a.colors.get(), osg::Array::BIND_PER_VERTEX);
    g->setTexCoordArray(0, a.texcoords.get(), osg::Array::BIND_PER_VERTEX);
    osg::ref_ptr<osg::DrawElementsUInt> tris = new osg::DrawElementsUInt(*a.triangles, osg::CopyOp::SHALLOW_COPY);
    tris->setNumInstances(int(instances));
    g->addPrimitiveSet(tris.get());
    for (unsigned c = 0; c < 4; ++c)
        g->setVertexAttribArray(kInstanceAttrib0 + c, cols[c], osg::Array::BIND_PER_VERTEX);
    g->setInitialBound(bound);
    g->setStateSet(a.state.get());
    return g;
}

bool isTreeImpostorName(const std::string& name, long* prototype) {
    if (name.rfind(kTreeImpostorGeometryPrefix, 0) != 0) return false;
    if (prototype) *prototype = std::strtol(name.c_str() + std::strlen(kTreeImpostorGeometryPrefix), nullptr, 10);
    return true;
}

}  // namespace vista
