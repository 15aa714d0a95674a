#include "citygen/params.h"
#include "citygen/json_input.h"
#include "foundation/format.h"
#include "foundation/input_file.h"
#include "foundation/number_text.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <nlohmann/json.hpp>

namespace vista {
namespace {

enum class Kind { Double, Int, U64 };
struct Field {
    ParamSpec spec;
    Kind kind;
    double CityParams::*d = nullptr;
    int CityParams::*i = nullptr;
    uint64_t CityParams::*u = nullptr;
};

Field D(const char* n, double CityParams::*m, const char* unit, double lo, double hi, const char* help) {
    Field f{{n, unit, lo, hi, help}, Kind::Double};
    f.d = m;
    return f;
}
Field I(const char* n, int CityParams::*m, const char* unit, double lo, double hi, const char* help) {
    Field f{{n, unit, lo, hi, help}, Kind::Int};
    f.i = m;
    return f;
}

const std::vector<Field>& fields() {
    static const std::vector<Field> kFields = [] {
        std::vector<Field> v;
        Field seed{{"seed", "", 0, 18446744073709551615.0, "random seed; every stream derives from (seed, entity id)"},
                   Kind::U64};
        seed.u = &CityParams::seed;
        v.push_back(seed);
        v.push_back(D("size_m", &CityParams::size_m, "metres", 100, 64000,
                      "side of the square city area (above 16000 only as paged output)"));
        v.push_back(
            D("origin_x", &CityParams::origin_x, "metres", -2e7, 2e7, "world east position of the city centre"));
        v.push_back(
            D("origin_y", &CityParams::origin_y, "metres", -2e7, 2e7, "world north position of the city centre"));
        v.push_back(D("tile_size_m", &CityParams::tile_size_m, "metres", 50, 2000, "side of the square output tiles"));
        v.push_back(
            I("threads", &CityParams::threads, "", 0, 256, "worker threads (0 = all); output does not depend on it"));
        v.push_back(D("centre_density", &CityParams::centre_density, "", 0, 1, "population density at the centre"));
        v.push_back(D("density_radius_m", &CityParams::density_radius_m, "metres", 50, 1e5,
                      "e-folding radius of the density falloff"));
        v.push_back(D("park_fraction", &CityParams::park_fraction, "", 0, 0.9, "share of blocks that become parks"));
        v.push_back(D("highway_spacing_m", &CityParams::highway_spacing_m, "metres", 200, 1e5,
                      "mean distance between highways"));
        v.push_back(D("arterial_spacing_m", &CityParams::arterial_spacing_m, "metres", 100, 1e4,
                      "mean distance between arterials"));
        v.push_back(
            D("local_spacing_m", &CityParams::local_spacing_m, "metres", 40, 1000, "mean block side of local streets"));
        v.push_back(D("pattern_grid", &CityParams::pattern_grid, "", 0, 1, "weight of grid street patterns"));
        v.push_back(D("pattern_radial", &CityParams::pattern_radial, "", 0, 1, "weight of radial street patterns"));
        v.push_back(D("pattern_organic", &CityParams::pattern_organic, "", 0, 1, "weight of organic street patterns"));
        v.push_back(D("min_segment_m", &CityParams::min_segment_m, "metres", 1, 200, "minimum street edge length"));
        v.push_back(
            D("min_angle_deg", &CityParams::min_angle_deg, "degrees", 5, 80, "minimum angle between edges at a node"));
        v.push_back(
            D("snap_radius_m", &CityParams::snap_radius_m, "metres", 0, 200, "snap radius to existing intersections"));
        v.push_back(D("sidewalk_m", &CityParams::sidewalk_m, "metres", 0, 10, "sidewalk width on each side"));
        v.push_back(I("detail", &CityParams::detail, "", 0, 3,
                      "facade detail: 0 boxes, 1 bands, 2 window recesses, 3 + sills"));
        v.push_back(D("floor_height_m", &CityParams::floor_height_m, "metres", 2.2, 6, "storey height"));
        v.push_back(I("max_floors", &CityParams::max_floors, "", 1, 200, "floors of the tallest towers"));
        v.push_back(I("min_floors", &CityParams::min_floors, "", 1, 200, "floors of the smallest houses"));
        v.push_back(D("setback_m", &CityParams::setback_m, "metres", 0, 30, "footprint setback from the lot boundary"));
        v.push_back(D("lot_width_m", &CityParams::lot_width_m, "metres", 6, 200, "typical lot frontage"));
        v.push_back(D("window_width_m", &CityParams::window_width_m, "metres", 0.4, 5, "window width"));
        v.push_back(D("window_recess_m", &CityParams::window_recess_m, "metres", 0, 2, "depth of window recesses"));
        v.push_back(D("street_tree_spacing_m", &CityParams::street_tree_spacing_m, "metres", 0, 500,
                      "street tree spacing (0 = none)"));
        v.push_back(
            D("park_tree_density", &CityParams::park_tree_density, "1/m^2", 0, 0.05, "park trees per square metre"));
        v.push_back(D("parked_car_share", &CityParams::parked_car_share, "", 0, 1,
                      "share of the free parking slots (curbs, lots) holding a parked car (0 = none)"));
        v.push_back(D("hills_amplitude_m", &CityParams::hills_amplitude_m, "metres", 0, 200,
                      "terrain height amplitude (0 = flat)"));
        v.push_back(
            D("hills_wavelength_m", &CityParams::hills_wavelength_m, "metres", 100, 1e5, "terrain feature size"));
        v.push_back(
            D("sun_azimuth_deg", &CityParams::sun_azimuth_deg, "degrees", 0, 360, "sun azimuth, clockwise from north"));
        v.push_back(D("sun_elevation_deg", &CityParams::sun_elevation_deg, "degrees", 1, 90,
                      "sun elevation above the horizon"));
        v.push_back(D("ambient", &CityParams::ambient, "", 0, 1, "ambient share of the prelit lighting"));
        return v;
    }();
    return kFields;
}

std::string rangeMessage(const ParamSpec& s, const std::string& value) {
    // The seed's range is every uint64_t: printed exactly, not as the double 1.8446744073709552e+19.
    const std::string hi = s.max >= 18446744073709551615.0 ? "18446744073709551615" : exactDecimal(s.max);
    std::string m = "parameter '" + std::string(s.name) + "' = " + value + " is out of range [" + exactDecimal(s.min) +
                    ", " + hi + "]";
    if (*s.unit) m += std::string(" (") + s.unit + ")";
    return m;
}

const ParamSpec kGeoLat{"geo.lat0_deg", "degrees", -90, 90, "WGS84 latitude of the city frame's origin"};
const ParamSpec kGeoLon{"geo.lon0_deg", "degrees", -180, 180, "WGS84 longitude of the city frame's origin"};

Status validateGeo(const GeoReference& g) {
    for (auto [spec, v] : {std::pair<const ParamSpec*, double>{&kGeoLat, g.lat0_deg}, {&kGeoLon, g.lon0_deg}})
        if (!std::isfinite(v) || v < spec->min || v > spec->max)
            return Status::error(rangeMessage(*spec, exactDecimal(v)));
    return Status::ok();
}

// The "geo" object: {"projection": "tmerc", "lat0_deg": .., "lon0_deg": ..}, every key required.
Result<GeoReference> parseGeo(const nlohmann::json& j, const std::string& source) {
    const std::string shape =
        std::string("{\"projection\": \"") + kGeoProjection + "\", \"lat0_deg\": .., \"lon0_deg\": ..}";
    if (!j.is_object()) return Status::error(source + ": parameter 'geo' must be an object " + shape);
    GeoReference g;
    bool projection = false, lat = false, lon = false;
    for (auto it = j.begin(); it != j.end(); ++it) {
        const std::string& key = it.key();
        const auto& val = it.value();
        if (!key.empty() && key[0] == '_') continue;
        if (key == "projection") {
            if (!val.is_string() || val.get<std::string>() != kGeoProjection)
                return Status::error(source + ": parameter 'geo.projection' = " + val.dump() +
                                     " is not supported (known: \"" + kGeoProjection + "\")");
            projection = true;
        } else if (key == "lat0_deg" || key == "lon0_deg") {
            if (!val.is_number())
                return Status::error(source + ": parameter 'geo." + key + "' must be a number, got " + val.dump());
            (key == "lat0_deg" ? g.lat0_deg : g.lon0_deg) = val.get<double>();
            (key == "lat0_deg" ? lat : lon) = true;
        } else {
            return Status::error(source + ": unknown parameter 'geo." + key +
                                 "' (known: projection, lat0_deg, lon0_deg)");
        }
    }
    if (!projection || !lat || !lon)
        return Status::error(source + ": parameter 'geo' lacks '" +
                             (!projection ? "projection"
                              : !lat      ? "lat0_deg"
                                          : "lon0_deg") +
                             "' (it must be " + shape + ")");
    if (Status s = validateGeo(g); !s) return Status::error(source + ": " + s.message());
    return g;
}

}  // namespace

const std::vector<ParamSpec>& paramSpecs() {
    static const std::vector<ParamSpec> kSpecs = [] {
        std::vector<ParamSpec> v;
        for (const auto& f : fields()) v.push_back(f.spec);
        return v;
    }();
    return kSpecs;
}

Status validateParams(const CityParams& p) {
    for (const auto& f : fields()) {
        double v = 0;
        switch (f.kind) {
            case Kind::Double: v = p.*(f.d); break;
            case Kind::Int: v = p.*(f.i); break;
            case Kind::U64: continue;
        }
        if (!std::isfinite(v) || v < f.spec.min || v > f.spec.max)
            return Status::error(rangeMessage(f.spec, exactDecimal(v)));
    }
    if (p.min_floors > p.max_floors)
        return Status::error("parameter 'min_floors' = " + std::to_string(p.min_floors) +
                             " must not exceed 'max_floors' = " + std::to_string(p.max_floors));
    if (p.pattern_grid + p.pattern_radial + p.pattern_organic <= 0)
        return Status::error("parameters 'pattern_grid', 'pattern_radial', 'pattern_organic' must not all be 0");
    if (Status e = validateEffects(p.effects); !e) return e;
    if (p.geo) VISTA_RETURN_IF_ERROR(validateGeo(*p.geo));
    if (p.local_spacing_m > p.arterial_spacing_m)
        return Status::error("parameter 'local_spacing_m' = " + exactDecimal(p.local_spacing_m) +
                             " must not exceed 'arterial_spacing_m' = " + exactDecimal(p.arterial_spacing_m));
    return Status::ok();
}

Status checkSingleFileSize(const CityParams& p) {
    if (p.size_m > kMaxSingleFileSizeM)
        return Status::error("parameter 'size_m' = " + exactDecimal(p.size_m) + " is out of range [100, " +
                             exactDecimal(kMaxSingleFileSizeM) +
                             "] for a single-file city (metres); larger cities (up to " + exactDecimal(kMaxPagedSizeM) +
                             ") are written as a paged city: vista gen -o DIR.paged");
    return Status::ok();
}

Result<CityParams> parseParamsJson(const std::string& text, const std::string& source, const CityParams& base) {
    auto input = parseJsonInput(text, source);
    if (!input) return input.status();
    const nlohmann::json& j = input->doc;
    if (!j.is_object()) return Status::error(source + ": parameters must be a JSON object");
    CityParams p = base;
    for (auto it = j.begin(); it != j.end(); ++it) {
        const std::string& key = it.key();
        if (!key.empty() && key[0] == '_') continue;  // "_comment" and the like
        if (key == "effects") {
            auto e = parseEffectsJson(it.value().dump(), source);
            if (!e) return e.status();
            p.effects = *e;
            continue;
        }
        if (key == "geo") {
            auto g = parseGeo(it.value(), source);
            if (!g) return g.status();
            p.geo = *g;
            continue;
        }
        const Field* f = nullptr;
        for (const auto& cand : fields())
            if (key == cand.spec.name) f = &cand;
        if (!f) {
            std::string known;
            for (const auto& cand : fields()) known += std::string(known.empty() ? "" : ", ") + cand.spec.name;
            return Status::error(source + ": unknown parameter '" + echoText(key) + "' (known: " + known +
                                 ", effects, geo)");
        }
        const auto& val = it.value();
        if (!val.is_number())
            return Status::error(source + ": parameter '" + key + "' must be a number, got " + echoText(val.dump()));
        const std::string written = input->textOf("/" + key, val);
        if (f->kind == Kind::Double) {
            p.*(f->d) = val.get<double>();
        } else {
            // From the text as written: 2^64 is out of range, not a double that rounds; 2.5 is not an integer.
            if (written.find_first_of(".eE") != std::string::npos)
                return Status::error(source + ": parameter '" + key + "' must be an integer, got " + written);
            if (f->kind == Kind::U64) {
                auto v = parseUnsignedText(key, written, 0, UINT64_MAX);
                if (!v) return Status::error(source + ": " + rangeMessage(f->spec, written));
                p.*(f->u) = *v;
            } else {
                auto v = parseSignedText(key, written, int64_t(f->spec.min), int64_t(f->spec.max));
                if (!v) return Status::error(source + ": " + rangeMessage(f->spec, written));
                p.*(f->i) = int(*v);
            }
        }
    }
    Status s = validateParams(p);
    if (!s) return Status::error(source + ": " + s.message());
    return p;
}

Result<CityParams> loadParamsFile(const std::string& path, const CityParams& base) {
    auto text = readInputFile("parameter file", path, kMaxParamsFileBytes);
    if (!text) return text.status();
    return parseParamsJson(*text, path, base);
}

std::string paramsToJson(const CityParams& p) {
    nlohmann::ordered_json j;
    for (const auto& f : fields()) {
        if (std::string(f.spec.name) == "threads") continue;  // never part of the output
        switch (f.kind) {
            case Kind::Double: j[f.spec.name] = p.*(f.d); break;
            case Kind::Int: j[f.spec.name] = p.*(f.i); break;
            case Kind::U64: j[f.spec.name] = p.*(f.u); break;
        }
    }
    if (p.effects.any()) j["effects"] = nlohmann::ordered_json::parse(effectsToJson(p.effects));
    if (p.geo)
        j["geo"] = {{"projection", kGeoProjection}, {"lat0_deg", p.geo->lat0_deg}, {"lon0_deg", p.geo->lon0_deg}};
    return j.dump(1);
}

}  // namespace vista
