// The shapes of a traffic run's moving agents and where they stand at a time:
// what the near field (nodes/traffic_node.h), the ray-cast far field and the
// label passes draw.
//
// Contract:
// - agentModels(light) gives the prototype meshes, each in its own frame:
//   x forward, y left, z up, the footprint's centre at the origin on the
//   ground (z = 0), counter-clockwise outward faces, prelit with `light`.
//   Vehicles are the parked cars' procedural shape (citygen/parked_cars.h):
//   cars are the four parked-car models in body colours of their palette;
//   vans, buses and trucks the same shape at SUMO's type sizes
//   (agentTypeInfo); a bicycle is a low-poly frame, wheels and rider; a
//   pedestrian a low-poly walker (legs, torso, arms, head) of
//   agentTypeInfo(Pedestrian).height. Vertices of vehicles carry
//   Material::Vehicle, of pedestrians Material::Pedestrian; their ids are 0
//   (the agent's instance id is per placement). Deterministic.
// - agentPrototype(type, agent): the prototype an agent is drawn with (a
//   function of its type and number alone: stable over a run).
// - agentLabel(type, agent): its instance id (citygen/labels.h: kind vehicle
//   or pedestrian, index = the agent's number); agentClass(type) its class
//   (labels.h: car, van, bus, truck, bicycle or pedestrian by type).
// - placeAgents(tracks, models, params, t): every agent present at time t
//   (TrafficTracks::poseAt) with its world transform (model frame -> world):
//   SUMO's reference point is the middle of a vehicle's front bumper and a
//   person's centre, so a vehicle's model centre stands half its model's
//   length behind (x, y) along the heading; z is the terrain height
//   (terrainHeight) at that centre, as the parked cars stand. Sorted by
//   agent number. Empty outside the run's time span.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "citygen/lighting.h"
#include "citygen/mesh.h"
#include "citygen/params.h"
#include "runtime/traffic/traffic_tracks.h"

namespace vista {

struct AgentModel {
    AgentType type = AgentType::Car;
    Mesh mesh;          // model frame (see above)
    double length = 0;  // metres along x (the vehicle's reference point is at +length / 2)
    double width = 0, height = 0;
};

struct AgentModels {
    std::vector<AgentModel> models;
    // First prototype and prototype count of each type (indexed by AgentType).
    uint32_t first[kAgentTypeCount] = {};
    uint32_t count[kAgentTypeCount] = {};
};

AgentModels agentModels(const Lighting& light);
uint32_t agentPrototype(const AgentModels& models, AgentType type, uint32_t agent);
uint32_t agentLabel(AgentType type, uint32_t agent);
uint8_t agentClass(AgentType type);

struct AgentPlacement {
    uint32_t agent = 0;
    uint32_t prototype = 0;
    glm::dmat4 transform{1.0};  // model frame -> world
    glm::dvec3 centre{0.0};     // world centre of the footprint at ground level
    double radius = 0;          // bounding radius around centre (metres)
};

std::vector<AgentPlacement> placeAgents(const TrafficTracks& tracks, const AgentModels& models,
                                        const CityParams& params, double t);

}  // namespace vista
