// The traffic step: a city's OpenDRIVE → netconvert → a SUMO network;
// seeded demand (traffic_demand.h) → sumo headless → floating-car data and
// traffic-light states, kept as files in a traffic directory
// (docs/formats.md "Traffic directory").
//
// Contract:
// - makeTraffic() builds the directory under "<dir>.partial" and renames it
//   to `dir` when every file is written, so `dir` appears whole or not at
//   all; `dir` must not exist (outputs never overwrite), the ".partial"
//   folder of an interrupted run is removed and rebuilt. The files: city.xodr
//   (the input), city.net.xml (netconvert's network, sidewalks and crossings
//   guessed where the city has sidewalks; no lane changes on its junctions'
//   internal lanes, junction_lanes.h; long vehicles kept off tight junction
//   turns, junction_turns.h), demand.rou.xml, traffic.sumocfg
//   (sumo -c traffic.sumocfg in the folder runs it again), fcd.xml (SUMO's
//   FCD: every agent at every step), signals.xml (SUMO's traffic-light
//   states at every switch), collisions.xml (SUMO's collision output: one
//   <collision> per step and pair in contact), traffic.json (the manifest: options, SUMO
//   version, network offset, counts and SUMO's statistics).
// - The same xodr and options give the same bytes: SUMO runs single-threaded
//   with the seed, and the wall-clock dates SUMO writes into its headers are
//   removed (sumo_process.h).
// - SUMO missing or failing is an error naming the program and what it
//   said; the ".partial" folder is removed then. Progress stages: network,
//   demand, simulation.
// - Not thread-safe with another run on the same `dir`.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "foundation/progress.h"
#include "foundation/status.h"
#include "runtime/traffic/traffic_demand.h"

namespace vista {

struct TrafficOptions {
    TrafficDemandOptions demand;
    double stepS = 0.5;  // SUMO's step and the FCD's sample interval, seconds
};

// The <collision> records of SUMO's collision output. SUMO writes one
// record per step in which a pair is in contact, so a contact lasting two
// steps is two events (statistics.xml counts it once).
struct CollisionCounts {
    int events = 0;
    int withPedestrians = 0;  // the victim is a pedestrian (on a crossing or walking area)
    int betweenVehicles = 0;  // every other record (vehicle on vehicle, on a lane or in a junction)
};

// Reads SUMO's collision output (collisions.xml). A missing, truncated or
// malformed file, or one whose root is not <collisions>, is an error naming
// the file and the line. Pure, thread-safe.
Result<CollisionCounts> readCollisions(const std::string& path);

struct TrafficRunSummary {
    TrafficDemandCounts demand;
    int vehiclesInserted = 0, personsInserted = 0;
    int collisions = 0, teleports = 0, emergencyStops = 0;
    CollisionCounts collisionEvents;
    double netOffsetX = 0.0, netOffsetY = 0.0;
    std::string sumoVersion;
    // Per SUMO vehicle class: the junction turns closed to it (junction_turns.h).
    std::vector<std::pair<std::string, size_t>> turnsClosed;
    // Internal lanes widened to their crossing conflict (junction_conflicts.h).
    size_t conflictLanesWidened = 0;
};

// Ranges of the options (checked by checkTrafficOptions, named in messages).
constexpr int kMaxTrafficAgents = 100000;
constexpr double kMaxTrafficDurationS = 24.0 * 3600.0;
constexpr double kMinTrafficStepS = 0.05, kMaxTrafficStepS = 2.0;

// Names the option (--vehicles, --pedestrians, --duration, --step) and its range.
Status checkTrafficOptions(const TrafficOptions& opt);

Status makeTraffic(const std::string& xodrText, const TrafficOptions& opt, const std::string& dir, Progress& progress,
                   TrafficRunSummary* summary);

}  // namespace vista
