// Tag parsing and completion of OSM building footprints; contracts in osm_buildings.h.
#include "citygen/osm_buildings.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string>

#include <tbb/parallel_for.h>

#include "citygen/building_geometry.h"
#include "citygen/polygon.h"
#include "citygen/terrain.h"
#include "foundation/hash.h"
#include "foundation/rng.h"
#include "foundation/units.h"

namespace vista {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kFoot_m = 0.3048;
constexpr double kDowntown = 0.65;  // as placeBuildings: denser areas get no houses
constexpr double kSuburb = 0.35;    // as placeBuildings: below this, houses
constexpr double kMinEaves_m = 0.5;

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
    return s;
}

// A plain non-negative decimal at the start of `s` ("12", "12.5", "12,5"); advances `s`.
bool leadingNumber(std::string_view& s, double& v) {
    std::string digits;
    size_t p = 0;
    bool any = false, dot = false;
    while (p < s.size()) {
        const char c = s[p];
        if (c >= '0' && c <= '9') {
            digits += c;
            any = true;
        } else if ((c == '.' || c == ',') && !dot) {
            digits += '.';
            dot = true;
        } else break;
        ++p;
    }
    if (!any || digits.size() > 24) return false;
    auto r = std::from_chars(digits.data(), digits.data() + digits.size(), v);
    if (r.ec != std::errc() || !std::isfinite(v)) return false;
    s.remove_prefix(p);
    return true;
}

bool pitched(RoofType r) { return r != RoofType::Flat; }

// Storeys of an untagged footprint: mapped buildings without height tags are mostly ordinary
// ones, so no towers: 4-8 downtown, 2-5 in between, 1-3 in the suburbs (as lots there), at most
// ~4 x the footprint's narrow side tall, within [min_floors, max_floors].
int untaggedFloors(Rng& rng, double density, double width, const CityParams& params) {
    int floors;
    if (density >= kDowntown) floors = 4 + int(rng.range(0, 4));
    else if (density >= kSuburb) floors = 2 + int(4.0 * std::pow(rng.uniform(), 1.5));
    else floors = std::min(3, 1 + int(rng.range(0, 2)) * int(rng.range(0, 1)) + int(rng.chance(0.5)));
    floors = std::min(floors, std::max(1, int(4.0 * width / params.floor_height_m)));
    const int lo = std::max(1, params.min_floors);
    return std::clamp(floors, lo, std::max(lo, params.max_floors));
}

RoofType toRoofType(OsmRoofShape s) {
    switch (s) {
        case OsmRoofShape::Gabled: return RoofType::Gabled;
        case OsmRoofShape::Hipped: return RoofType::Hipped;
        default: return RoofType::Flat;
    }
}

bool finitePositive(double v) { return std::isfinite(v) && v > 0; }

// Can meshBuilding build this pitched roof on the footprint (else it would fall back to flat)?
bool roofBuildable(const Building& b) {
    if (!b.holes.empty() || !(b.roof_height > 0)) return false;
    if (b.roof == RoofType::Hipped) {
        std::vector<std::vector<glm::dvec3>> faces;
        double maxT = 0;
        return hippedRoofFaces(b.footprint, faces, maxT) && maxT > 1e-6;
    }
    const OrientedBox box = orientedBox(b.footprint);
    if (!(box.halfV > 1e-3)) return false;
    FlaggedPolygon whole{b.footprint, std::vector<uint8_t>(b.footprint.size(), 1)};
    return splitPolygonByLine(whole, box.centre, box.u).size() >= 2;
}

Building resolveOne(const OsmFootprint& f, const CityParams& params, OsmBuildingStats& st) {
    Building b;
    b.lot = kNoLot;
    b.footprint = f.outer;
    b.holes = f.holes;
    b.source = f.source;
    b.osm_id = f.osm_id;
    const double storey = params.floor_height_m;
    Rng rng(params.seed, hashKeys(uint64_t(f.osm_id), uint64_t(f.source), f.ring), Stream::Buildings);
    double area = signedArea(f.outer);
    for (const auto& h : f.holes) area -= std::abs(signedArea(h));
    const OrientedBox box = orientedBox(f.outer);
    const double density = std::clamp(populationDensity(params, centroid(f.outer)), 0.0, 1.0);

    // 1. Storeys (estimate for the roof choice) and where the height comes from.
    const bool tagHeight = finitePositive(f.height_m), tagLevels = finitePositive(f.levels);
    int floors;
    if (tagHeight) {
        floors = std::max(1, int(std::lround(f.height_m / storey)));
        ++st.heightFromTag;
    } else if (tagLevels) {
        floors = std::max(1, int(std::lround(f.levels)));
        ++st.heightFromLevels;
    } else {
        floors = untaggedFloors(rng, density, 2.0 * box.halfV, params);
        ++st.heightProcedural;
    }
    // 2. Roof shape: the tag, else houses (low, small, outside downtown) pitched, the rest flat.
    if (f.roof != OsmRoofShape::Absent) {
        b.roof = toRoofType(f.roof);
        ++st.roofFromTag;
    } else {
        const double fill = area / std::max(1e-9, 4.0 * box.halfU * box.halfV);
        const bool house = floors <= 3 && area <= 350.0 && density < kDowntown && f.holes.empty();
        b.roof = !house                                                     ? RoofType::Flat
                 : (fill > 0.85 && f.outer.size() <= 6 && !rng.chance(0.3)) ? RoofType::Gabled
                                                                            : RoofType::Hipped;
        ++st.roofProcedural;
    }
    // 3. Roof height of pitched roofs: roof:height, else roof:levels storeys, else a seeded pitch.
    double rh = 0;
    if (pitched(b.roof)) {
        if (finitePositive(f.roof_height_m)) rh = f.roof_height_m;
        else if (finitePositive(f.roof_levels)) rh = f.roof_levels * storey;
        else rh = box.halfV * std::tan(rng.uniform(25.0, 40.0) * kPi / 180.0);
    }
    // 4. Wall bottom (min_height / building:min_level) and eaves.
    double minH = 0;
    if (std::isfinite(f.min_height_m)) minH = f.min_height_m;
    else if (std::isfinite(f.min_level)) minH = f.min_level * storey;
    double eaves;
    if (tagHeight) {
        const double top = f.height_m;
        if (rh > 0.8 * (top - minH)) rh = 0.5 * std::max(0.0, top - minH);  // roof taller than the building: halve
        eaves = top - rh;
    } else if (tagLevels) {
        eaves = f.levels * storey;
        if (!pitched(b.roof) && finitePositive(f.roof_levels)) eaves += f.roof_levels * storey;
        if (std::isfinite(f.min_level) && !std::isfinite(f.min_height_m)) eaves = std::max(eaves, minH + storey);
    } else {
        eaves = floors * storey + minH;
    }
    if (!(minH < eaves - kMinEaves_m)) minH = 0;  // a bottom at or above the eaves: on the ground
    eaves = std::max(eaves, kMinEaves_m);
    b.roof_height = pitched(b.roof) ? rh : 0.0;
    b.height = eaves;
    b.min_height = minH;
    // 5. Shapes the roof code cannot build: flat at the top height.
    if (pitched(b.roof) && !roofBuildable(b)) {
        b.height += b.roof_height;
        b.roof_height = 0;
        b.roof = RoofType::Flat;
        ++st.roofFallbackFlat;
    }
    if (!pitched(b.roof)) b.roof_height = 0;
    b.floors = std::max(1, int(std::lround((b.height - b.min_height) / storey)));
    if (tagLevels && !tagHeight) {
        const double lv = f.levels - (std::isfinite(f.min_level) ? f.min_level : 0.0);
        if (lv >= 1) b.floors = int(std::lround(lv));
    }
    double zmin = 1e300;
    for (const auto& p : f.outer) zmin = std::min(zmin, terrainHeight(params, p));
    b.base_z = std::isfinite(zmin) ? zmin : 0.0;
    return b;
}

struct Bounds {
    glm::dvec2 lo{1e300}, hi{-1e300};
    void add(const glm::dvec2& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    bool overlaps(const Bounds& o, double m = 0) const {
        return lo.x <= o.hi.x + m && o.lo.x <= hi.x + m && lo.y <= o.hi.y + m && o.lo.y <= hi.y + m;
    }
};
Bounds boundsOf(const Polygon2& p) {
    Bounds b;
    for (const auto& q : p) b.add(q);
    return b;
}

// Uniform grid of item bounding boxes (cell metres), for the overlap queries.
class BoxGrid {
public:
    BoxGrid(const std::vector<Bounds>& boxes, double cell) : _cell(cell) {
        for (const auto& b : boxes)
            if (b.lo.x <= b.hi.x) {
                _lo = glm::min(_lo, b.lo);
                _hi = glm::max(_hi, b.hi);
            }
        if (!(_lo.x <= _hi.x)) return;
        _nx = std::clamp(int((_hi.x - _lo.x) / cell) + 1, 1, 4096);
        _ny = std::clamp(int((_hi.y - _lo.y) / cell) + 1, 1, 4096);
        _cells.resize(size_t(_nx) * size_t(_ny));
        for (uint32_t i = 0; i < boxes.size(); ++i) {
            if (!(boxes[i].lo.x <= boxes[i].hi.x)) continue;
            forCells(boxes[i], [&](size_t c) { _cells[c].push_back(i); });
        }
    }
    // Calls f(item) once per item whose cells overlap `b` (ascending per cell; may repeat across cells).
    template <class F>
    void query(const Bounds& b, F f) const {
        if (_cells.empty()) return;
        forCells(b, [&](size_t c) {
            for (uint32_t i : _cells[c]) f(i);
        });
    }

private:
    template <class F>
    void forCells(const Bounds& b, F f) const {
        const int x0 = std::clamp(int(std::floor((b.lo.x - _lo.x) / _cell)), 0, _nx - 1);
        const int x1 = std::clamp(int(std::floor((b.hi.x - _lo.x) / _cell)), 0, _nx - 1);
        const int y0 = std::clamp(int(std::floor((b.lo.y - _lo.y) / _cell)), 0, _ny - 1);
        const int y1 = std::clamp(int(std::floor((b.hi.y - _lo.y) / _cell)), 0, _ny - 1);
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) f(size_t(y) * size_t(_nx) + size_t(x));
    }
    double _cell;
    glm::dvec2 _lo{1e300}, _hi{-1e300};
    int _nx = 0, _ny = 0;
    std::vector<std::vector<uint32_t>> _cells;
};

double segmentDistance(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c, const glm::dvec2& d) {
    auto orient = [](const glm::dvec2& p, const glm::dvec2& q, const glm::dvec2& r) {
        return (q.x - p.x) * (r.y - p.y) - (q.y - p.y) * (r.x - p.x);
    };
    const double o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
    if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0))) return 0.0;
    return std::min({pointSegmentDistance(a, c, d), pointSegmentDistance(b, c, d), pointSegmentDistance(c, a, b),
                     pointSegmentDistance(d, a, b)});
}

}  // namespace

double parseOsmLength(std::string_view text) {
    std::string_view s = trim(text);
    double v = 0;
    if (!leadingNumber(s, v)) return kNaN;
    s = trim(s);
    double m = kNaN;
    if (s.empty() || s == "m" || s == "metre" || s == "metres" || s == "meter" || s == "meters") {
        m = v;
    } else if (s == "ft" || s == "feet" || s == "'") {
        m = v * kFoot_m;
    } else if (s.front() == '\'') {  // 12'6"
        s.remove_prefix(1);
        s = trim(s);
        double inches = 0;
        if (leadingNumber(s, inches) && s == "\"" && inches < 12) m = (v + inches / 12.0) * kFoot_m;
    }
    return std::isfinite(m) && m >= 0 && m <= kOsmMaxHeight_m ? m : kNaN;
}

double parseOsmLevels(std::string_view text) {
    std::string_view s = trim(text);
    double v = 0;
    if (!leadingNumber(s, v) || !trim(s).empty()) return kNaN;
    return v <= kOsmMaxLevels ? v : kNaN;
}

OsmRoofShape parseOsmRoofShape(std::string_view text) {
    const std::string_view s = trim(text);
    if (s.empty()) return OsmRoofShape::Absent;
    static const char* gabled[] = {"gabled", "gambrel", "saltbox", "round", "double_saltbox", "quadruple_saltbox"};
    static const char* hipped[] = {"hipped", "half-hipped", "side_hipped", "mansard",          "pyramidal",
                                   "dome",   "onion",       "cone",        "side_half-hipped", "half_hipped"};
    for (const char* g : gabled)
        if (s == g) return OsmRoofShape::Gabled;
    for (const char* h : hipped)
        if (s == h) return OsmRoofShape::Hipped;
    return OsmRoofShape::Flat;
}

std::vector<Building> resolveOsmBuildings(const std::vector<OsmFootprint>& footprints, const CityParams& params,
                                          OsmBuildingStats& stats) {
    // In parallel (the roof checks run the straight skeleton); counts per footprint, summed in order.
    std::vector<Building> out(footprints.size());
    std::vector<OsmBuildingStats> counts(footprints.size());
    tbb::parallel_for(size_t(0), footprints.size(),
                      [&](size_t i) { out[i] = resolveOne(footprints[i], params, counts[i]); });
    for (const auto& c : counts) {
        stats.heightFromTag += c.heightFromTag;
        stats.heightFromLevels += c.heightFromLevels;
        stats.heightProcedural += c.heightProcedural;
        stats.roofFromTag += c.roofFromTag;
        stats.roofProcedural += c.roofProcedural;
        stats.roofFallbackFlat += c.roofFallbackFlat;
    }
    return out;
}

size_t dropCoveredLots(std::vector<Lot>& lots, const std::vector<Building>& imported) {
    if (imported.empty() || lots.empty()) return 0;
    std::vector<Bounds> boxes;
    boxes.reserve(imported.size());
    for (const auto& b : imported) boxes.push_back(boundsOf(b.footprint));
    const BoxGrid grid(boxes, 64.0);
    std::vector<Lot> kept;
    kept.reserve(lots.size());
    size_t dropped = 0;
    for (auto& lot : lots) {
        const Bounds lb = boundsOf(lot.outline);
        bool covered = false;
        grid.query(lb, [&](uint32_t i) {
            if (!covered && lb.overlaps(boxes[i]) && polygonsOverlap(lot.outline, imported[i].footprint, 1e-6))
                covered = true;
        });
        if (covered) ++dropped;
        else kept.push_back(std::move(lot));
    }
    lots = std::move(kept);
    return dropped;
}

size_t countOnCarriageway(const std::vector<Building>& imported, const StreetGraph& g) {
    std::vector<Bounds> boxes;
    std::vector<double> halfWidth;
    for (const auto& e : g.edges) {
        Bounds b;
        if (e.a < g.nodes.size() && e.b < g.nodes.size()) {
            b.add(g.nodes[e.a]);
            b.add(g.nodes[e.b]);
        }
        const double w = std::isfinite(double(e.width)) && e.width > 0.5f ? double(e.width) : roadWidth(e.cls);
        b.lo -= 0.5 * w;
        b.hi += 0.5 * w;
        boxes.push_back(b);
        halfWidth.push_back(0.5 * w);
    }
    const BoxGrid grid(boxes, 64.0);
    size_t count = 0;
    for (const auto& b : imported) {
        const Polygon2& fp = b.footprint;
        const Bounds fb = boundsOf(fp);
        bool on = false;
        grid.query(fb, [&](uint32_t e) {
            if (on || !fb.overlaps(boxes[e])) return;
            const glm::dvec2 &p = g.nodes[g.edges[e].a], &q = g.nodes[g.edges[e].b];
            if (pointInPolygon(fp, p) || pointInPolygon(fp, q)) {
                on = true;
                return;
            }
            for (size_t k = 0; k < fp.size() && !on; ++k)
                on = segmentDistance(fp[k], fp[(k + 1) % fp.size()], p, q) < halfWidth[e];
        });
        count += on ? 1 : 0;
    }
    return count;
}

}  // namespace vista
