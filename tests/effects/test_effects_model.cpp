// Effects without GL: declaration (params), haze maths, the reflection stage,
// baked lighting (shadows against an independent analytic test, hard cases).
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

// ---- declaration ---------------------------------------------------------------

TEST(EffectsParams, AbsentMeansNoneAndTheParameterJsonIsUnchanged) {
    CityParams p;
    EXPECT_FALSE(p.effects.any());
    EXPECT_EQ(paramsToJson(p).find("effects"), std::string::npos);
    auto r = parseParamsJson(R"({"seed": 3})", "t.json");
    ASSERT_TRUE(r) << r.status().message();
    EXPECT_FALSE(r->effects.any());
}

TEST(EffectsParams, DeclaredEffectsRoundTripWithTheirParameters) {
    auto r = parseParamsJson(R"({"effects": {"sun_shadows": {"softness_deg": 1.5}, "haze": {"visibility_m": 800},
                                 "glass": {}, "night": {"lit_share": 0.1}, "materials": {"variety": 0.5},
                                 "ambient_occlusion": {"samples": 4}}})",
                             "t.json");
    ASSERT_TRUE(r) << r.status().message();
    const Effects& e = r->effects;
    ASSERT_TRUE(e.sun_shadows && e.haze && e.glass && e.night && e.materials && e.ambient_occlusion);
    EXPECT_DOUBLE_EQ(e.sun_shadows->softness_deg, 1.5);
    EXPECT_EQ(e.sun_shadows->samples, SunShadowsEffect().samples);  // absent field keeps its default
    EXPECT_DOUBLE_EQ(e.haze->visibility_m, 800);
    EXPECT_DOUBLE_EQ(e.glass->reflectance, GlassEffect().reflectance);
    EXPECT_EQ(e.ambient_occlusion->samples, 4);
    auto back = parseParamsJson(paramsToJson(*r), "round trip");
    ASSERT_TRUE(back) << back.status().message();
    EXPECT_TRUE(back->effects == e);
    EXPECT_EQ(paramsToJson(*back), paramsToJson(*r));
}

TEST(EffectsParams, BadDeclarationsNameTheEffectTheFieldAndTheRange) {
    struct Case {
        const char* json;
        std::vector<std::string> mustSay;
    };
    const Case cases[] = {
        {R"({"effects": {"fog": {}}})", {"unknown effect 'fog'", "sun_shadows", "haze", "glass", "night"}},
        {R"({"effects": {"haze": {"visibility_m": 5}}})", {"'haze'", "'visibility_m'", "[20, 1000000]", "metres"}},
        {R"({"effects": {"haze": {"visibility_m": 2e6}}})", {"'visibility_m'", "out of range"}},
        {R"({"effects": {"haze": {"distance": 5}}})", {"unknown field 'distance'", "visibility_m"}},
        {R"({"effects": {"glass": 1}})", {"'glass'", "must be an object"}},
        {R"({"effects": {"glass": {"ray_budget": 2.5}}})", {"'ray_budget'", "integer"}},
        {R"({"effects": {"sun_shadows": {"samples": "8"}}})", {"'samples'", "must be a number"}},
        {R"({"effects": {"night": {"street_light_spacing_m": 2}}})", {"'street_light_spacing_m'", "[5, 500]"}},
        {R"({"effects": []})", {"'effects' must be an object"}},
    };
    for (const auto& c : cases) {
        auto r = parseParamsJson(c.json, "bad.json");
        ASSERT_FALSE(r) << c.json;
        for (const auto& s : c.mustSay) EXPECT_NE(r.status().message().find(s), std::string::npos) << c.json << " -> " << r.status().message();
    }
}

// ---- haze ----------------------------------------------------------------------

TEST(Haze, KoschmiederContrastAtTheVisibilityAndStableFrom20mTo1e6m) {
    for (double v : {20.0, 150.0, 1500.0, 1e4, 1e6}) {
        FrameEffects fx;
        fx.haze = true;
        fx.visibility = v;
        // Independent: 2 % contrast at the visibility distance (Koschmieder, ln 50 = 3.912).
        EXPECT_NEAR(fx.transmittance(v), 0.02, 1e-4) << v;
        EXPECT_FLOAT_EQ(fx.transmittance(0), 1.0f);
        EXPECT_DOUBLE_EQ(fx.hazeFar(), v);
        const glm::u8vec4 c(10, 200, 30, 128), h = fx.hazeColor();
        EXPECT_EQ(fx.applyHaze(c, 0.0), c);
        const glm::u8vec4 far = fx.applyHaze(c, 1e9);
        for (int k = 0; k < 3; ++k) EXPECT_EQ(far[k], h[k]) << v;
        EXPECT_EQ(far.w, 128) << "glass marks survive haze";
        int last = -1;
        for (double z = 0; z <= 2 * v; z += v / 16) {  // monotone towards the haze colour
            const int d = std::abs(int(fx.applyHaze(c, z).y) - int(h.y));
            if (last >= 0) { EXPECT_LE(d, last) << v << " " << z; }
            last = d;
        }
        for (double z : {-1.0, std::numeric_limits<double>::infinity(), 1e300})
            EXPECT_TRUE(std::isfinite(fx.transmittance(z))) << z;
    }
}

// A hand-built scene: a wall of glass (alpha kGlassAlpha) facing -y at y = 20
// and a red wall behind the camera at y = -30 (so the glass reflects red).
SceneModel glassScene() {
    SceneModel m;
    SceneMesh glass, red;
    auto quad = [](SceneMesh& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, glm::u8vec4 col) {
        const uint32_t base = uint32_t(s.positions.size());
        for (auto p : {a, b, c, d}) {
            s.positions.push_back(p);
            s.colors.push_back(col);
        }
        for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) s.indices.push_back(base + i);
    };
    // Counter-clockwise seen from -y (the camera side).
    quad(glass, {-50, 20, -10}, {50, 20, -10}, {50, 20, 40}, {-50, 20, 40}, {40, 60, 90, kGlassAlpha});
    quad(red, {50, -30, -10}, {-50, -30, -10}, {-50, -30, 40}, {50, -30, 40}, {230, 10, 10, 255});
    m.meshes = {glass, red};
    m.triangles = 4;
    return m;
}

Camera lookNorth(int w = 64, int h = 48) {
    Camera c;
    c.eye = {0, 0, 2};
    c.heading = 0;
    c.width = w;
    c.height = h;
    c.fovY = 0.8;
    return c;
}

TEST(Reflections, GlassReflectsTheCityAndNoGlassCastsNoRay) {
    auto rays = RayScene::build(glassScene());
    ASSERT_TRUE(rays) << rays.status().message();
    const Camera cam = lookNorth();
    FrameEffects fx;
    fx.glass = fx.glassMarked = true;
    fx.reflectance = 0.5;
    fx.rayBudget = 100000;
    Image img(cam.width, cam.height);
    RayCounts counts;
    castFrame(**rays, cam, img, counts, 1);
    const glm::u8vec4 before = img.at(cam.width / 2, cam.height / 2);
    ASSERT_EQ(before.w, kGlassAlpha) << "the ray caster keeps the glass mark";
    FrameStats st;
    reflectionStage(rays->get(), cam, fx, img, st);
    const glm::u8vec4 after = img.at(cam.width / 2, cam.height / 2);
    EXPECT_GT(int(after.x), int(before.x) + 40) << "red reflected into the glass";
    EXPECT_EQ(after.w, 255);
    EXPECT_TRUE(st.stages.ran(Stage::Reflect));
    EXPECT_TRUE(st.effects.ran(EffectId::Glass));
    EXPECT_GT(st.reflectionRays, 0u);
    EXPECT_FALSE(hasGlassPixels(img));
    // Independent Fresnel check at normal incidence-ish (centre pixel, cos ~ 1):
    // after = before (1 - F) + red F with F ~ F0 = 0.5.
    const double F = (double(after.x) - before.x) / (230.0 - before.x);
    EXPECT_NEAR(F, 0.5, 0.06);

    // Looking away from the glass: nothing marked, no stage, no ray.
    Camera away = cam;
    away.heading = 3.14159;
    Image img2(cam.width, cam.height);
    castFrame(**rays, away, img2, counts, 1);
    FrameStats st2;
    reflectionStage(rays->get(), away, fx, img2, st2);
    EXPECT_FALSE(st2.stages.ran(Stage::Reflect));
    EXPECT_EQ(st2.reflectionRays, 0u);
    EXPECT_EQ(st2.raysCast, 0u);
}

TEST(Reflections, BudgetBoundsTheRaysAndZeroBudgetOnlyClearsMarks) {
    auto rays = RayScene::build(glassScene());
    ASSERT_TRUE(rays);
    const Camera cam = lookNorth(320, 240);
    Image base(cam.width, cam.height);
    RayCounts counts;
    castFrame(**rays, cam, base, counts, 1);
    for (int64_t budget : {int64_t(0), int64_t(50), int64_t(1000), int64_t(1) << 40}) {
        FrameEffects fx;
        fx.glass = fx.glassMarked = true;
        fx.rayBudget = budget;
        Image img = base;
        FrameStats st;
        reflectionStage(rays->get(), cam, fx, img, st);
        EXPECT_FALSE(hasGlassPixels(img)) << budget;
        // Two rays (find the pane, reflect) per sampled block, at most `budget` blocks
        // (the stride stops at 64 pixels: at most ceil(320/64) * ceil(240/64) blocks).
        EXPECT_LE(st.reflectionRays, uint64_t(2 * std::max<int64_t>(budget == 0 ? 0 : 20, std::min<int64_t>(budget, 320 * 240))))
            << budget;
        if (budget == 0) EXPECT_EQ(st.reflectionRays, 0u);
        else EXPECT_GT(st.reflectionRays, 0u);
    }
}

TEST(Reflections, GrazingAndParallelRaysStayFinite) {
    auto rays = RayScene::build(glassScene());
    ASSERT_TRUE(rays);
    FrameEffects fx;
    fx.glass = fx.glassMarked = true;
    fx.rayBudget = 1 << 20;
    fx.haze = true;
    fx.visibility = 20;  // the shortest haze too
    for (double heading : {1.55, 1.5707963, 1.58, -1.5707963}) {  // along the pane (x axis)
        for (double z : {20.0 - 1e-4, 20.0 - 0.01}) {              // eye on / next to the glass plane's side
            Camera c = lookNorth(96, 64);
            c.eye = {0, z, 2};
            c.heading = heading;
            Image img(c.width, c.height);
            RayCounts counts;
            castFrame(**rays, c, img, counts, 1);
            FrameStats st;
            reflectionStage(rays->get(), c, fx, img, st);
            EXPECT_FALSE(hasGlassPixels(img));
            for (size_t i = 3; i < img.rgba.size(); i += 4) ASSERT_EQ(img.rgba[i], 255);
        }
    }
}

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
                if (std::max(std::abs(p.x), std::abs(p.y)) > 5 + 6.5) { EXPECT_GE(g.colors[i].x + 2, lit.x) << p.x << "," << p.y; }
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
    EXPECT_EQ(city.tiles[0].meshes[size_t(Material::Ground)].colors, copy.tiles[0].meshes[size_t(Material::Ground)].colors);
}

}  // namespace
}  // namespace vista
