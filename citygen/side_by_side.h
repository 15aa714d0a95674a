// Side-by-side street edges: OpenStreetMap maps a divided road as two one-way
// ways a few metres apart (and a service road may run close beside a main
// road). Each edge gets the width its lanes have at their class's lane width,
// so two such edges' carriageways may share area although their centre lines
// are apart; a simulator then sees two roads overlapping outside any
// junction. narrowSideBySide() narrows them to the room between their centre
// lines.
//
// Contract (lengths metres, city frame):
// - A pair of edges is side by side when both are valid (distinct finite
//   nodes, length > 0), they share no node, their directions lie within
//   kSideBySideAngle of parallel (either way round), and their carriageways
//   (the rectangle of the centre segment and half the carriageway width,
//   lanes.h carriagewayWidth, on each side) share area. Edges that meet at a
//   node are parted by their junction or transition (lanes.h), not here.
// - Each side-by-side pair asks both carriageways to shrink by one factor s
//   in (0, 1], the largest that leaves the two rectangles at least
//   kSideBySideClearance apart; a pair whose centre segments touch or cross
//   (no s would part them) asks nothing. An edge takes the smallest factor
//   of its pairs: width' = s x width.
// - The edge keeps its driving lanes while each is at least kMinLaneWidth
//   wide; else it drops lanes, one at a time from the direction with more
//   lanes (forward on a tie), never a direction's last lane, until the lanes
//   are that wide or each direction has one. A direction that loses lanes
//   loses its turn:lanes value (it listed the lanes it had). The lane split
//   is then explicit (lanesForward / lanesBackward), so a one-way edge stays
//   one-way and a two-way edge two-way.
// - Widths only shrink; other fields stay. Deterministic; pure function of
//   the graph.
#pragma once
#include <cstddef>

#include "citygen/street_graph.h"

namespace vista {

constexpr double kSideBySideAngle = 0.5235987755982988;  // 30 degrees: closer to parallel counts as side by side
constexpr double kSideBySideClearance = 0.05;            // gap left between two side-by-side carriageways
constexpr double kMinLaneWidth = 2.5;                    // narrowest driving lane before a lane is dropped

struct SideBySideStats {
    size_t pairs = 0;          // side-by-side edge pairs whose carriageways shared area
    size_t edgesNarrowed = 0;  // edges given a narrower carriageway
    size_t lanesDropped = 0;   // driving lanes dropped to keep kMinLaneWidth
};

SideBySideStats narrowSideBySide(StreetGraph& g);

}  // namespace vista
