// ImpostorFrame: the frame an impostor is baked and stored in.
//
// Origin at the street end (world x, y; z = the cell's ground minimum); x axis
// = direction of the street end, away from the cell; y = left; z = up.
// Points, the far-field soup and the sampling geometry are in this frame
// (float points, double set-up); the baked node's MatrixTransform holds it.
// Plain value type; pure.
#pragma once
#include <glm/glm.hpp>

#include "bake/box3.h"
#include "bake/view_cells.h"

namespace vista {

struct ImpostorFrame {
    glm::dvec3 origin{0.0};  // world
    glm::dvec2 x{1.0, 0.0};  // world direction of the frame's x axis (unit)

    glm::dvec3 toLocal(const glm::dvec3& w) const {
        const glm::dvec3 d = w - origin;
        return {d.x * x.x + d.y * x.y, -d.x * x.y + d.y * x.x, d.z};
    }
    glm::dvec3 toWorld(const glm::dvec3& l) const {
        return origin + glm::dvec3(l.x * x.x - l.y * x.y, l.x * x.y + l.y * x.x, l.z);
    }
};

// The frame of (cell, end): end 0 looks towards the street's node a, 1 towards b.
inline ImpostorFrame impostorFrame(const ViewCell& cell, int end) {
    const glm::dvec2 u = end == 1 ? cell.box.axis : -cell.box.axis;
    return {glm::dvec3(glm::dvec2(cell.box.center) + u * cell.box.halfLength, cell.groundMin), u};
}

// The view cell box in a frame (the bounding box of its 8 corners).
inline Box3 cellInFrame(const ViewCell& c, const ImpostorFrame& f) {
    glm::dvec3 corners[8];
    c.box.corners(corners);
    Box3 b{glm::dvec3(1e300), glm::dvec3(-1e300)};
    for (const auto& k : corners) {
        const glm::dvec3 l = f.toLocal(k);
        b.lo = glm::min(b.lo, l);
        b.hi = glm::max(b.hi, l);
    }
    return b;
}

}  // namespace vista
