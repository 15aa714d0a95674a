// Trees: procedural prototypes (recursive branching + low-poly leaf clusters)
// and their placement along streets and in parks. See trees.h for the
// contract and docs/reference/trees-and-surfaces.md for budgets and rules.
#include "citygen/trees.h"
#include "foundation/units.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "citygen/mesh_builder.h"
#include "citygen/polygon.h"
#include "foundation/rng.h"
#include "citygen/terrain.h"

namespace vista {

namespace {

constexpr int kSpecies = 3;                                  // 0 broadleaf, 1 conifer, 2 columnar
constexpr int kVariants = 3;                                 // small, medium, large
constexpr double kMinBranchRadius = 0.035;                   // thinnest twig, metres
constexpr size_t kMinTriangles = 400, kMaxTriangles = 1500;  // per prototype

// Nominal prototype heights (metres) per species and size variant; instances
// scale by 0.85..1.15, so every tree stays within 5..22 m.
constexpr double kHeights[kSpecies][kVariants] = {{7.5, 11.5, 16.0}, {8.5, 13.0, 18.5}, {7.0, 11.0, 15.5}};

// Writes the prototype geometry with one MeshBuilder whose material switches
// between Trunk and Leaves.
class TreeShaper {
public:
    TreeShaper(Mesh& mesh, const Lighting& light, Rng& rng)
        : _b(mesh, glm::dvec3(0.0), Material::Trunk, light), _rng(rng) {}

    // Tapered prism from p0 (radius r0) to p1 (radius r1) with `sides` faces, no caps.
    void limb(const glm::dvec3& p0, const glm::dvec3& p1, double r0, double r1, int sides) {
        glm::dvec3 dir = p1 - p0;
        double len = glm::length(dir);
        if (!(len > 1e-4)) return;
        glm::dvec3 d = dir / len;
        glm::dvec3 helper = std::abs(d.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0);
        glm::dvec3 u = glm::normalize(glm::cross(d, helper));
        glm::dvec3 v = glm::cross(d, u);  // (u, v, d) right-handed
        _b.setMaterial(Material::Trunk);
        _b.setId(uint32_t(Material::Trunk));  // prototypes: the part (labels.h)
        _b.setVariation(_barkVariation);
        double phase = _rng.uniform(0.0, 2 * kPi);
        for (int i = 0; i < sides; ++i) {
            double a0 = phase + 2 * kPi * i / sides, a1 = phase + 2 * kPi * (i + 1) / sides;
            glm::dvec3 e0 = u * std::cos(a0) + v * std::sin(a0), e1 = u * std::cos(a1) + v * std::sin(a1);
            _b.quad(p0 + e0 * r0, p0 + e1 * r0, p1 + e1 * r1, p1 + e0 * r1);
        }
    }

    // Closed low-poly leaf cluster: an irregular bipyramid over a `ring`-gon
    // (2 * ring triangles) with half-extents rx, ry (horizontal) and rz.
    void blob(const glm::dvec3& c, double rh, double rz, int ring = 4) {
        _b.setMaterial(Material::Leaves);
        _b.setId(uint32_t(Material::Leaves));
        _b.setVariation(std::clamp(_leafVariation + _rng.uniform(-0.35, 0.35), -1.0, 1.0));
        double phase = _rng.uniform(0.0, 2 * kPi);
        std::vector<glm::dvec3> rim(static_cast<size_t>(ring));
        for (int i = 0; i < ring; ++i) {
            double a = phase + 2 * kPi * (i + _rng.uniform(-0.15, 0.15)) / ring;
            double r = rh * _rng.uniform(0.8, 1.15);
            rim[size_t(i)] = c + glm::dvec3(r * std::cos(a), r * std::sin(a), rz * _rng.uniform(-0.2, 0.2));
        }
        glm::dvec3 top = c + glm::dvec3(_rng.uniform(-0.15, 0.15) * rh, _rng.uniform(-0.15, 0.15) * rh,
                                        rz * _rng.uniform(0.85, 1.15));
        glm::dvec3 bot = c - glm::dvec3(0, 0, rz * _rng.uniform(0.6, 0.9));
        for (int i = 0; i < ring; ++i) {
            const glm::dvec3& a = rim[size_t(i)];
            const glm::dvec3& b = rim[size_t((i + 1) % ring)];
            _b.triangle(a, b, top);
            _b.triangle(b, a, bot);
        }
    }

    // Conifer foliage tier: a double cone (apex above the trunk, skirt ring
    // around it, flat-ish underside), 2 * ring triangles.
    void tier(const glm::dvec3& trunkAt, double radius, double up, double down, int ring) {
        _b.setMaterial(Material::Leaves);
        _b.setId(uint32_t(Material::Leaves));
        _b.setVariation(std::clamp(_leafVariation + _rng.uniform(-0.25, 0.25), -1.0, 1.0));
        double phase = _rng.uniform(0.0, 2 * kPi);
        std::vector<glm::dvec3> rim(static_cast<size_t>(ring));
        for (int i = 0; i < ring; ++i) {
            double a = phase + 2 * kPi * i / ring;
            double r = radius * _rng.uniform(0.8, 1.1);
            rim[size_t(i)] = trunkAt + glm::dvec3(r * std::cos(a), r * std::sin(a), -down * _rng.uniform(0.7, 1.0));
        }
        glm::dvec3 top = trunkAt + glm::dvec3(0, 0, up), bot = trunkAt + glm::dvec3(0, 0, -0.35 * down);
        for (int i = 0; i < ring; ++i) {
            const glm::dvec3& a = rim[size_t(i)];
            const glm::dvec3& b = rim[size_t((i + 1) % ring)];
            _b.triangle(a, b, top);
            _b.triangle(b, a, bot);
        }
    }

    void setBarkVariation(double v) { _barkVariation = v; }
    void setLeafVariation(double v) { _leafVariation = v; }
    Rng& rng() { return _rng; }

private:
    MeshBuilder _b;
    Rng& _rng;
    double _barkVariation = 0, _leafVariation = 0;
};

// Unit vector at angle `tilt` from `d`, rotated by `az` around it.
glm::dvec3 deviate(const glm::dvec3& d, double tilt, double az) {
    glm::dvec3 helper = std::abs(d.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0);
    glm::dvec3 u = glm::normalize(glm::cross(d, helper));
    glm::dvec3 v = glm::cross(d, u);
    return glm::normalize(d * std::cos(tilt) + (u * std::cos(az) + v * std::sin(az)) * std::sin(tilt));
}

struct BranchStyle {
    int maxDepth = 3;
    int minChildren = 2, maxChildren = 3;
    double tiltMin = 0.45, tiltMax = 0.85;  // child angle from parent (radians)
    double lenRatio = 0.72;                 // child length / parent length
    double leafRadius = 1.0;                // horizontal half-extent of a tip cluster
    double leafFlatten = 0.7;               // vertical / horizontal extent
    double upBias = 0.15;                   // pull of children towards +z
    int leafRing = 4;
    int deepMaxChildren = 3;     // cap on children from depth 2 on
    double midLeafChance = 0.0;  // cluster at the middle of outer branches
};

// Recursive branch: two slightly bent tapered segments, then children; leaf
// clusters on the last two levels.
void branch(TreeShaper& t, const BranchStyle& s, const glm::dvec3& p, const glm::dvec3& d, double len, double r,
            int depth) {
    Rng& rng = t.rng();
    double rEnd = std::max(kMinBranchRadius, r * 0.62);
    int sides = depth <= 1 ? 4 : 3;
    glm::dvec3 bend = deviate(d, rng.uniform(0.05, 0.25), rng.uniform(0.0, 2 * kPi));
    glm::dvec3 mid = p + d * (0.5 * len);
    glm::dvec3 end = mid + bend * (0.5 * len);
    if (depth >= s.maxDepth) {
        t.limb(p, end, r, rEnd, 3);
        t.blob(end, s.leafRadius * rng.uniform(0.85, 1.15), s.leafRadius * s.leafFlatten, s.leafRing);
        return;
    }
    if (depth <= 1) {
        t.limb(p, mid, r, 0.5 * (r + rEnd), sides);
        t.limb(mid, end, 0.5 * (r + rEnd), rEnd, sides);
    } else {
        t.limb(p, end, r, rEnd, sides);
    }
    // Clusters along the outer branches (not only at the tips) round the crown.
    if (depth >= s.maxDepth - 2 && depth >= 2 && rng.chance(s.midLeafChance))
        t.blob(mid - glm::dvec3(0, 0, 0.3 * s.leafRadius), s.leafRadius * rng.uniform(0.8, 1.1),
               s.leafRadius * s.leafFlatten, s.leafRing);
    if (depth == s.maxDepth - 1 && rng.chance(0.85))
        t.blob(end, s.leafRadius * rng.uniform(0.9, 1.25), s.leafRadius * s.leafFlatten, s.leafRing);
    int n = int(rng.range(s.minChildren, depth >= 2 ? std::min(s.maxChildren, s.deepMaxChildren) : s.maxChildren));
    double az0 = rng.uniform(0.0, 2 * kPi);
    for (int i = 0; i < n; ++i) {
        double az = az0 + 2 * kPi * (i + rng.uniform(-0.2, 0.2)) / n;
        glm::dvec3 cd = deviate(bend, rng.uniform(s.tiltMin, s.tiltMax), az);
        cd = glm::normalize(cd + glm::dvec3(0, 0, s.upBias));
        branch(t, s, end, cd, len * s.lenRatio * rng.uniform(0.85, 1.1), std::max(kMinBranchRadius, rEnd * 0.8),
               depth + 1);
    }
}

void makeBroadleaf(TreeShaper& t, int variant, double h) {
    Rng& rng = t.rng();
    BranchStyle s;
    s.maxDepth = variant == 2 ? 4 : 3;
    s.minChildren = 2;
    s.maxChildren = variant == 0 ? 2 : 3;
    s.leafRadius = h * (variant == 0 ? 0.11 : (variant == 1 ? 0.095 : 0.075));
    s.leafFlatten = 0.75;
    s.upBias = 0.3;
    s.leafRing = variant == 0 ? 5 : 4;
    s.deepMaxChildren = variant == 2 ? 2 : 3;
    s.midLeafChance = 0.7;
    s.tiltMax = 0.75;
    double trunkH = h * 0.36, r0 = h * 0.019;
    glm::dvec3 lean(rng.uniform(-0.03, 0.03) * h, rng.uniform(-0.03, 0.03) * h, trunkH);
    t.limb({0, 0, -0.1}, lean * 0.5 + glm::dvec3(0, 0, -0.05), r0, r0 * 0.9, 6);
    t.limb(lean * 0.5 + glm::dvec3(0, 0, -0.05), lean, r0 * 0.9, r0 * 0.75, 6);
    int mains = 4;
    double az0 = rng.uniform(0.0, 2 * kPi);
    // Main limbs spread outwards; total reach ~ crown radius 0.38 h.
    double len = h * (s.maxDepth == 3 ? 0.22 : 0.17);
    for (int i = 0; i < mains; ++i) {
        double az = az0 + 2 * kPi * (i + rng.uniform(-0.2, 0.2)) / mains;
        double elev = rng.uniform(0.7, 1.05);
        glm::dvec3 d(std::cos(az) * std::cos(elev), std::sin(az) * std::cos(elev), std::sin(elev));
        glm::dvec3 start = lean * rng.uniform(0.85, 1.0);
        branch(t, s, start, d, len * rng.uniform(0.9, 1.1), r0 * 0.55, 1);
    }
}

void makeConifer(TreeShaper& t, int variant, double h) {
    Rng& rng = t.rng();
    double r0 = h * 0.016;
    // Trunk to the tip in 4 tapering segments.
    const int segs = 4;
    for (int i = 0; i < segs; ++i) {
        double z0 = i == 0 ? -0.1 : h * 0.97 * i / segs, z1 = h * 0.97 * (i + 1) / segs;
        double ra = std::max(kMinBranchRadius, r0 * (1.0 - 0.85 * i / segs));
        double rb = std::max(kMinBranchRadius, r0 * (1.0 - 0.85 * (i + 1) / segs));
        t.limb({0, 0, z0}, {0, 0, z1}, ra, rb, 6);
    }
    int whorls = 9 + 3 * variant;
    double zStart = h * rng.uniform(0.18, 0.26), crownR = h * 0.22;
    int perWhorl = 4;
    for (int w = 0; w < whorls; ++w) {
        double f = double(w) / whorls;  // 0 at the bottom whorl
        double z = zStart + (h * 0.95 - zStart) * f;
        double reach = crownR * std::pow(1.0 - f, 0.9) + 0.35;
        double spacing = (h * 0.95 - zStart) / whorls;
        double az0 = rng.uniform(0.0, 2 * kPi);
        for (int k = 0; k < perWhorl; ++k) {
            double az = az0 + 2 * kPi * (k + rng.uniform(-0.2, 0.2)) / perWhorl;
            double droop = rng.uniform(0.1, 0.35);
            glm::dvec3 dir(std::cos(az) * std::cos(droop), std::sin(az) * std::cos(droop), -std::sin(droop));
            double rb = std::max(kMinBranchRadius, r0 * 0.35 * (1.0 - f));
            t.limb({0, 0, z}, glm::dvec3(0, 0, z) + dir * (reach * 0.95), rb, kMinBranchRadius, 3);
        }
        t.tier({0, 0, z}, reach, spacing * 1.6, spacing * 0.7, 8);
    }
    t.blob({0, 0, h * 0.96}, 0.35 + 0.05 * h * 0.05, h * 0.05, 4);
}

// Kept apart from makeConifer on purpose (duplicates lists the trunk loops as
// alike): each species' taper and segment count are tuned on their own.
void makeColumnar(TreeShaper& t, int variant, double h) {
    Rng& rng = t.rng();
    double r0 = h * 0.017;
    const int segs = 3;
    for (int i = 0; i < segs; ++i) {
        double z0 = i == 0 ? -0.1 : h * 0.9 * i / segs, z1 = h * 0.9 * (i + 1) / segs;
        t.limb({0, 0, z0}, {0, 0, z1}, std::max(kMinBranchRadius, r0 * (1.0 - 0.7 * i / segs)),
               std::max(kMinBranchRadius, r0 * (1.0 - 0.7 * (i + 1) / segs)), 6);
    }
    int n = 18 + 4 * variant;
    double crownR = h * 0.13, z0 = h * 0.14, z1 = h * 0.88;
    double leaf = h * 0.055;
    for (int i = 0; i < n; ++i) {
        double f = (i + rng.uniform(0.0, 1.0)) / n;
        double z = z0 + (z1 - z0) * f;
        double az = i * 2.39996 + rng.uniform(-0.3, 0.3);   // golden angle spiral
        double profile = std::sin(kPi * (0.15 + 0.8 * f));  // spindle-shaped crown
        double elev = rng.uniform(1.0, 1.25);               // steep, upward branches
        glm::dvec3 dir(std::cos(az) * std::cos(elev), std::sin(az) * std::cos(elev), std::sin(elev));
        double len = (crownR * profile + 0.4) / std::cos(elev);
        glm::dvec3 a(0, 0, z), b = a + dir * len;
        double rb = std::max(kMinBranchRadius, r0 * 0.3);
        t.limb(a, b, rb, kMinBranchRadius, 3);
        t.blob(b, leaf * (0.8 + profile * 0.5), leaf * 1.8, 5);
        if (rng.chance(0.6)) {
            glm::dvec3 twig = deviate(dir, rng.uniform(0.4, 0.7), rng.uniform(0.0, 2 * kPi));
            glm::dvec3 c = a + dir * (len * 0.5);
            t.limb(c, c + twig * (len * 0.5), kMinBranchRadius, kMinBranchRadius, 3);
            t.blob(c + twig * (len * 0.5), leaf * 0.8, leaf * 1.5, 4);
        }
    }
    t.blob({0, 0, h * 0.9}, leaf * 1.2, h * 0.08, 5);
}

double meshTop(const Mesh& m) {
    double top = 0;
    for (const auto& p : m.positions) top = std::max(top, double(p.z));
    return top;
}

}  // namespace

std::vector<TreePrototype> makeTreePrototypes(const CityParams& params, const Lighting& light) {
    std::vector<TreePrototype> out;
    out.reserve(size_t(kSpecies * kVariants));
    for (int species = 0; species < kSpecies; ++species) {
        for (int variant = 0; variant < kVariants; ++variant) {
            int id = species * kVariants + variant;
            TreePrototype p;
            // Deterministic retries keep every prototype inside the triangle budget.
            for (uint64_t attempt = 0; attempt < 8; ++attempt) {
                Rng rng(params.seed, uint64_t(id) + 0x7EE0000ull + (attempt << 8), Stream::Trees);
                p = TreePrototype();
                p.species = species;
                p.variant = variant;
                double h = kHeights[species][variant];
                TreeShaper t(p.mesh, light, rng);
                t.setBarkVariation(rng.uniform(-0.3, 0.3));
                if (species == 0) {
                    t.setLeafVariation(rng.uniform(-0.1, 0.3));
                    makeBroadleaf(t, variant, h);
                } else if (species == 1) {
                    t.setBarkVariation(-0.4);
                    t.setLeafVariation(rng.uniform(-0.9, -0.6));
                    makeConifer(t, variant, h);
                } else {
                    t.setLeafVariation(rng.uniform(0.2, 0.5));
                    makeColumnar(t, variant, h);
                }
                p.height = meshTop(p.mesh);
                size_t n = p.mesh.triangleCount();
                if (n >= kMinTriangles && n <= kMaxTriangles) break;
            }
            out.push_back(std::move(p));
        }
    }
    return out;
}

// ---------------------------------------------------------------------------
// Placement

namespace {

// Uniform grid over the city square holding item indices per cell (CSR).
class CellIndex {
public:
    CellIndex(double half, double cell) : _half(half), _cell(cell) {
        _n = std::max(1, int(std::ceil(2 * half / cell)));
        _start.assign(size_t(_n) * size_t(_n) + 1, 0);
    }
    int cx(double x) const { return std::clamp(int(std::floor((x + _half) / _cell)), 0, _n - 1); }
    int cy(double y) const { return std::clamp(int(std::floor((y + _half) / _cell)), 0, _n - 1); }
    // Two passes: count(...) for every item, then finishCounts(), then fill(...) for every item in the same order.
    template <class F>
    void forCells(const glm::dvec2& lo, const glm::dvec2& hi, F f) const {
        for (int y = cy(lo.y), y1 = cy(hi.y); y <= y1; ++y)
            for (int x = cx(lo.x), x1 = cx(hi.x); x <= x1; ++x) f(size_t(y) * size_t(_n) + size_t(x));
    }
    void count(const glm::dvec2& lo, const glm::dvec2& hi) {
        forCells(lo, hi, [&](size_t c) { ++_start[c + 1]; });
    }
    void finishCounts() {
        for (size_t i = 1; i < _start.size(); ++i) _start[i] += _start[i - 1];
        _items.resize(_start.back());
        _fill.assign(_start.begin(), _start.end() - 1);
    }
    void fill(const glm::dvec2& lo, const glm::dvec2& hi, uint32_t item) {
        forCells(lo, hi, [&](size_t c) { _items[_fill[c]++] = item; });
    }
    template <class F>
    void forItems(size_t c, F f) const {
        for (uint32_t i = _start[c]; i < _start[c + 1]; ++i) f(_items[i]);
    }
    template <class F>
    bool any(const glm::dvec2& p, F pred) const {
        size_t c = size_t(cy(p.y)) * size_t(_n) + size_t(cx(p.x));
        for (uint32_t i = _start[c]; i < _start[c + 1]; ++i)
            if (pred(_items[i])) return true;
        return false;
    }

private:
    double _half, _cell;
    int _n;
    std::vector<uint32_t> _start, _fill, _items;
};

// Carriageway width as drawn by meshSurfaces (invalid widths fall back to the class default).
double edgeWidth(const StreetEdge& e) {
    double w = double(e.width);
    return std::isfinite(w) && w > 0.5 ? w : roadWidth(e.cls);
}

uint64_t quantKey(const glm::dvec2& p) {
    int64_t qx = std::llround(p.x * 10.0), qy = std::llround(p.y * 10.0);  // 10 cm
    return hashKeys(uint64_t(qx), uint64_t(qy), 0x7EEull);
}

constexpr double kRoadClearance = 1.0;      // trunk to carriageway edge, metres
constexpr double kBuildingClearance = 1.5;  // trunk to building footprint, metres
constexpr double kIntersectionClearance = 10.0;
constexpr double kMinTreeDistance = 3.0;    // between any two trees
constexpr double kParkEdgeClearance = 2.0;  // park trees from the park outline
constexpr double kCrownSearch = 12.0;       // search radius for facades near a crown
constexpr double kCrownOverlap = 1.0;       // a crown may touch a facade by this much

struct Candidate {
    glm::dvec2 p;
    int tile;
    uint64_t key;
    bool street;
    int species;  // -1: choose per tree
};

// Where trees may not stand and how much room their crowns have: buildings
// and carriageways in cell indices (cell 32 m), and the crown radius of every
// prototype.
class SiteIndex {
public:
    SiteIndex(const City& city, double half) : _city(city), _bIdx(half, kCell), _eIdx(half, kCell) {
        indexBuildings();
        indexEdges();
        measureCrowns();
    }

    // Whether each street edge has valid, finite end points.
    const std::vector<uint8_t>& edgeOk() const { return _edgeOk; }

    // Whether a trunk at p stands within the clearance of a carriageway.
    bool onRoad(const glm::dvec2& p) const {
        const StreetGraph& g = _city.streets;
        return _eIdx.any(p, [&](uint32_t e) {
            const auto& E = g.edges[e];
            return pointSegmentDistance(p, g.nodes[E.a], g.nodes[E.b]) < 0.5 * edgeWidth(E) + kRoadClearance;
        });
    }

    // Whether a trunk at p stands inside a building footprint or within its clearance.
    bool inBuilding(const glm::dvec2& p) const {
        return _bIdx.any(p, [&](uint32_t i) {
            const auto& fp = _city.buildings[i].footprint;
            if (p.x < _bBox[i].first.x || p.y < _bBox[i].first.y || p.x > _bBox[i].second.x || p.y > _bBox[i].second.y)
                return false;
            if (fp.size() >= 3 && pointInPolygon(fp, p)) return true;
            for (size_t k = 0; k < fp.size(); ++k)
                if (pointSegmentDistance(p, fp[k], fp[(k + 1) % fp.size()]) < kBuildingClearance) return true;
            return false;
        });
    }

    // Distance from p to the nearest building footprint, capped at kCrownSearch.
    double clearance(const glm::dvec2& p) const {
        double best = kCrownSearch;
        const glm::dvec2 lo = p - kCrownSearch, hi = p + kCrownSearch;
        _bIdx.forCells(lo, hi, [&](size_t cellId) {
            _bIdx.forItems(cellId, [&](uint32_t i) {
                const auto& fp = _city.buildings[i].footprint;
                if (_bBox[i].second.x < lo.x || _bBox[i].second.y < lo.y || _bBox[i].first.x > hi.x ||
                    _bBox[i].first.y > hi.y)
                    return;
                for (size_t k = 0; k < fp.size(); ++k)
                    best = std::min(best, pointSegmentDistance(p, fp[k], fp[(k + 1) % fp.size()]));
            });
        });
        return best;
    }

    double crownRadius(int species, int variant) const { return _crown[size_t(species * kVariants + variant)]; }

private:
    static constexpr double kCell = 32.0;

    // Indexes every building's footprint box, grown by the building clearance.
    void indexBuildings() {
        _bBox.resize(_city.buildings.size());
        for (size_t i = 0; i < _city.buildings.size(); ++i) {
            glm::dvec2 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
            for (const auto& q : _city.buildings[i].footprint) lo = glm::min(lo, q), hi = glm::max(hi, q);
            _bBox[i] = {lo - kBuildingClearance, hi + kBuildingClearance};
            if (!std::isfinite(lo.x + lo.y + hi.x + hi.y)) _bBox[i] = {glm::dvec2(1.0), glm::dvec2(0.0)};  // skipped
        }
        for (const auto& b : _bBox)
            if (b.first.x <= b.second.x) _bIdx.count(b.first, b.second);
        _bIdx.finishCounts();
        for (size_t i = 0; i < _bBox.size(); ++i)
            if (_bBox[i].first.x <= _bBox[i].second.x) _bIdx.fill(_bBox[i].first, _bBox[i].second, uint32_t(i));
    }

    // Indexes every carriageway with valid, finite end points (the graph
    // contract guarantees them; the check keeps bad input safe anyway).
    void indexEdges() {
        const StreetGraph& g = _city.streets;
        _edgeOk.assign(g.edges.size(), 0);
        for (size_t e = 0; e < g.edges.size(); ++e) {
            const auto& E = g.edges[e];
            _edgeOk[e] = E.a < g.nodes.size() && E.b < g.nodes.size() &&
                         std::isfinite(g.nodes[E.a].x + g.nodes[E.a].y + g.nodes[E.b].x + g.nodes[E.b].y);
        }
        auto edgeBox = [&](size_t e) {
            const auto& a = g.nodes[g.edges[e].a];
            const auto& b = g.nodes[g.edges[e].b];
            double m = 0.5 * edgeWidth(g.edges[e]) + kRoadClearance;
            return std::make_pair(glm::min(a, b) - m, glm::max(a, b) + m);
        };
        for (size_t e = 0; e < g.edges.size(); ++e)
            if (_edgeOk[e]) {
                auto bb = edgeBox(e);
                _eIdx.count(bb.first, bb.second);
            }
        _eIdx.finishCounts();
        for (size_t e = 0; e < g.edges.size(); ++e)
            if (_edgeOk[e]) {
                auto bb = edgeBox(e);
                _eIdx.fill(bb.first, bb.second, uint32_t(e));
            }
    }

    // Measures the crown radius (max horizontal extent) of every prototype.
    void measureCrowns() {
        _crown.assign(size_t(kSpecies * kVariants), 0.0);
        for (int i = 0; i < kSpecies * kVariants; ++i) {
            if (size_t(i) < _city.treePrototypes.size()) {
                for (const auto& q : _city.treePrototypes[size_t(i)].mesh.positions)
                    _crown[size_t(i)] = std::max(_crown[size_t(i)], std::hypot(double(q.x), double(q.y)));
            } else {
                _crown[size_t(i)] = 0.3 * kHeights[i / kVariants][i % kVariants];  // nominal
            }
        }
    }

    const City& _city;
    CellIndex _bIdx, _eIdx;
    std::vector<std::pair<glm::dvec2, glm::dvec2>> _bBox;
    std::vector<uint8_t> _edgeOk;
    std::vector<double> _crown;
};

bool inCity(const glm::dvec2& p, double half) { return std::abs(p.x) <= half - 1.0 && std::abs(p.y) <= half - 1.0; }

// Adds street tree candidates: evenly spaced along both sides of every
// street, clear of its intersections, one species per street.
void addStreetCandidates(const City& city, const std::vector<uint8_t>& edgeOk, double half,
                         std::vector<Candidate>& cand) {
    const CityParams& P = city.params;
    const StreetGraph& g = city.streets;
    std::vector<int> deg(g.nodes.size(), 0);
    for (size_t e = 0; e < g.edges.size(); ++e)
        if (edgeOk[e]) ++deg[g.edges[e].a], ++deg[g.edges[e].b];
    const double spacing = P.street_tree_spacing_m;
    for (size_t e = 0; e < g.edges.size(); ++e) {
        if (!edgeOk[e]) continue;
        const auto& E = g.edges[e];
        glm::dvec2 A = g.nodes[E.a], B = g.nodes[E.b];
        double L = glm::length(B - A);
        if (!(L > 1e-6)) continue;
        glm::dvec2 d = (B - A) / L, n(-d.y, d.x);
        auto clearance = [&](uint32_t node) {
            int k = deg[node];
            return k >= 3 ? kIntersectionClearance : (k == 2 ? 4.0 : 3.0);
        };
        double ca = clearance(E.a), cb = clearance(E.b);
        double usable = L - ca - cb;
        if (usable < 0) continue;
        // Evenly spaced, centred in the usable stretch.
        int count = int(std::floor(usable / spacing)) + 1;
        double first = ca + 0.5 * (usable - (count - 1) * spacing);
        // Species per street (stable key: quantised end points, order-independent).
        uint64_t ka = quantKey(A), kb = quantKey(B);
        Rng srng(P.seed, hashKeys(std::min(ka, kb), std::max(ka, kb), 0x57EE7ull), Stream::Trees);
        int streetSpecies = int(srng.range(0, kSpecies - 1));
        double off = 0.5 * edgeWidth(E) + 0.5 * P.sidewalk_m;
        for (int side = -1; side <= 1; side += 2) {
            for (int i = 0; i < count; ++i) {
                glm::dvec2 p = A + d * (first + i * spacing) + n * (side * off);
                if (!inCity(p, half)) continue;
                cand.push_back({p, 0, quantKey(p), true, streetSpecies});
            }
        }
    }
}

// Adds park tree candidates: a jittered grid anchored to the city frame (cells
// seeded by their lattice index, so a park's trees do not depend on other
// blocks), kept off the park outline.
void addParkCandidates(const City& city, double half, std::vector<Candidate>& cand) {
    const CityParams& P = city.params;
    const double c = 1.0 / std::sqrt(P.park_tree_density);
    for (const auto& blk : city.blocks) {
        if (!blk.park || blk.outline.size() < 3) continue;
        glm::dvec2 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
        for (const auto& q : blk.outline) lo = glm::min(lo, q), hi = glm::max(hi, q);
        if (!std::isfinite(lo.x + lo.y + hi.x + hi.y)) continue;
        // Clamp to the city square (park blocks lie inside it; guards huge loops on bad input).
        lo = glm::max(lo, glm::dvec2(-half)), hi = glm::min(hi, glm::dvec2(half));
        if (!(hi.x > lo.x && hi.y > lo.y)) continue;
        int64_t i0 = int64_t(std::floor(lo.x / c)), i1 = int64_t(std::floor(hi.x / c));
        int64_t j0 = int64_t(std::floor(lo.y / c)), j1 = int64_t(std::floor(hi.y / c));
        for (int64_t j = j0; j <= j1; ++j) {
            for (int64_t i = i0; i <= i1; ++i) {
                Rng r(P.seed, hashKeys(uint64_t(i), uint64_t(j), 0x9A2Cull), Stream::Trees);
                glm::dvec2 p((double(i) + r.uniform(0.1, 0.9)) * c, (double(j) + r.uniform(0.1, 0.9)) * c);
                if (!pointInPolygon(blk.outline, p) || !inCity(p, half)) continue;
                bool nearEdge = false;
                for (size_t k = 0; k < blk.outline.size() && !nearEdge; ++k)
                    nearEdge = pointSegmentDistance(p, blk.outline[k], blk.outline[(k + 1) % blk.outline.size()]) <
                               kParkEdgeClearance;
                if (nearEdge) continue;
                cand.push_back({p, 0, quantKey(p), false, -1});
            }
        }
    }
}

// Puts the candidates in canonical order (tile, then position, street trees
// first), so the greedy spacing filter does not depend on edge order.
void sortCandidates(const CityParams& P, std::vector<Candidate>& cand) {
    TileGrid grid(P);
    for (auto& c : cand) c.tile = grid.tileOf(c.p);
    std::sort(cand.begin(), cand.end(), [&](const Candidate& a, const Candidate& b) {
        if (a.tile != b.tile) return a.tile < b.tile;
        if (a.p.y != b.p.y) return a.p.y < b.p.y;
        if (a.p.x != b.p.x) return a.p.x < b.p.x;
        return a.street > b.street;
    });
}

// Accepted trunks in a hash grid (cell = kMinTreeDistance): head per cell + linked list.
class TrunkGrid {
public:
    explicit TrunkGrid(size_t capacity) { _head.reserve(capacity); }

    // Whether an accepted trunk stands closer than kMinTreeDistance to p.
    bool close(const glm::dvec2& p) const {
        int64_t gx = cellOf(p.x), gy = cellOf(p.y);
        bool close = false;
        for (int64_t y = gy - 1; y <= gy + 1 && !close; ++y)
            for (int64_t x = gx - 1; x <= gx + 1 && !close; ++x) {
                auto it = _head.find(cellKey(x, y));
                if (it == _head.end()) continue;
                for (uint32_t k = it->second; k != kNone && !close; k = _next[k])
                    close = glm::length(_pos[k] - p) < kMinTreeDistance;
            }
        return close;
    }

    void add(const glm::dvec2& p) {
        auto ins = _head.emplace(cellKey(cellOf(p.x), cellOf(p.y)), kNone);
        _next.push_back(ins.first->second);
        _pos.push_back(p);
        ins.first->second = uint32_t(_pos.size() - 1);
    }

private:
    static constexpr uint32_t kNone = 0xFFFFFFFFu;
    static int64_t cellOf(double v) { return int64_t(std::floor(v / kMinTreeDistance)); }
    static uint64_t cellKey(int64_t x, int64_t y) { return (uint64_t(x) << 32) ^ (uint64_t(y) & 0xFFFFFFFFull); }

    std::unordered_map<uint64_t, uint32_t> _head;
    std::vector<glm::dvec2> _pos;
    std::vector<uint32_t> _next;
};

// Grows the tree of an accepted candidate: species, variant, yaw and scale
// drawn from the candidate's own stream, the crown shrunk to fit between facades.
TreeInstance growTree(const CityParams& P, const Candidate& c, const SiteIndex& sites, int protoCount) {
    Rng r(P.seed, c.key, Stream::Trees);
    int species;
    if (c.species >= 0) {
        species = r.chance(0.85) ? c.species : int(r.range(0, kSpecies - 1));
    } else {
        double u = r.uniform();  // parks: mostly broadleaf
        species = u < 0.55 ? 0 : (u < 0.85 ? 1 : 2);
    }
    int variant = c.street ? (r.chance(0.6) ? 1 : int(r.range(0, 1)) * 2) : int(r.range(0, kVariants - 1));
    TreeInstance t;
    t.position = glm::dvec3(c.p, terrainHeight(P, c.p));
    t.yaw = float(r.uniform(0.0, 2 * kPi));
    double scale = r.uniform(0.85, 1.15);
    // Crowns should not grow into facades: near buildings take a smaller
    // variant (then a smaller scale) so the crown radius fits the clearance.
    double room = sites.clearance(c.p) + kCrownOverlap;
    while (variant > 0 && sites.crownRadius(species, variant) * scale > room) --variant;
    if (sites.crownRadius(species, variant) * scale > room)
        scale = std::max(0.85, room / std::max(sites.crownRadius(species, variant), 1e-6));
    t.scale = float(scale);
    t.prototype = uint16_t(std::min(species * kVariants + variant, protoCount - 1));
    t.street = c.street;
    return t;
}

}  // namespace

std::vector<TreeInstance> placeTrees(const City& city, Progress* progress) {
    const CityParams& P = city.params;
    const double half = P.size_m * 0.5;
    const int protoCount = city.treePrototypes.empty() ? kSpecies * kVariants : int(city.treePrototypes.size());
    std::vector<TreeInstance> out;
    if (progress) progress->update(0.0);

    const SiteIndex sites(city, half);
    std::vector<Candidate> cand;
    if (P.street_tree_spacing_m > 0 && !city.streets.edges.empty())
        addStreetCandidates(city, sites.edgeOk(), half, cand);
    if (progress) progress->update(0.3);
    if (P.park_tree_density > 0) addParkCandidates(city, half, cand);
    if (progress) progress->update(0.5);

    // Rejects conflicts in canonical order: too close to a kept tree, on a
    // carriageway or in a building.
    sortCandidates(P, cand);
    TrunkGrid kept(cand.size());
    out.reserve(cand.size());
    for (const auto& c : cand) {
        if (kept.close(c.p) || sites.onRoad(c.p) || sites.inBuilding(c.p)) continue;
        kept.add(c.p);
        out.push_back(growTree(P, c, sites, protoCount));
    }
    if (progress) progress->update(1.0);
    return out;
}

}  // namespace vista
