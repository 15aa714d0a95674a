// Prelit vertex colours: material palette x (ambient + diffuse sun light),
// and the declared effects that change colours at generation (effects.h).
//
// Contract: deterministic and pure. The returned colour is what both the
// rasteriser and the ray caster display (lighting is baked, not computed at
// draw time), so their images agree exactly. `normal` need not be unit length
// (it is normalised; a zero normal gets the ambient term only). `variation`
// in [-1, 1] brightens/darkens the albedo slightly (per building, per tree).
// Glass: with the `glass` effect, window colours carry alpha kGlassAlpha
// (every other colour alpha 255): the mark by which every renderer finds
// reflective pixels. Night: no sun, a dim moonlit ambient (kNightAmbient),
// emissive lit windows and lamp heads; the night sky of skyColor().
// lightLevel() is the scalar light a colour was prelit with, so a later pass
// (the engine's baked lighting) can rescale colours exactly.
#pragma once
#include <cstdint>

#include <glm/glm.hpp>

#include "citygen/mesh.h"
#include "citygen/params.h"

namespace vista {

constexpr uint8_t kGlassAlpha = 128;  // alpha of glass in vertex colours and images
constexpr double kNightAmbient = 0.14;

struct Lighting {
    glm::dvec3 sunDir{0, 0, 1};  // unit vector towards the sun, city frame (x east, y north, z up)
    double ambient = 0.45;
    double sun = 1.0;    // direct sun strength: 1 by day, 0 at night
    bool glass = false;  // windows are glass (alpha kGlassAlpha)
    bool night = false;
    double litShare = 0.0;  // night: share of windows lit from inside
    uint64_t seed = 0;      // night: picks the lit windows
    explicit Lighting(const CityParams& p);
    Lighting() = default;
};

glm::dvec3 materialAlbedo(Material m);  // linear 0..1 RGB
// Scalar light of a surface with `normal`: ambient + (1 - ambient) * sun * max(0, n.s).
double lightLevel(const glm::dvec3& normal, const Lighting& light);
glm::u8vec4 prelitColor(Material m, const glm::dvec3& normal, const Lighting& light, double variation = 0.0);
// The same with an explicit linear albedo (materials effect palettes).
glm::u8vec4 prelitAlbedo(const glm::dvec3& albedo, const glm::dvec3& normal, const Lighting& light,
                         uint8_t alpha = 255);
// Linear 0..1 -> sRGB byte (the encoding of every prelit colour) and back.
uint8_t encodeSrgb(double linear);
double decodeSrgb(uint8_t v);
// Night: is the window whose pane centre is `centre` (city frame) lit? Deterministic in (seed, position).
bool windowLit(const glm::dvec3& centre, const Lighting& light);
glm::u8vec4 litWindowColor();
glm::u8vec4 lampHeadColor();

// Sky colour seen at elevation angle `elev` (radians, 0 = horizon, pi/2 = zenith).
// Used by every renderer for the background, so modes agree on sky pixels.
// night: the dark night sky.
glm::u8vec4 skyColor(double elev, bool night = false);

}  // namespace vista
