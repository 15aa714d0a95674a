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
// Sightings: per instance with a city box or a moving object's box (boxes.h
// MovingObject, `movers` sorted by id), the sensors that saw it in one
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
// yaw, velocity} and `vehicle` {center, size, yaw, velocity} (boxInPoseFrame
// of the frame's vehicle pose); positions, yaws and velocities rounded to
// 0.001. velocity: the box centre's velocity over the ground in m/s (0 for
// the city's instances; a moving object's MovingObject::velocity), in the
// vehicle's axes under `vehicle` (the same vector, not relative to the
// vehicle's own motion). A moving object also carries `class` (its semantic
// class name).
//
// kittiRigLabels(): KITTI object label lines (one per box, '\n'-terminated)
// in the rig's rectified frame (rig_dataset.h kittiCalib) at `rectified`,
// its world pose (sensorPose of the vehicle and kittiRectifiedMount; x
// forward, y left, z up; its OpenCV axes are (-y, -z, x)): type,
// truncated, occluded (0: visibleFraction >= 0.8, 1: >= 0.4, 2: less),
// alpha (type: boxes.h kittiType of the box), bbox (the visible extent in the labelling camera, inclusive pixel
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
#include <utility>
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
void addLidarSightings(FrameSightings& s, const std::string& lidar, const LidarSweep& sweep, const CityBoxes& boxes,
                       const std::vector<MovingObject>& movers = {});

std::string kittiRigLabels(const std::vector<FrameBox>& boxes, const RigPose& rectified);

// KITTI tracking lines of one camera (the devkit's label_02/NNNN.txt of one
// sequence): from the object lines of each frame that the camera labelled
// (kittiRigLabels text, with the frame's number), every moving agent's line
// (instance kind vehicle or pedestrian, 16th column) as "frame track_id
// type truncated occluded alpha left top right bottom h w l x y z
// rotation_y": track_id = the agent's number (instanceIndex of its id; the
// same agent keeps it in every frame, camera and run of the same traffic),
// truncated the tracking benchmark's level (an integer: 0 when the object
// line's share is below 0.01, 1 below 0.5, else 2), the other columns those
// of the object line; frames in the order given.
// Lines that are not 16 columns are skipped.
std::string kittiTrackingLines(const std::vector<std::pair<size_t, std::string>>& frameLabels);

std::string frameBoxes3dJson(const CityBoxes& boxes, const FrameSightings& seen, const RigPose& vehicle,
                             const glm::dvec3& worldOffset, const std::string& frame, double t,
                             const std::vector<MovingObject>& movers = {});

}  // namespace vista
