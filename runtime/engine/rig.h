// A sensor rig (`vista render --rig rig.json`): cameras and rotating LiDARs
// mounted on the vehicle that drives the walkthrough path, each with its own
// rate; the rig file that describes it; and the poses of its sensors.
//
// Frames (metres, radians inside): the vehicle frame is x forward, y left,
// z up, with its origin at the path's sample position (a generated car path:
// 1.2 m above the road) and its axes turned by the sample's heading and
// pitch (as Camera's; the vehicle does not roll). A sensor's mount places
// its own frame (x forward, y left, z up; a camera looks along its x) in the
// vehicle frame: position (x, y, z), then rotation Rz(yaw) Ry(-pitch) Rx(roll):
// yaw turns x toward y (to the left), pitch raises x (nose up), roll turns
// y toward z (the left side up, the right side down). A camera's OpenCV frame
// (x right, y down, z forward) is (-y, -z, x) of its sensor frame.
//
// Firing: the rig frames are the path samples the run renders, in order,
// at the samples' times t_0 < t_1 < ... A sensor with rate r fires at the
// first frame and then at every frame whose time is at least one period
// (1 / r) after its last firing (a tolerance of 1 us absorbs the rounding of
// sample times); without a rate it fires at every frame. A LiDAR firing
// starts a sweep at the frame's time; each column is cast from the pose the
// vehicle has at that column's firing time, the path's samples interpolated
// linearly (position, pitch; heading along the shorter arc) and clamped at
// the path's ends. Its rate defaults to its rotation rate (one sweep per
// revolution).
//
// Rig file (JSON, at most kMaxRigFileBytes, citygen/json_input.h rules:
// no duplicate keys, bounded nesting): {"sensors": [SENSOR, ...]} with 1 ..
// kMaxRigSensors sensors; keys starting with '_' are comments. A SENSOR:
//   "name": 1 .. 32 characters of [A-Za-z0-9_-], unique in the rig;
//   "type": "pinhole" | "fisheye" | "lidar";
//   "pose": {"x", "y", "z": metres in [-100, 100], "yaw_deg": [-360, 360],
//            "pitch_deg": [-90, 90], "roll_deg": [-180, 180]} (each optional, 0);
//   "rate_hz": (0, 1000] (optional, see Firing);
// cameras: "intrinsics": {"width", "height": 1 .. 8192, "fx", "fy": (0, 1e6]
//   pixels and at least minFocalLength() (a field-of-view limit, below),
//   "cx": [0, width], "cy": [0, height], fisheye also "max_fov_deg":
//   (0, 360]} and "channels": a non-empty list of "rgb", "depth", "semantic",
//   "instance", "flow", "boxes" (no repeats; boxes: runtime/engine/rig_boxes.h);
// LiDARs (LidarSpec): "beams": a list of 1 .. 256 elevations in [-90, 90]
//   degrees, or {"count": 1 .. 256, "min_deg", "max_deg": [-90, 90], min <=
//   max} (evenBeamTable); "columns": 1 .. 65536 (beams x columns at most
//   kMaxLidarRays); "min_range_m": [0, 10000), "max_range_m": (min_range_m,
//   10000]; "rotation_hz": (0, 100]; "start_azimuth_deg": [-360, 360];
//   "clockwise": true | false. Only "beams" is required; the others default
//   to LidarSpec's values.
// Every error names the source, the field as a path ("sensors[2].intrinsics.fx"),
// the value as written and the allowed range or values; unknown keys are
// refused with the known ones listed. Pure; thread-safe.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "foundation/status.h"
#include "runtime/engine/lidar.h"
#include "runtime/scene/camera_model.h"
#include "runtime/scene/paths.h"

namespace vista {

constexpr uint64_t kMaxRigFileBytes = uint64_t(1) << 20;  // 1 MiB
constexpr int kMaxRigSensors = 64;
constexpr size_t kMaxLidarRays = size_t(1) << 22;  // beams x columns of one sweep
constexpr double kMaxFocalLength = 1e6;            // pixels
// The widest field of view a pinhole rig camera may span across its width or
// height (the limit of --fov): near 180 degrees a pinhole image stretches
// without bound, and a focal length like 1e-300 sends every pixel's ray 90
// degrees off the axis (depth along the axis 0, or +inf after division).
constexpr double kMaxRigPinholeFovDeg = 179.0;
// The smallest focal length (pixels) along x (fx, width, cx) or y (fy, height,
// cy) of camera `m` with its size and principal point: the image's farthest
// edge from the principal point, e = max(c + 0.5, size - 0.5 - c), divided by
// tan(kMaxRigPinholeFovDeg / 2) for a pinhole (each side of the principal
// point then spans at most half of kMaxRigPinholeFovDeg) and by pi for an equidistant
// fisheye (its edge at most 180 degrees off the axis: straight behind).
double minFocalLength(const CameraModel& m, bool x);

// Channels a rig camera writes (bit set).
enum RigChannel : unsigned {
    kRigRgb = 1,
    kRigDepth = 2,
    kRigSemantic = 4,
    kRigInstance = 8,
    kRigFlow = 16,
    kRigBoxes = 32
};
// "rgb,depth,..." in the order above.
std::string rigChannelList(unsigned channels);

struct SensorMount {
    glm::dvec3 position{0.0};                      // vehicle frame, metres
    double yawDeg = 0, pitchDeg = 0, rollDeg = 0;  // degrees
};

struct RigCamera {
    std::string name;
    SensorMount mount;
    double rateHz = 0;  // 0 = every frame
    CameraModel model;
    unsigned channels = 0;  // RigChannel bits, never 0
};

struct RigLidar {
    std::string name;
    SensorMount mount;
    double rateHz = 0;  // sweeps per second (0: spec.rotationHz)
    LidarSpec spec;
};

// Cameras and LiDARs in the order of the rig file within each kind; `order`
// lists every sensor's name in file order.
struct Rig {
    std::vector<RigCamera> cameras;
    std::vector<RigLidar> lidars;
    std::vector<std::string> order;
};

Result<Rig> parseRigJson(const std::string& text, const std::string& source);
Result<Rig> loadRigFile(const std::string& path);  // readInputFile("rig file", path, kMaxRigFileBytes)
// The rig in a canonical JSON form (every field, defaults filled in): the
// manifest of a run and its resume check.
std::string rigToJson(const Rig& rig);

// A rigid pose: `position` (world metres) and `rotation` whose columns are
// the body's x (forward), y (left), z (up) axes in the world.
struct RigPose {
    glm::dvec3 position{0.0};
    glm::dmat3 rotation{1.0};
};
// The mount's rotation (columns: the sensor's axes in the vehicle frame).
glm::dmat3 mountRotation(const SensorMount& mount);
// The vehicle's pose at path sample i, and at time t (interpolated, clamped).
RigPose vehiclePose(const PathSample& sample);
RigPose vehiclePoseAt(const Path& path, double t);
// The sensor's world pose on a vehicle at `vehicle`.
RigPose sensorPose(const RigPose& vehicle, const SensorMount& mount);
// The same pose as LiDAR heading / pitch / roll (lidar.h); exact unless the
// sensor's x points straight up or down.
LidarPose lidarPoseOf(const RigPose& pose);

// Per frame: 1 where a sensor of rate `rateHz` (0 = every frame) fires, given
// the frames' times (non-decreasing); see Firing above.
std::vector<uint8_t> firingFrames(double rateHz, const std::vector<double>& frameTimes);
// The time a camera's flow at frame f looks ahead to: its next firing at a
// later time (`fires` = firingFrames()), else, after its last firing, one
// period after frame f (rate 0: `sampleAfter`, the time of the path sample
// after frame f's).
double nextFiringTime(double rateHz, const std::vector<uint8_t>& fires, const std::vector<double>& frameTimes, size_t f,
                      double sampleAfter);

}  // namespace vista
