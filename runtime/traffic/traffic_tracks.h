// Moving agents over time, read from SUMO's floating-car data (FCD XML):
// the plain arrays that the near field, the ray scene and the sensors draw
// traffic from.
//
// Contract:
// - Positions are in vista's world frame (the OpenDRIVE file's): SUMO's x, y
//   minus the network offset given to readFcd(). SUMO reports a vehicle at
//   the middle of its front bumper and a person at its centre; AgentPose
//   keeps that reference point (x, y) and the heading. heading is radians
//   counter-clockwise from +x (SUMO's angle is degrees clockwise from north).
// - Agents are numbered in the order they first appear; their SUMO ids and
//   types are kept. Frames are the FCD's time steps in file order; a frame's
//   poses are sorted by agent number.
// - poseAt() gives an agent's pose at any time inside the run, linear between
//   the two enclosing samples (the heading along the shorter turn); false
//   when the agent is not in both samples (it departs or arrives between
//   them) unless `t` is a sample's own time.
// - readFcd() streams the file (expat). A file that is not FCD, is truncated
//   or malformed, has times that do not increase, or a vehicle or person of a
//   type vista does not know, or a value out of range (|time| <= 1e9 s,
//   world |x|, |y| <= 2e7 m, |angle| <= 36000 degrees, speed 0 .. 1000 m/s),
//   is an error naming the file, the line and the reason. Thread-safe (const after reading).
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "foundation/status.h"
#include "runtime/traffic/traffic_demand.h"

namespace vista {

class SignalStates;  // signal_states.h

struct AgentPose {
    uint32_t agent = 0;
    float x = 0.f, y = 0.f;  // world metres (see above)
    float heading = 0.f;     // radians CCW from +x
    float speed = 0.f;       // m/s
};

struct TrafficTracks {
    std::vector<std::string> agentIds;  // SUMO ids
    std::vector<AgentType> agentTypes;  // per agent
    std::vector<double> times;          // seconds, one per frame, increasing
    std::vector<uint32_t> frameStart;   // frame f's poses: [frameStart[f], frameStart[f+1])
    std::vector<AgentPose> poses;
    // The run's traffic-light states (signal_states.h) when loaded with the
    // tracks (the CLI's --traffic), else null: heads keep their static lamps.
    std::shared_ptr<const SignalStates> signals;

    size_t frames() const { return times.size(); }
    // Index of the last frame at or before `t` (0 before the first).
    size_t frameAt(double t) const;
    bool poseAt(uint32_t agent, double t, AgentPose* out) const;
};

Result<TrafficTracks> readFcd(const std::string& path, double offsetX, double offsetY);

// The tracks of a traffic directory (`vista traffic`, docs/formats.md):
// DIR/traffic.json (format "vista-traffic", version 1, its net_offset and
// fcd file name) and the FCD it names. Errors name the directory and field.
Result<TrafficTracks> loadTrafficTracks(const std::string& dir);

}  // namespace vista
