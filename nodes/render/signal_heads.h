// Traffic-light heads lit in the state SUMO had (runtime/traffic/
// signal_states.h): where each head of a city stands and the lamp overlay
// that TrafficScene draws over its static lamps.
//
// Contract:
// - signalHeads() lists the traffic lights of the city's lane model (the
//   same model, blocks included, as the city's OpenDRIVE: city_opendrive.h),
//   one SignalHead per traffic-light placement, in LaneModel::signals order;
//   stop and yield signs and non-finite placements are left out. `frame`
//   maps the head frame to the world (city frame plus params.origin): x to
//   the right of the traffic facing the head, y up, z toward the traffic
//   (SignalPlacement::facing), origin at the pole's foot on the terrain.
//   Pure, deterministic.
// - lampOverlay(state) is the overlay of a lamp state in the head frame:
//   three octagon discs (red, amber, green from the top) at the static
//   lamps' centres (citygen/traffic_signals.h), kLampOverlayProud in front of
//   the static lamp faces and slightly larger, so that they cover them; the
//   lit lamps of the state (Red: red; RedAmber: red and amber; Amber: amber;
//   Green: green; Off: none) have bright unlit colours, the others dark
//   ones. Normals face +z; colours are final (drawn with lighting off, as
//   the city's prelit colours).
// - lampOverlayCentre() / kLampOverlayRadius: a sphere in the head frame
//   holding the overlay (split decisions).
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "citygen/mesh.h"
#include "citygen/params.h"
#include "citygen/street_graph.h"
#include "runtime/traffic/signal_states.h"

namespace vista {

struct SignalHead {
    uint32_t signal = 0;    // OpenDRIVE <signal id> = LaneModel::signals index
    glm::dmat4 frame{1.0};  // head frame -> world (see above)
};

std::vector<SignalHead> signalHeads(const StreetGraph& streets, const CityParams& params);

constexpr double kLampOverlayProud = 0.01;  // metres in front of the static lamp faces
constexpr double kLampOverlayRadius = 0.6;  // metres: bounds the overlay around lampOverlayCentre()
constexpr int kLampStates = 5;              // LampState values, Off .. Green

glm::dvec3 lampOverlayCentre();
Mesh lampOverlay(LampState state);

}  // namespace vista
