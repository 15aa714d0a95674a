// Plain 2D polygon helpers (no CGAL): area, centroid, containment, ear-clipping.
//
// Contract: polygons are std::vector<glm::dvec2>, simple, without a repeated
// closing vertex. Functions accept either orientation unless stated. All are
// pure and thread-safe. Degenerate input (fewer than 3 vertices, zero area)
// yields area 0 / an empty triangulation, never NaN.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace vista {

double signedArea(const std::vector<glm::dvec2>& poly);    // > 0 for counter-clockwise
glm::dvec2 centroid(const std::vector<glm::dvec2>& poly);  // area centroid (vertex mean if degenerate)
bool pointInPolygon(const std::vector<glm::dvec2>& poly, const glm::dvec2& p);
// True if every vertex of `inner` is inside or within `eps` of `outer`, and no
// edges properly cross.
bool polygonInside(const std::vector<glm::dvec2>& inner, const std::vector<glm::dvec2>& outer, double eps = 1e-6);
// True if the two polygons' interiors overlap by more than `eps` (edge contact is not overlap).
bool polygonsOverlap(const std::vector<glm::dvec2>& a, const std::vector<glm::dvec2>& b, double eps = 1e-6);
// Distance from p to segment ab.
double pointSegmentDistance(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b);
// Removes consecutive duplicates (within eps) and collinear vertices.
std::vector<glm::dvec2> cleanPolygon(const std::vector<glm::dvec2>& poly, double eps = 1e-7);
// Convex hull (Andrew's monotone chain), counter-clockwise. A point stays on
// the hull only where the turn's cross product exceeds collinearEps, so
// collinear and duplicate points are dropped. Fewer than 3 distinct points
// come back sorted and deduplicated (callers that need a polygon check size).
std::vector<glm::dvec2> convexHull(std::vector<glm::dvec2> pts, double collinearEps = 0.0);
// Ear clipping; returns index triples into `poly` oriented counter-clockwise.
std::vector<uint32_t> triangulate(const std::vector<glm::dvec2>& poly);

}  // namespace vista
