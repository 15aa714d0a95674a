#include "runtime/traffic/ego_path.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "citygen/terrain.h"
#include "foundation/hash.h"
#include "foundation/units.h"

namespace vista {

Result<uint32_t> chooseEgo(const TrafficTracks& tracks, const std::string& id, uint64_t seed) {
    if (!id.empty()) {
        for (uint32_t a = 0; a < tracks.agentIds.size(); ++a) {
            if (tracks.agentIds[a] != id) continue;
            if (tracks.agentTypes[a] == AgentType::Pedestrian)
                return Status::error("--ego = '" + id + "' is a pedestrian: give a vehicle's id (veh<N>)");
            return a;
        }
        return Status::error("--ego = '" + id + "' is not a vehicle of the traffic (ids are veh0, veh1, ...)");
    }
    // Presence (samples) per car.
    std::vector<uint32_t> samples(tracks.agentIds.size(), 0);
    for (const AgentPose& p : tracks.poses) ++samples[p.agent];
    std::vector<uint32_t> cars;
    for (uint32_t a = 0; a < tracks.agentIds.size(); ++a)
        if (tracks.agentTypes[a] == AgentType::Car && samples[a] > 1) cars.push_back(a);
    if (cars.empty()) return Status::error("the traffic has no car to ride (give --ego with a vehicle's id)");
    std::sort(cars.begin(), cars.end(), [&](uint32_t a, uint32_t b) {
        return samples[a] != samples[b] ? samples[a] > samples[b] : tracks.agentIds[a] < tracks.agentIds[b];
    });
    const size_t n = std::min(cars.size(), size_t(kEgoCandidates));
    return cars[size_t(splitmix64(seed ^ 0x65676f) % n)];
}

Result<Path> egoPath(const TrafficTracks& tracks, uint32_t ego, const CityParams& params, double dt, double duration,
                     double eyeHeight) {
    VISTA_CHECK(ego < tracks.agentIds.size());
    double first = -1.0, last = -1.0;
    for (size_t f = 0; f < tracks.frames(); ++f) {
        const auto begin = tracks.poses.begin() + tracks.frameStart[f];
        const auto end = f + 1 < tracks.frames() ? tracks.poses.begin() + tracks.frameStart[f + 1] : tracks.poses.end();
        if (std::any_of(begin, end, [&](const AgentPose& p) { return p.agent == ego; })) {
            if (first < 0) first = tracks.times[f];
            last = tracks.times[f];
        }
    }
    if (first < 0 || last <= first)
        return Status::error("vehicle '" + tracks.agentIds[ego] + "' is in the traffic for less than one step");
    const double length = agentTypeInfo(tracks.agentTypes[ego]).length;
    const double end = std::min(last, first + duration);
    Path path;
    for (size_t i = 0;; ++i) {
        const double t = first + double(i) * dt;
        if (t > end + 1e-9) break;
        AgentPose p;
        if (!tracks.poseAt(ego, std::min(t, last), &p)) break;
        const glm::dvec2 front(p.x, p.y);
        const glm::dvec2 eye = front - kEgoEyeBack * length * glm::dvec2(std::cos(p.heading), std::sin(p.heading));
        const glm::dvec2 local = eye - glm::dvec2(params.origin_x, params.origin_y);
        PathSample s;
        s.t = t;  // the traffic's clock: --traffic draws the others as they were then
        s.position = glm::dvec3(eye, terrainHeight(params, local) + eyeHeight);
        s.heading = std::remainder(kHalfPi - double(p.heading), kTwoPi);
        s.pitch = 0.0;
        path.samples.push_back(s);
    }
    if (path.samples.size() < 2)
        return Status::error("vehicle '" + tracks.agentIds[ego] + "' gives fewer than two samples at --dt");
    return path;
}

}  // namespace vista
