// importOsm(): highway=* ways from .osm / .osm.pbf via libosmium, projected
// equirectangularly about the data's bbox centre, then planarize().
#include <cmath>
#include <cstring>
#include <exception>
#include <fstream>

#include <osmium/handler.hpp>
#include <osmium/handler/node_locations_for_ways.hpp>
#include <osmium/index/map/flex_mem.hpp>
#include <osmium/io/any_input.hpp>
#include <osmium/visitor.hpp>

#include "citygen/streets.h"
#include "foundation/units.h"

namespace vista {

namespace {

using Index = osmium::index::map::FlexMem<osmium::unsigned_object_id_type, osmium::Location>;
using LocationHandler = osmium::handler::NodeLocationsForWays<Index>;

bool classify(const char* hw, RoadClass& cls) {
    static const char* highway[] = {"motorway", "motorway_link", "trunk", "trunk_link", "primary", "primary_link"};
    static const char* arterial[] = {"secondary", "secondary_link", "tertiary", "tertiary_link"};
    static const char* skip[] = {"footway", "path", "cycleway", "steps", "bridleway", "pedestrian", "corridor",
                                 "proposed", "construction", "platform", "elevator", "abandoned", "raceway"};
    for (const char* s : skip) if (!std::strcmp(hw, s)) return false;
    for (const char* s : highway) if (!std::strcmp(hw, s)) { cls = RoadClass::Highway; return true; }
    for (const char* s : arterial) if (!std::strcmp(hw, s)) { cls = RoadClass::Arterial; return true; }
    cls = RoadClass::Local;
    return true;
}

struct Way {
    std::vector<glm::dvec2> lonlat;
    RoadClass cls;
};

struct WayCollector : public osmium::handler::Handler {
    std::vector<Way> ways;
    void way(const osmium::Way& w) {
        const char* hw = w.tags()["highway"];
        if (!hw) return;
        RoadClass cls;
        if (!classify(hw, cls)) return;
        Way out;
        out.cls = cls;
        for (const auto& nr : w.nodes()) {
            const osmium::Location& loc = nr.location();
            if (!loc.valid()) continue;  // node missing from the file
            out.lonlat.emplace_back(loc.lon(), loc.lat());
        }
        if (!out.lonlat.empty()) ways.push_back(std::move(out));
    }
};

}  // namespace

Result<StreetGraph> importOsm(const std::string& path, const CityParams& params) {
    {
        std::ifstream probe(path, std::ios::binary);
        if (!probe) return Status::error("OSM file '" + path + "' cannot be opened");
    }
    WayCollector collector;
    try {
        osmium::io::File file(path);
        osmium::io::Reader reader(file, osmium::osm_entity_bits::node | osmium::osm_entity_bits::way);
        Index index;
        LocationHandler locations(index);
        locations.ignore_errors();
        osmium::apply(reader, locations, collector);
        reader.close();
    } catch (const std::exception& e) {
        return Status::error("OSM file '" + path + "' could not be read: " + e.what());
    }
    if (collector.ways.empty())
        return Status::error("OSM file '" + path + "' contains no usable highway=* ways (roads with node locations)");
    double lonMin = 1e300, lonMax = -1e300, latMin = 1e300, latMax = -1e300;
    for (const auto& w : collector.ways)
        for (const auto& p : w.lonlat) {
            lonMin = std::min(lonMin, p.x); lonMax = std::max(lonMax, p.x);
            latMin = std::min(latMin, p.y); latMax = std::max(latMax, p.y);
        }
    const double lon0 = 0.5 * (lonMin + lonMax), lat0 = 0.5 * (latMin + latMax);
    const double kEarthRadius = 6371008.8, kDeg = kPi / 180.0;
    const double cosLat = std::cos(lat0 * kDeg);
    std::vector<RawSegment> segs;
    for (const auto& w : collector.ways) {
        for (size_t k = 1; k < w.lonlat.size(); ++k) {
            auto proj = [&](const glm::dvec2& ll) {
                return glm::dvec2((ll.x - lon0) * kDeg * kEarthRadius * cosLat, (ll.y - lat0) * kDeg * kEarthRadius);
            };
            segs.push_back({proj(w.lonlat[k - 1]), proj(w.lonlat[k]), w.cls});
        }
    }
    StreetGraph g = planarize(segs, params.snap_radius_m, params.min_segment_m);
    if (g.edges.empty())
        return Status::error("OSM file '" + path + "' has highway ways but none longer than min_segment_m = " +
                             std::to_string(params.min_segment_m) + " m");
    return g;
}

}  // namespace vista
