// Window recesses flattened: a coarser version of an indexed mesh whose
// recessed windows (buildings.h, detail >= 2: glass set back by a depth
// behind four jamb quads of wall) become flat glass on the facade plane.
//
// Recognition (from the geometry alone, any tile mesh or near-field chunk):
// a glass window is a connected group of Material::Window triangles (shared
// vertex indices); its plane is the first triangle's, its normal the
// counter-clockwise front face's (outward). A jamb of that window is a
// Material::Wall triangle with at least one vertex at a glass vertex's
// position whose every vertex lies at a glass vertex's position moved along
// the normal by 0 or by one common depth d, 0 < d <= maxDepth. A window with
// jambs has recess depth = its largest jamb depth; its glass vertices move
// out by that depth (onto the facade plane), and its jambs are dropped. A
// window without jambs (detail 1 bands, or its jambs in another mesh) and
// every other triangle stay as they are.
//
// Error: every point of the flattened mesh lies within `maxRecessDepth` of the
// original surface and every point of the original within it of the
// flattened one (the glass moves by its depth, the dropped jambs span it), so
// the flattened mesh's screen-space deviation from the original is at most
// screenDeviationPx(maxRecessDepth, ...) (nodes/near_field_chunks.h) for a
// camera at least that far away.
//
// Contract: positions, indices (multiple of 3, each < positions.size()) and
// one Material per triangle (triangleMaterial.size() == indices.size() / 3);
// anything else is a VISTA_CHECK. Pure, deterministic, no allocation beyond
// the result.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "citygen/mesh.h"

namespace vista {

struct RecessFlattening {
    std::vector<uint8_t> jamb;     // per triangle: 1 = a recess jamb (dropped in the flat version)
    std::vector<glm::vec3> moved;  // positions of the flat version (glass moved onto the facade)
    uint64_t jambTriangles = 0;    // triangles with jamb = 1
    uint64_t windows = 0;          // windows flattened (glass groups with jambs)
    double maxRecessDepth = 0;     // metres: the largest depth moved (0 = nothing to flatten)
};

// maxDepth: the deepest recess recognised (metres; jambs deeper than this stay).
RecessFlattening flattenRecesses(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
                                 const std::vector<Material>& triangleMaterial, double maxDepth = 2.0);

}  // namespace vista
