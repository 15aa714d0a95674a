#include "nodes/render/effects_state.h"

#include <algorithm>

#include <osg/Program>
#include <osg/Shader>
#include <osg/Uniform>

#include "runtime/scene/scene_graph.h"

namespace vista {

namespace {

// Two-sided colour is never enabled, so only gl_FrontColor: an unused vertex
// output still costs the rasteriser.
const char* const kHazeVertexShader = R"(#version 120
void main() {
    gl_Position = ftransform();
    gl_FrontColor = gl_Color;
}
)";

osg::Program* hazeProgram() {
    static osg::ref_ptr<osg::Program> prog = [] {
        osg::ref_ptr<osg::Program> p = new osg::Program;
        p->setName("vista.haze");
        p->addShader(new osg::Shader(osg::Shader::VERTEX, kHazeVertexShader));
        p->addShader(new osg::Shader(osg::Shader::FRAGMENT,
                                     std::string(kHazeGlsl) + "void main() { gl_FragColor = vistaHaze(gl_Color); }\n"));
        return p;
    }();
    return prog.get();
}

}  // namespace

void applyEffectsState(osg::StateSet& ss, const FrameEffects& fx, bool hazeInRaster) {
    const bool haze = fx.haze && hazeInRaster;
    // The uniforms stay set (density 0 = no haze) so programs that kept an
    // older value (GL keeps uniform values per program) are reset too.
    const glm::u8vec4 c = fx.hazeColor();
    ss.getOrCreateUniform(kHazeDensityUniform, osg::Uniform::FLOAT)->set(haze ? float(fx.extinction()) : 0.0f);
    ss.getOrCreateUniform(kHazeColorUniform, osg::Uniform::FLOAT_VEC3)
        ->set(osg::Vec3(c.x / 255.0f, c.y / 255.0f, c.z / 255.0f));
    if (haze) ss.setAttributeAndModes(hazeProgram(), osg::StateAttribute::ON);
    else ss.removeAttribute(osg::StateAttribute::PROGRAM);
}

double effectsFarPlane(double zFar, const FrameEffects& fx) {
    if (!fx.haze) return zFar;
    return zFar > 0 ? std::min(zFar, fx.hazeFar()) : fx.hazeFar();
}

}  // namespace vista
