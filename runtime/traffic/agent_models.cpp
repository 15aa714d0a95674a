// The moving agents' shapes and placements (agent_models.h).
#include "runtime/traffic/agent_models.h"

#include <algorithm>
#include <cmath>

#include "citygen/labels.h"
#include "citygen/mesh_builder.h"
#include "citygen/parked_cars.h"
#include "citygen/terrain.h"

namespace vista {

namespace {

constexpr glm::dvec3 kSkin{0.62, 0.42, 0.30};
constexpr glm::dvec3 kTrousers{0.08, 0.09, 0.12};
constexpr glm::dvec3 kTyre{0.02, 0.02, 0.02};
constexpr glm::dvec3 kFrame{0.55, 0.05, 0.04};
constexpr glm::dvec3 kCargo{0.80, 0.80, 0.78};
constexpr glm::dvec3 kShirts[] = {{0.55, 0.06, 0.05}, {0.05, 0.18, 0.50}, {0.80, 0.62, 0.10}, {0.10, 0.40, 0.15}};
constexpr int kCarVariants = 8;
constexpr int kPedestrianVariants = 4;

// A convex planar face wound so that its normal points along `out`.
void face(MeshBuilder& b, glm::dvec3 p0, glm::dvec3 p1, glm::dvec3 p2, glm::dvec3 p3, const glm::dvec3& out) {
    if (glm::dot(glm::cross(p1 - p0, p2 - p0), out) < 0) {
        std::swap(p0, p3);
        std::swap(p1, p2);
    }
    b.quad(p0, p1, p2, p3);
}

// A box [x0, x1] x [y0, y1] x [z0, z1] in the model frame, faces outward.
void box(MeshBuilder& b, double x0, double x1, double y0, double y1, double z0, double z1) {
    using V = glm::dvec3;
    face(b, V(x1, y0, z0), V(x1, y1, z0), V(x1, y1, z1), V(x1, y0, z1), V(1, 0, 0));
    face(b, V(x0, y0, z0), V(x0, y1, z0), V(x0, y1, z1), V(x0, y0, z1), V(-1, 0, 0));
    face(b, V(x0, y1, z0), V(x1, y1, z0), V(x1, y1, z1), V(x0, y1, z1), V(0, 1, 0));
    face(b, V(x0, y0, z0), V(x1, y0, z0), V(x1, y0, z1), V(x0, y0, z1), V(0, -1, 0));
    face(b, V(x0, y0, z1), V(x1, y0, z1), V(x1, y1, z1), V(x0, y1, z1), V(0, 0, 1));
    face(b, V(x0, y0, z0), V(x1, y0, z0), V(x1, y1, z0), V(x0, y1, z0), V(0, 0, -1));
}

// The parked cars' shape stretched to a SUMO type's size (van, bus, truck).
CarModel typeModel(AgentType t) {
    const AgentTypeInfo& ti = agentTypeInfo(t);
    const double L = ti.length, H = ti.height, hl = 0.5 * L;
    CarModel m{};
    m.name = ti.id;
    m.length = L;
    m.width = ti.width;
    m.height = H;
    m.clearance = 0.35;
    switch (t) {
        case AgentType::Van:  // a tall box with a short bonnet
            m.belt = 1.10;
            m.cabinFront = hl - 0.75;
            m.roofFront = hl - 1.35;
            m.cabinRear = m.roofRear = -hl + 0.05;
            m.wheelRadius = 0.36;
            break;
        case AgentType::Bus:  // glass all along, a flat front
            m.belt = 1.25;
            m.cabinFront = m.roofFront = hl - 0.05;
            m.cabinRear = m.roofRear = -hl + 0.10;
            m.wheelRadius = 0.50;
            break;
        default:  // truck: a cab in front of a cargo box (vehicleModel adds the box)
            m.height = H - 0.5;
            m.belt = 1.30;
            m.cabinFront = hl - 0.20;
            m.roofFront = hl - 0.45;
            m.cabinRear = m.roofRear = hl - 2.20;
            m.wheelRadius = 0.50;
            break;
    }
    m.wheelBase = L - 2.4 * m.wheelRadius - 1.2;
    return m;
}

AgentModel vehicleModel(AgentType t, const CarModel& m, const glm::dvec3& body, const Lighting& light) {
    AgentModel a;
    a.type = t;
    a.length = m.length;
    a.width = m.width;
    a.height = m.height;
    meshCarShape(m, body, glm::dvec3(0.0), 0.0, glm::dvec3(0.0), light, Material::Vehicle, a.mesh, 0);
    if (t == AgentType::Truck) {
        const AgentTypeInfo& ti = agentTypeInfo(t);
        a.height = ti.height;
        MeshBuilder b(a.mesh, glm::dvec3(0.0), Material::Vehicle, light);
        b.setAlbedo(kCargo);
        const double hl = 0.5 * m.length, hw = 0.5 * m.width - 0.02;
        box(b, -hl + 0.05, m.cabinRear - 0.10, -hw, hw, m.belt, ti.height);
    }
    return a;
}

AgentModel bicycleModel(const Lighting& light) {
    const AgentTypeInfo& ti = agentTypeInfo(AgentType::Bicycle);
    AgentModel a;
    a.type = AgentType::Bicycle;
    a.length = ti.length;
    a.width = ti.width;
    a.height = ti.height;
    MeshBuilder b(a.mesh, glm::dvec3(0.0), Material::Vehicle, light);
    const double hl = 0.5 * ti.length, r = 0.34;
    b.setAlbedo(kTyre);
    for (double x : {hl - r - 0.05, -hl + r + 0.05}) box(b, x - r, x + r, -0.02, 0.02, 0.0, 2 * r);
    b.setAlbedo(kFrame);
    box(b, -hl + r + 0.05, hl - r - 0.05, -0.025, 0.025, 0.50, 0.58);  // top tube
    box(b, -0.10, 0.0, -0.025, 0.025, 0.30, 0.80);                     // seat tube
    box(b, hl - r - 0.12, hl - r - 0.02, -0.30, 0.30, 0.95, 1.00);     // handlebar
    b.setMaterial(Material::Vehicle);                                  // the rider is part of the vehicle (labels.h)
    b.setAlbedo(kTrousers);
    box(b, -0.20, 0.05, -0.14, 0.14, 0.80, 0.95);  // seat and thighs
    box(b, 0.05, 0.18, -0.14, -0.04, 0.25, 0.90);  // legs to the pedals
    box(b, -0.05, 0.08, 0.04, 0.14, 0.25, 0.90);
    b.setAlbedo(kShirts[1]);
    box(b, -0.20, 0.10, -0.18, 0.18, 0.95, 1.45);           // torso, leaning
    box(b, 0.10, hl - r - 0.10, -0.26, -0.18, 1.05, 1.15);  // arms to the bar
    box(b, 0.10, hl - r - 0.10, 0.18, 0.26, 1.05, 1.15);
    b.setAlbedo(kSkin);
    box(b, -0.08, 0.12, -0.10, 0.10, 1.48, 1.70);  // head
    return a;
}

AgentModel walkerModel(int variant, const Lighting& light) {
    const AgentTypeInfo& ti = agentTypeInfo(AgentType::Pedestrian);
    AgentModel a;
    a.type = AgentType::Pedestrian;
    a.length = ti.length;
    a.width = ti.width;
    a.height = ti.height;
    const double H = ti.height, hip = 0.49 * H, shoulder = 0.82 * H, neck = 0.86 * H;
    MeshBuilder b(a.mesh, glm::dvec3(0.0), Material::Pedestrian, light);
    // Legs in a stride: one ahead, one behind.
    b.setAlbedo(kTrousers);
    box(b, 0.02, 0.16, 0.02, 0.14, 0.0, hip);
    box(b, -0.16, -0.02, -0.14, -0.02, 0.0, hip);
    b.setAlbedo(kShirts[variant % 4]);
    box(b, -0.11, 0.11, -0.19, 0.19, hip, shoulder);  // torso
    // Arms swinging against the legs.
    box(b, -0.14, 0.0, 0.19, 0.27, hip + 0.05, shoulder);
    box(b, 0.0, 0.14, -0.27, -0.19, hip + 0.05, shoulder);
    b.setAlbedo(kSkin);
    box(b, -0.10, 0.10, -0.09, 0.09, neck, H);  // head
    return a;
}

}  // namespace

AgentModels agentModels(const Lighting& light) {
    AgentModels out;
    const auto begin = [&](AgentType t) { out.first[int(t)] = uint32_t(out.models.size()); };
    const auto end = [&](AgentType t) { out.count[int(t)] = uint32_t(out.models.size()) - out.first[int(t)]; };
    begin(AgentType::Car);
    for (int v = 0; v < kCarVariants; ++v)
        out.models.push_back(vehicleModel(AgentType::Car, carModels()[size_t(v % kCarModelCount)],
                                          carColour((v * 3) % kCarColourCount), light));
    end(AgentType::Car);
    for (AgentType t : {AgentType::Van, AgentType::Bus, AgentType::Truck}) {
        begin(t);
        for (int v = 0; v < 2; ++v)
            out.models.push_back(vehicleModel(t, typeModel(t), carColour((v * 5 + int(t)) % kCarColourCount), light));
        end(t);
    }
    begin(AgentType::Bicycle);
    out.models.push_back(bicycleModel(light));
    end(AgentType::Bicycle);
    begin(AgentType::Pedestrian);
    for (int v = 0; v < kPedestrianVariants; ++v) out.models.push_back(walkerModel(v, light));
    end(AgentType::Pedestrian);
    return out;
}

uint32_t agentPrototype(const AgentModels& models, AgentType type, uint32_t agent) {
    const int t = int(type);
    return models.first[t] + (models.count[t] ? agent % models.count[t] : 0u);
}

uint32_t agentLabel(AgentType type, uint32_t agent) {
    return makeInstanceId(type == AgentType::Pedestrian ? InstanceKind::Pedestrian : InstanceKind::Vehicle,
                          agent & kInstanceIndexMask);
}

uint8_t agentClass(AgentType type) {
    switch (type) {
        case AgentType::Car: return uint8_t(SemanticClass::Car);
        case AgentType::Van: return uint8_t(SemanticClass::Van);
        case AgentType::Bus: return uint8_t(SemanticClass::Bus);
        case AgentType::Truck: return uint8_t(SemanticClass::Truck);
        case AgentType::Bicycle: return uint8_t(SemanticClass::Bicycle);
        case AgentType::Pedestrian: break;
    }
    return uint8_t(SemanticClass::Pedestrian);
}

std::vector<AgentPlacement> placeAgents(const TrafficTracks& tracks, const AgentModels& models,
                                        const CityParams& params, double t) {
    std::vector<AgentPlacement> out;
    if (tracks.times.empty() || !(t >= tracks.times.front() && t <= tracks.times.back())) return out;
    const size_t f = tracks.frameAt(t);
    const size_t b = tracks.frameStart[f],
                 e = f + 1 < tracks.frameStart.size() ? tracks.frameStart[f + 1] : tracks.poses.size();
    out.reserve(e - b);
    const glm::dvec2 origin(params.origin_x, params.origin_y);
    for (size_t i = b; i < e; ++i) {
        const uint32_t agent = tracks.poses[i].agent;
        AgentPose p;
        if (agent >= tracks.agentTypes.size() || !tracks.poseAt(agent, t, &p)) continue;
        const AgentType type = tracks.agentTypes[agent];
        AgentPlacement a;
        a.agent = agent;
        a.prototype = agentPrototype(models, type, agent);
        const AgentModel& m = models.models[a.prototype];
        const glm::dvec2 dir(std::cos(double(p.heading)), std::sin(double(p.heading)));
        glm::dvec2 c(double(p.x), double(p.y));
        if (type != AgentType::Pedestrian) c -= 0.5 * m.length * dir;
        const double z = terrainHeight(params, c - origin);
        a.centre = glm::dvec3(c, z);
        a.radius = 0.5 * std::sqrt(m.length * m.length + m.width * m.width + 4.0 * m.height * m.height);
        glm::dmat4 x(1.0);
        x[0] = glm::dvec4(dir.x, dir.y, 0.0, 0.0);
        x[1] = glm::dvec4(-dir.y, dir.x, 0.0, 0.0);
        x[3] = glm::dvec4(a.centre, 1.0);
        a.transform = x;
        out.push_back(a);
    }
    return out;
}

}  // namespace vista
