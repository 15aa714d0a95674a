// Internal 2D geometry helpers of the block / lot / building stages.
//
// Contract: polygons are Polygon2 (double metres, city frame), simple,
// without a repeated closing vertex. All functions are pure and thread-safe;
// degenerate input (fewer than 3 vertices, zero area, NaN) yields an empty
// result, never NaN and never an exception. The skeleton-based functions
// (insetPolygonSkeleton, hippedRoofFaces) use CGAL inside roofs.cpp and catch
// every CGAL exception (returning empty / false).
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "citygen/city.h"

namespace vista {

// Returns the polygon counter-clockwise (reversed if it was clockwise).
Polygon2 makeCounterClockwise(Polygon2 poly);

// Stable 64-bit id of an entity anchored at `p` (quantised to 1 cm), for Rng keys.
uint64_t stableIdOf(const glm::dvec2& p);

// Minimum-area oriented bounding box. `u` is the unit direction of the longer
// side (halfU >= halfV), v = perp(u).
struct OrientedBox {
    glm::dvec2 centre{0.0};
    glm::dvec2 u{1.0, 0.0}, v{0.0, 1.0};
    double halfU = 0, halfV = 0;
};
OrientedBox orientedBox(const Polygon2& poly);

// True if no two non-adjacent edges touch or cross and no adjacent edges fold
// back (tolerance eps metres).
bool isSimplePolygon(const Polygon2& poly, double eps = 1e-7);

// Per-edge inset of a counter-clockwise polygon: edge i (poly[i] -> poly[i+1])
// moves inwards by d[i] >= 0 (lines intersected with their neighbours; zero
// width spikes (dead ends) get a square cap; very sharp reflex corners a
// bevel). Returns false (out untouched) when the result is not a valid simple
// polygon whose edges keep their directions and whose vertices keep distance
// d[j] from every input edge j.
bool insetPolygonMiter(const Polygon2& ccw, const std::vector<double>& d, Polygon2& out);

// Uniform inset of a counter-clockwise simple polygon by `d` through CGAL's
// interior straight skeleton; may return several polygons or none.
std::vector<Polygon2> insetPolygonSkeleton(const Polygon2& ccw, double d);

// Uniform inset: miter first, straight skeleton as fallback. Results CCW and cleaned.
std::vector<Polygon2> insetPolygon(const Polygon2& poly, double d);

// Polygon with a flag per edge (edge i runs from pts[i] to pts[i+1]).
struct FlaggedPolygon {
    Polygon2 pts;
    std::vector<uint8_t> flags;
};
// Splits a simple polygon (either orientation) by the line through `origin`
// with direction `dir`. Edges along the cut get flag 0; split edges keep
// theirs. Concave polygons may yield more than two pieces. Returns the input
// unchanged (one piece) when the line does not cross it. Vertices closer than
// 1e-7 m to the line are treated as lying slightly on its positive side.
std::vector<FlaggedPolygon> splitPolygonByLine(const FlaggedPolygon& poly, const glm::dvec2& origin,
                                               const glm::dvec2& dir);

// Hipped roof faces of a counter-clockwise simple footprint through CGAL's
// straight skeleton: every face is a planar polygon (counter-clockwise seen
// from above) with x, y in the city frame and z = skeleton offset time (the
// horizontal distance to the face's eave edge). Returns false on any failure.
bool hippedRoofFaces(const Polygon2& ccw, std::vector<std::vector<glm::dvec3>>& faces, double& maxTime);

}  // namespace vista
