// Traffic lights, stop signs and yield signs standing in the scene: the
// meshes of the lane model's signals (lanes.h SignalPlacement), the same
// placements the OpenDRIVE writer declares as <signal>s.
//
// meshSignal(): one signal into `mesh` (tile-local: positions relative to
// `origin`, city frame), every vertex carrying the label `id` (labels.h):
// - a pole (square, kSignalPoleWidth wide) from the terrain (terrainHeight at
//   the placement) to the top of the head;
// - a traffic light: a housing kTrafficLightWidth x kTrafficLightHeight,
//   kTrafficLightDepth deep, its bottom kTrafficLightBottom above the
//   ground, with three lamp faces (red, amber, green from the top) 5 mm in
//   front of it;
// - a stop sign: a white octagon plate kSignSize across the flats with a
//   red octagon face on it; a yield sign: an equilateral triangle kSignSize
//   wide, point down, red with a white inner face; both with their lower
//   edge kSignBottom above the ground.
// The head stands in front of the pole toward the traffic: its front faces
// (the lamp faces, the sign faces) have the normal SignalPlacement::facing;
// every other face is grey or dark and faces outward (counter-clockwise from
// outside). Colours are prelit (lighting.h) from fixed albedos, nothing is
// emissive. The heights are those of the OpenDRIVE <signal>s (zOffset,
// height, width). Pure and deterministic; non-finite placements add nothing.
// signalMaterial() / signalInstanceKind(): the tile mesh and the label kind
// of a signal kind (traffic light: Material::TrafficLight,
// InstanceKind::TrafficLight; stop and yield: TrafficSign); the instance
// index of a signal is its index in LaneModel::signals.
#pragma once
#include <cstdint>

#include <glm/glm.hpp>

#include "citygen/labels.h"
#include "citygen/lanes.h"
#include "citygen/lighting.h"
#include "citygen/mesh.h"
#include "citygen/params.h"

namespace vista {

constexpr double kSignalPoleWidth = 0.1;     // metres
constexpr double kTrafficLightBottom = 2.5;  // housing bottom above the ground
constexpr double kTrafficLightHeight = 0.9, kTrafficLightWidth = 0.3, kTrafficLightDepth = 0.25;
constexpr double kSignBottom = 1.8;  // plate's lower edge above the ground
constexpr double kSignSize = 0.75;   // octagon across the flats; triangle side
constexpr double kSignThickness = 0.02;

Material signalMaterial(SignalPlacement::Kind kind);
InstanceKind signalInstanceKind(SignalPlacement::Kind kind);
void meshSignal(const SignalPlacement& signal, const CityParams& params, const glm::dvec3& origin,
                const Lighting& light, Mesh& mesh, uint32_t id);

}  // namespace vista
