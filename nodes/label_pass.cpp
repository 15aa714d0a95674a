// Label pass state: the programs that write ids, classes and eye depth (label_pass.h).
#include "nodes/label_pass.h"

#include <string>

#include <osg/BlendFunc>
#include <osg/CullFace>
#include <osg/Program>
#include <osg/Shader>
#include <osg/VertexAttribDivisor>

#include "runtime/scene/scene_graph.h"

namespace vista {

namespace {

const char* const kFragment = R"(#version 130
flat in uint vista_id;
flat in uint vista_class;
in float vista_depth;
void main() {
    gl_FragData[0] = vec4(float(vista_id & 255u), float((vista_id >> 8) & 255u), float((vista_id >> 16) & 255u),
                          float(vista_id >> 24)) / 255.0;
    gl_FragData[1] = vec4(vista_depth, float(vista_class), 0.0, 1.0);
}
)";

const char* const kMeshVertex = R"(#version 130
in uint vista_label_id;
in uint vista_label_class;
flat out uint vista_id;
flat out uint vista_class;
out float vista_depth;
void main() {
    gl_Position = ftransform();
    vista_depth = -(gl_ModelViewMatrix * gl_Vertex).z;
    vista_id = vista_label_id;
    vista_class = vista_label_class;
}
)";

const char* const kTreeVertex = R"(#version 130
in vec4 vista_instance0;
in vec4 vista_instance1;
in vec4 vista_instance2;
in vec4 vista_instance3;
in uint vista_tree_id;
in uint vista_label_class;
flat out uint vista_id;
flat out uint vista_class;
out float vista_depth;
void main() {
    mat4 instance = mat4(vista_instance0, vista_instance1, vista_instance2, vista_instance3);
    vec4 p = instance * gl_Vertex;
    gl_Position = gl_ModelViewProjectionMatrix * p;
    vista_depth = -(gl_ModelViewMatrix * p).z;
    vista_id = vista_tree_id;
    vista_class = vista_label_class;
}
)";

osg::ref_ptr<osg::Program> program(const char* name, const char* vertex) {
    osg::ref_ptr<osg::Program> p = new osg::Program;
    p->setName(name);
    p->addShader(new osg::Shader(osg::Shader::VERTEX, vertex));
    p->addShader(new osg::Shader(osg::Shader::FRAGMENT, kFragment));
    p->addBindAttribLocation("vista_label_class", kLabelClassAttrib);
    return p;
}

}  // namespace

osg::ref_ptr<osg::StateSet> labelRootState() {
    osg::ref_ptr<osg::StateSet> ss = new osg::StateSet;
    osg::ref_ptr<osg::Program> p = program("vista.label_meshes", kMeshVertex);
    p->addBindAttribLocation("vista_label_id", kLabelAttrib);
    ss->setAttributeAndModes(p.get(), osg::StateAttribute::ON);
    ss->setMode(GL_BLEND, osg::StateAttribute::OFF | osg::StateAttribute::OVERRIDE);
    ss->setMode(GL_LIGHTING, osg::StateAttribute::OFF);
    ss->setAttributeAndModes(new osg::CullFace(osg::CullFace::BACK), osg::StateAttribute::ON);
    return ss;
}

osg::ref_ptr<osg::StateSet> labelTreeState() {
    osg::ref_ptr<osg::StateSet> ss = new osg::StateSet;
    {
        osg::ref_ptr<osg::Program> p = program("vista.label_trees", kTreeVertex);
        for (unsigned c = 0; c < 4; ++c)
            p->addBindAttribLocation("vista_instance" + std::to_string(c), kInstanceAttrib0 + c);
        p->addBindAttribLocation("vista_tree_id", kTreeIdAttrib);
        ss->setAttributeAndModes(p.get(), osg::StateAttribute::ON);
        for (unsigned c = 0; c < 4; ++c) ss->setAttribute(new osg::VertexAttribDivisor(kInstanceAttrib0 + c, 1));
        ss->setAttribute(new osg::VertexAttribDivisor(kTreeIdAttrib, 1));
    }
    return ss;
}

}  // namespace vista
