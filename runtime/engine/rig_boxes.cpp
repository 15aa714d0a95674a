// The boxes of a rig run (rig_boxes.h).
#include "runtime/engine/rig_boxes.h"

#include <cmath>
#include <cstdlib>
#include <sstream>

#include <nlohmann/json.hpp>

#include "citygen/labels.h"
#include "foundation/units.h"
#include "runtime/engine/rig_dataset.h"

namespace vista {

namespace {

double round3(double v) { return std::round(v * 1000.0) / 1000.0; }

nlohmann::json vec3Json(const glm::dvec3& v) { return {round3(v.x), round3(v.y), round3(v.z)}; }

nlohmann::json boxJson(const OrientedBox& b, const glm::dvec3& offset, const glm::dvec3& velocity) {
    return {{"center", vec3Json(b.center - offset)},
            {"size", vec3Json(b.size)},
            {"yaw", round3(b.yaw)},
            {"velocity", vec3Json(velocity)}};
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

void addLidarSightings(FrameSightings& s, const std::string& lidar, const LidarSweep& sweep, const CityBoxes& boxes,
                       const std::vector<MovingObject>& movers) {
    uint32_t last = 0;
    BoxSighting* at = nullptr;
    for (const LidarPoint& p : sweep.points) {
        if (p.instance == 0) continue;
        if (p.instance != last || !at) {
            last = p.instance;
            at = boxes.find(p.instance) || findMover(movers, p.instance) ? &s[p.instance] : nullptr;
            if (at) addSensor(*at, lidar);
        }
        if (at) ++at->lidarPoints;
    }
}

namespace {

double wrapTurn(double a) {  // into (-pi, pi]
    while (a > kPi) a -= kTwoPi;
    while (a <= -kPi) a += kTwoPi;
    return a;
}

}  // namespace

std::string kittiRigLabels(const std::vector<FrameBox>& boxes, const RigPose& rectified) {
    // The rectified frame's OpenCV axes (x right, y down, z forward) in the world.
    const glm::dmat3 axes(-rectified.rotation[1], -rectified.rotation[2], rectified.rotation[0]);
    const glm::dmat3 toRect = glm::transpose(axes);
    std::string out;
    char line[512];
    for (const FrameBox& f : boxes) {
        const glm::dvec3 l = toRect * f.box.lengthAxis();
        const double ry = wrapTurn(std::atan2(-l.z, l.x));
        const glm::dvec3 u(std::cos(ry), 0.0, -std::sin(ry)), w(std::sin(ry), 0.0, std::cos(ry));
        glm::dvec3 lo(1e300), hi(-1e300);  // along u, y, w
        for (const glm::dvec3& c : f.box.corners()) {
            const glm::dvec3 p = toRect * (c - rectified.position);
            const glm::dvec3 q(glm::dot(p, u), p.y, glm::dot(p, w));
            lo = glm::min(lo, q), hi = glm::max(hi, q);
        }
        const glm::dvec3 size = hi - lo;  // length, height, width
        const glm::dvec3 mid = 0.5 * (lo + hi);
        const glm::dvec3 loc = u * mid.x + w * mid.z + glm::dvec3(0.0, hi.y, 0.0);  // bottom: largest y
        const double alpha = wrapTurn(ry - std::atan2(loc.x, loc.z));
        const int occluded = f.visibleFraction >= 0.8 ? 0 : f.visibleFraction >= 0.4 ? 1 : 2;
        std::snprintf(line, sizeof line, "%s %.2f %d %.2f %.2f %.2f %.2f %.2f %.3f %.3f %.3f %.3f %.3f %.3f %.3f %u\n",
                      kittiType(f), f.truncated, occluded, alpha, double(f.visibleU0), double(f.visibleV0),
                      double(f.visibleU1), double(f.visibleV1), size.y, size.z, size.x, loc.x, loc.y, loc.z, ry,
                      unsigned(f.id));
        out += line;
    }
    return out;
}

std::string kittiTrackingLines(const std::vector<std::pair<size_t, std::string>>& frameLabels) {
    std::string out;
    for (const auto& [frame, text] : frameLabels) {
        std::istringstream lines(text);
        std::string line;
        while (std::getline(lines, line)) {
            std::istringstream cols(line);
            std::vector<std::string> c;
            for (std::string w; cols >> w;) c.push_back(w);
            if (c.size() != 16) continue;
            char* end = nullptr;
            const unsigned long id = std::strtoul(c[15].c_str(), &end, 10);
            if (end == c[15].c_str() || *end != '\0' || id > 0xFFFFFFFFul) continue;
            const InstanceKind kind = instanceKind(uint32_t(id));
            if (kind != InstanceKind::Vehicle && kind != InstanceKind::Pedestrian) continue;
            // The tracking benchmark's truncation is a level, not the object benchmark's share.
            const double share = std::strtod(c[1].c_str(), nullptr);
            c[1] = share < 0.01 ? "0" : share < 0.5 ? "1" : "2";
            out += std::to_string(frame) + ' ' + std::to_string(instanceIndex(uint32_t(id)));
            for (size_t i = 0; i < 15; ++i) out += ' ' + c[i];
            out += '\n';
        }
    }
    return out;
}

std::string frameBoxes3dJson(const CityBoxes& boxes, const FrameSightings& seen, const RigPose& vehicle,
                             const glm::dvec3& worldOffset, const std::string& frame, double t,
                             const std::vector<MovingObject>& movers) {
    nlohmann::json list = nlohmann::json::array();
    for (const auto& [id, s] : seen) {
        const InstanceBox* ib = boxes.find(id);
        const MovingObject* mo = ib ? nullptr : findMover(movers, id);
        if (!ib && !mo) continue;
        const OrientedBox& box = ib ? ib->box : mo->box;
        const glm::dvec3 v = mo ? mo->velocity : glm::dvec3(0.0);
        nlohmann::json b = {
            {"id", id},
            {"kind", instanceKindName(instanceKind(id))},
            {"index", instanceIndex(id)},
            {"seen_by", s.sensors},
            {"lidar_points", s.lidarPoints},
            {"world", boxJson(box, worldOffset, v)},
            {"vehicle", boxJson(boxInPoseFrame(box, vehicle), glm::dvec3(0.0), glm::transpose(vehicle.rotation) * v)}};
        if (mo) b["class"] = semanticClassName(SemanticClass(mo->semantic));
        list.push_back(std::move(b));
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
