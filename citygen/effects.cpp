#include "citygen/effects.h"

#include <cmath>
#include <sstream>
#include <nlohmann/json.hpp>

#include "citygen/json_input.h"
#include "foundation/number_text.h"

namespace vista {
namespace {

struct Field {
    EffectFieldSpec spec;
    double (*get)(const Effects&);
    void (*set)(Effects&, double);
};

#define VISTA_EFFECT_FIELD(E, member, field, unit, lo, hi, def, integer, help)                        \
    Field {                                                                                           \
        {EffectId::E, #field, unit, lo, hi, def, integer, help},                                      \
            [](const Effects& e) { return double(e.member->field); },                                 \
            [](Effects& e, double v) { e.member->field = static_cast<decltype(e.member->field)>(v); } \
    }

const std::vector<Field>& fields() {
    static const std::vector<Field> kFields = {
        VISTA_EFFECT_FIELD(SunShadows, sun_shadows, softness_deg, "degrees", 0, 10, 0.53, false,
                           "angular diameter of the sun disc (0 = hard shadows)"),
        VISTA_EFFECT_FIELD(SunShadows, sun_shadows, samples, "", 1, 256, 8, true, "shadow rays per shaded point"),
        VISTA_EFFECT_FIELD(SunShadows, sun_shadows, resolution_m, "metres", 0.1, 50, 2.0, false,
                           "surfaces are refined down to this edge length where the shadow changes"),
        VISTA_EFFECT_FIELD(AmbientOcclusion, ambient_occlusion, samples, "", 1, 1024, 16, true,
                           "hemisphere rays per shaded point"),
        VISTA_EFFECT_FIELD(AmbientOcclusion, ambient_occlusion, radius_m, "metres", 0.1, 100, 6.0, false,
                           "occluders farther than this do not darken"),
        VISTA_EFFECT_FIELD(AmbientOcclusion, ambient_occlusion, strength, "", 0, 1, 0.8, false,
                           "0 = no darkening, 1 = ambient light scaled by the open share of the sky"),
        VISTA_EFFECT_FIELD(AmbientOcclusion, ambient_occlusion, resolution_m, "metres", 0.1, 50, 2.0, false,
                           "surfaces are refined down to this edge length where occlusion changes"),
        VISTA_EFFECT_FIELD(Haze, haze, visibility_m, "metres", 20, 1e6, 1500.0, false,
                           "meteorological visibility (contrast falls to 2 %); nothing beyond it is traced or drawn"),
        VISTA_EFFECT_FIELD(Glass, glass, reflectance, "", 0, 1, 0.2, false,
                           "window reflectance at normal incidence (Schlick F0; 1 at grazing angles)"),
        VISTA_EFFECT_FIELD(Glass, glass, ray_budget, "rays/frame", 0, 1e8, 50000, true,
                           "reflection rays per frame at most (0 = base colour only)"),
        VISTA_EFFECT_FIELD(Night, night, lit_share, "", 0, 1, 0.35, false, "share of windows lit from inside"),
        VISTA_EFFECT_FIELD(Night, night, street_light_spacing_m, "metres", 0, 500, 30.0, false,
                           "distance between street lights along streets (0 = none; else at least 5)"),
        VISTA_EFFECT_FIELD(Night, night, light_radius_m, "metres", 1, 100, 14.0, false,
                           "radius of a street light's pool of light"),
        VISTA_EFFECT_FIELD(Materials, materials, variety, "", 0, 1, 1.0, false,
                           "0 = one palette; 1 = full facade and roof palettes by district and building type"),
    };
    return kFields;
}
#undef VISTA_EFFECT_FIELD

const char* const kNames[kEffectCount] = {"sun_shadows", "ambient_occlusion", "haze", "glass", "night", "materials"};

std::string fmt(double v) {
    std::ostringstream s;
    s.precision(15);
    s << v;
    return s.str();
}

std::string fieldNames(EffectId e) {
    std::string s;
    for (const auto& f : fields())
        if (f.spec.effect == e) s += std::string(s.empty() ? "" : ", ") + f.spec.name;
    return s;
}

std::string rangeMessage(const EffectFieldSpec& s, const std::string& value) {
    std::string m = std::string("effect '") + kNames[int(s.effect)] + "' field '" + s.name + "' = " + value +
                    " is out of range [" + fmt(s.min) + ", " + fmt(s.max) + "]";
    if (*s.unit) m += std::string(" (") + s.unit + ")";
    return m;
}

Status checkField(const Field& f, double v) {
    if (!std::isfinite(v) || v < f.spec.min || v > f.spec.max) return Status::error(rangeMessage(f.spec, fmt(v)));
    if (f.spec.integer && v != std::floor(v))
        return Status::error(rangeMessage(f.spec, fmt(v)) + "; must be an integer");
    return Status::ok();
}

}  // namespace

const char* effectName(EffectId e) { return int(e) >= 0 && int(e) < kEffectCount ? kNames[int(e)] : "?"; }

bool effectIsBaked(EffectId e) {
    return e == EffectId::SunShadows || e == EffectId::AmbientOcclusion || e == EffectId::Materials ||
           e == EffectId::Night;
}

std::string effectNames() {
    std::string s;
    for (int i = 0; i < kEffectCount; ++i) s += std::string(i ? ", " : "") + kNames[i];
    return s;
}

bool findEffect(const std::string& name, EffectId& out) {
    for (int i = 0; i < kEffectCount; ++i)
        if (name == kNames[i]) {
            out = EffectId(i);
            return true;
        }
    return false;
}

bool Effects::has(EffectId e) const {
    switch (e) {
        case EffectId::SunShadows: return sun_shadows.has_value();
        case EffectId::AmbientOcclusion: return ambient_occlusion.has_value();
        case EffectId::Haze: return haze.has_value();
        case EffectId::Glass: return glass.has_value();
        case EffectId::Night: return night.has_value();
        case EffectId::Materials: return materials.has_value();
        case EffectId::Count: break;
    }
    return false;
}

void Effects::clear(EffectId e) {
    switch (e) {
        case EffectId::SunShadows: sun_shadows.reset(); break;
        case EffectId::AmbientOcclusion: ambient_occlusion.reset(); break;
        case EffectId::Haze: haze.reset(); break;
        case EffectId::Glass: glass.reset(); break;
        case EffectId::Night: night.reset(); break;
        case EffectId::Materials: materials.reset(); break;
        case EffectId::Count: break;
    }
}

void Effects::enable(EffectId e) {
    switch (e) {
        case EffectId::SunShadows:
            if (!sun_shadows) sun_shadows.emplace();
            break;
        case EffectId::AmbientOcclusion:
            if (!ambient_occlusion) ambient_occlusion.emplace();
            break;
        case EffectId::Haze:
            if (!haze) haze.emplace();
            break;
        case EffectId::Glass:
            if (!glass) glass.emplace();
            break;
        case EffectId::Night:
            if (!night) night.emplace();
            break;
        case EffectId::Materials:
            if (!materials) materials.emplace();
            break;
        case EffectId::Count: break;
    }
}

bool Effects::any() const {
    for (int i = 0; i < kEffectCount; ++i)
        if (has(EffectId(i))) return true;
    return false;
}

std::string Effects::list() const {
    std::string s;
    for (int i = 0; i < kEffectCount; ++i)
        if (has(EffectId(i))) s += std::string(s.empty() ? "" : ",") + kNames[i];
    return s.empty() ? "none" : s;
}

bool Effects::operator==(const Effects& o) const { return effectsToJson(*this) == effectsToJson(o); }

const std::vector<EffectFieldSpec>& effectSpecs() {
    static const std::vector<EffectFieldSpec> kSpecs = [] {
        std::vector<EffectFieldSpec> v;
        for (const auto& f : fields()) v.push_back(f.spec);
        return v;
    }();
    return kSpecs;
}

Status validateEffects(const Effects& e) {
    for (const auto& f : fields()) {
        if (!e.has(f.spec.effect)) continue;
        Status s = checkField(f, f.get(e));
        if (!s) return s;
    }
    if (e.night && e.night->street_light_spacing_m > 0 && e.night->street_light_spacing_m < 5)
        return Status::error("effect 'night' field 'street_light_spacing_m' = " + fmt(e.night->street_light_spacing_m) +
                             " is out of range: 0 (no street lights) or [5, 500] (metres)");
    return Status::ok();
}

Result<Effects> parseEffectsJson(const std::string& text, const std::string& source) {
    // The same rules as a parameter file: nesting bounded, duplicate keys refused.
    auto input = parseJsonInput(text, source);
    if (!input) return input.status();
    const nlohmann::json& j = input->doc;
    if (!j.is_object())
        return Status::error(source + ": 'effects' must be an object of effects (known: " + effectNames() + ")");
    Effects out;
    for (auto it = j.begin(); it != j.end(); ++it) {
        EffectId id;
        if (!findEffect(it.key(), id))
            return Status::error(source + ": unknown effect '" + echoText(it.key()) + "' (known: " + effectNames() +
                                 ")");
        const auto& obj = it.value();
        if (!obj.is_object())
            return Status::error(source + ": effect '" + it.key() + "' must be an object of its parameters (" +
                                 fieldNames(id) + "), e.g. {} for the defaults");
        out.enable(id);
        for (auto f = obj.begin(); f != obj.end(); ++f) {
            const Field* field = nullptr;
            for (const auto& cand : fields())
                if (cand.spec.effect == id && f.key() == cand.spec.name) field = &cand;
            if (!field)
                return Status::error(source + ": unknown field '" + echoText(f.key()) + "' of effect '" + it.key() +
                                     "' (known: " + fieldNames(id) + ")");
            if (!f.value().is_number())
                return Status::error(source + ": effect '" + it.key() + "' field '" + f.key() +
                                     "' must be a number, got " + echoText(f.value().dump()));
            double v = f.value().get<double>();
            Status s = checkField(*field, v);
            if (!s) return Status::error(source + ": " + s.message());
            field->set(out, v);
        }
    }
    Status s = validateEffects(out);
    if (!s) return Status::error(source + ": " + s.message());
    return out;
}

std::string effectsToJson(const Effects& e) {
    nlohmann::ordered_json j = nlohmann::ordered_json::object();
    for (int i = 0; i < kEffectCount; ++i) {
        if (!e.has(EffectId(i))) continue;
        nlohmann::ordered_json o = nlohmann::ordered_json::object();
        for (const auto& f : fields()) {
            if (f.spec.effect != EffectId(i)) continue;
            if (f.spec.integer) o[f.spec.name] = int64_t(f.get(e));
            else o[f.spec.name] = f.get(e);
        }
        j[kNames[i]] = o;
    }
    return j.dump();
}

}  // namespace vista
