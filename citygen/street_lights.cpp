#include "citygen/street_lights.h"

#include <algorithm>
#include <cmath>

#include "citygen/street_graph.h"
#include "citygen/terrain.h"

namespace vista {
namespace {

constexpr double kIntersectionClear = 6.0;

// Axis-aligned box [lo, hi] with one colour per face direction.
void box(Mesh& m, const glm::dvec3& origin, const glm::dvec3& lo, const glm::dvec3& hi, const glm::u8vec4& side,
         const glm::u8vec4& top, const glm::u8vec4& bottom, bool withBottom, uint32_t id) {
    m.ids.resize(m.positions.size(), 0u);
    const glm::dvec3 c[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                             {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
    struct Face {
        int v[4];
        glm::vec3 n;
    };
    const Face faces[6] = {{{0, 1, 5, 4}, {0, -1, 0}}, {{1, 2, 6, 5}, {1, 0, 0}}, {{2, 3, 7, 6}, {0, 1, 0}},
                           {{3, 0, 4, 7}, {-1, 0, 0}}, {{4, 5, 6, 7}, {0, 0, 1}}, {{3, 2, 1, 0}, {0, 0, -1}}};
    for (int f = 0; f < 6; ++f) {
        if (f == 5 && !withBottom) continue;
        const glm::u8vec4 col = f == 4 ? top : (f == 5 ? bottom : side);
        const uint32_t base = uint32_t(m.positions.size());
        for (int k = 0; k < 4; ++k) {
            m.positions.push_back(glm::vec3(c[faces[f].v[k]] - origin));
            m.normals.push_back(faces[f].n);
            m.colors.push_back(col);
            m.ids.push_back(id);
        }
        m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
}

}  // namespace

std::vector<glm::dvec3> placeStreetLights(const City& city) {
    std::vector<glm::dvec3> out;
    const CityParams& P = city.params;
    if (!P.effects.night || !(P.effects.night->street_light_spacing_m > 0)) return out;
    const double spacing = P.effects.night->street_light_spacing_m, half = 0.5 * P.size_m - 1.0;
    const StreetGraph& g = city.streets;
    for (const StreetEdge& e : g.edges) {
        if (e.a >= g.nodes.size() || e.b >= g.nodes.size()) continue;
        const glm::dvec2 A = g.nodes[e.a], B = g.nodes[e.b];
        const double L = glm::length(B - A);
        if (!std::isfinite(L) || L < 2 * kIntersectionClear) continue;
        const glm::dvec2 d = (B - A) / L, n(-d.y, d.x);
        double w = double(e.width);
        if (!std::isfinite(w) || w <= 0.5) w = roadWidth(e.cls);
        const double off = 0.5 * w + 0.5 * P.sidewalk_m;
        const double usable = L - 2 * kIntersectionClear;
        const int count = int(std::floor(usable / spacing)) + 1;
        const double first = kIntersectionClear + 0.5 * (usable - (count - 1) * spacing);
        for (int i = 0; i < count; ++i) {
            const double side = (i % 2 == 0) ? 1.0 : -1.0;
            const glm::dvec2 p = A + d * (first + i * spacing) + n * (side * off);
            if (std::abs(p.x) > half || std::abs(p.y) > half) continue;
            out.emplace_back(p, terrainHeight(P, p));
        }
    }
    return out;
}

void meshStreetLight(const glm::dvec3& base, const glm::dvec3& origin, const Lighting& light, Mesh& mesh, uint32_t id) {
    const double r = 0.09, h = kStreetLightHeight;
    const glm::u8vec4 side = prelitColor(Material::Lamp, {1, 0, 0}, light),
                      top = prelitColor(Material::Lamp, {0, 0, 1}, light);
    box(mesh, origin, base + glm::dvec3(-r, -r, 0), base + glm::dvec3(r, r, h - 0.15), side, top, side, false, id);
    const glm::u8vec4 glow = lampHeadColor();
    box(mesh, origin, base + glm::dvec3(-0.35, -0.35, h - 0.15), base + glm::dvec3(0.35, 0.35, h + 0.1), glow,
        prelitColor(Material::Lamp, {0, 0, 1}, light), glow, true, id);
}

}  // namespace vista
