// growStreets(): hierarchical street growth on a global, seeded lattice.
//
// Highways and arterials are the lines of a jittered lattice (spacing
// arterial_spacing_m) whose points are warped towards concentric rings where
// the radial pattern dominates and jittered where the organic pattern does;
// every highway_spacing_m/arterial_spacing_m-th lattice line is a highway.
// Each lattice cell is filled with local streets: straight through-streets
// (grid / radial cells; streets continue across arterials because adjacent
// cells subdivide their shared side identically) or recursive irregular cuts
// (organic cells), spacing from the population density. All random choices
// come from Rng(seed, id of the lattice point / line / cell, Stream::Streets),
// so a cell looks the same whatever the city size. Everything is clipped to
// the city square, planarized exactly, and edges meeting at less than
// min_angle_deg are pruned.
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "foundation/rng.h"
#include "foundation/units.h"
#include "citygen/street_geometry.h"
#include "citygen/streets.h"
#include "citygen/terrain.h"

namespace vista {

namespace {

uint64_t cellId(uint64_t tag, int64_t i, int64_t j) { return hashKeys(tag, uint64_t(i), uint64_t(j)); }

double smoothstep(double e0, double e1, double x) {
    double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return t * t * (3 - 2 * t);
}

// Liang-Barsky clip of segment ab to the square [-h, h]^2.
bool clipToSquare(glm::dvec2& a, glm::dvec2& b, double h) {
    double t0 = 0, t1 = 1;
    glm::dvec2 d = b - a;
    const double p[4] = {-d.x, d.x, -d.y, d.y};
    const double q[4] = {a.x + h, h - a.x, a.y + h, h - a.y};
    for (int k = 0; k < 4; ++k) {
        if (p[k] == 0) {
            if (q[k] < 0) return false;
        } else {
            double t = q[k] / p[k];
            if (p[k] < 0) t0 = std::max(t0, t);
            else t1 = std::min(t1, t);
        }
    }
    if (t0 >= t1) return false;
    glm::dvec2 na = a + d * t0, nb = a + d * t1;
    a = glm::clamp(na, glm::dvec2(-h), glm::dvec2(h));
    b = glm::clamp(nb, glm::dvec2(-h), glm::dvec2(h));
    return a != b;
}

class Grower {
public:
    Grower(const CityParams& p, Progress* progress) : _p(p), _progress(progress) {
        _h = 0.5 * p.size_m;
        _s = p.arterial_spacing_m;
        Rng rng(p.seed, 0x5EED, Stream::Streets);
        _theta = rng.uniform(-0.35, 0.35);  // lattice orientation (radians)
        _rot = glm::dvec2(std::cos(_theta), std::sin(_theta));
        _hwEvery = std::max<int64_t>(2, int64_t(std::lround(p.highway_spacing_m / _s)));
        _hwPhaseI = rng.range(0, _hwEvery - 1);
        _hwPhaseJ = rng.range(0, _hwEvery - 1);
        _ringK = std::max<int64_t>(_hwEvery + 1, int64_t(std::lround(1.3 * p.highway_spacing_m / _s)));
        _ext = std::min(2.0, 0.45 * p.min_segment_m);
        // Lattice index range covering the square after rotation and warp.
        double reach = _h * 1.5 + 2 * _s;
        _i0 = int64_t(std::floor(-reach / _s));
        _i1 = int64_t(std::ceil(reach / _s));
    }

    StreetGraph run() {
        const int64_t n = _i1 - _i0 + 1;
        _pts.resize(size_t(n * n));
        for (int64_t j = _i0; j <= _i1; ++j)
            for (int64_t i = _i0; i <= _i1; ++i) _pts[idx(i, j)] = latticePoint(i, j);
        report(0.05);
        addLatticeRoads();
        report(0.1);
        int64_t done = 0;
        for (int64_t j = _i0; j < _i1; ++j) {
            for (int64_t i = _i0; i < _i1; ++i) fillCell(i, j);
            done++;
            report(0.1 + 0.3 * double(done) / double(n));
        }
        StreetGraph g = planarize(_segs, _p.snap_radius_m, _p.min_segment_m);
        report(0.85);
        pruneAngles(g);
        report(1.0);
        return g;
    }

private:
    size_t idx(int64_t i, int64_t j) const { return size_t((j - _i0) * (_i1 - _i0 + 1) + (i - _i0)); }
    const glm::dvec2& pt(int64_t i, int64_t j) const { return _pts[idx(i, j)]; }

    glm::dvec2 toWorld(const glm::dvec2& q) const { return {q.x * _rot.x - q.y * _rot.y, q.x * _rot.y + q.y * _rot.x}; }

    double lineOffset(uint64_t axis, int64_t k) const {
        Rng r(_p.seed, cellId(0xA1 + axis, k, 0), Stream::Streets);
        return k * _s + r.uniform(-0.1, 0.1) * _s;
    }
    bool highwayI(int64_t i) const { return ((i - _hwPhaseI) % _hwEvery + _hwEvery) % _hwEvery == 0; }
    bool highwayJ(int64_t j) const { return ((j - _hwPhaseJ) % _hwEvery + _hwEvery) % _hwEvery == 0; }

    glm::dvec2 latticePoint(int64_t i, int64_t j) const {
        glm::dvec2 base(lineOffset(0, i), lineOffset(1, j));
        glm::dvec2 w0 = toWorld(base);
        glm::dvec3 w = patternWeights(_p, w0);
        // Radial: map lattice squares onto circles (rings + spokes).
        double rad = smoothstep(0.2, 0.5, w.y);
        glm::dvec2 q = base;
        double len = glm::length(base);
        if (len > 1e-9 && rad > 0) {
            glm::dvec2 circ = base * (std::max(std::abs(base.x), std::abs(base.y)) / len);
            q = glm::mix(base, circ, rad);
        }
        // Organic: jitter the point.
        double org = smoothstep(0.3, 0.7, w.z);
        if (org > 0) {
            Rng r(_p.seed, cellId(0xA3, i, j), Stream::Streets);
            double amp = 0.2 * _s * org * ((highwayI(i) || highwayJ(j)) ? 0.3 : 1.0);
            q += glm::dvec2(r.uniform(-1, 1), r.uniform(-1, 1)) * amp;
        }
        return toWorld(q);
    }

    double density(const glm::dvec2& p) const { return populationDensity(_p, p); }

    void add(glm::dvec2 a, glm::dvec2 b, RoadClass cls) {
        if (!clipToSquare(a, b, _h)) return;
        _segs.push_back({a, b, cls});
    }
    void addExtended(glm::dvec2 a, glm::dvec2 b, RoadClass cls) {
        glm::dvec2 d = b - a;
        double l = glm::length(d);
        if (l < 1e-9) return;
        d /= l;
        add(a - d * _ext, b + d * _ext, cls);
    }

    bool outside(const glm::dvec2& a, const glm::dvec2& b) const {
        return (a.x < -_h && b.x < -_h) || (a.x > _h && b.x > _h) || (a.y < -_h && b.y < -_h) || (a.y > _h && b.y > _h);
    }

    int64_t cheb(int64_t i, int64_t j) const { return std::max(std::abs(i), std::abs(j)); }

    void addLatticeRoads() {
        for (int64_t j = _i0; j <= _i1; ++j)
            for (int64_t i = _i0; i <= _i1; ++i)
                for (int dir = 0; dir < 2; ++dir) {
                    int64_t i2 = i + (dir == 0), j2 = j + (dir == 1);
                    if (i2 > _i1 || j2 > _i1) continue;
                    glm::dvec2 a = pt(i, j), b = pt(i2, j2);
                    if (outside(a, b)) continue;
                    bool hw = dir == 0 ? highwayJ(j) : highwayI(i);
                    bool ring = cheb(i, j) == _ringK && cheb(i2, j2) == _ringK && _h > 0.6 * _ringK * _s;
                    if (hw || ring) {
                        add(a, b, RoadClass::Highway);
                        continue;
                    }
                    double d = density(0.5 * (a + b));
                    if (d < 0.03) continue;
                    if (d < 0.08) {  // sparse arterials in the outskirts
                        Rng r(_p.seed, cellId(0xA4 + dir, i, j), Stream::Streets);
                        if (!r.chance((d - 0.03) / 0.05)) continue;
                    }
                    add(a, b, RoadClass::Arterial);
                }
    }

    // Local street spacing for density d (denser centre -> smaller blocks).
    double spacingFor(double d) const {
        double e = 1.0 - d;
        return _p.local_spacing_m * (0.6 + 0.7 * e * e);
    }

    void fillCell(int64_t i, int64_t j) {
        const glm::dvec2 c00 = pt(i, j), c10 = pt(i + 1, j), c11 = pt(i + 1, j + 1), c01 = pt(i, j + 1);
        glm::dvec2 lo = glm::min(glm::min(c00, c10), glm::min(c11, c01));
        glm::dvec2 hi = glm::max(glm::max(c00, c10), glm::max(c11, c01));
        if (hi.x < -_h || hi.y < -_h || lo.x > _h || lo.y > _h) return;
        glm::dvec2 centre = 0.25 * (c00 + c10 + c11 + c01);
        double d = density(centre);
        if (d < 0.06) return;  // countryside
        Rng rng(_p.seed, cellId(0xC0, i, j), Stream::Streets);
        glm::dvec3 w = patternWeights(_p, centre);
        glm::dvec3 w3 = w * w * w;
        double u = rng.uniform() * (w3.x + w3.y + w3.z);
        int pattern = u < w3.x ? 0 : (u < w3.x + w3.y ? 1 : 2);
        double spacing = spacingFor(d);
        if (pattern == 2) {
            std::vector<glm::dvec2> poly = {c00, c10, c11, c01};
            organicSplit(poly, spacing * spacing * 1.15, rng, d, 0);
            return;
        }
        // Grid / radial: straight streets between opposite sides at equal fractions,
        // so neighbouring cells with the same count continue them across arterials.
        double wI = 0.5 * (glm::length(c10 - c00) + glm::length(c11 - c01));  // extent along i
        double wJ = 0.5 * (glm::length(c01 - c00) + glm::length(c11 - c10));  // extent along j
        // Regional block aspect (Manhattan-like long blocks in some regions).
        double aspectNoise = valueNoise(_p.seed, 0xA5, centre / (4.0 * _s));
        double aspect = 1.0 + std::max(0.0, aspectNoise) * 2.0;
        bool longAlongI = valueNoise(_p.seed, 0xA6, centre / (5.0 * _s)) > 0;
        double spI = spacing * (longAlongI ? aspect : 1.0), spJ = spacing * (longAlongI ? 1.0 : aspect);
        int nI = std::max(0, int(std::lround(wI / spI)) - 1);  // lines crossing the i extent
        int nJ = std::max(0, int(std::lround(wJ / spJ)) - 1);
        for (int k = 1; k <= nJ; ++k) {
            double f = double(k) / (nJ + 1);
            addExtended(glm::mix(c00, c01, f), glm::mix(c10, c11, f), RoadClass::Local);
        }
        for (int k = 1; k <= nI; ++k) {
            double f = double(k) / (nI + 1);
            addExtended(glm::mix(c00, c10, f), glm::mix(c01, c11, f), RoadClass::Local);
        }
    }

    // Recursive irregular subdivision of a simple polygon with cuts roughly
    // perpendicular to its longest side; occasional dead ends at low density.
    void organicSplit(const std::vector<glm::dvec2>& poly, double targetArea, Rng& rng, double d, int depth) {
        double area = 0;
        for (size_t k = 0; k < poly.size(); ++k) {
            const auto& a = poly[k];
            const auto& b = poly[(k + 1) % poly.size()];
            area += a.x * b.y - a.y * b.x;
        }
        area = 0.5 * std::abs(area);
        if (area < targetArea * rng.uniform(0.8, 1.6) || depth > 12 || poly.size() > 40) return;
        size_t longest = 0;
        double best = -1;
        for (size_t k = 0; k < poly.size(); ++k) {
            double l = glm::length(poly[(k + 1) % poly.size()] - poly[k]);
            if (l > best) {
                best = l;
                longest = k;
            }
        }
        const glm::dvec2 a = poly[longest], b = poly[(longest + 1) % poly.size()];
        glm::dvec2 start = glm::mix(a, b, rng.uniform(0.38, 0.62));
        glm::dvec2 t = (b - a) / best;
        double ang = rng.uniform(-0.3, 0.3);
        glm::dvec2 nrm(-t.y, t.x);
        glm::dvec2 dir = nrm * std::cos(ang) + t * std::sin(ang);
        // Orient dir into the polygon (counter-clockwise polygon has interior on the left).
        double signedArea = 0;
        for (size_t k = 0; k < poly.size(); ++k) {
            const auto& p0 = poly[k];
            const auto& p1 = poly[(k + 1) % poly.size()];
            signedArea += p0.x * p1.y - p0.y * p1.x;
        }
        if (signedArea < 0) dir = -dir;
        // Find the nearest exit of the ray start + s*dir (s > eps) through the polygon.
        double bestS = 1e300;
        size_t exitEdge = SIZE_MAX;
        for (size_t k = 0; k < poly.size(); ++k) {
            if (k == longest) continue;
            glm::dvec2 p0 = poly[k], p1 = poly[(k + 1) % poly.size()];
            glm::dvec2 e = p1 - p0;
            double den = dir.x * e.y - dir.y * e.x;
            if (std::abs(den) < 1e-12) continue;
            glm::dvec2 w0 = p0 - start;
            double s = (w0.x * e.y - w0.y * e.x) / den;
            double r = (w0.x * dir.y - w0.y * dir.x) / den;
            if (s > 1e-6 && r >= 0 && r <= 1 && s < bestS) {
                bestS = s;
                exitEdge = k;
            }
        }
        if (exitEdge == SIZE_MAX) return;
        glm::dvec2 end = start + dir * bestS;
        if (bestS < _p.min_segment_m * 2) return;
        // Dead end (cul-de-sac) now and then in low density: the cut stops halfway, no split.
        if (d < 0.45 && depth >= 1 && rng.chance(0.18)) {
            addExtended(start, start + dir * (0.55 * bestS), RoadClass::Local);
            // continue splitting the untouched polygon (once more, shallower)
            if (depth < 6) organicSplit(poly, targetArea * 1.5, rng, d, depth + 3);
            return;
        }
        addExtended(start, end, RoadClass::Local);
        // Split the polygon along start (on edge `longest`) -> end (on edge `exitEdge`).
        std::vector<glm::dvec2> p1, p2;
        const size_t n = poly.size();
        p1.push_back(start);
        for (size_t k = (longest + 1) % n;; k = (k + 1) % n) {
            p1.push_back(poly[k]);
            if (k == exitEdge) break;
        }
        p1.push_back(end);
        p2.push_back(end);
        for (size_t k = (exitEdge + 1) % n;; k = (k + 1) % n) {
            p2.push_back(poly[k]);
            if (k == longest) break;
        }
        p2.push_back(start);
        organicSplit(p1, targetArea, rng, d, depth + 1);
        organicSplit(p2, targetArea, rng, d, depth + 1);
    }

    // Removes edges meeting another at a node at less than min_angle_deg
    // (lower class, then shorter, goes), then isolated nodes.
    void pruneAngles(StreetGraph& g) const {
        const double minAng = _p.min_angle_deg * kPi / 180.0;
        std::vector<char> removed(g.edges.size(), 0);
        for (int pass = 0; pass < 8; ++pass) {
            std::vector<std::vector<uint32_t>> inc(g.nodes.size());
            for (uint32_t e = 0; e < g.edges.size(); ++e)
                if (!removed[e]) {
                    inc[g.edges[e].a].push_back(e);
                    inc[g.edges[e].b].push_back(e);
                }
            bool changed = false;
            for (uint32_t v = 0; v < g.nodes.size(); ++v) {
                auto& list = inc[v];
                if (list.size() < 2) continue;
                auto angleOf = [&](uint32_t e) {
                    uint32_t o = g.edges[e].a == v ? g.edges[e].b : g.edges[e].a;
                    glm::dvec2 d = g.nodes[o] - g.nodes[v];
                    return std::atan2(d.y, d.x);
                };
                std::vector<std::pair<double, uint32_t>> angs;
                for (uint32_t e : list) angs.emplace_back(angleOf(e), e);
                std::sort(angs.begin(), angs.end());
                for (size_t k = 0; k < angs.size(); ++k) {
                    auto [a0, e0] = angs[k];
                    auto [a1, e1] = angs[(k + 1) % angs.size()];
                    if (removed[e0] || removed[e1]) continue;
                    double gap = a1 - a0;
                    if (k + 1 == angs.size()) gap += 2 * kPi;
                    if (gap >= minAng) continue;
                    auto key = [&](uint32_t e) { return std::make_pair(-int(g.edges[e].cls), g.edgeLength(e)); };
                    removed[key(e0) < key(e1) ? e0 : e1] = 1;
                    changed = true;
                }
            }
            if (!changed) break;
        }
        std::vector<uint32_t> newIndex(g.nodes.size(), UINT32_MAX);
        StreetGraph out;
        for (uint32_t e = 0; e < g.edges.size(); ++e) {
            if (removed[e]) continue;
            StreetEdge se = g.edges[e];
            for (uint32_t* v : {&se.a, &se.b}) {
                if (newIndex[*v] == UINT32_MAX) { newIndex[*v] = 0; }
            }
            out.edges.push_back(se);
        }
        // Keep canonical node order (planarize sorted by coordinates).
        uint32_t next = 0;
        for (uint32_t v = 0; v < g.nodes.size(); ++v)
            if (newIndex[v] != UINT32_MAX) {
                newIndex[v] = next++;
                out.nodes.push_back(g.nodes[v]);
            }
        for (auto& e : out.edges) {
            e.a = newIndex[e.a];
            e.b = newIndex[e.b];
        }
        g = std::move(out);
    }

    void report(double f) {
        if (_progress) _progress->update(f);
    }

    const CityParams& _p;
    Progress* _progress;
    double _h = 0, _s = 0, _theta = 0, _ext = 0;
    glm::dvec2 _rot{1, 0};
    int64_t _hwEvery = 4, _hwPhaseI = 0, _hwPhaseJ = 0, _ringK = 5;
    int64_t _i0 = 0, _i1 = 0;
    std::vector<glm::dvec2> _pts;
    std::vector<RawSegment> _segs;
};

}  // namespace

StreetGraph growStreets(const CityParams& params, Progress* progress) {
    Grower g(params, progress);
    return g.run();
}

}  // namespace vista
