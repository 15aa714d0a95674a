// The boxes of a rig run (rig_boxes.h).
#include "runtime/engine/rig_boxes.h"

#include <cmath>

#include <nlohmann/json.hpp>

#include "citygen/labels.h"
#include "foundation/units.h"
#include "runtime/engine/rig_dataset.h"

namespace vista {

namespace {

double round3(double v) { return std::round(v * 1000.0) / 1000.0; }

nlohmann::json vec3Json(const glm::dvec3& v) { return {round3(v.x), round3(v.y), round3(v.z)}; }

nlohmann::json boxJson(const OrientedBox& b, const glm::dvec3& offset) {
    return {{"center", vec3Json(b.center - offset)}, {"size", vec3Json(b.size)}, {"yaw", round3(b.yaw)}};
}

void addSensor(BoxSighting& s, const std::string& sensor) {
    if (s.sensors.empty() || s.sensors.back() != sensor) s.sensors.push_back(sensor);
}

}  // namespace

BoxCamera rigBoxCamera(const CameraModel& model, const RigPose& pose) {
    BoxCamera c;
    c.eye = pose.position;
    // The OpenCV axes (x right, y down, z forward) are -y, -z and x of the sensor frame.
    c.axes = glm::dmat3(-pose.rotation[1], -pose.rotation[2], pose.rotation[0]);
    c.model = model;
    c.zNear = kRigBoxNearM;
    return c;
}

OrientedBox boxInPoseFrame(const OrientedBox& world, const RigPose& pose) {
    const glm::dmat3 toBody = glm::transpose(pose.rotation);
    const glm::dvec3 axis = toBody * world.lengthAxis();
    OrientedBox b = world;
    b.center = toBody * (world.center - pose.position);
    double yaw = std::atan2(axis.y, axis.x);
    while (yaw > kHalfPi) yaw -= kPi;
    while (yaw <= -kHalfPi) yaw += kPi;
    b.yaw = yaw;
    return b;
}

void addCameraSightings(FrameSightings& s, const std::string& camera, const std::vector<FrameBox>& boxes) {
    for (const FrameBox& f : boxes) addSensor(s[f.id], camera);
}

void addLidarSightings(FrameSightings& s, const std::string& lidar, const LidarSweep& sweep, const CityBoxes& boxes) {
    uint32_t last = 0;
    BoxSighting* at = nullptr;
    for (const LidarPoint& p : sweep.points) {
        if (p.instance == 0) continue;
        if (p.instance != last || !at) {
            last = p.instance;
            at = boxes.find(p.instance) ? &s[p.instance] : nullptr;
            if (at) addSensor(*at, lidar);
        }
        if (at) ++at->lidarPoints;
    }
}

std::string frameBoxes3dJson(const CityBoxes& boxes, const FrameSightings& seen, const RigPose& vehicle,
                             const glm::dvec3& worldOffset, const std::string& frame, double t) {
    nlohmann::json list = nlohmann::json::array();
    for (const auto& [id, s] : seen) {
        const InstanceBox* ib = boxes.find(id);
        if (!ib) continue;
        list.push_back({{"id", id},
                        {"kind", instanceKindName(instanceKind(id))},
                        {"index", instanceIndex(id)},
                        {"seen_by", s.sensors},
                        {"lidar_points", s.lidarPoints},
                        {"world", boxJson(ib->box, worldOffset)},
                        {"vehicle", boxJson(boxInPoseFrame(ib->box, vehicle), glm::dvec3(0.0))}});
    }
    nlohmann::json m = nlohmann::json::array();
    for (const auto& row : poseToWorld(vehicle, worldOffset)) m.push_back({row[0], row[1], row[2], row[3]});
    const nlohmann::json doc = {{"format", "vista.boxes_3d"},
                                {"version", 1},
                                {"frame", frame},
                                {"t_s", t},
                                {"world_offset", {worldOffset.x, worldOffset.y, worldOffset.z}},
                                {"vehicle_to_world", m},
                                {"boxes", list}};
    return doc.dump(1) + "\n";
}

}  // namespace vista
