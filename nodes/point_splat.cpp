#include "nodes/point_splat.h"

#include "foundation/units.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>

#include <osg/BlendFunc>
#include <osg/ColorMask>
#include <osg/Depth>
#include <osg/FrameBufferObject>
#include <osg/GLExtensions>
#include <osg/Notify>
#include <osg/PointSprite>
#include <osg/Program>
#include <osg/Shader>
#include <osg/State>
#include <osg/Texture2D>
#include <osg/Uniform>

namespace vista {
namespace {

const char* const kImpostorVertexLib = R"(
uniform vec3 vista_planeOrigin;
uniform vec3 vista_planeU;
uniform vec3 vista_planeV;
uniform vec2 vista_texels;
uniform vec2 vista_atlasSize;
uniform int vista_useTexture;
uniform vec4 vista_dequant;
varying vec2 vUv;
varying float vTextured;
vec3 vista_impostorVertex() {
    vec4 e4 = gl_ModelViewMatrixInverse * vec4(0.0, 0.0, 0.0, 1.0);
    vec3 eye = e4.xyz / e4.w;
    vec3 p = vista_dequant.xyz + vista_dequant.w * gl_Vertex.xyz;
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
    return p;
}
)";

// Splat vertex: the point pushed back along its eye ray by vista_splatPush x
// its distance (the projection is unchanged), sprite of vista_splatSize px.
const char* const kSplatVertexMain = R"(
uniform float vista_splatSize;
uniform float vista_splatPush;
void main() {
    vec4 pe = gl_ModelViewMatrix * vec4(vista_impostorVertex(), 1.0);
    pe.xyz *= 1.0 + vista_splatPush;
    gl_Position = gl_ProjectionMatrix * pe;
    gl_PointSize = vista_splatSize;
}
)";

const char* const kSplatFragment = R"(#version 120
uniform sampler2D vista_atlas;
uniform int vista_splatPass;
uniform float vista_splatSize;
uniform float vista_splatSigma;
varying vec2 vUv;
varying float vTextured;
void main() {
    vec2 o = (gl_PointCoord - vec2(0.5)) * vista_splatSize;
    float r2 = dot(o, o);
    float R = 0.5 * vista_splatSize;
    if (r2 > R * R) discard;
    if (vista_splatPass == 0) { gl_FragColor = vec4(0.0); return; }
    float w = exp(-0.5 * r2 / (vista_splatSigma * vista_splatSigma));
    vec3 c = vTextured > 0.5 ? texture2D(vista_atlas, vUv).rgb : gl_Color.rgb;
    gl_FragColor = vec4(c * w, w);
}
)";

const char* const kNormaliseVertex = R"(#version 120
void main() { gl_Position = gl_Vertex; }
)";

const char* const kNormaliseFragment = R"(#version 120
uniform sampler2D vista_splatColor;
uniform sampler2D vista_splatDepth;
uniform vec4 vista_splatViewport;
void main() {
    vec2 uv = (gl_FragCoord.xy - vista_splatViewport.xy) * vista_splatViewport.zw;
    vec4 a = texture2D(vista_splatColor, uv);
    if (a.a <= 1e-4) discard;
    gl_FragColor = vec4(a.rgb / a.a, 1.0);
    gl_FragDepth = texture2D(vista_splatDepth, uv).r;
}
)";

// The focal length (pixels) of the bake's default target: 480 rows over 60 degrees.
const double kBakeFocalPx = 240.0 / std::tan(30.0 * kPi / 180.0);
// Kernel cut-off in sigmas (weight exp(-2) = 0.14 at the rim; at the default
// sigma of 0.25 px the rim is half a pixel: a point feeds only the pixels
// whose centre is within half a pixel of it).
constexpr float kRadiusSigmas = 2.0f;

osg::ref_ptr<osg::Texture2D> targetTexture(int w, int h, GLint internal, GLenum format, GLenum type) {
    osg::ref_ptr<osg::Texture2D> t = new osg::Texture2D;
    t->setTextureSize(w, h);
    t->setInternalFormat(internal);
    t->setSourceFormat(format);
    t->setSourceType(type);
    t->setFilter(osg::Texture::MIN_FILTER, osg::Texture::NEAREST);
    t->setFilter(osg::Texture::MAG_FILTER, osg::Texture::NEAREST);
    t->setWrap(osg::Texture::WRAP_S, osg::Texture::CLAMP_TO_EDGE);
    t->setWrap(osg::Texture::WRAP_T, osg::Texture::CLAMP_TO_EDGE);
    t->setResizeNonPowerOfTwoHint(false);
    return t;
}

// Everything one graphics context needs (drawn from one thread at a time).
struct SplatTarget {
    int width = 0, height = 0;
    bool broken = false;
    osg::ref_ptr<osg::Texture2D> color, depth;
    osg::ref_ptr<osg::FrameBufferObject> fbo;
    osg::ref_ptr<osg::StateSet> visibility, accumulate, normalise;
    osg::ref_ptr<osg::Uniform> size, sigma, push, viewport;
    osg::ref_ptr<osg::Geometry> quad;

    SplatTarget() {
        osg::ref_ptr<osg::Program> prog = new osg::Program;
        prog->setName("vista.point_splat");
        prog->addShader(new osg::Shader(osg::Shader::VERTEX,
                                        std::string("#version 120\n") + kImpostorVertexLib + kSplatVertexMain));
        prog->addShader(new osg::Shader(osg::Shader::FRAGMENT, kSplatFragment));
        size = new osg::Uniform("vista_splatSize", 1.0f);
        sigma = new osg::Uniform("vista_splatSigma", 0.25f);
        push = new osg::Uniform("vista_splatPush", 0.0f);
        viewport = new osg::Uniform("vista_splatViewport", osg::Vec4f());
        const auto on = osg::StateAttribute::ON | osg::StateAttribute::PROTECTED;
        for (int pass = 0; pass < 2; ++pass) {
            osg::ref_ptr<osg::StateSet> ss = new osg::StateSet;
            ss->setAttributeAndModes(prog.get(), on);
            ss->setTextureAttributeAndModes(0, new osg::PointSprite, on);
            ss->setMode(GL_VERTEX_PROGRAM_POINT_SIZE, on);
            ss->addUniform(size.get());
            ss->addUniform(sigma.get());
            ss->addUniform(new osg::Uniform("vista_splatPass", pass));
            if (pass == 0) {
                ss->addUniform(push.get());
                ss->setAttributeAndModes(new osg::ColorMask(false, false, false, false), on);
                ss->setAttributeAndModes(new osg::Depth(osg::Depth::LESS, 0.0, 1.0, true), on);
                ss->setMode(GL_BLEND, osg::StateAttribute::OFF | osg::StateAttribute::PROTECTED);
                visibility = ss;
            } else {
                ss->addUniform(new osg::Uniform("vista_splatPush", 0.0f));
                ss->setAttributeAndModes(new osg::ColorMask(true, true, true, true), on);
                ss->setAttributeAndModes(new osg::Depth(osg::Depth::LEQUAL, 0.0, 1.0, false), on);
                ss->setAttributeAndModes(new osg::BlendFunc(GL_ONE, GL_ONE), on);
                accumulate = ss;
            }
        }
        osg::ref_ptr<osg::Program> norm = new osg::Program;
        norm->setName("vista.point_splat_normalise");
        norm->addShader(new osg::Shader(osg::Shader::VERTEX, kNormaliseVertex));
        norm->addShader(new osg::Shader(osg::Shader::FRAGMENT, kNormaliseFragment));
        normalise = new osg::StateSet;
        normalise->setAttributeAndModes(norm.get(), on);
        normalise->setAttributeAndModes(new osg::ColorMask(true, true, true, true), on);
        normalise->setAttributeAndModes(new osg::Depth(osg::Depth::ALWAYS, 0.0, 1.0, true), on);
        normalise->setMode(GL_BLEND, osg::StateAttribute::OFF | osg::StateAttribute::PROTECTED);
        normalise->addUniform(new osg::Uniform("vista_splatColor", 1));
        normalise->addUniform(new osg::Uniform("vista_splatDepth", 2));
        normalise->addUniform(viewport.get());
        quad = new osg::Geometry;
        quad->setUseDisplayList(false);
        quad->setUseVertexBufferObjects(true);
        osg::ref_ptr<osg::Vec3Array> v = new osg::Vec3Array;
        v->push_back({-1, -1, 0});
        v->push_back({1, -1, 0});
        v->push_back({-1, 1, 0});
        v->push_back({1, 1, 0});
        quad->setVertexArray(v.get());
        quad->addPrimitiveSet(new osg::DrawArrays(GL_TRIANGLE_STRIP, 0, 4));
    }

    // Colour and depth textures of the viewport's size, attached to the FBO.
    void resize(int w, int h) {
        if (w == width && h == height && fbo) return;
        width = w;
        height = h;
        color = targetTexture(w, h, GL_RGBA16F_ARB, GL_RGBA, GL_FLOAT);
        depth = targetTexture(w, h, GL_DEPTH_COMPONENT24, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT);
        fbo = new osg::FrameBufferObject;
        fbo->setAttachment(osg::Camera::COLOR_BUFFER0, osg::FrameBufferAttachment(color.get()));
        fbo->setAttachment(osg::Camera::DEPTH_BUFFER, osg::FrameBufferAttachment(depth.get()));
        normalise->setTextureAttributeAndModes(1, color.get(),
                                               osg::StateAttribute::ON | osg::StateAttribute::PROTECTED);
        normalise->setTextureAttributeAndModes(2, depth.get(),
                                               osg::StateAttribute::ON | osg::StateAttribute::PROTECTED);
    }
};

SplatTarget& targetFor(unsigned contextId) {
    static std::mutex m;
    static std::map<unsigned, std::unique_ptr<SplatTarget>> targets;
    std::lock_guard<std::mutex> lock(m);
    auto& t = targets[contextId];
    if (!t) t = std::make_unique<SplatTarget>();
    return *t;
}

struct Rect {
    int x = 0, y = 0, w = 0, h = 0;
};

// Window rectangle (viewport-relative) of the box under modelview x projection,
// grown by `grow` pixels and clipped to the viewport; the whole viewport when
// a corner is at or behind the eye.
Rect screenRect(const osg::BoundingBox& bb, const osg::Matrix& mvp, int W, int H, int grow) {
    double lx = 1e300, ly = 1e300, hx = -1e300, hy = -1e300;
    for (int k = 0; k < 8; ++k) {
        const osg::Vec4d c = osg::Vec4d(bb.corner(unsigned(k)), 1.0) * mvp;
        if (!(c.w() > 1e-6)) return {0, 0, W, H};
        const double x = (c.x() / c.w() * 0.5 + 0.5) * W, y = (c.y() / c.w() * 0.5 + 0.5) * H;
        lx = std::min(lx, x), ly = std::min(ly, y), hx = std::max(hx, x), hy = std::max(hy, y);
    }
    Rect r;
    r.x = std::clamp(int(std::floor(lx)) - grow, 0, W);
    r.y = std::clamp(int(std::floor(ly)) - grow, 0, H);
    r.w = std::clamp(int(std::ceil(hx)) + grow, 0, W) - r.x;
    r.h = std::clamp(int(std::ceil(hy)) + grow, 0, H) - r.y;
    return r;
}

}  // namespace

const char* impostorVertexLibrary() { return kImpostorVertexLib; }

bool drawSplats(const osg::Geometry& geometry, osg::RenderInfo& ri, const SplatParams& params) {
    osg::State& st = *ri.getState();
    const osg::Viewport* vp = st.getCurrentViewport();
    osg::GLExtensions* ext = st.get<osg::GLExtensions>();
    if (!vp || !ext || !ext->isFrameBufferObjectSupported) return false;
    const int W = int(vp->width()), H = int(vp->height()), vx = int(vp->x()), vy = int(vp->y());
    if (W < 1 || H < 1) return true;
    GLint sampleBuffers = 0;
    glGetIntegerv(GL_SAMPLE_BUFFERS, &sampleBuffers);
    if (sampleBuffers > 0) return false;  // a multisampled depth buffer cannot be copied into a texture
    SplatTarget& t = targetFor(st.getContextID());
    if (t.broken) return false;

    // Kernel in pixels: sigma at the bake's focal length, scaled up for a longer focal length.
    const osg::Matrix& proj = st.getProjectionMatrix();
    const double focalPx = std::abs(proj(1, 1)) * 0.5 * H;
    const float sigma = params.sigmaPx * float(std::max(1.0, focalPx / kBakeFocalPx));
    const float radius = kRadiusSigmas * sigma;
    const Rect r =
        screenRect(geometry.getBoundingBox(), st.getModelViewMatrix() * proj, W, H, int(std::ceil(radius)) + 1);
    if (r.w <= 0 || r.h <= 0) return true;
    t.size->set(2.0f * radius);
    t.sigma->set(sigma);
    t.push->set(focalPx > 0 ? float(params.push * radius / focalPx) : 0.0f);
    t.viewport->set(osg::Vec4f(float(vx), float(vy), 1.0f / float(W), 1.0f / float(H)));
    t.resize(W, H);

    GLint prevDraw = 0, prevRead = 0;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING_EXT, &prevDraw);
    glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING_EXT, &prevRead);
    GLfloat clear[4];
    glGetFloatv(GL_COLOR_CLEAR_VALUE, clear);
    const GLboolean scissorWas = glIsEnabled(GL_SCISSOR_TEST);
    GLint scissorBox[4];
    glGetIntegerv(GL_SCISSOR_BOX, scissorBox);

    // 1. The depth drawn so far (read from the caller's framebuffer) into the private depth texture.
    t.fbo->apply(st, osg::FrameBufferObject::READ_DRAW_FRAMEBUFFER);
    if (ext->glCheckFramebufferStatus(GL_FRAMEBUFFER_EXT) != GL_FRAMEBUFFER_COMPLETE_EXT) {
        OSG_WARN << "vista: point splats need a float colour target; drawing plain points" << std::endl;
        t.broken = true;
        ext->glBindFramebuffer(GL_DRAW_FRAMEBUFFER_EXT, GLuint(prevDraw));
        ext->glBindFramebuffer(GL_READ_FRAMEBUFFER_EXT, GLuint(prevRead));
        return false;
    }
    ext->glBindFramebuffer(GL_READ_FRAMEBUFFER_EXT, GLuint(prevDraw));
    t.depth->copyTexSubImage2D(st, r.x, r.y, vx + r.x, vy + r.y, r.w, r.h);
    ext->glBindFramebuffer(GL_READ_FRAMEBUFFER_EXT, 0);
    glViewport(0, 0, W, H);
    glEnable(GL_SCISSOR_TEST);
    glScissor(r.x, r.y, r.w, r.h);
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT);

    // 2. Visibility (depth only, pushed back), 3. accumulation (additive, depth LEQUAL).
    // OSG applies a drawable's own state set without pushing it (RenderLeaf),
    // so it is pushed here for the splat passes to inherit its uniforms and atlas.
    const osg::StateSet* own = geometry.getStateSet();
    if (own) st.pushStateSet(own);
    st.apply(t.visibility.get());
    geometry.osg::Geometry::drawImplementation(ri);
    st.apply(t.accumulate.get());
    geometry.osg::Geometry::drawImplementation(ri);

    // 4. Normalisation into the caller's framebuffer, within the rectangle.
    ext->glBindFramebuffer(GL_DRAW_FRAMEBUFFER_EXT, GLuint(prevDraw));
    ext->glBindFramebuffer(GL_READ_FRAMEBUFFER_EXT, GLuint(prevRead));
    glViewport(vx, vy, W, H);
    glScissor(vx + r.x, vy + r.y, r.w, r.h);
    st.apply(t.normalise.get());
    t.quad->draw(ri);

    glScissor(scissorBox[0], scissorBox[1], scissorBox[2], scissorBox[3]);
    if (!scissorWas) glDisable(GL_SCISSOR_TEST);
    glClearColor(clear[0], clear[1], clear[2], clear[3]);
    if (own) {
        st.popStateSet();
        st.apply(own);  // back to the state OSG applied for this drawable (RenderLeaf)
    } else {
        st.apply();
    }
    return true;
}

}  // namespace vista
