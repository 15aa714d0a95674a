// View cells from street segments (thesis 5.5: "view cells are formed from
// street segments"). One cell per street edge: the box swept by the street
// cross-section (carriageway width) along the segment, between eye heights
// eyeMin and eyeMax above the ground.
//
// Contract: cells are in the world frame (city frame + params origin).
// Cell ids are the edge ids, so they are stable for a given city. Degenerate
// edges (length < minLength, including zero length, or non-finite nodes) get
// no cell: they are listed in `skipped` with the reason and their id is never
// used. Very short edges (>= minLength) get a short box. Pure; thread-safe.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "citygen/street_graph.h"
#include "nodes/view_cell_switch.h"

namespace vista {

struct ViewCellParams {
    double eyeMin = 1.2;  // metres above ground
    double eyeMax = 2.0;
    double minLength = 0.5;  // metres; shorter edges get no cell
    double minWidth = 2.0;   // metres; narrower streets are widened to this
};

struct ViewCell {
    uint32_t id = 0;                      // = street edge id
    ViewCellBox box;                      // world frame
    double groundMin = 0, groundMax = 0;  // ground height range under the cell
};

struct SkippedCell {
    uint32_t edge = 0;
    std::string reason;
};

// `ground(p)` = ground height at city-frame position p; `origin` = world
// position of the city frame origin (params.origin_x/_y).
std::vector<ViewCell> makeViewCells(const StreetGraph& g, const glm::dvec2& origin,
                                    const std::function<double(const glm::dvec2&)>& ground, const ViewCellParams& p,
                                    std::vector<SkippedCell>* skipped = nullptr);

}  // namespace vista
