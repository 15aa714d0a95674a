// FrameEffects: the run-time effects of a frame (haze, glass reflections,
// the night sky), taken from the scene's declared effects (citygen/effects.h)
// and possibly overridden by the program (`vista bench --effects`, the
// viewer's toggles). The maths every renderer shares, so the rasteriser and
// the ray caster agree:
//   haze: colour' = colour * T + hazeColour * (1 - T), T = exp(-beta z),
//         beta = 3.912 / visibility (Koschmieder: 2 % contrast at the
//         visibility), z = eye-plane depth (what the fixed-function fog of
//         the rasteriser uses), in 8-bit sRGB as the rasteriser blends.
//         Beyond hazeFar() = the visibility distance (T = 0.02: by definition
//         nothing is discernible there) nothing is drawn or traced: the far
//         plane, the rays' tfar, the horizon and the bake's far set stop
//         there, and those pixels show the sky in every renderer alike.
//         The haze colour is the sky's horizon colour.
//   glass: windows carry alpha kGlassAlpha; the reflection stage
//         (reflections.h) blends reflections into marked pixels.
//   night: the night sky (skyColor(elev, true)).
// Plain values; thread-safe to share const.
#pragma once
#include <cstdint>

#include <glm/glm.hpp>

#include "citygen/effects.h"

namespace vista {

struct FrameEffects {
    bool haze = false;
    double visibility = 1e30;  // metres
    bool glass = false;        // reflections on (the scene must declare glass for marks to exist)
    bool glassMarked = false;  // the scene's colours carry glass marks (declared glass)
    double reflectance = 0.2;
    int64_t rayBudget = 0;  // reflection rays per frame
    bool night = false;

    // The run-time part of a scene's effects (baked ones are in the colours).
    static FrameEffects fromScene(const Effects& e);
    bool any() const { return haze || glass || glassMarked || night; }
    double extinction() const { return haze ? 3.912 / visibility : 0.0; }
    // Distance beyond which nothing is drawn or traced (the visibility): 0 = no limit.
    double hazeFar() const;
    float transmittance(double eyeDepth) const;
    glm::u8vec4 hazeColor() const;
    // Haze applied to an sRGB colour at eye-plane depth z (alpha kept).
    glm::u8vec4 applyHaze(const glm::u8vec4& c, double eyeDepth) const;
    // Sky colour of a ray direction (unit, world frame): day or night.
    glm::u8vec4 sky(const glm::dvec3& dir) const;
};

}  // namespace vista
