// Walkthrough paths: deterministic drives along the street graph, and their
// CSV form.
//
// A path is a list of samples at a fixed time step (PathOptions::dt): time
// (s), eye position (world metres: city frame + params.origin), heading
// (radians clockwise from north, as Camera) and pitch (radians).
// Walk and fly: the vehicle follows a route of street-graph edges chosen by a
// seeded random walk (vista::Rng(seed, 0, Stream::Paths); U-turns only at
// dead ends, straight continuations preferred), steering with pure pursuit of
// a point ahead on the route centre line.
// Car: the vehicle drives in lanes of the lane model (citygen/lanes.h, built
// with the blocks of the street graph, extractBlocks, as `vista gen --xodr`
// builds it): its route is a LaneRoute (lane_route.h: street lanes, the
// junctions' connecting roads and the transitions between them, U-turns at
// dead ends into the opposite lane; right-hand traffic, or the lanes driven
// mirrored with PathOptions::leftHandTraffic), and it steers along the lane
// centre (the centre line's curvature as feed-forward, the lateral and
// heading error as feedback). Its speed stays below kCarYawShare of the yaw
// rate limit divided by the curvature ahead, braking in time; each sample
// carries the OpenDRIVE position of the eye (Path::lanes). Where the lanes
// form no network a car can keep driving (LaneRoute::create fails), the car
// follows the street centre lines as walk does and carries no positions.
// Limits hold at every step by construction:
// |speed| <= maxSpeed, |heading change| <= maxYawRate * dt, |dv| <= accel * dt
// (speeding up) and decel * dt (braking); the vehicle slows before turns so
// that it stays on the carriageway (the car: in its lane).
// The vehicle starts at rest at the route's first node (the car: at the
// start of its first lane); the first PathOptions::runUp seconds are
// simulated and dropped, so that the returned path starts at cruising speed
// (measurements must not be flattered by a slow start, where frame-to-frame
// coherence is highest).
// Eye height above the terrain: walk 1.7 m, car 1.2 m, fly flyHeight (the
// elevated fly-over where occlusion is weak; pitched down by flyPitch).
// Output depends only on (graph, params, options): no threads, no clocks.
//
// CSV: header `t_s,x_m,y_m,z_m,heading_deg,pitch_deg`, one sample per line
// (degrees at this user interface). loadPathCsv rejects missing files,
// malformed lines, non-finite values and non-increasing time with a message
// naming the line. savePathCsv writes atomically.
// Lane positions CSV (car paths): header `t_s,road_id,lane_id,s_m,t_offset_m`,
// one line per sample: the OpenDRIVE road and lane the car drives in, s along
// that road's reference line and the lateral offset of the eye's xy from the
// lane centre (left of the road's reference line positive, whatever the
// direction of travel), so that evaluating the .xodr at (road, lane, s,
// t_offset) gives the sample's x, y. saveLanePositionsCsv writes atomically.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "citygen/params.h"
#include "foundation/number_text.h"
#include "foundation/status.h"
#include "citygen/street_graph.h"
#include "runtime/scene/camera.h"
#include "runtime/scene/lane_route.h"

namespace vista {

enum class PathKind { Walk, Car, Fly };
const char* pathKindName(PathKind k);
Result<PathKind> parsePathKind(const std::string& s);  // "walk" | "car" | "fly"
const char* routeStyleName(RouteStyle s);
Result<RouteStyle> parseRouteStyle(const std::string& s);  // "tour" | "wander"
// The kind's pace when the user gives none: walk 1.4 m/s (a walker), car and
// fly 14 m/s (about 50 km/h).
double defaultSpeed(PathKind k);

struct PathOptions {
    uint64_t seed = 1;
    PathKind kind = PathKind::Car;
    double duration = 60.0;                  // seconds, > 0
    double dt = 1.0 / 30.0;                  // seconds between samples, > 0
    double maxSpeed = 14.0;                  // m/s, > 0 (programs set defaultSpeed(kind))
    double maxYawRate = 0.7853981633974483;  // rad/s (45 deg/s), > 0
    double accel = 2.5;                      // m/s^2 speeding up
    double decel = 4.0;                      // m/s^2 braking
    double flyHeight = 80.0;                 // metres above the terrain (Fly)
    double flyPitch = -0.2;                  // radians (Fly)
    // Seconds driven before t = 0 and dropped, so that a measured path starts
    // at cruising speed instead of at rest (0 = start at rest), 0 .. 600.
    double runUp = 8.0;
    // Car: left-hand traffic, every lane driven against its right-hand
    // direction (lane_route.h; the lane model itself is right-hand traffic).
    bool leftHandTraffic = false;
    // How the route chooses its turns (lane_route.h, tour.h): Tour heads for
    // far goals along shortest paths, so a long drive keeps going across the
    // city; Wander is a seeded random walk that prefers going straight on.
    RouteStyle route = RouteStyle::Tour;
    double eyeHeight() const { return kind == PathKind::Walk ? 1.7 : kind == PathKind::Car ? 1.2 : flyHeight; }
};
// The ranges of the path options (validatePathOptions; `vista path`, bench,
// render and view read their flags within them): seconds, m/s, metres, and
// the yaw rate and fly pitch in degrees (their flags' unit).
namespace path_range {
constexpr RealRange duration = RealRange::openMin(0, 86400), dt = RealRange::openMin(0, 10),
                    speed = RealRange::openMin(0, 1000), yawRateDeg = RealRange::openMin(0, 720),
                    flyHeight = RealRange::open(0, 10000), flyPitchDeg = RealRange::open(-90, 90),
                    runUp = RealRange::closed(0, 600);
}  // namespace path_range
// Checks ranges; message names the option.
Status validatePathOptions(const PathOptions& o);

struct PathSample {
    double t = 0;
    glm::dvec3 position{0.0};  // world metres
    double heading = 0;        // radians
    double pitch = 0;          // radians
};

// Share of the yaw-rate limit a car's speed leaves to the lane's curvature
// (the rest corrects lateral and heading errors).
constexpr double kCarYawShare = 0.7;

struct Path {
    std::vector<PathSample> samples;
    // Car paths from generatePath: the OpenDRIVE position of each sample's eye
    // (lane_route.h); empty for other kinds and for paths read from a CSV.
    std::vector<LanePosition> lanes;
    // Why `lanes` is empty, for messages: a walk or fly path, a car path whose
    // lanes cannot be driven (the reason; it then follows the street centre
    // lines), or a path read from a CSV.
    std::string lanesMissing = "a path read from a CSV carries no lane positions";
    // Camera at sample i: eye/heading/pitch and time from the sample, the rest (fov,
    // size, zNear) from `base`.
    Camera camera(size_t i, const Camera& base) const;
    // Indices of n samples spread evenly over the whole path (first and last
    // included; repeats when n exceeds the sample count).
    std::vector<size_t> spread(size_t n) const;
    // Indices of n samples in `runs` runs of consecutive samples (the frames a
    // simulator renders), the runs' starts spread evenly over the path (first
    // run at 0, last ending at the last sample when the path is long enough);
    // runs = 1: the first n samples. Run lengths differ by at most one; runs
    // is clamped to 1 .. n; repeats the last sample when n exceeds the count.
    std::vector<size_t> runs(size_t n, size_t runs) const;
    // The frames a bench renders: spread(n) when runs == 0, else runs(n, runs).
    std::vector<size_t> frames(size_t n, int runs) const { return runs <= 0 ? spread(n) : this->runs(n, size_t(runs)); }
};
// How `vista bench` samples its frames (--sampling): 0 = spread evenly over
// the path, k >= 1 = k runs of consecutive samples.
constexpr int kDefaultSampleRuns = 8;

// How far the camera moves between consecutive rendered frames (the samples
// `frames`, in order): metres of eye travel and degrees of view rotation
// (heading and pitch combined), median and maximum. All 0 for < 2 frames.
// Measurements report it beside their figures: a cache or an impostor is
// only as good as the motion it was measured under.
struct PathMotion {
    size_t frames = 0;
    double metresMedian = 0, metresMax = 0;
    double degreesMedian = 0, degreesMax = 0;
};
PathMotion pathMotion(const Path& path, const std::vector<size_t>& frames);

// Generates a drive. Errors: invalid options, a graph without edges.
Result<Path> generatePath(const StreetGraph& streets, const CityParams& params, const PathOptions& options);

Status savePathCsv(const Path& path, const std::string& file);
// Errors: the path has no lane positions (the message gives
// Path::lanesMissing and names no file: `file` may be a staged name); I/O.
Status saveLanePositionsCsv(const Path& path, const std::string& file);
Result<Path> loadPathCsv(const std::string& file);

// Distance (metres, 2D) from city-frame point p to the nearest street centre
// line, and that edge's index (for tests and diagnostics). -1 if no edges.
double distanceToStreets(const StreetGraph& streets, const glm::dvec2& p, int* edge = nullptr);

}  // namespace vista
