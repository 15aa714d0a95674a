// extractBlocks(): faces of the street arrangement, inset per edge.
//
// 1. CGAL Arrangement_2 (exact kernel) of all street edges plus the city square.
// 2. Every bounded face inside the square: its outer boundary as a vertex
//    cycle. Dead ends (antennas) inside the face appear as back-and-forth
//    edges; the per-edge inset turns them into notches with a square cap.
// 3. Per-edge inset: street edges by width/2 + sidewalk, border edges by 0.
//    When that is not a valid simple polygon (a dead end reaching across the
//    face, edges vanishing): exact CGAL polygon difference of the face minus
//    every boundary street edge buffered by its own offset (may split the face).
// 4. Safety net: a block whose distance to any street centre line is below
//    half that street's width is dropped; tiny or thin blocks are dropped.
// 5. Density, parks (seeded score favouring low density), sort by centroid.
#include "citygen/blocks.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <unordered_map>

#include <CGAL/Arr_segment_traits_2.h>
#include <CGAL/Arrangement_2.h>
#include <CGAL/Boolean_set_operations_2.h>
#include <CGAL/Polygon_set_2.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <tbb/parallel_for.h>

#include "citygen/building_geometry.h"
#include "citygen/polygon.h"
#include "foundation/rng.h"
#include "citygen/terrain.h"

namespace vista {

namespace {

using EK = CGAL::Exact_predicates_exact_constructions_kernel;
using Traits = CGAL::Arr_segment_traits_2<EK>;
using Arrangement = CGAL::Arrangement_2<Traits>;
using ExactPolygon = CGAL::Polygon_2<EK>;

constexpr double kMinBlockArea = 100.0;
constexpr double kMinBlockWidth = 6.0;
constexpr double kGridCell = 64.0;

// Uniform grid over street edges for nearest-edge queries.
class EdgeGrid {
public:
    explicit EdgeGrid(const StreetGraph& g) {
        for (uint32_t e = 0; e < g.edges.size(); ++e) {
            if (g.edges[e].a >= g.nodes.size() || g.edges[e].b >= g.nodes.size()) continue;  // invalid: ignored
            glm::dvec2 a = g.nodes[g.edges[e].a], b = g.nodes[g.edges[e].b];
            double r = 0.5 * g.edges[e].width + 1.0;
            int x0 = cell(std::min(a.x, b.x) - r), x1 = cell(std::max(a.x, b.x) + r);
            int y0 = cell(std::min(a.y, b.y) - r), y1 = cell(std::max(a.y, b.y) + r);
            if (x1 - x0 > 4096 || y1 - y0 > 4096) {
                _huge.push_back(e);
                continue;
            }
            for (int y = y0; y <= y1; ++y)
                for (int x = x0; x <= x1; ++x) _cells[key(x, y)].push_back(e);
        }
    }
    // Calls f(edge) for every edge whose cell range touches the box [lo, hi] (may repeat).
    template <class F>
    void query(glm::dvec2 lo, glm::dvec2 hi, F f) const {
        for (uint32_t e : _huge) f(e);
        int x0 = cell(lo.x), x1 = cell(hi.x), y0 = cell(lo.y), y1 = cell(hi.y);
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) {
                auto it = _cells.find(key(x, y));
                if (it != _cells.end())
                    for (uint32_t e : it->second) f(e);
            }
    }

private:
    static int cell(double v) { return int(std::floor(std::clamp(v, -1e9, 1e9) / kGridCell)); }
    static uint64_t key(int x, int y) { return (uint64_t(uint32_t(x)) << 32) | uint32_t(y); }
    std::unordered_map<uint64_t, std::vector<uint32_t>> _cells;
    std::vector<uint32_t> _huge;
};

bool finiteGraph(const StreetGraph& g) {
    for (const auto& n : g.nodes)
        if (!std::isfinite(n.x) || !std::isfinite(n.y)) return false;
    return true;
}

// Distance from polygon (boundary and interior) to segment ab.
double polygonSegmentDistance(const Polygon2& poly, const glm::dvec2& a, const glm::dvec2& b) {
    if (pointInPolygon(poly, a) || pointInPolygon(poly, b)) return 0.0;
    double d = 1e300;
    for (size_t i = 0; i < poly.size(); ++i) {
        const auto& p = poly[i];
        const auto& q = poly[(i + 1) % poly.size()];
        auto orient = [](const glm::dvec2& u, const glm::dvec2& v, const glm::dvec2& w) {
            return (v.x - u.x) * (w.y - u.y) - (v.y - u.y) * (w.x - u.x);
        };
        double o1 = orient(p, q, a), o2 = orient(p, q, b), o3 = orient(a, b, p), o4 = orient(a, b, q);
        if (((o1 > 0) != (o2 > 0)) && ((o3 > 0) != (o4 > 0)) && o1 != 0 && o2 != 0 && o3 != 0 && o4 != 0) return 0.0;
        d = std::min({d, pointSegmentDistance(p, a, b), pointSegmentDistance(q, a, b), pointSegmentDistance(a, p, q),
                      pointSegmentDistance(b, p, q)});
    }
    return d;
}

struct FaceLoop {
    Polygon2 pts;                  // outer boundary incl. antennas (both sides)
    std::vector<uint8_t> antenna;  // per edge: both sides belong to this face
};

// Offset of the face edge p->q: street half width + sidewalk, or 0 on the border.
double edgeOffset(const glm::dvec2& p, const glm::dvec2& q, const StreetGraph& g, const EdgeGrid& grid,
                  const CityParams& params) {
    glm::dvec2 m = 0.5 * (p + q);
    double len = glm::length(q - p);
    double best = -1;
    grid.query(m, m, [&](uint32_t e) {
        glm::dvec2 a = g.nodes[g.edges[e].a], b = g.nodes[g.edges[e].b];
        double tol = 1e-6 * std::max(1.0, len);
        if (pointSegmentDistance(m, a, b) <= tol && pointSegmentDistance(p, a, b) <= tol + 1e-6 &&
            pointSegmentDistance(q, a, b) <= tol + 1e-6)
            best = std::max(best, 0.5 * double(g.edges[e].width) + params.sidewalk_m);
    });
    return best < 0 ? 0.0 : best;
}

std::vector<Polygon2> insetFace(const FaceLoop& f, const StreetGraph& g, const EdgeGrid& grid,
                                const CityParams& params) {
    std::vector<Polygon2> out;
    size_t n = f.pts.size();
    if (n < 3) return out;
    std::vector<double> d(n);
    double dmax = 0;
    for (size_t i = 0; i < n; ++i) {
        d[i] = edgeOffset(f.pts[i], f.pts[(i + 1) % n], g, grid, params);
        dmax = std::max(dmax, d[i]);
    }
    if (dmax <= 0) return out;  // no street on this face (e.g. an empty graph): not a block
    Polygon2 r;
    if (insetPolygonMiter(f.pts, d, r)) {
        out.push_back(std::move(r));
        return out;
    }
    // Fallback: exact polygon difference: the face (without antennas) minus the
    // union of every boundary street edge buffered by its own offset (square caps).
    Polygon2 outer;
    for (size_t i = 0; i < n; ++i)
        if (!f.antenna[i]) {
            if (outer.empty() || glm::length(outer.back() - f.pts[i]) > 1e-9) outer.push_back(f.pts[i]);
        }
    outer = cleanPolygon(outer, 1e-9);
    if (outer.size() < 3 || !(signedArea(outer) > 0)) return out;
    try {
        ExactPolygon face;
        for (const auto& q : outer) face.push_back(EK::Point_2(q.x, q.y));
        if (!face.is_simple()) return out;
        if (!face.is_counterclockwise_oriented()) face.reverse_orientation();
        std::vector<ExactPolygon> rects;
        for (size_t i = 0; i < n; ++i) {
            if (d[i] <= 0) continue;
            glm::dvec2 a = f.pts[i], b = f.pts[(i + 1) % n];
            double len = glm::length(b - a);
            if (!(len > 1e-9)) continue;
            glm::dvec2 t = (b - a) / len, nn(-t.y, t.x);
            glm::dvec2 a0 = a - t * d[i], b0 = b + t * d[i];
            ExactPolygon r;
            r.push_back(EK::Point_2((a0 - nn * d[i]).x, (a0 - nn * d[i]).y));
            r.push_back(EK::Point_2((b0 - nn * d[i]).x, (b0 - nn * d[i]).y));
            r.push_back(EK::Point_2((b0 + nn * d[i]).x, (b0 + nn * d[i]).y));
            r.push_back(EK::Point_2((a0 + nn * d[i]).x, (a0 + nn * d[i]).y));
            if (r.is_simple() && r.is_counterclockwise_oriented()) rects.push_back(std::move(r));
        }
        CGAL::Polygon_set_2<EK> roads;
        roads.join(rects.begin(), rects.end());
        CGAL::Polygon_set_2<EK> rest(face);
        rest.difference(roads);
        std::vector<CGAL::Polygon_with_holes_2<EK>> pieces;
        rest.polygons_with_holes(std::back_inserter(pieces));
        for (const auto& pw : pieces) {
            if (pw.is_unbounded() || pw.number_of_holes() > 0) continue;
            Polygon2 q;
            for (auto it = pw.outer_boundary().vertices_begin(); it != pw.outer_boundary().vertices_end(); ++it)
                q.emplace_back(CGAL::to_double(it->x()), CGAL::to_double(it->y()));
            q = cleanPolygon(makeCounterClockwise(std::move(q)), 1e-7);
            if (q.size() >= 3 && signedArea(q) > 0 && isSimplePolygon(q)) out.push_back(std::move(q));
        }
    } catch (const std::exception&) { out.clear(); }
    return out;
}

bool keepBlock(const Polygon2& poly, const StreetGraph& g, const EdgeGrid& grid) {
    if (poly.size() < 3) return false;
    double area = signedArea(poly);
    if (!(area >= kMinBlockArea)) return false;
    OrientedBox box = orientedBox(poly);
    if (2.0 * box.halfV < kMinBlockWidth) return false;
    double perim = 0;
    for (size_t i = 0; i < poly.size(); ++i) perim += glm::length(poly[(i + 1) % poly.size()] - poly[i]);
    if (2.0 * area / perim < 0.4 * kMinBlockWidth) return false;
    // Road clearance safety net.
    glm::dvec2 lo(1e300), hi(-1e300);
    for (const auto& p : poly) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    bool ok = true;
    grid.query(lo - glm::dvec2(20.0), hi + glm::dvec2(20.0), [&](uint32_t e) {
        if (!ok) return;
        glm::dvec2 a = g.nodes[g.edges[e].a], b = g.nodes[g.edges[e].b];
        if (polygonSegmentDistance(poly, a, b) < 0.5 * double(g.edges[e].width) - 1e-6) ok = false;
    });
    return ok;
}

}  // namespace

std::vector<Block> extractBlocks(const StreetGraph& g, const CityParams& params, Progress* progress) {
    std::vector<Block> blocks;
    if (!finiteGraph(g) || !(params.size_m > 0)) return blocks;
    const double half = 0.5 * params.size_m;
    std::vector<FaceLoop> loops;
    try {
        std::vector<Traits::X_monotone_curve_2> segs;
        segs.reserve(g.edges.size() + 4);
        for (const auto& e : g.edges) {
            if (e.a >= g.nodes.size() || e.b >= g.nodes.size()) continue;
            glm::dvec2 a = g.nodes[e.a], b = g.nodes[e.b];
            if (glm::length(b - a) < 1e-9) continue;
            segs.emplace_back(EK::Point_2(a.x, a.y), EK::Point_2(b.x, b.y));
        }
        EK::Point_2 c0(-half, -half), c1(half, -half), c2(half, half), c3(-half, half);
        segs.emplace_back(c0, c1);
        segs.emplace_back(c1, c2);
        segs.emplace_back(c2, c3);
        segs.emplace_back(c3, c0);
        Arrangement arr;
        CGAL::insert(arr, segs.begin(), segs.end());
        if (progress) progress->update(0.4);
        for (auto f = arr.faces_begin(); f != arr.faces_end(); ++f) {
            if (f->is_unbounded() || !f->has_outer_ccb()) continue;
            FaceLoop loop;
            auto c0h = f->outer_ccb();
            auto c = c0h;
            do {
                const auto& p = c->source()->point();
                loop.pts.emplace_back(CGAL::to_double(p.x()), CGAL::to_double(p.y()));
                loop.antenna.push_back(c->twin()->face() == c->face() ? 1 : 0);
            } while (++c != c0h);
            if (loop.pts.size() < 3) continue;
            // Faces outside the city square (streets running past the border) are skipped.
            Polygon2 noAnt;
            for (size_t i = 0; i < loop.pts.size(); ++i)
                if (!loop.antenna[i]) noAnt.push_back(loop.pts[i]);
            auto tris = triangulate(noAnt);
            glm::dvec2 inner =
                tris.size() >= 3 ? (noAnt[tris[0]] + noAnt[tris[1]] + noAnt[tris[2]]) / 3.0 : centroid(noAnt);
            if (std::abs(inner.x) > half || std::abs(inner.y) > half) continue;
            if (!(signedArea(loop.pts) > 0)) continue;  // outer CCBs of bounded faces are CCW
            loops.push_back(std::move(loop));
        }
    } catch (const std::exception&) { return blocks; }
    if (progress) progress->update(0.6);

    EdgeGrid grid(g);
    std::vector<std::vector<Polygon2>> insets(loops.size());
    tbb::parallel_for(size_t(0), loops.size(), [&](size_t i) {
        for (auto& p : insetFace(loops[i], g, grid, params))
            if (keepBlock(p, g, grid)) insets[i].push_back(std::move(p));
    });
    for (auto& v : insets)
        for (auto& p : v) {
            Block b;
            b.outline = std::move(p);
            b.density = std::clamp(populationDensity(params, centroid(b.outline)), 0.0, 1.0);
            blocks.push_back(std::move(b));
        }
    // Deterministic order: by centroid (y, then x).
    std::vector<glm::dvec2> cent(blocks.size());
    std::vector<size_t> order(blocks.size());
    for (size_t i = 0; i < blocks.size(); ++i) {
        cent[i] = centroid(blocks[i].outline);
        order[i] = i;
    }
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        if (cent[a].y != cent[b].y) return cent[a].y < cent[b].y;
        return cent[a].x < cent[b].x;
    });
    std::vector<Block> sorted;
    sorted.reserve(blocks.size());
    for (size_t i : order) sorted.push_back(std::move(blocks[i]));
    blocks = std::move(sorted);

    // Parks: the park_fraction of blocks with the highest seeded score (favouring low density).
    size_t nParks = size_t(std::llround(params.park_fraction * double(blocks.size())));
    if (nParks > 0) {
        std::vector<std::pair<double, size_t>> score(blocks.size());
        for (size_t i = 0; i < blocks.size(); ++i) {
            Rng rng(params.seed, stableIdOf(centroid(blocks[i].outline)), Stream::Blocks);
            score[i] = {(1.0 - blocks[i].density) + 0.6 * rng.uniform(), i};
        }
        std::sort(score.begin(), score.end(), [](const auto& a, const auto& b) {
            return a.first > b.first || (a.first == b.first && a.second < b.second);
        });
        for (size_t k = 0; k < std::min(nParks, score.size()); ++k) blocks[score[k].second].park = true;
    }
    if (progress) progress->update(1.0);
    return blocks;
}

}  // namespace vista
