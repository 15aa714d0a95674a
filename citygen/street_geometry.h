// Internal helpers shared by the street-graph files (street_graph.cpp,
// planarize.cpp, streets.cpp, osm_import.cpp). Not part of the public citygen contract.
//
// findConflictingEdges(): every pair of edges (e < f) that violates
// planarity: edges without a shared node that intersect at all (crossing,
// touching, overlapping), or edges sharing one node that overlap collinearly
// beyond it. Exact predicates on the double coordinates (CGAL filtered
// predicates), a uniform grid keeps it near-linear. Indices must be valid
// and coordinates finite (checked by the caller). Pure, thread-safe.
#pragma once
#include <cstdint>
#include <utility>
#include <vector>

#include "citygen/street_graph.h"

namespace vista {

std::vector<std::pair<uint32_t, uint32_t>> findConflictingEdges(const StreetGraph& g, size_t maxPairs);

}  // namespace vista
