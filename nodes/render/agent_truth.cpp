// The ground truth of a traffic run's agents (agent_truth.h).
#include "nodes/render/agent_truth.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "foundation/units.h"

namespace vista {

namespace {

// The box centres of the agents placed at t, by agent number.
std::map<uint32_t, glm::dvec3> centres(const TrafficTracks& tracks, const AgentModels& models, const CityParams& params,
                                       double t) {
    std::map<uint32_t, glm::dvec3> out;
    for (const AgentPlacement& a : placeAgents(tracks, models, params, t)) {
        const double h = models.models[a.prototype].height;
        out[a.agent] = glm::dvec3(a.transform * glm::dvec4(0.0, 0.0, 0.5 * h, 1.0));
    }
    return out;
}

AgentType typeOf(const TrafficTracks& tracks, uint32_t agent) {
    return agent < tracks.agentTypes.size() ? tracks.agentTypes[agent] : AgentType::Car;
}

}  // namespace

std::vector<MovingObject> agentObjects(const TrafficTracks& tracks, const AgentModels& models, const CityParams& params,
                                       double t) {
    const double h = kAgentVelocityStepS;
    const auto before = centres(tracks, models, params, t - h), after = centres(tracks, models, params, t + h);
    std::vector<MovingObject> out;
    for (const AgentPlacement& a : placeAgents(tracks, models, params, t)) {
        const AgentModel& m = models.models[a.prototype];
        const AgentType type = typeOf(tracks, a.agent);
        MovingObject o;
        o.id = agentLabel(type, a.agent);
        o.semantic = agentClass(type);
        o.mesh = &m.mesh;
        o.toWorld = a.transform;
        o.box.center = glm::dvec3(a.transform * glm::dvec4(0.0, 0.0, 0.5 * m.height, 1.0));
        o.box.size = glm::dvec3(m.length, m.width, m.height);
        const glm::dvec3 x(a.transform[0]);
        double yaw = std::atan2(x.y, x.x);
        while (yaw > kHalfPi) yaw -= kPi;
        while (yaw <= -kHalfPi) yaw += kPi;
        o.box.yaw = yaw;
        const auto b = before.find(a.agent), e = after.find(a.agent);
        const bool hasB = b != before.end(), hasE = e != after.end();
        if (hasB && hasE) o.velocity = (e->second - b->second) / (2.0 * h);
        else if (hasE) o.velocity = (e->second - o.box.center) / h;
        else if (hasB) o.velocity = (o.box.center - b->second) / h;
        out.push_back(o);
    }
    std::sort(out.begin(), out.end(), [](const MovingObject& p, const MovingObject& q) { return p.id < q.id; });
    return out;
}

std::vector<ObjectMotion> agentMotions(const TrafficTracks& tracks, const AgentModels& models, const CityParams& params,
                                       double t0, double t1) {
    std::map<uint32_t, glm::dmat4> next;
    for (const AgentPlacement& a : placeAgents(tracks, models, params, t1)) next[a.agent] = a.transform;
    std::vector<ObjectMotion> out;
    for (const AgentPlacement& a : placeAgents(tracks, models, params, t0)) {
        ObjectMotion m;
        m.id = agentLabel(typeOf(tracks, a.agent), a.agent);
        const auto it = next.find(a.agent);
        m.known = it != next.end();
        if (m.known) m.motion = it->second * glm::inverse(a.transform);
        out.push_back(m);
    }
    std::sort(out.begin(), out.end(), [](const ObjectMotion& p, const ObjectMotion& q) { return p.id < q.id; });
    return out;
}

}  // namespace vista
