// Lanes inside junctions keep their vehicles: forbidJunctionLaneChanges()
// marks every lane of a SUMO network's internal edges (<edge
// function="internal">) so that no vehicle of vista's demand changes lane
// on it.
//
// Why: netconvert lets vehicles change lanes on a multi-lane internal edge
// whose links all have priority (a straight link of two lanes, or a
// signalised one). SUMO's lane change is instantaneous, and the lane changer
// does not look at the pedestrian crossings the new lane passes, so a vehicle
// moved sideways onto a pedestrian waiting on a crossing inside the junction
// (a collision that SUMO's junction check reports). Vehicles pick their lane
// before the junction instead, as the lane model's turning lanes intend.
//
// Contract:
// - Each <lane> child of an internal <edge> gains changeLeft="ignoring" and
//   changeRight="ignoring" at the end of its start tag (SUMO's lane-change
//   permissions: only the class
//   `ignoring`, which vista's demand never uses, may change); a lane that
//   already carries either attribute keeps its own. Nothing else of the file
//   changes (same bytes elsewhere), so the result is deterministic.
// - The file is replaced atomically; a file that is not a SUMO network, is
//   truncated or malformed is an error naming the file and line, and leaves
//   the file as it was. Returns the number of lanes marked.
#pragma once
#include <cstddef>
#include <string>

#include "foundation/status.h"

namespace vista {

Result<size_t> forbidJunctionLaneChanges(const std::string& netPath);

}  // namespace vista
