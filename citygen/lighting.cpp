#include "citygen/lighting.h"
#include "foundation/units.h"

#include <algorithm>
#include <cmath>

namespace vista {

Lighting::Lighting(const CityParams& p) {
    const double az = glm::radians(p.sun_azimuth_deg), el = glm::radians(p.sun_elevation_deg);
    sunDir = glm::dvec3(std::sin(az) * std::cos(el), std::cos(az) * std::cos(el), std::sin(el));
    ambient = p.ambient;
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
        case Material::Count: break;
    }
    return {1, 0, 1};
}

glm::u8vec4 prelitColor(Material m, const glm::dvec3& normal, const Lighting& light, double variation) {
    glm::dvec3 albedo = materialAlbedo(m) * (1.0 + 0.18 * std::clamp(variation, -1.0, 1.0));
    double len = glm::length(normal);
    double diffuse = len > 0 ? std::max(0.0, glm::dot(normal / len, light.sunDir)) : 0.0;
    double l = light.ambient + (1.0 - light.ambient) * diffuse;
    glm::dvec3 c = glm::clamp(albedo * l * 1.25, 0.0, 1.0);
    auto q = [](double v) { return uint8_t(std::lround(std::pow(v, 1.0 / 2.2) * 255.0)); };
    return {q(c.x), q(c.y), q(c.z), 255};
}

glm::u8vec4 skyColor(double elev) {
    double t = std::clamp(elev / kHalfPi, 0.0, 1.0);
    t = std::sqrt(t);
    glm::dvec3 horizon(0.78, 0.85, 0.93), zenith(0.36, 0.56, 0.86);
    glm::dvec3 c = horizon * (1 - t) + zenith * t;
    return {uint8_t(std::lround(c.x * 255)), uint8_t(std::lround(c.y * 255)), uint8_t(std::lround(c.z * 255)), 255};
}

}  // namespace vista
