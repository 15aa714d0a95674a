// TexturedDepthMesh: a textured depth mesh of one view cell's far field
// (Chen et al. 2003, "single-view" mesh) as an osg::Geometry.
//
// Data (TexturedDepthMeshData, plain arrays, model-local float frame = the
// frame of the MatrixTransform above it): a triangle mesh whose vertices lie
// on the rays of a perspective image taken from `eye`, and that image (RGBA,
// width x height, row 0 at the bottom) as its texture. The texture is
// projective (Chen's projective textures): per vertex texcoord
// (s q, t q, 0, q) with (s, t) the vertex's image position in [0, 1] and q its
// depth along the image camera's forward axis, so the fixed-function divide
// by q maps every fragment to the image pixel its ray went through, also
// inside large triangles that are not parallel to the image plane.
// Drawing: GL_TRIANGLES, fixed function (no shader), lighting off, texture
// REPLACE, LINEAR filter, CLAMP_TO_EDGE, alpha test > 0.5 (texels of alpha 0
// are sky: the silhouette comes from the texture); triangles are counter-clockwise as
// seen from `eye` (back faces culled as the city's). Everything the GPU needs
// is ordinary OSG state (Texture2D with its image stored inline), so the osgb
// file carries it; the wrapper "vista::TexturedDepthMesh" adds CellId, End
// and Eye. validate() checks a mesh read from an untrusted file (array sizes,
// index range, finite values, q > 0, texture present): a bad mesh is
// reported, never drawn. setData() with inconsistent data is a contract
// violation (VISTA_CHECK).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <osg/Geometry>

namespace vista {

struct TexturedDepthMeshData {
    glm::vec3 eye{0.0f};               // projection centre (model frame)
    int width = 0, height = 0;         // image size in pixels (>= 1 each)
    std::vector<glm::u8vec4> image;    // width * height, row-major, row 0 at the bottom; alpha 0 = transparent (sky)
    std::vector<glm::vec3> positions;  // model frame
    std::vector<glm::vec4> texcoords;  // per vertex (s q, t q, 0, q), q > 0
    std::vector<uint32_t> indices;     // 3 per triangle
    size_t triangleCount() const { return indices.size() / 3; }
};

// Bytes a mesh takes in memory/on disk, roughly: 12 + 16 per vertex, 4 per index, 4 per texel.
size_t depthMeshBytes(const TexturedDepthMeshData& d);

class TexturedDepthMesh : public osg::Geometry {
public:
    TexturedDepthMesh();
    TexturedDepthMesh(const TexturedDepthMesh& o, const osg::CopyOp& op = osg::CopyOp::SHALLOW_COPY);
    META_Object(vista, TexturedDepthMesh)

        // Builds arrays, primitive set, texture and state from `d` (replaces any previous content).
        void setData(const TexturedDepthMeshData& d);
    size_t vertexCount() const;
    size_t triangleCount() const;
    // "" if arrays, primitive set, texture and properties are consistent, else the reason.
    std::string validate() const;

    // Serialized properties.
    unsigned getCellId() const { return _cellId; }
    void setCellId(unsigned c) { _cellId = c; }
    int getEnd() const { return _end; }
    void setEnd(int e) { _end = e; }
    const osg::Vec3f& getEye() const { return _eye; }
    void setEye(const osg::Vec3f& e) { _eye = e; }

protected:
    ~TexturedDepthMesh() override = default;

private:
    unsigned _cellId = 0;
    int _end = 0;
    osg::Vec3f _eye;
};

}  // namespace vista
