// Long vehicles keep off junction turns tighter than they can take:
// restrictTightTurns() closes a SUMO network's internal lanes to the vehicle
// classes whose turning need exceeds the lane's radius, so that SUMO routes
// those vehicles through other junctions.
//
// Why: SUMO moves a vehicle along its lane as a flexible tube, but checks
// collisions with the straight box between its front and its back. On a
// turn of radius R that box cuts the inside of the turn by the sagitta
// R (1 - cos(L / 2R)) of a vehicle of length L: a 12 m bus on a 6.5 m right
// turn cuts 2.8 m into the crossing or the neighbouring lane it passes, and
// a pedestrian stepping on behind it or a car waiting there is reported as
// a collision although the vehicle's lane is clear.
//
// Contract:
// - turnRadius(shape): the mean radius of a lane's bend: the length of the
//   polyline between the first and the last vertex where its heading turns
//   (by more than 1e-3 rad) over the lane's heading change (the straight
//   parts before and after the bend do not count). A lane turning by less
//   than kMinTurnDeg in all is straight (infinity).
// - turningNeedM(length): the smallest radius on which the box of a vehicle
//   of `length` cuts the inside of the turn by at most kMaxBoxCutM (the
//   sagitta above; 0 for a vehicle no longer than kMaxBoxCutM allows on any
//   radius).
// - restrictTightTurns(netPath, classes): for each lane of an internal edge
//   (<edge function="internal">) and each class of `classes` whose need
//   exceeds the lane's turnRadius, removes the class from the lane's
//   permissions: appended to its `disallow` list, removed from its `allow`
//   list, or a new `disallow` when the lane has neither. Nothing else of the
//   file changes (same bytes elsewhere), so the result is deterministic.
//   Returns the number of lanes closed per class (in the order of
//   `classes`).
// - The file is replaced atomically; a file that is not a SUMO network, is
//   truncated or malformed is an error naming the file and line, and leaves
//   the file as it was.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "foundation/status.h"

namespace vista {

constexpr double kMaxBoxCutM = 1.0;
constexpr double kMinTurnDeg = 10.0;

struct TurnClass {
    std::string sumoClass;  // SUMO's vClass name ("bus", ...)
    double lengthM = 0.0;   // the vehicle's length
};

double turnRadius(const std::vector<std::pair<double, double>>& shape);
double turningNeedM(double lengthM);

Result<std::vector<size_t>> restrictTightTurns(const std::string& netPath, const std::vector<TurnClass>& classes);

}  // namespace vista
