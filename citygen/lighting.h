// Prelit vertex colours: material palette x (ambient + diffuse sun light).
//
// Contract: deterministic and pure. The returned colour is what both the
// rasteriser and the ray caster display (lighting is baked, not computed at
// draw time), so their images agree exactly. `normal` need not be unit length
// (it is normalised; a zero normal gets the ambient term only). `variation`
// in [-1, 1] brightens/darkens the albedo slightly (per building, per tree).
#pragma once
#include <glm/glm.hpp>

#include "citygen/mesh.h"
#include "citygen/params.h"

namespace vista {

struct Lighting {
    glm::dvec3 sunDir{0, 0, 1};  // unit vector towards the sun, city frame (x east, y north, z up)
    double ambient = 0.45;
    explicit Lighting(const CityParams& p);
    Lighting() = default;
};

glm::dvec3 materialAlbedo(Material m);  // linear 0..1 RGB
glm::u8vec4 prelitColor(Material m, const glm::dvec3& normal, const Lighting& light, double variation = 0.0);

// Sky colour seen at elevation angle `elev` (radians, 0 = horizon, pi/2 = zenith).
// Used by every renderer for the background, so modes agree on sky pixels.
glm::u8vec4 skyColor(double elev);

}  // namespace vista
