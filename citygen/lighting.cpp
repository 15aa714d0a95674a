#include "citygen/lighting.h"
#include "foundation/hash.h"
#include "foundation/units.h"

#include <algorithm>
#include <cmath>

namespace vista {

Lighting::Lighting(const CityParams& p) {
    const double az = glm::radians(p.sun_azimuth_deg), el = glm::radians(p.sun_elevation_deg);
    sunDir = glm::dvec3(std::sin(az) * std::cos(el), std::cos(az) * std::cos(el), std::sin(el));
    ambient = p.ambient;
    glass = p.effects.glass.has_value();
    if (p.effects.night) {
        night = true;
        sun = 0.0;
        ambient = kNightAmbient;
        litShare = p.effects.night->lit_share;
        seed = p.seed;
    }
}

glm::dvec3 materialAlbedo(Material m) {
    switch (m) {
        case Material::Ground: return {0.41, 0.40, 0.34};
        case Material::Road: return {0.22, 0.22, 0.24};
        case Material::Marking: return {0.85, 0.85, 0.80};
        case Material::Sidewalk: return {0.62, 0.60, 0.57};
        case Material::Grass: return {0.27, 0.46, 0.18};
        case Material::Wall: return {0.78, 0.70, 0.60};
        case Material::Window: return {0.22, 0.30, 0.40};
        case Material::Roof: return {0.55, 0.30, 0.25};
        case Material::Trunk: return {0.33, 0.24, 0.17};
        case Material::Leaves: return {0.15, 0.33, 0.11};
        case Material::Lamp: return {0.30, 0.31, 0.32};
        case Material::TrafficLight: return {0.06, 0.07, 0.06};
        case Material::TrafficSign: return {0.45, 0.46, 0.47};
        case Material::Car: return {0.45, 0.46, 0.47};
        case Material::Vehicle: return {0.45, 0.46, 0.47};
        case Material::Pedestrian: return {0.40, 0.32, 0.26};
        case Material::Count: break;
    }
    return {1, 0, 1};
}

double lightLevel(const glm::dvec3& normal, const Lighting& light) {
    const double len = glm::length(normal);
    const double diffuse = len > 0 ? std::max(0.0, glm::dot(normal / len, light.sunDir)) : 0.0;
    return light.ambient + (1.0 - light.ambient) * light.sun * diffuse;
}

uint8_t encodeSrgb(double v) { return uint8_t(std::lround(std::pow(std::clamp(v, 0.0, 1.0), 1.0 / 2.2) * 255.0)); }
double decodeSrgb(uint8_t v) { return std::pow(v / 255.0, 2.2); }

glm::u8vec4 prelitAlbedo(const glm::dvec3& albedo, const glm::dvec3& normal, const Lighting& light, uint8_t alpha) {
    const glm::dvec3 c = glm::clamp(albedo * lightLevel(normal, light) * 1.25, 0.0, 1.0);
    return {encodeSrgb(c.x), encodeSrgb(c.y), encodeSrgb(c.z), alpha};
}

glm::u8vec4 prelitColor(Material m, const glm::dvec3& normal, const Lighting& light, double variation) {
    const glm::dvec3 albedo = materialAlbedo(m) * (1.0 + 0.18 * std::clamp(variation, -1.0, 1.0));
    const uint8_t alpha = light.glass && m == Material::Window ? kGlassAlpha : 255;
    return prelitAlbedo(albedo, normal, light, alpha);
}

bool windowLit(const glm::dvec3& c, const Lighting& light) {
    if (!light.night || light.litShare <= 0) return false;
    const auto q = [](double v) { return uint64_t(int64_t(std::floor(v * 4.0))); };  // 25 cm cells
    const uint64_t h = hashKeys(light.seed ^ 0x4E16'47ull, hashKeys(q(c.x), q(c.y), q(c.z)), 0x77ull);
    return double(h >> 11) * (1.0 / 9007199254740992.0) < light.litShare;
}

glm::u8vec4 litWindowColor() { return {255, 226, 168, 255}; }
glm::u8vec4 lampHeadColor() { return {255, 246, 222, 255}; }

glm::u8vec4 skyColor(double elev, bool night) {
    double t = std::clamp(elev / kHalfPi, 0.0, 1.0);
    t = std::sqrt(t);
    const glm::dvec3 horizon = night ? glm::dvec3(0.10, 0.12, 0.20) : glm::dvec3(0.78, 0.85, 0.93);
    const glm::dvec3 zenith = night ? glm::dvec3(0.01, 0.02, 0.06) : glm::dvec3(0.36, 0.56, 0.86);
    glm::dvec3 c = horizon * (1 - t) + zenith * t;
    return {uint8_t(std::lround(c.x * 255)), uint8_t(std::lround(c.y * 255)), uint8_t(std::lround(c.z * 255)), 255};
}

}  // namespace vista
