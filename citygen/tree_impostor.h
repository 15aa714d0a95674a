// Tree impostors: cross billboards with a baked RGBA atlas (Real-Time
// Rendering ch. 13, "cross billboards"), the far form of an instanced tree
// prototype (city.h TreePrototype). Pure CPU, no OSG: the OSG geometry and
// state live in runtime/scene/tree_impostor_graph.h.
//
// Quads (prototype frame: trunk base at the origin, z up, metres):
//   kImpostorVerticalQuads vertical quads through the trunk axis (the z axis)
//   at yaw k * pi / kImpostorVerticalQuads, each 2R wide (R = the largest
//   horizontal distance of a prototype vertex from the axis) and spanning
//   the prototype's z range [zMin, zMax]; plus one horizontal quad, 2R x 2R,
//   at zMin + kImpostorTopQuadHeight * (zMax - zMin). 4 quads, 8 triangles,
//   16 vertices (quads do not share vertices: each has its own atlas cell).
// Atlas: 2 x 2 cells of `cellPixels` square texels (RGBA8, row 0 = texture
//   t = 0, i.e. the bottom row: zMin for vertical cells, y = -R for the top
//   cell). Cell k (k = 0..2: vertical quad k, 3: the top quad) sits at column
//   k % 2, row k / 2. Each cell keeps kImpostorPadPixels of empty border (no
//   bleeding between cells under linear filtering), the quad maps to the
//   inner square. Every cell is an orthographic view of the prototype along
//   the quad's normal (vertical quad k: horizontal axis d = (cos a, sin a, 0),
//   seen from +n = (-sin a, cos a, 0); top quad: seen from above), depth
//   buffered, kImpostorSupersample^2 samples per texel on a fixed-point
//   (1/256 texel) grid with integer edge functions. Colour = the average of
//   the covered samples' interpolated vertex colours; the vertex colours are
//   the city's prelit colours (citygen/lighting.h: ambient + Lambert from the
//   city's sun direction), so no second shading is applied and the impostor
//   shows the colours its prototype mesh shows. Alpha = coverage (covered
//   samples / all samples, rounded to 0..255); the renderer alpha-tests at
//   kImpostorAlphaRef (no blending, so draw order does not matter).
//   Transparent texels take the average colour of their covered neighbours
//   (a few dilation passes) so that filtering does not darken the edges.
// Determinism: the atlas bytes depend only on the mesh and cellPixels (the
//   cells are baked in parallel, each by one thread, with integer coverage),
//   so they are the same for any thread count.
//
// Contract: colors.size() == positions.size(), indices.size() % 3 == 0, every
// index < positions.size(), cellPixels in [kMinImpostorCellPixels,
// kMaxImpostorCellPixels] (VISTA_CHECK otherwise: callers pass meshes they
// built). A mesh without triangles or with zero radius or height gives an
// impostor without quads (empty() is true) and an all-zero atlas.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace vista {

constexpr int kImpostorVerticalQuads = 3;
constexpr int kImpostorCells = kImpostorVerticalQuads + 1;  // + the top quad
constexpr int kImpostorCellPixels = 64;                     // osglod's far levels
constexpr int kCoarseImpostorCellPixels = 32;  // paged coarse levels (trees beyond about 1 km): 16 KB per prototype
constexpr int kMinImpostorCellPixels = 8, kMaxImpostorCellPixels = 1024;
constexpr int kImpostorPadPixels = 2;
constexpr int kImpostorSupersample = 4;         // samples per texel side
constexpr int kImpostorAlphaRef = 128;          // alpha test: drawn when alpha >= 128/255
constexpr double kImpostorTopQuadHeight = 0.5;  // top quad height, fraction of the z range

struct TreeImpostor {
    float radius = 0;          // R, metres
    float zMin = 0, zMax = 0;  // z range of the prototype, metres
    int cellPixels = 0;
    int atlasWidth = 0, atlasHeight = 0;  // 2 * cellPixels each
    std::vector<uint8_t> atlas;           // RGBA8, atlasWidth * atlasHeight * 4, row 0 = bottom
    std::vector<glm::vec3> positions;     // quad corners, prototype frame
    std::vector<glm::vec3> normals;       // per vertex (the quad's normal)
    std::vector<glm::vec2> texcoords;     // per vertex, atlas [0, 1]^2
    std::vector<uint32_t> indices;        // 2 triangles per quad
    bool empty() const { return indices.empty(); }
    size_t triangleCount() const { return indices.size() / 3; }
};

// The impostor of one prototype mesh (see above).
TreeImpostor makeTreeImpostor(const std::vector<glm::vec3>& positions, const std::vector<glm::u8vec4>& colors,
                              const std::vector<uint32_t>& indices, int cellPixels = kImpostorCellPixels);

// The view of atlas cell `cell` (0..kImpostorCells-1) of an impostor with
// radius R and z range [zMin, zMax]: maps a prototype-frame point to the
// cell's quad coordinates (u, v) in [0, 1]^2 over the quad (u along the
// quad's horizontal axis, v along z or y) and its depth (larger = nearer to
// the viewer). Shared by the baker and by tests.
struct ImpostorView {
    glm::dvec3 uAxis, vAxis, depthAxis;
    double uMin, uSpan, vMin, vSpan;
    glm::dvec3 project(const glm::vec3& p) const {
        const glm::dvec3 q(p);
        return {(glm::dot(q, uAxis) - uMin) / uSpan, (glm::dot(q, vAxis) - vMin) / vSpan, glm::dot(q, depthAxis)};
    }
};
ImpostorView impostorView(int cell, double radius, double zMin, double zMax);

}  // namespace vista
