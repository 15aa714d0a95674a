// Effects declaration (citygen/effects.h): absent means none, round trips, bad declarations.
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
        for (const auto& s : c.mustSay)
            EXPECT_NE(r.status().message().find(s), std::string::npos) << c.json << " -> " << r.status().message();
    }
}

}  // namespace
}  // namespace vista
