// busiestRide(trafficDir, seconds): the id of the car that a test's ride
// follows (`vista path --traffic DIR --ego ID`): among the cars present for at
// least `seconds` from their first sample, the one with the most other agents
// within kBusyRadiusM over those seconds (summed over the traffic's samples;
// ties by id). A test of what a camera sees of the traffic then rides among
// other agents whatever the demand's mix and routes, instead of a car picked
// by a seed. Empty when the directory cannot be read or no car qualifies.
#pragma once
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "runtime/traffic/traffic_tracks.h"

namespace vista::test {

inline constexpr double kBusyRadiusM = 60.0;

inline std::string busiestRide(const std::string& trafficDir, double seconds) {
    auto tracks = loadTrafficTracks(trafficDir);
    if (!tracks) return "";
    const TrafficTracks& tr = *tracks;
    const size_t agents = tr.agentIds.size();
    std::vector<double> first(agents, -1.0), last(agents, -1.0);
    for (size_t f = 0; f < tr.frames(); ++f)
        for (uint32_t i = tr.frameStart[f]; i < (f + 1 < tr.frames() ? tr.frameStart[f + 1] : tr.poses.size()); ++i) {
            const uint32_t a = tr.poses[i].agent;
            if (first[a] < 0) first[a] = tr.times[f];
            last[a] = tr.times[f];
        }
    std::vector<uint64_t> company(agents, 0);
    for (size_t f = 0; f < tr.frames(); ++f) {
        const uint32_t begin = tr.frameStart[f];
        const uint32_t end = f + 1 < tr.frames() ? tr.frameStart[f + 1] : uint32_t(tr.poses.size());
        for (uint32_t i = begin; i < end; ++i) {
            const AgentPose& p = tr.poses[i];
            if (tr.agentTypes[p.agent] != AgentType::Car || tr.times[f] > first[p.agent] + seconds) continue;
            for (uint32_t j = begin; j < end; ++j)
                if (j != i && std::hypot(tr.poses[j].x - p.x, tr.poses[j].y - p.y) < kBusyRadiusM) ++company[p.agent];
        }
    }
    std::string best;
    uint64_t most = 0;
    for (size_t a = 0; a < agents; ++a) {
        if (tr.agentTypes[a] != AgentType::Car || last[a] - first[a] < seconds) continue;
        if (company[a] > most || (company[a] == most && !best.empty() && tr.agentIds[a] < best)) {
            most = company[a];
            best = tr.agentIds[a];
        }
    }
    return best;
}

}  // namespace vista::test
