#include "runtime/engine/frame_effects.h"

#include <algorithm>
#include <cmath>

#include "citygen/lighting.h"

namespace vista {

FrameEffects FrameEffects::fromScene(const Effects& e) {
    FrameEffects f;
    if (e.haze) {
        f.haze = true;
        f.visibility = e.haze->visibility_m;
    }
    if (e.glass) {
        f.glass = true;
        f.glassMarked = true;
        f.reflectance = e.glass->reflectance;
        f.rayBudget = e.glass->ray_budget;
    }
    f.night = e.night.has_value();
    return f;
}

double FrameEffects::hazeFar() const { return haze ? visibility : 0.0; }

float FrameEffects::transmittance(double z) const {
    if (!haze) return 1.0f;
    return float(std::exp(-extinction() * std::max(0.0, z)));
}

glm::u8vec4 FrameEffects::hazeColor() const { return skyColor(0.0, night); }

glm::u8vec4 FrameEffects::applyHaze(const glm::u8vec4& c, double z) const {
    if (!haze) return c;
    const float t = transmittance(z);
    const glm::u8vec4 h = hazeColor();
    glm::u8vec4 o = c;
    for (int k = 0; k < 3; ++k) o[k] = uint8_t(std::lround(std::clamp(c[k] * t + h[k] * (1.0f - t), 0.0f, 255.0f)));
    return o;
}

glm::u8vec4 FrameEffects::sky(const glm::dvec3& dir) const {
    if (!(dir.z > 0.0)) return skyColor(0.0, night);  // at and below the horizon: its colour, no asin
    return skyColor(std::asin(std::min(dir.z, 1.0)), night);
}

}  // namespace vista
