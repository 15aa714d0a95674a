// Terrain height field and population density map: analytic, deterministic
// functions of (params, position), so every stage and every tile agrees
// without sharing state. Pure and thread-safe.
#pragma once
#include <glm/glm.hpp>

#include "citygen/params.h"

namespace vista {

// Ground height (metres) at city-frame position p. 0 everywhere when
// params.hills_amplitude_m == 0. Smooth (C1), bounded by the amplitude.
double terrainHeight(const CityParams& params, const glm::dvec2& p);

// Population density in [0, 1] at p: a centre peak falling off with
// density_radius_m, modulated by a seeded low-frequency noise (sub-centres).
double populationDensity(const CityParams& params, const glm::dvec2& p);

// Street-pattern weights at p (grid, radial, organic), each >= 0, summing to 1.
// Regions are large (several arterial spacings) and seeded; the centre prefers
// the pattern with the largest weight in params.
glm::dvec3 patternWeights(const CityParams& params, const glm::dvec2& p);

// Smooth seeded value noise in [-1, 1] with unit feature size; used by the above.
double valueNoise(uint64_t seed, uint64_t stream, const glm::dvec2& p);

}  // namespace vista
