// Seeded traffic demand for SUMO: trips of vehicles of several types and
// walks of pedestrians over a SUMO network (sumo_net.h), as a SUMO routes
// file that `sumo` routes itself.
//
// Contract:
// - Agent types (agentTypeInfo): car, van, bus, truck, bicycle (SUMO classes
//   passenger, delivery, bus, truck, bicycle) and pedestrian, with the
//   dimensions vista draws them at. Vehicles are drawn from kDefaultMix; a
//   type whose class has no connected network, or one with fewer trip edges
//   than kMinNetworkShare of the cars' (long vehicles kept off a town's tight
//   junction turns, junction_turns.h), is replaced by a car (counted in
//   TrafficDemandCounts::substituted).
// - Every trip starts and ends on normal edges at least kMinTripEdgeM long
//   that lie in the largest strongly connected part of the network for its
//   class (through the junctions' connections whose internal lane allows it) (pedestrians: the largest connected part
//   of the walkable network, sidewalks, walking areas and crossings), so sumo can route every one. Origins and
//   destinations are kept at least a third of the network's extent apart (vehicles) or 80 to 600 m apart (pedestrians)
//   where the network allows (the best of kTripTries draws otherwise).
// - Departures are spread evenly over [0, duration): agent i of n departs in
//   the i-th of n equal slots at a seeded offset; the file lists vehicles
//   and pedestrians merged by departure time, as sumo requires.
// - Deterministic: the text depends only on (net, options). Every random
//   draw comes from Rng(seed, agent index, stream).
// - An error when vehicles > 0 and no edge can carry a car, or pedestrians >
//   0 and the network has no walkable edge (the message says which, and that
//   netconvert found no sidewalk / driving lane in the city).
#pragma once
#include <array>
#include <cstdint>
#include <string>

#include "foundation/status.h"
#include "runtime/traffic/sumo_net.h"

namespace vista {

enum class AgentType : uint8_t { Car, Van, Bus, Truck, Bicycle, Pedestrian };
constexpr int kAgentTypeCount = 6;

struct AgentTypeInfo {
    const char* id;                // the vType id in SUMO's files ("car", ...)
    const char* sumoClass;         // SUMO's vClass
    uint32_t classBit;             // TrafficClass
    double length, width, height;  // metres
    double maxSpeed;               // m/s
};
const AgentTypeInfo& agentTypeInfo(AgentType t);
// The type whose vType id is `id`; false when none is.
bool agentTypeFromId(const std::string& id, AgentType* t);

// Shares of the vehicle types (car, van, bus, truck, bicycle); sum 1.
constexpr std::array<double, 5> kDefaultMix = {0.70, 0.10, 0.05, 0.05, 0.10};
constexpr double kMinTripEdgeM = 20.0;
constexpr double kMinNetworkShare = 0.5;
constexpr int kTripTries = 16;

struct TrafficDemandOptions {
    int vehicles = 300;
    int pedestrians = 300;
    double durationS = 600.0;
    uint64_t seed = 1;
};

struct TrafficDemandCounts {
    std::array<int, kAgentTypeCount> byType{};  // indexed by AgentType
    int substituted = 0;                        // vehicles whose type had no network, made cars
};

Result<std::string> makeDemandXml(const SumoNet& net, const TrafficDemandOptions& opt, TrafficDemandCounts* counts);

}  // namespace vista
