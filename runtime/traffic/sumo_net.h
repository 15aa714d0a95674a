// The parts of a SUMO network (.net.xml, written by netconvert) that vista
// needs: the network offset, the edges with their lanes' permissions, the
// connections between edges and the traffic-light ids.
//
// Contract:
// - SUMO's coordinates are the input's plus `offset` (<location
//   netOffset>): a point of the network at (x, y) is (x, y) - offset in the
//   OpenDRIVE file's (vista's world) frame.
// - A lane's permissions are the classes of its `allow` list, or every class
//   not in its `disallow` list, or every class (neither given), restricted
//   to the classes vista's demand uses (TrafficClass).
// - A connection's `via` lane (the internal lane a vehicle drives through
//   the junction) is kept as its edge and lane index, so that the lane's
//   permissions apply to the connection too.
// - signalLinks: every junction link a traffic-light signal of the input
//   OpenDRIVE controls: netconvert keeps the <signal id> on the link's
//   internal lane (<param key="signalID">), and the <connection> through
//   that lane names the light (tl) and the link's index in its state
//   string. Sorted by (signalId, linkIndex), without repeats.
// - readSumoNet() streams the file (expat); a file that is not a SUMO
//   network, is truncated or malformed is an error naming the file, the line
//   and the reason. Pure, thread-safe.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "foundation/status.h"

namespace vista {

// The SUMO vehicle classes of vista's agents (bits of SumoLane::allow).
enum TrafficClass : uint32_t {
    kClassPassenger = 1u << 0,
    kClassDelivery = 1u << 1,
    kClassBus = 1u << 2,
    kClassTruck = 1u << 3,
    kClassBicycle = 1u << 4,
    kClassPedestrian = 1u << 5,
};
constexpr uint32_t kAllTrafficClasses = (1u << 6) - 1;

struct SumoLane {
    int index = 0;
    double length = 0.0;  // metres
    uint32_t allow = 0;   // TrafficClass bits
};

struct SumoEdge {
    std::string id;
    std::string function;  // "" (a normal edge), "internal", "crossing", "walkingarea", ...
    std::vector<SumoLane> lanes;
    double x = 0.0, y = 0.0;  // the middle of its first lane's shape, SUMO frame
    uint32_t allow() const {
        uint32_t a = 0;
        for (const SumoLane& l : lanes) a |= l.allow;
        return a;
    }
    bool normal() const { return function.empty() || function == "normal"; }
};

struct SumoConnection {
    uint32_t from = 0, to = 0;  // edge indices
    int fromLane = 0, toLane = 0;
    int64_t viaEdge = -1;  // the internal edge of its `via` lane (edge index), -1 without one
    int viaLane = 0;       // that lane's index
};

struct SumoSignalLink {
    uint32_t signalId = 0;  // the OpenDRIVE <signal id> (vista: the LaneModel::signals index)
    uint32_t light = 0;     // index into SumoNet::trafficLights
    int linkIndex = 0;      // the link's letter in the light's state string
};

struct SumoNet {
    double offsetX = 0.0, offsetY = 0.0;  // <location netOffset>
    std::vector<SumoEdge> edges;
    std::vector<SumoConnection> connections;
    std::vector<std::string> trafficLights;  // tlLogic ids, in file order
    std::vector<SumoSignalLink> signalLinks;
};

Result<SumoNet> readSumoNet(const std::string& path);

// Permissions from a lane's allow / disallow attributes (either may be null).
uint32_t sumoPermissions(const char* allow, const char* disallow);

}  // namespace vista
