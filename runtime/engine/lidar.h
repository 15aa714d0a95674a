// A rotating LiDAR ray-cast into a city RayScene: one sweep (a revolution)
// of a spinning multi-beam sensor, every point cast from the pose the
// sensor has at that point's firing time, as a real spinning LiDAR on a
// moving vehicle sees the world (the sweep is not motion-compensated).
//
// Contract:
// - Sensor frame (KITTI's velodyne frame): x forward, y left, z up, metres.
//   Beam b fires at elevation elevationDeg[b] (above the sensor's xy plane).
//   Column c of `columns` per revolution fires at time
//   t0 + c / (columns * rotationHz) at azimuth startAzimuthDeg -/+ c * 360 /
//   columns (degrees from x toward y, i.e. counter-clockwise seen from above;
//   `clockwise` spins the other way, as most sensors do seen from above).
// - Pose: the sensor's world pose at time t (position and heading / pitch /
//   roll as Camera's: heading clockwise from north +y, pitch up, roll right),
//   given by the caller; sensor x is the pose's forward, y its left, z its up.
// - A ray hits the first surface within (0, maxRange]; a hit nearer than
//   minRange is dropped (the sensor's blind zone). Back faces are culled as
//   in the ray scene. Misses and dropped hits are counted, not written.
// - Each point: the hit in the sensor frame at its firing time, its range,
//   the firing time since t0, the beam, the ground-truth label of the hit
//   (ground_truth.h rayLabel: semantic class and instance id), and an
//   intensity = lidarReflectivity(class) * |cos incidence| in [0, 1].
// - Points are in firing order (column by column, beams in table order).
//   Parallel over `threads` workers (0 = all); deterministic.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "foundation/status.h"
#include "runtime/scene/scene_model.h"

namespace vista {

class RayScene;

struct LidarSpec {
    std::vector<double> elevationDeg;  // beam table: 1 .. kMaxLidarBeams beams, each in [-90, 90]
    int columns = 1024;                // firings per revolution, 1 .. 65536
    double minRange = 0.5;             // metres, >= 0
    double maxRange = 120.0;           // metres, > minRange, <= 10000
    double rotationHz = 10.0;          // revolutions per second, (0, 100]
    double startAzimuthDeg = 180.0;    // azimuth of the first column (180: starts facing backwards)
    bool clockwise = true;             // spin direction seen from above
};
constexpr int kMaxLidarBeams = 256;

// Checks the ranges above; the message names the field and its range.
Status validateLidarSpec(const LidarSpec& spec);
// `beams` beams spread evenly from lowDeg to highDeg (both included; one beam: lowDeg).
std::vector<double> evenBeamTable(int beams, double lowDeg, double highDeg);

struct LidarPose {
    glm::dvec3 position{0.0};                 // world metres
    double heading = 0, pitch = 0, roll = 0;  // radians, as Camera
};
using LidarPoseAt = std::function<LidarPose(double t)>;

struct LidarPoint {
    glm::vec3 sensor{0.0f};  // x forward, y left, z up at the firing time
    float range = 0;         // metres
    float intensity = 0;     // 0 .. 1
    float time = 0;          // seconds since the sweep's start
    uint16_t beam = 0;
    uint8_t semantic = 0;   // SemanticClass
    uint32_t instance = 0;  // ground-truth instance id (labels.h), 0 = none
};

struct LidarSweep {
    std::vector<LidarPoint> points;
    size_t rays = 0;    // beams * columns
    size_t misses = 0;  // no surface within maxRange, or nearer than minRange
};

// Share of the beam a surface of this semantic class returns at normal
// incidence (0 .. 1): retro-reflective signs and lane paint high, glass and
// asphalt low (the table is in lidar.cpp).
float lidarReflectivity(uint8_t semanticClass);

// Rotation of the sensor frame (x forward, y left, z up) into the world for a pose.
glm::dmat3 lidarToWorld(const LidarPose& pose);

LidarSweep castLidarSweep(const SceneModel& city, const RayScene& rays, const LidarSpec& spec,
                          const LidarPoseAt& poseAt, double t0, int threads = 0);

// Moving objects seen where they are when each column fires: the sweep's
// columns are cast in time slices of at most `stepS` seconds (at least one
// column each), and before each slice place(t) moves the ray scene's
// moving objects to time t, the slice's middle column time (t0-based, as
// poseAt). An object moving at speed v is then seen within v * stepS / 2 of
// where it is at its points' firing times. place() runs on the calling
// thread between slices (no ray query meanwhile); its error ends the sweep
// and is returned. No place(): the sweep of the function above.
struct LidarMovers {
    std::function<Status(double t)> place;
    double stepS = 0.001;  // seconds, > 0
};
Result<LidarSweep> castLidarSweep(const SceneModel& city, const RayScene& rays, const LidarSpec& spec,
                                  const LidarPoseAt& poseAt, double t0, const LidarMovers& movers, int threads = 0);

}  // namespace vista
