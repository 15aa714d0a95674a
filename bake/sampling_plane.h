// Sampling plane, shaft and bounding triangle of one far field seen from one
// view cell (thesis 5.3.2, 5.4.1; steps 1-3 of docs/reference/bake.md "Pipeline").
//
// All positions are in the impostor frame (metres), where the view cell box
// `cell` and the far-field box `far` are axis-aligned.
//  1. Sampling plane: normal n = horizontal direction from the cell centre to
//     the far-box centre; the plane touches the cell on its far-field side
//     (dot(n, x) = max over the cell corners), so every viewing ray from the
//     cell to the far field crosses it inside the shaft.
//  2. Shaft polygon: the convex hull of the cell and the far box (the region
//     bounded by their supporting planes) cut by the sampling plane: the
//     convex hull of the crossings of the 64 corner-to-corner segments.
//  3. Bounding triangle: top edge parallel to the ground (along U), minimum
//     circumference, containing the polygon (2D search over the two side
//     directions, each side a supporting line). Its corners are the LDI
//     camera positions (bake/ldi_sampling.h).
// Contract: setupSampling() returns an error when the far box is not strictly
// in front of the sampling plane (cell touching or intersecting the far box)
// or a box is empty/non-finite; otherwise the cameras lie on the plane, never
// inside the far box, and every far-box corner is in front of every camera.
// Pure; thread-safe.
#pragma once
#include <array>
#include <vector>

#include <glm/glm.hpp>

#include "bake/box3.h"
#include "foundation/status.h"

namespace vista {

struct SamplingSetup {
    glm::dvec3 n{1, 0, 0}, U{0, -1, 0}, V{0, 0, 1};  // plane normal, right, up (orthonormal)
    double planeD = 0;                               // plane: dot(n, x) = planeD
    std::vector<glm::dvec2> polygon;                 // shaft cut, plane coords (U, V), counter-clockwise
    glm::dvec2 rectLo{0.0}, rectHi{0.0};             // bounding rectangle of the polygon
    std::array<glm::dvec2, 3> tri{};                 // bounding triangle: top-left, top-right, bottom
    std::array<glm::dvec3, 3> cameras{};             // triangle corners in the frame
    glm::dvec2 circumcentre{0.0};
    double circumradius = 0;
    double dNear = 0;  // nearest far-box depth in front of the plane
    double dFar = 0;   // farthest

    glm::dvec3 toFrame(const glm::dvec2& q) const { return n * planeD + U * q.x + V * q.y; }
};

Result<SamplingSetup> setupSampling(const Box3& cell, const Box3& far);

double trianglePerimeter(const std::array<glm::dvec2, 3>& t);
// Minimum-circumference triangle with a top edge parallel to the x axis that
// contains the convex polygon `poly` (non-empty). Returns top-left, top-right, bottom.
std::array<glm::dvec2, 3> boundingTriangle(const std::vector<glm::dvec2>& poly);

}  // namespace vista
