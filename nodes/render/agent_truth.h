// The ground truth of a traffic run's moving agents at a frame's time, for
// the dataset writers (`vista render --rig --traffic`): each agent as a
// moving object (runtime/engine/boxes.h MovingObject) and its rigid motion
// over a flow's time step (runtime/engine/rig_camera.h ObjectMotion).
//
// agentObjects(tracks, models, params, t): every agent present at t
// (placeAgents), sorted by instance id: id agentLabel, class agentClass, mesh
// its prototype's (owned by `models`, which must outlive the result) with its
// placement's transform; box: the model's length, width and height, centred
// half its height above the footprint's centre, yaw that of the model's x
// axis wrapped into (-pi/2, pi/2] (boxes have no front: the velocity tells
// the heading of a moving agent); velocity: the box centre's central
// difference over t -+ kAgentVelocityStepS (one-sided where the agent is
// missing on one side, 0 where it is missing on both).
// agentMotions(tracks, models, params, t0, t1): per agent present at t0,
// sorted by instance id, the world motion T(t1) T(t0)^-1 of its placements
// (a rigid motion: a body point's world position at t0 -> at t1); not known
// when the agent is gone at t1. Pure; thread-safe.
#pragma once
#include <vector>

#include "citygen/params.h"
#include "runtime/engine/boxes.h"
#include "runtime/engine/rig_camera.h"
#include "runtime/traffic/agent_models.h"
#include "runtime/traffic/traffic_tracks.h"

namespace vista {

constexpr double kAgentVelocityStepS = 0.05;

std::vector<MovingObject> agentObjects(const TrafficTracks& tracks, const AgentModels& models, const CityParams& params,
                                       double t);
std::vector<ObjectMotion> agentMotions(const TrafficTracks& tracks, const AgentModels& models, const CityParams& params,
                                       double t0, double t1);

}  // namespace vista
