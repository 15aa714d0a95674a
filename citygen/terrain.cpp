#include "citygen/terrain.h"

#include <algorithm>
#include <cmath>

#include "foundation/rng.h"

namespace vista {

namespace {
double lattice(uint64_t seed, uint64_t stream, int64_t x, int64_t y) {
    uint64_t h = hashKeys(seed, (uint64_t(x) * 0x9E3779B1ull) ^ (uint64_t(y) * 0x85EBCA77ull), stream + 0x1000);
    return double(h >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}
double smooth(double t) { return t * t * (3 - 2 * t); }
}  // namespace

double valueNoise(uint64_t seed, uint64_t stream, const glm::dvec2& p) {
    double fx = std::floor(p.x), fy = std::floor(p.y);
    int64_t x0 = int64_t(fx), y0 = int64_t(fy);
    double tx = smooth(p.x - fx), ty = smooth(p.y - fy);
    double a = lattice(seed, stream, x0, y0), b = lattice(seed, stream, x0 + 1, y0);
    double c = lattice(seed, stream, x0, y0 + 1), d = lattice(seed, stream, x0 + 1, y0 + 1);
    return (a * (1 - tx) + b * tx) * (1 - ty) + (c * (1 - tx) + d * tx) * ty;
}

double terrainHeight(const CityParams& pr, const glm::dvec2& p) {
    if (pr.hills_amplitude_m <= 0) return 0.0;
    glm::dvec2 q = p / pr.hills_wavelength_m;
    double h = 0.65 * valueNoise(pr.seed, uint64_t(Stream::Terrain), q) +
               0.35 * valueNoise(pr.seed, uint64_t(Stream::Terrain) + 7, q * 2.03);
    return pr.hills_amplitude_m * h;
}

double populationDensity(const CityParams& pr, const glm::dvec2& p) {
    double r = glm::length(p);
    double base = pr.centre_density * std::exp(-r / pr.density_radius_m);
    double n = valueNoise(pr.seed, 101, p / 900.0);
    // Sub-centres: bumps of the noise add density away from the centre.
    double sub = 0.35 * std::max(0.0, n) * std::exp(-r / (3.0 * pr.density_radius_m));
    return std::clamp(base * (0.85 + 0.3 * n) + sub, 0.0, 1.0);
}

glm::dvec3 patternWeights(const CityParams& pr, const glm::dvec2& p) {
    glm::dvec3 w(pr.pattern_grid, pr.pattern_radial, pr.pattern_organic);
    double sum = w.x + w.y + w.z;
    w /= sum;
    glm::dvec2 q = p / std::max(600.0, 3.0 * pr.arterial_spacing_m);
    glm::dvec3 n(valueNoise(pr.seed, 201, q), valueNoise(pr.seed, 202, q), valueNoise(pr.seed, 203, q));
    glm::dvec3 v = glm::max(w * (1.0 + 0.9 * n), glm::dvec3(0.0));
    // Radial patterns live near the centre.
    v.y *= std::exp(-glm::length(p) / (2.5 * pr.arterial_spacing_m));
    double s = v.x + v.y + v.z;
    return s > 1e-12 ? v / s : w;
}

}  // namespace vista
