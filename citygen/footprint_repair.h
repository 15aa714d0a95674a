// Exact-predicate helpers for imported (OSM) building footprints: ring
// repair, ring nesting checks and triangulation of polygons with holes.
//
// Contract: rings are Polygon2 (double metres, city frame) without a repeated
// closing vertex, either orientation unless stated. Predicates (orientation,
// segment intersection, point location) are exact (CGAL's exact-predicates
// kernel, used only inside footprint_repair.cpp); the constructed points of a
// split (intersection points) are rounded to double. Every function is pure,
// thread-safe and never throws: non-finite coordinates or CGAL failures give
// the "no result" answer stated per function.
#pragma once
#include <array>
#include <vector>

#include <glm/glm.hpp>

#include "citygen/city.h"

namespace vista {

// Ring size up to which a self-intersecting ring is split (the pair search is
// quadratic); larger non-simple rings are not repaired.
constexpr size_t kMaxRepairRingNodes = 1000;

// True if the ring is a simple polygon (no two edges touch except neighbours
// at their shared vertex; at least 3 vertices; finite).
bool isSimpleRingExact(const Polygon2& ring);

// Makes a ring simple. A simple ring comes back counter-clockwise with
// `split` = false. A ring that touches or crosses itself is split at its
// self-intersections (at most 64 splits) into loops; the loop of largest
// area that is simple comes back counter-clockwise with `split` = true.
// Returns empty when no simple loop of positive area remains, or when the
// ring needs splitting and has more than kMaxRepairRingNodes vertices.
Polygon2 makeSimpleRing(const Polygon2& ring, bool& split);

// True if the simple ring `inner` lies strictly inside the simple ring
// `outer`: no edge of one touches or crosses an edge of the other, and a
// vertex of `inner` is inside `outer`.
bool ringStrictlyInside(const Polygon2& inner, const Polygon2& outer);

// True if the interiors and boundaries of two simple rings are disjoint (no
// edges touch or cross and neither contains the other).
bool ringsDisjoint(const Polygon2& a, const Polygon2& b);

// Constrained Delaunay triangulation of the region inside the simple ring
// `outer` and outside every ring of `holes` (simple, strictly inside outer,
// pairwise disjoint). Triangles are counter-clockwise seen from +z. Returns
// empty on invalid input.
std::vector<std::array<glm::dvec2, 3>> triangulateWithHoles(const Polygon2& outer, const std::vector<Polygon2>& holes);

}  // namespace vista
