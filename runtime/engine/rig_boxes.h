// The boxes of a rig run (`vista render --rig`, a camera with the channel
// "boxes"; docs/formats.md "Sensor rigs"): a rig camera as the boxes see it,
// the 3D boxes of one rig frame in the world and in the vehicle frame, and
// the file that lists them.
//
// rigBoxCamera(): the camera at `pose` (rig.h: columns x forward, y left,
// z up; its OpenCV frame is (-y, -z, x) of them) with the model's
// intrinsics (boxes.h BoxCamera). Rig cameras cast from their centre with
// no near plane; a pinhole's box near plane is kRigBoxNearM, so geometry
// closer than that to the image plane does not widen a full extent.
//
// boxInPoseFrame(): a world box in the frame of `pose` (x forward, y left,
// z up): the centre is R^T (c - p) exactly, the size unchanged, the yaw that
// of the length axis projected onto the frame's xy plane, in (-pi/2, pi/2]
// (exact when the frame is level; the box is upright in the world), as
// boxInVehicleFrame does for a LidarPose.
//
// Sightings: per instance with a city box, the sensors that saw it in one
// rig frame (a camera: the instance has an entry in its 2D boxes; a LiDAR:
// at least one of its points hit the instance), cameras first and then
// LiDARs as they were added, and its LiDAR points summed over the frame's
// sweeps.
//
// frameBoxes3dJson(): the frame's file boxes_3d/NNNNNN.json: format
// "vista.boxes_3d", version 1, `frame` (its name), `t_s` (the path time),
// `world_offset`, `vehicle_to_world` (4x4 row-major, world minus the
// offset), and per seen instance (sorted by id) `id`, `kind`, `index`,
// `seen_by`, `lidar_points`, `world` {center (minus world_offset), size,
// yaw} and `vehicle` {center, size, yaw} (boxInPoseFrame of the frame's
// vehicle pose); positions and yaws rounded to 0.001.
//
// kittiRigLabels(): KITTI object label lines (one per box, '\n'-terminated)
// in the rig's rectified frame (rig_dataset.h kittiCalib) at `rectified`,
// its world pose (sensorPose of the vehicle and kittiRectifiedMount; x
// forward, y left, z up; its OpenCV axes are (-y, -z, x)): type,
// truncated, occluded (0: visibleFraction >= 0.8, 1: >= 0.4, 2: less),
// alpha, bbox (the visible extent in the labelling camera, inclusive pixel
// indices), dimensions (height, width, length), location (bottom centre),
// rotation_y, then a 16th column: the instance id (labels.h, the id of the
// instance images and lidar_instance/). The box is the smallest one upright
// in the rectified frame (rotated about its y axis only), with rotation_y =
// the world box's length axis projected onto the frame's x-z plane, that
// contains the world box's 8 corners: the world box itself when the vehicle
// is level (the rectified frame's y is the world's -z), a box enclosing it
// otherwise. rotation_y = atan2(-l.z, l.x) of the length axis l, as the
// KITTI devkit builds corners (length along x rotated by rotation_y);
// alpha = rotation_y - atan2(x, z) of the location, in (-pi, pi].
// Pure; thread-safe for distinct outputs.
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "runtime/engine/boxes.h"
#include "runtime/engine/lidar.h"
#include "runtime/engine/rig.h"

namespace vista {

constexpr double kRigBoxNearM = 1e-3;

BoxCamera rigBoxCamera(const CameraModel& model, const RigPose& pose);
OrientedBox boxInPoseFrame(const OrientedBox& world, const RigPose& pose);

struct BoxSighting {
    std::vector<std::string> sensors;
    uint64_t lidarPoints = 0;
};
using FrameSightings = std::map<uint32_t, BoxSighting>;  // by instance id

void addCameraSightings(FrameSightings& s, const std::string& camera, const std::vector<FrameBox>& boxes);
void addLidarSightings(FrameSightings& s, const std::string& lidar, const LidarSweep& sweep, const CityBoxes& boxes);

std::string kittiRigLabels(const std::vector<FrameBox>& boxes, const RigPose& rectified);

std::string frameBoxes3dJson(const CityBoxes& boxes, const FrameSightings& seen, const RigPose& vehicle,
                             const glm::dvec3& worldOffset, const std::string& frame, double t);

}  // namespace vista
