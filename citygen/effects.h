// Effects: what a scene declares beyond plain prelit geometry (the `effects`
// object of the parameter file, stored with the parameters in the scene file).
//
// Contract: an effect is on when it is present (its std::optional holds a
// value); its fields are its parameters, each with a unit and a range listed
// by effectSpecs() (what docs/reference/params.md shows). parseEffectsJson() rejects
// unknown effect names, unknown fields, non-objects, non-numbers and values
// out of range with a message naming the effect, the field, the value and the
// range (and listing the known names). effectsToJson() is canonical (every
// field, fixed order); it is "{}" when nothing is declared, and the parameter
// JSON omits the key then, so a city without effects is byte-identical to one
// generated before effects existed.
// Baked effects (sun_shadows, ambient_occlusion, night's lights, materials)
// change the prelit colours at generation and cost nothing per frame; run-time
// effects (haze, glass reflections, night's sky) are applied per frame by
// every renderer, and only where they are on screen.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "foundation/status.h"

namespace vista {

struct SunShadowsEffect {
    double softness_deg = 0.53;  // angular diameter of the sun disc (0 = hard shadows)
    int samples = 8;             // shadow rays per shaded point
    double resolution_m = 2.0;   // surfaces are refined down to this edge length where shadows change
};
struct AmbientOcclusionEffect {
    int samples = 16;           // hemisphere rays per shaded point
    double radius_m = 6.0;      // occluders farther than this do not darken
    double strength = 0.8;      // 0 = no darkening, 1 = ambient fully scaled by the open share
    double resolution_m = 2.0;  // refinement edge length where occlusion changes
};
struct HazeEffect {
    double visibility_m = 1500.0;  // meteorological visibility: contrast falls to 2 % at this distance
};
struct GlassEffect {
    double reflectance = 0.2;  // reflectance at normal incidence (Schlick F0); 1 at grazing angles
    int ray_budget = 50000;    // reflection rays per frame at most (0 = base colour only)
};
struct NightEffect {
    double lit_share = 0.35;               // share of windows lit from inside
    double street_light_spacing_m = 30.0;  // distance between street lights along streets (0 = none)
    double light_radius_m = 14.0;          // radius of a street light's pool of light
};
struct MaterialsEffect {
    double variety = 1.0;  // 0 = the one default palette, 1 = full palettes by district and building type
};

enum class EffectId { SunShadows, AmbientOcclusion, Haze, Glass, Night, Materials, Count };
constexpr int kEffectCount = int(EffectId::Count);
const char* effectName(EffectId e);  // "sun_shadows", ...
bool effectIsBaked(EffectId e);      // true: computed at generation (prelit colours)
std::string effectNames();           // "sun_shadows, ambient_occlusion, ..."
bool findEffect(const std::string& name, EffectId& out);

struct Effects {
    std::optional<SunShadowsEffect> sun_shadows;
    std::optional<AmbientOcclusionEffect> ambient_occlusion;
    std::optional<HazeEffect> haze;
    std::optional<GlassEffect> glass;
    std::optional<NightEffect> night;
    std::optional<MaterialsEffect> materials;

    bool has(EffectId e) const;
    void clear(EffectId e);
    void enable(EffectId e);  // with default parameters (keeps existing ones)
    bool any() const;
    std::string list() const;  // declared names, comma separated ("none" when empty)
    bool operator==(const Effects& o) const;
};

struct EffectFieldSpec {
    EffectId effect;
    const char* name;
    const char* unit;
    double min, max, defaultValue;
    bool integer;
    const char* help;
};
const std::vector<EffectFieldSpec>& effectSpecs();

// `text` is a JSON object {name: {field: number, ...}, ...}; `source` names
// the input in messages.
Result<Effects> parseEffectsJson(const std::string& text, const std::string& source);
// Checks every declared field against its range (for hand-filled structs).
Status validateEffects(const Effects& e);
std::string effectsToJson(const Effects& e);

}  // namespace vista
