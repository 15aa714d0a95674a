// PointImpostor: a point-based impostor (thesis ch. 5) as an osg::Geometry.
//
// Data (PointImpostorData, plain arrays, model-local float frame):
//   points with a mean colour each; textured points also own a block of
//   texelsX x texelsY colours over the sampling rectangle
//   planeOrigin + a*planeU + b*planeV (a, b in [0, 1]), texel (i, j) centred at
//   ((i + 0.5) / texelsX, (j + 0.5) / texelsY), row j = 0 at the bottom (b = 0).
// Storage (14 bytes per point): positions quantized to 16-bit integers,
// p = dequant.xyz + dequant.w * q (one scale for all axes, so the shader's
// plane projection stays orthogonal; step = largest half-extent / 32767, e.g.
// 1.2 cm for a 800 m far field), 8-bit RGBA colours, 16-bit atlas offsets.
// Drawing: as Gaussian splats with normalised accumulation (point_splat.h)
// while pointSplatSigma() > 0 (the default, kDefaultSplatSigma output
// pixels), else as GL_POINTS of 1 pixel (the stored state: what stock
// osgviewer draws without the plugin's class). A GLSL 1.20 shader intersects the
// ray from the viewer to the point with the sampling plane, maps it to the
// point's block in a packed atlas texture (offset per point in texcoord 0,
// x < 0 = single colour) and samples it bilinearly, clamped to the block so
// neighbours never bleed in. Uniform "vista_useTexture" (int, 1) switches to
// the single-colour preview when 0 (set it with OVERRIDE on a parent).
// Everything the GPU needs is ordinary OSG state (program, uniforms,
// Texture2D with its image stored inline), so the osgb file carries it; the
// wrapper "vista::PointImpostor" adds the plane and texel layout as
// properties. Atlas: width kAtlasBlocksPerRow * texelsX texels, rows of
// texelsY; more than kMaxAtlasHeight rows is a contract violation
// (VISTA_CHECK) — the bake never produces it.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <osg/Geometry>
#include <osg/Image>

namespace vista {

struct PointImpostorData {
    glm::vec3 planeOrigin{0.0f}, planeU{0.0f}, planeV{0.0f};
    int texelsX = 8, texelsY = 2;
    std::vector<glm::vec3> positions;
    std::vector<glm::u8vec4> colors;  // per point (mean over the texels)
    std::vector<int32_t> block;       // per point: -1 = single colour, else block index
    std::vector<glm::u8vec4> texels;  // blocks of texelsX * texelsY, row-major (j, then i)
};

// How every PointImpostor of the process draws: splats of this Gaussian sigma
// in output pixels (at the bake's focal length), or 1-pixel points for 0.
// Set before rendering (vista bench/view --point-splat); read on the draw thread.
constexpr float kDefaultSplatSigma = 0.25f;
void setPointSplatSigma(float sigmaPx);
float pointSplatSigma();

constexpr int kAtlasBlocksPerRow = 256;
constexpr int kMaxAtlasHeight = 8192;
constexpr size_t kPointBytes = 6 + 4 + 4;  // position, colour, atlas offset (texels: 4 bytes each, extra)

class PointImpostor : public osg::Geometry {
public:
    PointImpostor();
    PointImpostor(const PointImpostor& o, const osg::CopyOp& op = osg::CopyOp::SHALLOW_COPY);
    META_Object(vista, PointImpostor)

        // Builds vertex arrays, atlas and state from `d` (replaces any previous content).
        void setData(const PointImpostorData& d);
    size_t pointCount() const;
    size_t texturedCount() const { return _textured; }
    // Dequantized position of point k (model coordinates).
    osg::Vec3f position(size_t k) const;
    // "" if arrays, primitive set and properties are consistent, else the reason
    // (for files read from disk: a corrupt impostor is reported, never drawn).
    std::string validate() const;
    osg::BoundingBox computeBoundingBox() const override;
    // Splats or points, as pointSplatSigma() says.
    void drawImplementation(osg::RenderInfo& ri) const override;

    // The packed atlas of `d` (texel blocks laid out as the shader expects).
    static osg::ref_ptr<osg::Image> buildAtlas(const PointImpostorData& d, std::vector<glm::vec2>& offsets);

    // Serialized properties.
    const osg::Vec3f& getPlaneOrigin() const { return _planeOrigin; }
    void setPlaneOrigin(const osg::Vec3f& v) { _planeOrigin = v; }
    const osg::Vec3f& getPlaneU() const { return _planeU; }
    void setPlaneU(const osg::Vec3f& v) { _planeU = v; }
    const osg::Vec3f& getPlaneV() const { return _planeV; }
    void setPlaneV(const osg::Vec3f& v) { _planeV = v; }
    int getTexelsX() const { return _texelsX; }
    void setTexelsX(int v) { _texelsX = v; }
    int getTexelsY() const { return _texelsY; }
    void setTexelsY(int v) { _texelsY = v; }
    const osg::Vec4f& getDequant() const { return _dequant; }
    void setDequant(const osg::Vec4f& v) { _dequant = v; }
    unsigned getTexturedCount() const { return unsigned(_textured); }
    void setTexturedCount(unsigned v) { _textured = v; }

protected:
    ~PointImpostor() override = default;

private:
    osg::Vec3f dequantize(const osg::Vec3s& q) const;

    osg::Vec3f _planeOrigin, _planeU, _planeV;
    osg::Vec4f _dequant{0, 0, 0, 1};
    int _texelsX = 8, _texelsY = 2;
    size_t _textured = 0;
};

}  // namespace vista
