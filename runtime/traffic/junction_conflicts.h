// Crossing junction lanes as wide as their conflict: widenConflictLanes()
// sets the width of a SUMO network's internal lanes so that SUMO's junction
// model holds a vehicle as "in the way" until its body has left a crossing
// foe lane's vehicles, also where the two lanes cross at a slant.
//
// Why: SUMO 1.15 takes a vehicle on a foe lane as past the crossing point
// once its back is half the ego lane's width beyond the centre lines'
// crossing, measured along the foe lane: right for lanes crossing at right
// angles, short for slanted ones (a documented limit of SUMO's conflict
// estimate). A left turn leaves the oncoming straight lane at about 45
// degrees and keeps turning: a car stopped there for a pedestrian on the
// exit crossing counted as past while its rear corner still covered the
// straight lane, and a straight car with priority drove into it. The lane
// width is the only input of that estimate, so the lane carries the width
// the conflict needs; no position, shape or length changes, vehicles keep
// driving on the lane's centre line.
//
// Contract:
// - Foe pairs: for each junction <request index="i" foes="...">, the
//   internal lanes intLanes[i] (ego) and intLanes[j] (foe) for each link j
//   marked in `foes` (the string's last character is link 0); for each
//   internal junction (type="internal"), its internal incoming lane (ego)
//   and each of its intLanes (foe). Only lanes of internal edges count
//   (crossings and walking areas do not). A pair whose lanes start at the
//   same point (one source) or end at the same point (one target) is left
//   out: SUMO handles diverging and merging lanes without widths.
// - conflictHalfWidth(ego, foe, egoWidth, foeLength, foeWidth): the crossing
//   is the last intersection of the two centre lines along the foe lane
//   (SUMO's crossing point). Returns the distance along the foe lane from
//   the crossing to the first back position, in steps of kConflictStepM, at
//   which a foe vehicle (a rectangle from its back to its front on the foe
//   lane's centre line, the front extended straight past the lane's end)
//   keeps more than egoWidth / 2 from the ego lane's centre line; 0 without
//   a crossing, the foe lane's remaining length when it never clears.
// - widenConflictLanes(netPath, classes): for each foe pair, the ego width is
//   the widest class of `classes` the ego lane allows, and every class the
//   foe lane allows is tried as the foe vehicle (SUMO's permissions: allow or
//   disallow lists). The ego lane's width becomes the largest width for
//   which SUMO's test (back past the crossing by half the width, positions
//   scaled by the foe lane's length over its shape's length) holds only once
//   the foe has cleared, when that exceeds its width, capped at
//   kMaxConflictWidthM and at twice the distance from the start of each
//   pedestrian crossing (<edge function="crossing">) the lane crosses to
//   that crossing point. SUMO places a vehicle lane on a crossing at its
//   crossing point less half its width, clamped to the crossing's start, so
//   beyond the cap a vehicle would look for pedestrians (and pedestrians see
//   it) away from where it is; within it, what they see of each other does
//   not depend on the width. A lane never narrows. The `width` value is
//   replaced (or added, 2 decimals).
//   Nothing else of the file changes (same bytes elsewhere), so the result
//   is deterministic. Returns the number of lanes widened.
// - The file is replaced atomically; a file that is not a SUMO network, is
//   truncated or malformed is an error naming the file and line, and leaves
//   the file as it was.
#pragma once
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "foundation/status.h"

namespace vista {

constexpr double kConflictStepM = 0.05;
constexpr double kMaxConflictWidthM = 12.0;

struct ConflictClass {
    std::string sumoClass;  // SUMO's vClass name ("passenger", ...)
    double lengthM = 0.0, widthM = 0.0;
};

using Polyline2 = std::vector<std::pair<double, double>>;

double conflictHalfWidth(const Polyline2& ego, const Polyline2& foe, double egoWidthM, double foeLengthM,
                         double foeWidthM);

Result<size_t> widenConflictLanes(const std::string& netPath, const std::vector<ConflictClass>& classes);

}  // namespace vista
