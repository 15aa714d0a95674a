// The files of a rig run (`vista render --rig`, docs/formats.md "Sensor
// rigs"): byte encoders of the per-sensor files and the KITTI calibration.
//
// floBytes(): Middlebury .flo (the format of Middlebury, Sintel and
// FlyingChairs, read by OpenCV readOpticalFlow, torchvision and most flow
// code): the float 202021.25 ("PIEH"), int32 width, int32 height, then
// width * height (du, dv) float32 pairs row by row, little-endian.
// velodyneBytes(): KITTI velodyne .bin: float32 x, y, z, intensity per point
// (sensor frame at the point's firing time: x forward, y left, z up).
// lidarLabelBytes(): SemanticKITTI .label layout: one uint32 per point, the
// semantic class (citygen/labels.h) in the lower 16 bits, the upper 16 bits
// 0 (vista's stable instance ids need 32 bits: lidarInstanceBytes()).
// lidarInstanceBytes(): one uint32 per point, the instance id (the encoding
// of the instance images).
// kittiCalib(): KITTI odometry / object calib.txt lines for the rig: "Pk:"
// (3x4 row-major) for every pinhole camera k (its index among the rig's
// cameras), mapping points in the reference camera's OpenCV frame (the
// first pinhole camera) to pixels of camera k: K_k [R | t]; and, when the rig
// has a LiDAR, "Tr_velo_to_cam:" (3x4) from the first LiDAR's frame to the
// reference camera's. Fisheye cameras have no line (no 3x4 projection
// describes them). Empty when the rig has no pinhole camera.
// rigTransform(): the 4x4 row-major matrix of a pose (as JSON-friendly rows).
// Pure; thread-safe.
#pragma once
#include <array>
#include <string>

#include "runtime/engine/lidar.h"
#include "runtime/engine/rig.h"

namespace vista {

std::string floBytes(const float* flow, int width, int height);
std::string velodyneBytes(const LidarSweep& sweep);
std::string lidarLabelBytes(const LidarSweep& sweep);
std::string lidarInstanceBytes(const LidarSweep& sweep);
std::string kittiCalib(const Rig& rig);

using RowMajor4 = std::array<std::array<double, 4>, 4>;
// Maps body coordinates (x forward, y left, z up) to the world minus `offset`.
RowMajor4 poseToWorld(const RigPose& pose, const glm::dvec3& offset);
// A camera's OpenCV frame to the world minus `offset`.
RowMajor4 cameraToWorld(const RigPose& pose, const glm::dvec3& offset);

}  // namespace vista
