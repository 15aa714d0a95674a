// A walkthrough path that rides one of SUMO's vehicles (an "ego" vehicle
// inside the traffic): it stops at red lights and queues behind others
// because SUMO drove it so.
//
// Contract:
// - chooseEgo(): the vehicle named `id`, or (id empty) one chosen from
//   `seed` among the cars that stay in the simulation longest: the cars are
//   ranked by how long they are present (ties by id) and the seed picks one
//   of the first kEgoCandidates. An unknown id, a pedestrian or a run
//   without cars is an error naming the id / the traffic.
// - egoPath(): samples every `dt` seconds from the ego's first sample for
//   `duration` seconds (or until it leaves, whichever is first: the path is
//   then shorter, never padded), t on the traffic's clock (the FCD time of
//   each sample, from the ego's first), so that a walkthrough of the path
//   with --traffic shows the other agents as they were at that instant. The eye sits kEgoEyeBack of the
//   vehicle's length behind its front bumper along its heading, at the
//   terrain height (citygen/terrain.h) plus `eyeHeight`; the camera heading
//   is the vehicle's (radians clockwise from north), pitch 0. Positions are
//   SUMO's samples interpolated (traffic_tracks.h poseAt).
// Pure, thread-safe.
#pragma once
#include <cstdint>
#include <string>

#include "citygen/params.h"
#include "foundation/status.h"
#include "runtime/scene/paths.h"
#include "runtime/traffic/traffic_tracks.h"

namespace vista {

constexpr int kEgoCandidates = 16;
constexpr double kEgoEyeBack = 0.55;

Result<uint32_t> chooseEgo(const TrafficTracks& tracks, const std::string& id, uint64_t seed);

Result<Path> egoPath(const TrafficTracks& tracks, uint32_t ego, const CityParams& params, double dt, double duration,
                     double eyeHeight);

}  // namespace vista
