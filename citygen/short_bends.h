// Slight bends next to a junction: two OpenStreetMap ways that meet end to end
// a few metres from a junction leave a degree-2 node there (the import keeps
// way ends), and so a street edge between the junction and that node that is
// shorter than the junction's footprint and the bend's transition together
// (lanes.h): the junction's arm shrinks to 1 m and its connecting roads sweep
// over the arm and the transition beyond it. straightenShortBends() drops
// such a node where the road barely bends there, joining its two edges into
// one straight edge from the junction.
//
// Contract (lengths metres, city frame):
// - A node T is dropped when it has exactly two edges, e to a node J of
//   degree >= 3 and f to another node X (X != J, no edge J-X yet), e is at
//   most kShortBendArm long, the two edges carry the same road (class, width,
//   lane counts per direction, speed limit, turn lanes, read along J -> T ->
//   X), the road turns at T by at most kShortBendAngle, T and every node
//   dropped before on e or f lie within kShortBendDeviation of the segment
//   J-X, and no other node lies in the triangle J, T, X (so the new edge
//   crosses nothing the two edges did not).
// - The edge f becomes J-X (a one-way edge still runs along its traffic),
//   e and T are removed (later edges and nodes move down, keeping their
//   order). Nodes are visited in index order, again until none is dropped.
//   Returns the number of nodes dropped.
// Deterministic; graphs without such nodes are left as they are.
#pragma once
#include <cstddef>

#include "citygen/street_graph.h"

namespace vista {

constexpr double kShortBendArm = 25.0;                  // longest junction arm whose bend may be straightened
constexpr double kShortBendAngle = 0.2617993877991494;  // 15 degrees
constexpr double kShortBendDeviation = 1.5;             // farthest a dropped node lies off the straight edge

size_t straightenShortBends(StreetGraph& g);

}  // namespace vista
