// City generation parameters: the single input of the generator.
//
// Contract: every field has a documented unit, default and allowed range
// (see kParamSpecs in params.cpp, which is also what docs/reference/params.md lists).
// parseParamsJson() rejects unknown keys, wrong types, out-of-range values and
// malformed JSON (reporting line and column) with a Status naming the field.
// validateParams() checks a struct filled by hand or by command-line flags.
// Units: metres, degrees at this user-facing boundary only (converted inside).
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "citygen/effects.h"
#include "citygen/geodesy.h"
#include "foundation/status.h"

namespace vista {

struct CityParams {
    // Identity and extent.
    uint64_t seed = 1;
    double size_m = 2000.0;      // side of the square city area, centred on the origin
    double origin_x = 0.0;       // world position of the city centre (metres, east)
    double origin_y = 0.0;       // world position of the city centre (metres, north)
    double tile_size_m = 250.0;  // side of the square spatial tiles of the output
    int threads = 0;             // 0 = all hardware threads; output never depends on it

    // Population density map: peak at the centre, falling off with distance.
    double centre_density = 1.0;       // 0..1 density at the centre
    double density_radius_m = 1400.0;  // e-folding radius of the density falloff
    double park_fraction = 0.08;       // share of blocks that become parks (weighted by low density)

    // Street network.
    double highway_spacing_m = 1600.0;  // mean distance between highways
    double arterial_spacing_m = 420.0;  // mean distance between arterials
    double local_spacing_m = 110.0;     // mean block side length of local streets
    double pattern_grid = 0.5;          // mixing weights of street patterns by region (normalised)
    double pattern_radial = 0.2;
    double pattern_organic = 0.3;
    double min_segment_m = 12.0;  // no street edge shorter than this
    double min_angle_deg = 25.0;  // minimum angle between edges at an intersection
    double snap_radius_m = 14.0;  // new ends snap to intersections within this radius
    double sidewalk_m = 3.0;      // sidewalk width on each side of a street

    // Buildings.
    int detail = 2;  // 0 = plain boxes, 1 = window bands, 2 = window recesses, 3 = + sills
    double floor_height_m = 3.2;
    int max_floors = 45;  // tallest towers (downtown)
    int min_floors = 1;
    double setback_m = 2.0;     // footprint setback from the lot boundary (suburbs get more)
    double lot_width_m = 22.0;  // typical lot frontage
    double window_width_m = 1.4;
    double window_recess_m = 0.25;

    // Trees.
    double street_tree_spacing_m = 30.0;  // 0 = no street trees
    double park_tree_density = 0.002;     // trees per square metre of park

    // Parked cars (parked_cars.h).
    double parked_car_share = 0.3;  // share of the free parking slots (curbs, lots) that hold a car; 0 = none

    // Terrain.
    double hills_amplitude_m = 0.0;  // 0 = flat ground
    double hills_wavelength_m = 1500.0;

    // Lighting (prelit vertex colours).
    double sun_azimuth_deg = 135.0;  // clockwise from north
    double sun_elevation_deg = 40.0;
    double ambient = 0.45;  // 0..1 share of ambient light

    // Effects the scene declares (citygen/effects.h); none by default.
    Effects effects;

    // Where the city frame lies on Earth (citygen/geodesy.h): set by the OSM
    // import, absent for a generated city. JSON: "geo": {"projection": "tmerc",
    // "lat0_deg": -90..90, "lon0_deg": -180..180}, all three keys required.
    std::optional<GeoReference> geo;
};

// Describes one parameter for validation, help text and docs.
struct ParamSpec {
    const char* name;
    const char* unit;
    double min;
    double max;
    const char* help;
};
const std::vector<ParamSpec>& paramSpecs();

// Checks every field against its range. Error message format:
//   "parameter 'size_m' = 0 is out of range [100, 64000] (metres)"
Status validateParams(const CityParams& p);

// A city built whole in memory (generateCity, single-file output) is capped at
// kMaxSingleFileSizeM; up to kMaxPagedSizeM (the size_m range) it is generated
// region by region as a paged city (citygen/regions.h). checkSingleFileSize()
// returns an error naming 'size_m', the value, the single-file range and the
// paged alternative above the cap.
constexpr double kMaxSingleFileSizeM = 16000.0;
constexpr double kMaxPagedSizeM = 64000.0;
Status checkSingleFileSize(const CityParams& p);

// Parses a JSON object of parameters on top of `base` (keys absent keep base values).
// `source` names the input in messages (a file name). Unknown keys are errors.
Result<CityParams> parseParamsJson(const std::string& text, const std::string& source,
                                   const CityParams& base = CityParams());
Result<CityParams> loadParamsFile(const std::string& path, const CityParams& base = CityParams());

// Canonical JSON of all fields (sorted keys, stable formatting): stored in the
// output file and used in determinism hashes. Omits `threads`, which never
// changes the output, `effects` when none is declared and `geo` when absent.
std::string paramsToJson(const CityParams& p);

}  // namespace vista
