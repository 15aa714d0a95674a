// The road network of a decoded city as OpenDRIVE text: the same bytes as
// `vista gen ... --xodr` of that city (the blocks, which decide the sidewalk
// sides, are derived again from the street graph and parameters the city
// file carries). An error names `cityFile` when the city has no street graph
// or the writer refuses it. Pure, thread-safe.
#pragma once
#include <string>

#include "citygen/opendrive.h"
#include "foundation/status.h"
#include "runtime/scene/scene_model.h"

namespace vista {

Result<std::string> cityOpenDrive(const SceneModel& city, const std::string& cityFile,
                                  OpenDriveCounts* counts = nullptr);

}  // namespace vista
