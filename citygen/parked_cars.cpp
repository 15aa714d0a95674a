// Parked cars: models, placement and meshes (parked_cars.h).
#include "citygen/parked_cars.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "citygen/building_geometry.h"
#include "citygen/mesh_builder.h"
#include "citygen/polygon.h"
#include "citygen/terrain.h"
#include "foundation/rng.h"
#include "foundation/units.h"

namespace vista {
namespace {

constexpr double kSidewalkLift = 0.12;  // sidewalk top above the ground (surfaces.cpp)
constexpr double kCarGap = 0.5;         // between two cars' footprints
constexpr double kPoleRadius = 0.4;     // street light and signal poles with their heads
constexpr double kCell = 16.0;          // spatial index cell, metres

constexpr glm::dvec3 kPalette[kCarColourCount] = {
    {0.75, 0.75, 0.74},   // white
    {0.42, 0.43, 0.45},   // silver
    {0.03, 0.03, 0.035},  // black
    {0.13, 0.13, 0.14},   // dark grey
    {0.45, 0.04, 0.03},   // red
    {0.04, 0.10, 0.35},   // blue
    {0.05, 0.16, 0.08},   // green
    {0.50, 0.42, 0.30},   // beige
};
constexpr glm::dvec3 kGlass{0.02, 0.03, 0.04};
constexpr glm::dvec3 kTyre{0.02, 0.02, 0.02};

// An oriented rectangle: centre, unit axis u (length direction), half extents.
struct Rect {
    glm::dvec2 c{0.0}, u{1.0, 0.0};
    double hu = 0, hv = 0;
    glm::dvec2 v() const { return {-u.y, u.x}; }
    std::array<glm::dvec2, 4> corners() const {
        const glm::dvec2 a = u * hu, b = v() * hv;
        return {c - a - b, c + a - b, c + a + b, c - a + b};
    }
    Rect grown(double m) const { return {c, u, hu + m, hv + m}; }
    void bounds(glm::dvec2& lo, glm::dvec2& hi) const {
        const glm::dvec2 e(std::abs(u.x) * hu + std::abs(u.y) * hv, std::abs(u.y) * hu + std::abs(u.x) * hv);
        lo = c - e;
        hi = c + e;
    }
};

// Separating axis test of two oriented rectangles (touching is not overlap).
bool rectsOverlap(const Rect& a, const Rect& b) {
    const glm::dvec2 d = b.c - a.c;
    for (const glm::dvec2 axis : {a.u, a.v(), b.u, b.v()}) {
        const double ra = a.hu * std::abs(glm::dot(a.u, axis)) + a.hv * std::abs(glm::dot(a.v(), axis));
        const double rb = b.hu * std::abs(glm::dot(b.u, axis)) + b.hv * std::abs(glm::dot(b.v(), axis));
        if (std::abs(glm::dot(d, axis)) >= ra + rb) return false;
    }
    return true;
}

// Distance from p to the rectangle (0 inside).
double rectDistance(const Rect& r, const glm::dvec2& p) {
    const glm::dvec2 d = p - r.c;
    const double du = std::max(0.0, std::abs(glm::dot(d, r.u)) - r.hu);
    const double dv = std::max(0.0, std::abs(glm::dot(d, r.v())) - r.hv);
    return std::hypot(du, dv);
}

double cross2(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

bool segmentsCross(const glm::dvec2& p, const glm::dvec2& q, const glm::dvec2& a, const glm::dvec2& b) {
    const double d1 = cross2(q - p, a - p), d2 = cross2(q - p, b - p);
    const double d3 = cross2(b - a, p - a), d4 = cross2(b - a, q - a);
    return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0)) && d1 != 0 && d2 != 0 && d3 != 0 && d4 != 0;
}

// Whether a rectangle and a simple polygon overlap: a corner of either lies
// inside the other, or their edges cross.
bool rectPolygonOverlap(const Rect& r, const Polygon2& poly) {
    if (poly.size() < 3) return false;
    const auto c = r.corners();
    for (const auto& p : c)
        if (pointInPolygon(poly, p)) return true;
    for (const auto& q : poly)
        if (rectDistance(r, q) == 0.0) return true;
    for (size_t i = 0; i < poly.size(); ++i)
        for (int k = 0; k < 4; ++k)
            if (segmentsCross(c[size_t(k)], c[size_t((k + 1) % 4)], poly[i], poly[(i + 1) % poly.size()])) return true;
    return false;
}

// Items (indices) by the square cells their bounds touch.
class CellGrid {
public:
    void add(const glm::dvec2& lo, const glm::dvec2& hi, uint32_t item) {
        if (!std::isfinite(lo.x + lo.y + hi.x + hi.y)) return;
        forCells(lo, hi, [&](uint64_t k) { _cells[k].push_back(item); });
    }
    // Calls f(item) for every item whose cells meet [lo, hi] (an item may come more than once);
    // stops when f returns true, and returns whether it did.
    template <class F>
    bool any(const glm::dvec2& lo, const glm::dvec2& hi, F f) const {
        bool found = false;
        forCells(lo, hi, [&](uint64_t k) {
            if (found) return;
            auto it = _cells.find(k);
            if (it == _cells.end()) return;
            for (uint32_t i : it->second)
                if (f(i)) {
                    found = true;
                    return;
                }
        });
        return found;
    }

private:
    template <class F>
    static void forCells(const glm::dvec2& lo, const glm::dvec2& hi, F f) {
        const int64_t x0 = int64_t(std::floor(lo.x / kCell)), x1 = int64_t(std::floor(hi.x / kCell));
        const int64_t y0 = int64_t(std::floor(lo.y / kCell)), y1 = int64_t(std::floor(hi.y / kCell));
        for (int64_t y = y0; y <= y1; ++y)
            for (int64_t x = x0; x <= x1; ++x) f((uint64_t(x) << 32) ^ (uint64_t(y) & 0xFFFFFFFFull));
    }
    std::unordered_map<uint64_t, std::vector<uint32_t>> _cells;
};

struct Candidate {
    ParkedCar car;
    int lot = -1;  // lot slots: the lot the car must stay inside
    int tile = 0;
    uint64_t key = 0;
};

Rect rectOf(const ParkedCar& car) {
    const CarModel& m = carModels()[car.model];
    return {glm::dvec2(car.position), {std::cos(car.yaw), std::sin(car.yaw)}, 0.5 * m.length, 0.5 * m.width};
}

// The slot's own stream decides whether it holds a car, and which.
bool drawCar(const CityParams& P, uint64_t key, Rng& r, ParkedCar& car) {
    r = Rng(P.seed, key, Stream::Cars);
    if (!r.chance(P.parked_car_share)) return false;
    car.model = uint8_t(r.range(0, kCarModelCount - 1));
    car.colour = uint8_t(r.range(0, kCarColourCount - 1));
    return true;
}

void addCurbCandidates(const City& city, const LaneModel& lanes, std::vector<Candidate>& out) {
    const CityParams& P = city.params;
    for (size_t e = 0; e < lanes.edges.size(); ++e) {
        const EdgeLanes& L = lanes.edges[e];
        if (!L.valid || !(L.length >= kCurbSlot)) continue;
        const int count = int(std::floor(L.length / kCurbSlot));
        const double first = 0.5 * (L.length - (count - 1) * kCurbSlot);
        for (int side = -1; side <= 1; side += 2) {
            const double walk = L.hasWalk(side) ? L.sidewalk : 0.0;
            // Parked along the traffic of the nearest lanes (right-hand traffic).
            const bool along = side < 0 ? L.right > 0 || L.left == 0 : !(L.left > 0 || L.right == 0);
            for (int k = 0; k < count; ++k) {
                const glm::dvec2 slot = L.start + L.dir * (first + k * kCurbSlot) + L.normal() * (side * L.halfWidth());
                Candidate c;
                c.key = hashKeys(stableIdOf(slot), uint64_t(side + 1), 0xC0Bull);
                Rng r(0, 0, Stream::Cars);
                if (!drawCar(P, c.key, r, c.car)) continue;
                const CarModel& m = carModels()[c.car.model];
                if (walk > 0 && walk < m.width + kKerbGap + kMinWalkway) continue;  // no room beside the walkway
                const double s = first + k * kCurbSlot + r.uniform(-0.3, 0.3);
                const glm::dvec2 p =
                    L.start + L.dir * s + L.normal() * (side * (L.halfWidth() + kKerbGap + 0.5 * m.width));
                const glm::dvec2 f = along ? L.dir : -L.dir;
                c.car.position = glm::dvec3(p, terrainHeight(P, p) + (walk > 0 ? kSidewalkLift : 0.0));
                c.car.yaw = std::atan2(f.y, f.x);
                c.car.curb = true;
                out.push_back(c);
            }
        }
    }
}

void addLotCandidates(const City& city, std::vector<Candidate>& out) {
    const CityParams& P = city.params;
    for (size_t li = 0; li < city.lots.size(); ++li) {
        const Lot& lot = city.lots[li];
        if (lot.outline.size() < 3 || lot.block >= city.blocks.size()) continue;
        const Polygon2 lo = makeCounterClockwise(lot.outline);
        const Polygon2& bo = city.blocks[lot.block].outline;
        auto onBlock = [&](const glm::dvec2& q) {
            for (size_t k = 0; k < bo.size(); ++k)
                if (pointSegmentDistance(q, bo[k], bo[(k + 1) % bo.size()]) < 1e-6) return true;
            return false;
        };
        for (size_t k = 0; k < lo.size(); ++k) {
            const glm::dvec2 a = lo[k], b = lo[(k + 1) % lo.size()];
            const double len = glm::length(b - a);
            if (!(len >= kLotSlot) || !onBlock(a) || !onBlock(b) || !onBlock(0.5 * (a + b))) continue;
            const glm::dvec2 u = (b - a) / len, v(-u.y, u.x);  // v: into the lot
            const int count = int(std::floor(len / kLotSlot));
            for (int i = 0; i < count; ++i) {
                const glm::dvec2 slot = a + u * ((i + 0.5) * len / count);
                Candidate c;
                c.key = hashKeys(stableIdOf(slot), 0x107ull);
                Rng r(0, 0, Stream::Cars);
                if (!drawCar(P, c.key, r, c.car)) continue;
                const CarModel& m = carModels()[c.car.model];
                const bool parallel = r.chance(0.5);
                const double flip = r.chance(0.5) ? kPi : 0.0;
                const double depth = kYardGap + 0.5 * (parallel ? m.width : m.length);
                const glm::dvec2 p = slot + u * r.uniform(-0.5, 0.5) + v * depth;
                const glm::dvec2 f = parallel ? u : v;
                c.car.position = glm::dvec3(p, terrainHeight(P, p));
                c.car.yaw = std::atan2(f.y, f.x) + flip;
                c.car.curb = false;
                c.lot = int(li);
                out.push_back(c);
            }
        }
    }
}

// What a car must not overlap, indexed.
class Obstacles {
public:
    Obstacles(const City& city, const LaneModel& lanes) : _city(city) {
        const StreetGraph& g = city.streets;
        // Carriageways, node to node.
        for (size_t e = 0; e < g.edges.size() && e < lanes.edges.size(); ++e) {
            const StreetEdge& E = g.edges[e];
            if (E.a >= g.nodes.size() || E.b >= g.nodes.size()) continue;
            const glm::dvec2 A = g.nodes[E.a], B = g.nodes[E.b];
            const double len = glm::length(B - A);
            if (!std::isfinite(len) || !(len > 1e-9)) continue;
            Rect r{0.5 * (A + B), (B - A) / len, 0.5 * len, 0.5 * carriagewayWidth(E)};
            add(_roadIdx, r, uint32_t(_roads.size()));
            _roads.push_back(r);
        }
        // Junction and link road areas around the nodes.
        std::vector<double> radius(g.nodes.size(), 0.0);
        for (size_t e = 0; e < lanes.edges.size() && e < g.edges.size(); ++e) {
            const EdgeLanes& L = lanes.edges[e];
            if (!L.valid) continue;
            const StreetEdge& E = g.edges[e];
            if (lanes.degree[E.a] >= 2) radius[E.a] = std::max(radius[E.a], L.trimA + L.halfWidth());
            if (lanes.degree[E.b] >= 2) radius[E.b] = std::max(radius[E.b], L.trimB + L.halfWidth());
        }
        for (const Junction& j : lanes.junctions)
            for (uint32_t v : j.nodes)
                if (v < radius.size()) radius[v] = std::max(radius[v], j.radius);
        for (size_t n = 0; n < g.nodes.size(); ++n)
            if (radius[n] > 0) addDisc(g.nodes[n], radius[n] + kCarClearance);
        for (const SignalPlacement& s : lanes.signals) addDisc(s.position, kPoleRadius);
        for (const glm::dvec3& l : city.streetLights) addDisc(glm::dvec2(l), kPoleRadius);
        // Trees: the crown's radius around the trunk.
        std::vector<double> crown(city.treePrototypes.size(), 0.0);
        for (size_t i = 0; i < crown.size(); ++i)
            for (const auto& q : city.treePrototypes[i].mesh.positions)
                crown[i] = std::max(crown[i], std::hypot(double(q.x), double(q.y)));
        for (const TreeInstance& t : city.trees)
            addDisc(glm::dvec2(t.position),
                    std::max(0.5, (t.prototype < crown.size() ? crown[t.prototype] : 3.0) * double(t.scale)));
        // Buildings.
        for (uint32_t b = 0; b < city.buildings.size(); ++b) {
            glm::dvec2 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
            for (const auto& q : city.buildings[b].footprint) lo = glm::min(lo, q), hi = glm::max(hi, q);
            _buildingIdx.add(lo, hi, b);
        }
    }

    bool blocked(const Rect& car) const {
        glm::dvec2 lo, hi;
        car.bounds(lo, hi);
        if (_roadIdx.any(lo, hi, [&](uint32_t i) { return rectsOverlap(car, _roads[i]); })) return true;
        if (_discIdx.any(lo, hi, [&](uint32_t i) { return rectDistance(car, _discs[i].first) < _discs[i].second; }))
            return true;
        const Rect grown = car.grown(kCarClearance);
        grown.bounds(lo, hi);
        return _buildingIdx.any(lo, hi,
                                [&](uint32_t b) { return rectPolygonOverlap(grown, _city.buildings[b].footprint); });
    }

private:
    void add(CellGrid& idx, const Rect& r, uint32_t i) {
        glm::dvec2 lo, hi;
        r.bounds(lo, hi);
        idx.add(lo, hi, i);
    }
    void addDisc(const glm::dvec2& p, double r) {
        if (!std::isfinite(p.x + p.y + r)) return;
        _discIdx.add(p - r, p + r, uint32_t(_discs.size()));
        _discs.emplace_back(p, r);
    }

    const City& _city;
    std::vector<Rect> _roads;
    std::vector<std::pair<glm::dvec2, double>> _discs;
    CellGrid _roadIdx, _discIdx, _buildingIdx;
};

// A planar convex face, wound so that its normal points along `out`.
void face(MeshBuilder& b, std::vector<glm::dvec3> p, const glm::dvec3& out) {
    glm::dvec3 n(0.0);
    for (size_t i = 1; i + 1 < p.size(); ++i) n += glm::cross(p[i] - p[0], p[i + 1] - p[0]);
    if (glm::dot(n, out) < 0) std::reverse(p.begin(), p.end());
    if (p.size() == 4) b.quad(p[0], p[1], p[2], p[3]);
    else
        for (size_t i = 1; i + 1 < p.size(); ++i) b.triangle(p[0], p[i], p[i + 1]);
}

}  // namespace

const std::array<CarModel, kCarModelCount>& carModels() {
    //                                     name  length width height clear belt  cabF   cabR   roofF roofR  base   wheel
    static const std::array<CarModel, kCarModelCount> kModels = {{
        {"hatchback", 4.05, 1.74, 1.48, 0.26, 0.92, 0.80, -1.95, 0.00, -1.80, 2.50, 0.30},
        {"sedan", 4.65, 1.80, 1.45, 0.25, 0.90, 0.95, -1.35, 0.10, -0.85, 2.75, 0.32},
        {"estate", 4.75, 1.82, 1.50, 0.26, 0.93, 0.90, -2.25, 0.05, -2.10, 2.80, 0.32},
        {"suv", 4.60, 1.90, 1.60, 0.34, 1.05, 0.85, -2.10, 0.15, -2.00, 2.70, 0.36},
    }};
    return kModels;
}

glm::dvec3 carColour(int colour) { return kPalette[std::clamp(colour, 0, kCarColourCount - 1)]; }

std::vector<glm::dvec2> carFootprint(const ParkedCar& car) {
    const auto c = rectOf(car).corners();
    return {c[0], c[1], c[2], c[3]};
}

std::vector<ParkedCar> placeParkedCars(const City& city, const LaneModel& lanes) {
    std::vector<ParkedCar> out;
    const CityParams& P = city.params;
    if (!(P.parked_car_share > 0)) return out;
    std::vector<Candidate> cand;
    addCurbCandidates(city, lanes, cand);
    addLotCandidates(city, cand);
    // Canonical order: by tile, then by slot (street and lot order do not matter).
    const TileGrid grid(P);
    for (auto& c : cand) c.tile = grid.tileOf(glm::dvec2(c.car.position));
    std::sort(cand.begin(), cand.end(), [](const Candidate& a, const Candidate& b) {
        if (a.tile != b.tile) return a.tile < b.tile;
        if (a.key != b.key) return a.key < b.key;
        if (a.car.position.y != b.car.position.y) return a.car.position.y < b.car.position.y;
        return a.car.position.x < b.car.position.x;
    });
    const double half = 0.5 * P.size_m - 1.0;
    const Obstacles obstacles(city, lanes);
    CellGrid kept;
    std::vector<Rect> keptRects;
    for (const Candidate& c : cand) {
        if (!std::isfinite(c.car.position.x + c.car.position.y + c.car.position.z + c.car.yaw)) continue;
        const Rect r = rectOf(c.car);
        const auto corners = r.corners();
        bool ok = true;
        for (const auto& q : corners) ok = ok && std::abs(q.x) <= half && std::abs(q.y) <= half;
        if (!ok) continue;
        if (c.lot >= 0 &&
            !polygonInside({corners[0], corners[1], corners[2], corners[3]}, city.lots[size_t(c.lot)].outline))
            continue;
        if (obstacles.blocked(r)) continue;
        const Rect g = r.grown(0.5 * kCarGap);
        glm::dvec2 lo, hi;
        g.bounds(lo, hi);
        if (kept.any(lo, hi, [&](uint32_t i) { return rectsOverlap(g, keptRects[i].grown(0.5 * kCarGap)); })) continue;
        kept.add(lo, hi, uint32_t(keptRects.size()));
        keptRects.push_back(r);
        out.push_back(c.car);
    }
    return out;
}

void meshParkedCar(const ParkedCar& car, const glm::dvec3& origin, const Lighting& light, Mesh& mesh, uint32_t id) {
    if (!std::isfinite(car.position.x + car.position.y + car.position.z + car.yaw)) return;
    const CarModel& m = carModels()[std::min<size_t>(car.model, kCarModelCount - 1)];
    meshCarShape(m, carColour(car.colour), car.position, car.yaw, origin, light, Material::Car, mesh, id);
}

void meshCarShape(const CarModel& m, const glm::dvec3& bodyAlbedo, const glm::dvec3& position, double yaw,
                  const glm::dvec3& origin, const Lighting& light, Material material, Mesh& mesh, uint32_t id) {
    const glm::dvec3 f(std::cos(yaw), std::sin(yaw), 0.0), l(-f.y, f.x, 0.0), up(0, 0, 1);
    const auto at = [&](double x, double y, double z) { return position + f * x + l * y + up * z; };
    MeshBuilder b(mesh, origin, material, light);
    b.setId(id);
    // A box [x0, x1] x [y0, y1] x [z0, z1] in the car's frame, faces outward.
    const auto box = [&](double x0, double x1, double y0, double y1, double z0, double z1, bool top, bool bottom) {
        face(b, {at(x1, y0, z0), at(x1, y1, z0), at(x1, y1, z1), at(x1, y0, z1)}, f);
        face(b, {at(x0, y0, z0), at(x0, y1, z0), at(x0, y1, z1), at(x0, y0, z1)}, -f);
        face(b, {at(x0, y1, z0), at(x1, y1, z0), at(x1, y1, z1), at(x0, y1, z1)}, l);
        face(b, {at(x0, y0, z0), at(x1, y0, z0), at(x1, y0, z1), at(x0, y0, z1)}, -l);
        if (top) face(b, {at(x0, y0, z1), at(x1, y0, z1), at(x1, y1, z1), at(x0, y1, z1)}, up);
        if (bottom) face(b, {at(x0, y0, z0), at(x1, y0, z0), at(x1, y1, z0), at(x0, y1, z0)}, -up);
    };
    const double hl = 0.5 * m.length, hw = 0.5 * m.width;
    // Wheels: side faces only (their tops are inside the body).
    b.setAlbedo(kTyre);
    const double tyre = 0.22, r = m.wheelRadius;
    for (double x : {0.5 * m.wheelBase, -0.5 * m.wheelBase})
        for (double s : {1.0, -1.0}) {
            const double yo = s * (hw - 0.03), yi = s * (hw - 0.03 - tyre);
            box(x - 0.9 * r, x + 0.9 * r, std::min(yo, yi), std::max(yo, yi), 0.0, 2.0 * r, false, false);
        }
    // Body.
    b.setAlbedo(bodyAlbedo);
    box(-hl, hl, -hw, hw, m.clearance, m.belt, true, true);
    // Cabin: sloped windscreen and rear window, glass sides, a roof in the body colour.
    const double cw = hw - 0.05;
    face(b,
         {at(m.roofRear, -cw, m.height), at(m.roofFront, -cw, m.height), at(m.roofFront, cw, m.height),
          at(m.roofRear, cw, m.height)},
         up);
    b.setAlbedo(kGlass);
    const glm::dvec3 front = glm::normalize(f * (m.height - m.belt) + up * (m.cabinFront - m.roofFront));
    const glm::dvec3 rear = glm::normalize(-f * (m.height - m.belt) + up * (m.roofRear - m.cabinRear));
    face(b,
         {at(m.cabinFront, -cw, m.belt), at(m.cabinFront, cw, m.belt), at(m.roofFront, cw, m.height),
          at(m.roofFront, -cw, m.height)},
         front);
    face(b,
         {at(m.cabinRear, -cw, m.belt), at(m.cabinRear, cw, m.belt), at(m.roofRear, cw, m.height),
          at(m.roofRear, -cw, m.height)},
         rear);
    for (double s : {1.0, -1.0})
        face(b,
             {at(m.cabinRear, s * cw, m.belt), at(m.cabinFront, s * cw, m.belt), at(m.roofFront, s * cw, m.height),
              at(m.roofRear, s * cw, m.height)},
             l * s);
}

}  // namespace vista
