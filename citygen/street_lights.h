// Street lights of the `night` effect: where they stand and their meshes.
//
// placeStreetLights(): along every street edge, every
// effects.night->street_light_spacing_m, alternating sides, on the sidewalk
// (half the carriageway + half the sidewalk from the centre line), kept clear
// of intersections (6 m) and inside the city square; z on the terrain.
// Deterministic (depends on the street graph and params only). Empty when the
// city declares no night or a spacing of 0.
// meshStreetLight(): a pole (kStreetLightHeight tall, Material::Lamp, prelit)
// and an emissive head (lampHeadColor) into `mesh`, positions relative to
// `origin` (city frame), counter-clockwise outward faces; its vertices carry
// the label `id` (labels.h).
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include "citygen/city.h"
#include "citygen/lighting.h"

namespace vista {

constexpr double kStreetLightHeight = 6.5;  // lamp head centre above the ground, metres

std::vector<glm::dvec3> placeStreetLights(const City& city);
void meshStreetLight(const glm::dvec3& base, const glm::dvec3& origin, const Lighting& light, Mesh& mesh,
                     uint32_t id = 0);

}  // namespace vista
