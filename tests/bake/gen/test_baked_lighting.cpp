// Baked lighting (bake/gen/baked_lighting.h): shadows against an independent analytic test,
// hard cases, nothing changed when not called for.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "citygen/effects.h"
#include "citygen/lighting.h"
#include "citygen/mesh_builder.h"
#include "citygen/params.h"
#include "bake/gen/baked_lighting.h"
#include "runtime/engine/far_field_rays.h"
#include "runtime/engine/frame_raycast.h"
#include "runtime/engine/frame_effects.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/engine/reflections.h"

namespace vista {
namespace {
// ---- baked lighting ---------------------------------------------------------------

// One tile: a 120 m ground square and a 10 x 10 x 20 m block at the centre.
City blockCity(double elevationDeg, double azimuthDeg, const Effects& effects, double originX = 0.0) {
    City city;
    city.params.size_m = 200;
    city.params.sun_elevation_deg = elevationDeg;
    city.params.sun_azimuth_deg = azimuthDeg;
    city.params.origin_x = originX;
    city.params.effects = effects;
    Lighting light(city.params);
    Tile t;
    t.origin = {-100, -100, 0};
    MeshBuilder ground(t.meshes[size_t(Material::Ground)], t.origin, Material::Ground, light);
    ground.quad({-60, -60, 0}, {60, -60, 0}, {60, 60, 0}, {-60, 60, 0});
    MeshBuilder wall(t.meshes[size_t(Material::Wall)], t.origin, Material::Wall, light);
    wall.prism({{-5, -5}, {5, -5}, {5, 5}, {-5, 5}}, 0, 20, true);
    city.tiles.push_back(t);
    return city;
}

// Independent hard-shadow test: does the ray from p towards the sun hit the block? (slab test)
bool analyticShadow(const glm::dvec3& p, const glm::dvec3& s) {
    double t0 = 0, t1 = 1e30;
    const glm::dvec3 lo(-5, -5, 0), hi(5, 5, 20);
    for (int k = 0; k < 3; ++k) {
        if (std::abs(s[k]) < 1e-12) {
            if (p[k] < lo[k] || p[k] > hi[k]) return false;
            continue;
        }
        double a = (lo[k] - p[k]) / s[k], b = (hi[k] - p[k]) / s[k];
        if (a > b) std::swap(a, b);
        t0 = std::max(t0, a);
        t1 = std::min(t1, b);
    }
    return t0 <= t1;
}

TEST(BakedLighting, HardShadowsMatchAnAnalyticTestAndRefineOnlyAtTheirEdges) {
    Effects e;
    e.sun_shadows = SunShadowsEffect{0.0, 1, 0.5};  // hard, 1 sample, 0.5 m
    City city = blockCity(35, 200, e);
    const size_t before = city.tiles[0].meshes[size_t(Material::Ground)].triangleCount();
    BakedLightingStats st;
    ASSERT_TRUE(bakeLighting(city, nullptr, st));
    EXPECT_TRUE(st.ran);
    const Mesh& g = city.tiles[0].meshes[size_t(Material::Ground)];
    EXPECT_GT(g.triangleCount(), before);
    EXPECT_LT(g.triangleCount(), 20000u) << "refinement stays near the shadow's edges";
    const Lighting light(city.params);
    const glm::u8vec4 lit = prelitColor(Material::Ground, {0, 0, 1}, light);
    size_t agree = 0, total = 0, shadowed = 0;
    for (size_t i = 0; i < g.positions.size(); ++i) {
        const glm::dvec3 p = city.tiles[0].origin + glm::dvec3(g.positions[i]);
        if (std::abs(p.x) <= 5.2 && std::abs(p.y) <= 5.2) continue;  // under the block
        const bool dark = g.colors[i].x + 3 < lit.x;
        const bool expect = analyticShadow(p + glm::dvec3(0, 0, 0.02), light.sunDir);
        agree += dark == expect;
        shadowed += expect;
        ++total;
        ASSERT_TRUE(std::isfinite(g.positions[i].x + g.positions[i].y + g.positions[i].z));
    }
    EXPECT_GT(shadowed, 10u);
    EXPECT_GE(double(agree) / double(total), 0.97) << agree << " of " << total;
}

TEST(BakedLighting, HardCasesStayFinite) {
    Effects all;
    all.sun_shadows = SunShadowsEffect();
    all.ambient_occlusion = AmbientOcclusionEffect{4, 6.0, 0.8, 4.0};
    // Sun 1 degree over the horizon (shadow rays graze the ground and the walls), overhead, and 1,000 km away.
    for (auto [elev, originX] : {std::pair{1.0, 0.0}, std::pair{90.0, 0.0}, std::pair{40.0, 1e6}}) {
        City city = blockCity(elev, 90, all, originX);
        BakedLightingStats st;
        ASSERT_TRUE(bakeLighting(city, nullptr, st)) << elev;
        for (const Mesh& m : city.tiles[0].meshes) {
            ASSERT_EQ(m.colors.size(), m.positions.size());
            for (const auto& p : m.positions) ASSERT_TRUE(std::isfinite(p.x + p.y + p.z)) << elev;
            for (uint32_t i : m.indices) ASSERT_LT(i, m.positions.size());
        }
        if (elev == 90.0) {
            // Overhead sun: nothing outside the footprint is shadowed (AO aside, only near the walls).
            const Mesh& g = city.tiles[0].meshes[size_t(Material::Ground)];
            const Lighting light(city.params);
            const glm::u8vec4 lit = prelitColor(Material::Ground, {0, 0, 1}, light);
            for (size_t i = 0; i < g.positions.size(); ++i) {
                const glm::dvec3 p = city.tiles[0].origin + glm::dvec3(g.positions[i]);
                if (std::max(std::abs(p.x), std::abs(p.y)) > 5 + 6.5) {
                    EXPECT_GE(g.colors[i].x + 2, lit.x) << p.x << "," << p.y;
                }
            }
        }
    }
    // Night: the sun is below the horizon: sun_shadows has nothing to do, lamps light the ground.
    Effects night;
    night.night = NightEffect();
    night.sun_shadows = SunShadowsEffect();
    City city = blockCity(40, 90, night);
    city.streetLights = {{20, 0, 0}};
    BakedLightingStats st;
    ASSERT_TRUE(bakeLighting(city, nullptr, st));
    const Mesh& g = city.tiles[0].meshes[size_t(Material::Ground)];
    int nearLamp = -1, farAway = -1;
    for (size_t i = 0; i < g.positions.size(); ++i) {
        const glm::dvec3 p = city.tiles[0].origin + glm::dvec3(g.positions[i]);
        const double d = glm::length(glm::dvec2(p) - glm::dvec2(20, 0));
        if (d < 2.5 && nearLamp < 0) nearLamp = int(i);
        if (d > 40 && farAway < 0) farAway = int(i);
    }
    ASSERT_GE(nearLamp, 0);
    ASSERT_GE(farAway, 0);
    EXPECT_GT(int(g.colors[size_t(nearLamp)].x), int(g.colors[size_t(farAway)].x) + 40);
}

TEST(BakedLighting, NotCalledForMeansNothingChanges) {
    City city = blockCity(40, 90, Effects());
    const City copy = city;
    BakedLightingStats st;
    ASSERT_TRUE(bakeLighting(city, nullptr, st));
    EXPECT_FALSE(st.ran);
    EXPECT_EQ(city.tiles[0].meshes[size_t(Material::Ground)].colors,
              copy.tiles[0].meshes[size_t(Material::Ground)].colors);
}

}  // namespace
}  // namespace vista
