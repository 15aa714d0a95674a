// The files of a rig run (`vista render --rig`, docs/formats.md "Sensor
// rigs"): byte encoders of the per-sensor files and the KITTI calibration.
//
// floBytes(): Middlebury .flo (the format of Middlebury, Sintel and
// FlyingChairs, read by OpenCV readOpticalFlow, torchvision and most flow
// code): the float 202021.25 ("PIEH"), int32 width, int32 height, then
// width * height (du, dv) float32 pairs row by row, little-endian.
// velodyneBytes(): KITTI velodyne .bin: float32 x, y, z, intensity per point
// (sensor frame at the point's firing time: x forward, y left, z up).
// semanticKittiLabelBytes(): SemanticKITTI .label: one uint32 per point,
// the SemanticKITTI class id of the point's class (semanticKittiClass) in
// the lower 16 bits and, for an object instance (boxes.h isObjectKind), its
// SemanticKITTI instance id (semanticKittiInstance) in the upper 16 bits;
// surfaces (roads, junctions, sidewalks, parks, ground) carry 0 there, as
// SemanticKITTI's "stuff" classes do.
// vistaLabelBytes(): one uint32 per point, vista's semantic class
// (citygen/labels.h) in the lower 16 bits, the upper 16 bits 0.
// lidarInstanceBytes(): one uint32 per point, the instance id (the encoding
// of the instance images).
// lidarTimeBytes(): one float32 per point, seconds since the sweep's start
// (the rig frame's time in times.txt): the instant the point's column fired.
// semanticKittiClass(): the SemanticKITTI id (semantic-kitti.yaml of the
// SemanticKITTI API) of a vista class: sky 0 (unlabeled), terrain and grass
// 72 (terrain), road 40, lane marking 60, sidewalk 48, building wall,
// window and roof 50 (building), tree trunk 71 (trunk), leaves 70
// (vegetation), street light and traffic light 80 (pole: the class of
// lamp posts and signal poles), traffic sign 81, car and van 10 (SemanticKITTI's
// car includes vans), bus 13, truck 18, vehicle 20 (other-vehicle),
// pedestrian 30 (person), bicycle 31 (bicyclist: vista's bicycle carries its
// rider); 0 out of range. Moving agents keep these static ids (SemanticKITTI's
// single-scan classes; the moving-* ids are not written).
// semanticKittiInstance(): ((11 index + kind) mod 65535) + 1 of an object
// instance id (labels.h), 0 for a surface or no instance: stable across
// frames and runs, and distinct for distinct instances whose indices are
// below 5957 (11 index + kind < 65535); beyond that two instances share it
// only when 11 (index difference) + (kind difference) is a multiple of
// 65535 (lidar_instance/ has the exact 32-bit ids).
// semanticKittiYaml(): the mapping file written beside labels/: the
// SemanticKITTI config keys `labels` (id -> name), `color_map` (id -> BGR)
// for the ids vista writes, and `vista_to_semantic_kitti` (vista class id
// -> SemanticKITTI id) with `vista_classes` (vista id -> name).
//
// KITTI calibration of a rig (kittiCalib, docs/formats.md "Sensor rigs"):
// the reference camera is the rig's camera 0 (any model); the rectified
// frame is that camera levelled in the vehicle frame: its mount with pitch
// and roll 0 (same position and yaw), OpenCV axes (x right, y down along
// the vehicle's -z, z forward). Lines, in mmdetection3d's line order:
// "P0:" .. "P3:" (3x4) map the rectified frame to camera k's pixels,
// K_k [R_k | t_k] (a fisheye: its fx, fy, cx, cy as a pinhole, exact on
// the optical axis only; a camera index the rig lacks: all zeros);
// "R0_rect:" (3x3) the reference camera's frame to the rectified frame;
// "Tr_velo_to_cam:" (3x4) the first LiDAR's frame to the reference
// camera's (no LiDAR: the vehicle frame's); "Tr_imu_to_velo:" (3x4) the
// vehicle frame (standing in for KITTI's IMU) to the first LiDAR's
// (identity without a LiDAR); then "P4:", ... for cameras beyond four and
// "Tr_velo_j_to_cam:" for LiDAR j >= 1. So P_k R0_rect Tr_velo_to_cam X is
// the pixel of a LiDAR point X in pinhole camera k, as pykitti and
// mmdetection3d compute it. Empty when the rig has no camera.
// kittiRectifiedMount(): the rectified frame's mount (see above); the rig
// must have a camera (VISTA_CHECK).
// rigTransform(): the 4x4 row-major matrix of a pose (as JSON-friendly rows).
// Pure; thread-safe.
#pragma once
#include <array>
#include <cstdint>
#include <string>

#include "runtime/engine/lidar.h"
#include "runtime/engine/rig.h"

namespace vista {

std::string floBytes(const float* flow, int width, int height);
std::string velodyneBytes(const LidarSweep& sweep);
std::string semanticKittiLabelBytes(const LidarSweep& sweep);
std::string vistaLabelBytes(const LidarSweep& sweep);
std::string lidarInstanceBytes(const LidarSweep& sweep);
std::string lidarTimeBytes(const LidarSweep& sweep);
uint16_t semanticKittiClass(uint8_t vistaClass);
uint16_t semanticKittiInstance(uint32_t instanceId);
std::string semanticKittiYaml();
std::string kittiCalib(const Rig& rig);
SensorMount kittiRectifiedMount(const Rig& rig);

using RowMajor4 = std::array<std::array<double, 4>, 4>;
// Maps body coordinates (x forward, y left, z up) to the world minus `offset`.
RowMajor4 poseToWorld(const RigPose& pose, const glm::dvec3& offset);
// A camera's OpenCV frame to the world minus `offset`.
RowMajor4 cameraToWorld(const RigPose& pose, const glm::dvec3& offset);

}  // namespace vista
