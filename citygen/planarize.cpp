// planarize(): exact arrangement (CGAL Epeck) of arbitrary segments, then a
// cleanup in double precision (snap, contract short edges, dedup) that is
// re-checked with exact predicates and repeated until the graph is planar;
// a last-resort pass drops conflicting edges so the contract always holds.
// Carriageways (streets.h) ride along as edge data through every step, so
// each merge can ask which carriageways its two nodes lie on.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <map>
#include <numeric>
#include <tuple>
#include <unordered_map>

#include <CGAL/Arr_curve_data_traits_2.h>
#include <CGAL/Arr_segment_traits_2.h>
#include <CGAL/Arrangement_2.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>

#include "citygen/street_geometry.h"
#include "citygen/streets.h"

namespace vista {

namespace {

using Epeck = CGAL::Exact_predicates_exact_constructions_kernel;
using SegTraits = CGAL::Arr_segment_traits_2<Epeck>;
// A segment's road class and carriageway; overlapping pieces keep the highest
// class, and their carriageway only when both share it.
struct SegData {
    int cls = 2;
    uint32_t carriageway = 0;
    bool operator==(const SegData& o) const { return cls == o.cls && carriageway == o.carriageway; }
};
struct MergeSegData {
    SegData operator()(const SegData& a, const SegData& b) const {
        return {std::min(a.cls, b.cls), a.carriageway == b.carriageway ? a.carriageway : 0u};
    }
};
using Traits = CGAL::Arr_curve_data_traits_2<SegTraits, SegData, MergeSegData>;
using Arrangement = CGAL::Arrangement_2<Traits>;

struct WorkEdge {
    uint32_t a, b;
    int cls;
    uint32_t carriageway = 0;
};
struct WorkGraph {
    std::vector<glm::dvec2> nodes;
    std::vector<WorkEdge> edges;
};

bool lessPoint(const glm::dvec2& p, const glm::dvec2& q) { return p.x < q.x || (p.x == q.x && p.y < q.y); }

// Exact arrangement of the segments; vertices rounded to double.
WorkGraph arrange(const std::vector<RawSegment>& segs) {
    std::vector<Traits::Curve_2> curves;
    curves.reserve(segs.size());
    for (const auto& s : segs) {
        if (s.a == s.b) continue;
        curves.emplace_back(SegTraits::Curve_2(Epeck::Point_2(s.a.x, s.a.y), Epeck::Point_2(s.b.x, s.b.y)),
                            SegData{int(s.cls), s.carriageway});
    }
    WorkGraph g;
    if (curves.empty()) return g;
    Arrangement arr;
    CGAL::insert(arr, curves.begin(), curves.end());
    std::unordered_map<const void*, uint32_t> index;
    index.reserve(arr.number_of_vertices() * 2);
    for (auto v = arr.vertices_begin(); v != arr.vertices_end(); ++v) {
        index[&*v] = uint32_t(g.nodes.size());
        g.nodes.emplace_back(CGAL::to_double(v->point().x()), CGAL::to_double(v->point().y()));
    }
    for (auto e = arr.edges_begin(); e != arr.edges_end(); ++e) {
        uint32_t a = index[&*e->source()], b = index[&*e->target()];
        g.edges.push_back({a, b, std::clamp(e->curve().data().cls, 0, 2), e->curve().data().carriageway});
    }
    return g;
}

struct UnionFind {
    std::vector<uint32_t> p;
    explicit UnionFind(size_t n) : p(n) { std::iota(p.begin(), p.end(), 0u); }
    uint32_t find(uint32_t x) {
        while (p[x] != x) {
            p[x] = p[p[x]];
            x = p[x];
        }
        return x;
    }
};

// Applies a node mapping (old -> representative), removes self loops,
// duplicates (keeping the highest class) and isolated nodes.
void rebuild(WorkGraph& g, const std::vector<uint32_t>& rep) {
    std::map<std::pair<uint32_t, uint32_t>, SegData> best;
    for (const auto& e : g.edges) {
        uint32_t a = rep[e.a], b = rep[e.b];
        if (a == b) continue;
        auto key = std::make_pair(std::min(a, b), std::max(a, b));
        auto it = best.find(key);
        if (it == best.end()) best.emplace(key, SegData{e.cls, e.carriageway});
        else it->second = MergeSegData()(it->second, SegData{e.cls, e.carriageway});
    }
    std::vector<uint32_t> newIndex(g.nodes.size(), UINT32_MAX);
    WorkGraph out;
    for (const auto& [key, data] : best) {
        for (uint32_t v : {key.first, key.second})
            if (newIndex[v] == UINT32_MAX) {
                newIndex[v] = uint32_t(out.nodes.size());
                out.nodes.push_back(g.nodes[v]);
            }
        out.edges.push_back({newIndex[key.first], newIndex[key.second], data.cls, data.carriageway});
    }
    g = std::move(out);
}

// Node priority for snapping/merging: higher class first, then higher degree.
std::vector<std::pair<int, int>> nodeRank(const WorkGraph& g) {
    std::vector<std::pair<int, int>> r(g.nodes.size(), {3, 0});  // (best class, -degree)
    for (const auto& e : g.edges)
        for (uint32_t v : {e.a, e.b}) {
            r[v].first = std::min(r[v].first, e.cls);
            r[v].second--;
        }
    return r;
}

bool better(const WorkGraph& g, const std::vector<std::pair<int, int>>& rank, uint32_t a, uint32_t b) {
    if (rank[a] != rank[b]) return rank[a] < rank[b];
    return lessPoint(g.nodes[a], g.nodes[b]);
}

// The carriageways (sorted, distinct) of every node's incident edges.
using Carriageways = std::vector<uint32_t>;
std::vector<Carriageways> nodeCarriageways(const WorkGraph& g) {
    std::vector<Carriageways> c(g.nodes.size());
    for (const auto& e : g.edges)
        if (e.carriageway)
            for (uint32_t v : {e.a, e.b}) c[v].push_back(e.carriageway);
    for (auto& v : c) {
        std::sort(v.begin(), v.end());
        v.erase(std::unique(v.begin(), v.end()), v.end());
    }
    return c;
}

// Two nodes `d` apart may become one: one's carriageways are among the
// other's (so a way's own nodes and free nodes always may), or they are
// closer than kCarriagewayMerge_m.
bool mayMerge(const Carriageways& x, const Carriageways& y, double d) {
    return d < kCarriagewayMerge_m || std::includes(x.begin(), x.end(), y.begin(), y.end()) ||
           std::includes(y.begin(), y.end(), x.begin(), x.end());
}

void unite(Carriageways& into, const Carriageways& from) {
    if (from.empty()) return;
    Carriageways u;
    std::set_union(into.begin(), into.end(), from.begin(), from.end(), std::back_inserter(u));
    into = std::move(u);
}

// Merges nodes closer than `snap` onto the best-ranked node nearby that it may merge with.
bool snapNodes(WorkGraph& g, double snap) {
    const size_t n = g.nodes.size();
    auto rank = nodeRank(g);
    std::vector<uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return better(g, rank, a, b); });
    std::vector<uint32_t> rep(n);
    std::iota(rep.begin(), rep.end(), 0u);
    std::vector<Carriageways> cw = nodeCarriageways(g);  // of each representative: all it took in
    bool changed = false;
    const double cell = std::max(snap, 1e-9);
    std::unordered_map<uint64_t, std::vector<uint32_t>> grid;
    grid.reserve(n * 2);
    auto key = [](int64_t x, int64_t y) { return (uint64_t(x) << 32) ^ (uint64_t(y) & 0xffffffffull); };
    for (uint32_t v : order) {
        const glm::dvec2 p = g.nodes[v];
        int64_t cx = int64_t(std::floor(p.x / cell)), cy = int64_t(std::floor(p.y / cell));
        uint32_t found = UINT32_MAX;
        double bestD = 0;
        for (int64_t dy = -1; dy <= 1; ++dy)
            for (int64_t dx = -1; dx <= 1; ++dx) {
                auto it = grid.find(key(cx + dx, cy + dy));
                if (it == grid.end()) continue;
                for (uint32_t r : it->second) {
                    double d = glm::length(g.nodes[r] - p);
                    if (d <= snap && mayMerge(cw[r], cw[v], d) &&
                        (found == UINT32_MAX || d < bestD || (d == bestD && better(g, rank, r, found)))) {
                        found = r;
                        bestD = d;
                    }
                }
            }
        if (found != UINT32_MAX) {
            rep[v] = found;
            unite(cw[found], cw[v]);
            changed = true;
        } else grid[key(cx, cy)].push_back(v);
    }
    if (changed) rebuild(g, rep);
    return changed;
}

// Contracts edges shorter than minSegment (the better-ranked end survives).
bool contractShort(WorkGraph& g, double minSegment) {
    bool any = false;
    for (int pass = 0; pass < 50; ++pass) {
        auto rank = nodeRank(g);
        std::vector<uint32_t> order(g.edges.size());
        std::iota(order.begin(), order.end(), 0u);
        auto len = [&](uint32_t e) { return glm::length(g.nodes[g.edges[e].b] - g.nodes[g.edges[e].a]); };
        std::sort(order.begin(), order.end(), [&](uint32_t x, uint32_t y) {
            double lx = len(x), ly = len(y);
            return lx < ly || (lx == ly && x < y);
        });
        UnionFind uf(g.nodes.size());
        std::vector<Carriageways> cw = nodeCarriageways(g);  // of each root: all it took in
        bool changed = false;
        for (uint32_t e : order) {
            if (len(e) >= minSegment) break;
            uint32_t a = uf.find(g.edges[e].a), b = uf.find(g.edges[e].b);
            if (a == b) continue;
            const double d = glm::length(g.nodes[a] - g.nodes[b]);
            if (d >= minSegment || !mayMerge(cw[a], cw[b], d)) continue;
            if (better(g, rank, b, a)) std::swap(a, b);
            uf.p[b] = a;  // a survives at its own position
            unite(cw[a], cw[b]);
            changed = true;
        }
        if (!changed) break;
        any = true;
        std::vector<uint32_t> rep(g.nodes.size());
        for (uint32_t v = 0; v < g.nodes.size(); ++v) rep[v] = uf.find(v);
        rebuild(g, rep);
    }
    return any;
}

// Splits edges at nodes lying within a tolerance of their interior (the node
// is not incident to the edge): T-junctions that stop just short of / just
// past a street, and near-collinear overlaps left by rounding exact vertices.
// Dead ends (degree 1) use `snap`, other nodes min(snap, minSegment/2); both at
// least 1e-6 m.
bool snapNodesToEdges(WorkGraph& g, double snap, double minSegment) {
    const size_t nn = g.nodes.size(), ne = g.edges.size();
    if (ne == 0) return false;
    std::vector<int> deg(nn, 0);
    for (const auto& e : g.edges) {
        deg[e.a]++;
        deg[e.b]++;
    }
    const double tolDead = std::max(snap, 1e-6), tolOther = std::max(std::min(snap, 0.5 * minSegment), 1e-6);
    double sumLen = 0;
    for (const auto& e : g.edges) sumLen += glm::length(g.nodes[e.b] - g.nodes[e.a]);
    const double cell = std::max({sumLen / double(ne), tolDead, 1e-3});
    std::unordered_map<uint64_t, std::vector<uint32_t>> grid;
    auto key = [](int64_t x, int64_t y) { return (uint64_t(x) << 32) ^ (uint64_t(y) & 0xffffffffull); };
    for (uint32_t i = 0; i < ne; ++i) {
        glm::dvec2 a = g.nodes[g.edges[i].a], b = g.nodes[g.edges[i].b];
        glm::dvec2 lo = glm::min(a, b) - tolDead, hi = glm::max(a, b) + tolDead;
        int64_t x0 = int64_t(std::floor(lo.x / cell)), x1 = int64_t(std::floor(hi.x / cell));
        int64_t y0 = int64_t(std::floor(lo.y / cell)), y1 = int64_t(std::floor(hi.y / cell));
        if ((x1 - x0 + 1) * (y1 - y0 + 1) > 4096) continue;  // absurdly long edge: skip
        for (int64_t y = y0; y <= y1; ++y)
            for (int64_t x = x0; x <= x1; ++x) grid[key(x, y)].push_back(i);
    }
    std::vector<std::vector<std::pair<double, uint32_t>>> splits(ne);
    const std::vector<Carriageways> cw = nodeCarriageways(g);
    bool any = false;
    for (uint32_t v = 0; v < nn; ++v) {
        const glm::dvec2 p = g.nodes[v];
        const double tol = deg[v] <= 1 ? tolDead : tolOther;
        auto it = grid.find(key(int64_t(std::floor(p.x / cell)), int64_t(std::floor(p.y / cell))));
        if (it == grid.end()) continue;
        uint32_t best = UINT32_MAX;
        double bestD = tol, bestT = 0;
        for (uint32_t ei : it->second) {
            const auto& e = g.edges[ei];
            if (e.a == v || e.b == v) continue;
            glm::dvec2 a = g.nodes[e.a], d = g.nodes[e.b] - a;
            double dd = glm::dot(d, d);
            if (dd <= 0) continue;
            double t = glm::dot(p - a, d) / dd;
            if (t <= 0 || t >= 1) continue;
            double dist = glm::length(p - (a + t * d));
            if (e.carriageway && !mayMerge(cw[v], Carriageways{e.carriageway}, dist)) continue;
            if (dist < bestD || (dist == bestD && best != UINT32_MAX && ei < best)) {
                bestD = dist;
                best = ei;
                bestT = t;
            }
        }
        if (best != UINT32_MAX) {
            splits[best].emplace_back(bestT, v);
            any = true;
        }
    }
    if (!any) return false;
    std::vector<WorkEdge> edges;
    for (uint32_t i = 0; i < ne; ++i) {
        const auto& e = g.edges[i];
        if (splits[i].empty()) {
            edges.push_back(e);
            continue;
        }
        std::sort(splits[i].begin(), splits[i].end());
        uint32_t prev = e.a;
        for (auto [t, v] : splits[i]) {
            if (v != prev) edges.push_back({prev, v, e.cls, e.carriageway});
            prev = v;
        }
        edges.push_back({prev, e.b, e.cls, e.carriageway});
    }
    g.edges = std::move(edges);
    std::vector<uint32_t> ident(g.nodes.size());
    std::iota(ident.begin(), ident.end(), 0u);
    rebuild(g, ident);
    return true;
}

// The street graph of `w` in canonical order (nodes by (x, y), edges by (a, b)
// with a < b) and, when asked, each edge's carriageway.
StreetGraph toStreetGraph(const WorkGraph& w, std::vector<uint32_t>* carriageways = nullptr) {
    std::vector<uint32_t> order(w.nodes.size());
    std::iota(order.begin(), order.end(), 0u);
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return lessPoint(w.nodes[a], w.nodes[b]); });
    std::vector<uint32_t> newIndex(w.nodes.size());
    StreetGraph g;
    g.nodes.reserve(w.nodes.size());
    for (uint32_t i = 0; i < order.size(); ++i) {
        newIndex[order[i]] = i;
        g.nodes.push_back(w.nodes[order[i]]);
    }
    std::vector<std::pair<StreetEdge, uint32_t>> edges;
    edges.reserve(w.edges.size());
    for (const auto& e : w.edges) {
        StreetEdge se;
        se.a = std::min(newIndex[e.a], newIndex[e.b]);
        se.b = std::max(newIndex[e.a], newIndex[e.b]);
        se.cls = RoadClass(uint8_t(e.cls));
        se.width = float(roadWidth(se.cls));
        se.lanes = uint8_t(roadLanes(se.cls));
        edges.emplace_back(se, e.carriageway);
    }
    std::sort(edges.begin(), edges.end(), [](const auto& x, const auto& y) {
        return std::tie(x.first.a, x.first.b) < std::tie(y.first.a, y.first.b);
    });
    g.edges.reserve(edges.size());
    if (carriageways) carriageways->clear();
    for (const auto& [se, c] : edges) {
        g.edges.push_back(se);
        if (carriageways) carriageways->push_back(c);
    }
    return g;
}

std::vector<RawSegment> toSegments(const WorkGraph& g) {
    std::vector<RawSegment> s;
    s.reserve(g.edges.size());
    for (const auto& e : g.edges) s.push_back({g.nodes[e.a], g.nodes[e.b], RoadClass(uint8_t(e.cls)), e.carriageway});
    return s;
}

}  // namespace

StreetGraph planarize(const std::vector<RawSegment>& segments, double snap, double minSegment,
                      std::vector<uint32_t>* carriageways) {
    if (!std::isfinite(snap) || snap < 0) snap = 0;
    if (!std::isfinite(minSegment) || minSegment < 0) minSegment = 0;
    // Input hygiene: finite, bounded coordinates; valid classes; zero-length dropped.
    WorkGraph g;
    {
        std::map<std::pair<double, double>, uint32_t> ids;
        auto node = [&](const glm::dvec2& p) {
            auto [it, inserted] = ids.emplace(std::make_pair(p.x, p.y), uint32_t(g.nodes.size()));
            if (inserted) g.nodes.push_back(p);
            return it->second;
        };
        for (const auto& s : segments) {
            auto ok = [](const glm::dvec2& p) {
                return std::isfinite(p.x) && std::isfinite(p.y) && std::abs(p.x) < 1e9 && std::abs(p.y) < 1e9;
            };
            if (!ok(s.a) || !ok(s.b) || s.a == s.b) continue;
            // +0.0 canonicalises -0.0 so the map key matches.
            glm::dvec2 a(s.a.x + 0.0, s.a.y + 0.0), b(s.b.x + 0.0, s.b.y + 0.0);
            g.edges.push_back({node(a), node(b), std::clamp(int(s.cls), 0, 2), s.carriageway});
        }
    }
    // Pre-snap input endpoints, so near-coincident ends meet before the exact arrangement.
    std::vector<uint32_t> id(g.nodes.size());
    std::iota(id.begin(), id.end(), 0u);
    rebuild(g, id);
    snapNodes(g, snap);

    for (int iter = 0; iter < 6; ++iter) {
        g = arrange(toSegments(g));
        // Exact rounding to double may make distinct vertices coincide: snap handles it (distance 0 <= snap).
        for (int k = 0; k < 10; ++k) {
            bool c1 = snapNodes(g, snap);
            bool c2 = snapNodesToEdges(g, snap, minSegment);
            bool c3 = contractShort(g, minSegment);
            if (!c1 && !c2 && !c3) break;
        }
        std::vector<uint32_t> cw;
        StreetGraph sg = toStreetGraph(g, &cw);
        if (findConflictingEdges(sg, 1).empty()) {
            if (carriageways) *carriageways = std::move(cw);
            return sg;
        }
    }

    // Last resort: drop conflicting edges (lowest class, then shortest) until planar.
    for (int guard = 0; guard < 1000; ++guard) {
        std::vector<uint32_t> cw;
        StreetGraph sg = toStreetGraph(g, &cw);
        auto bad = findConflictingEdges(sg, SIZE_MAX);
        if (bad.empty()) break;
        std::vector<char> drop(sg.edges.size(), 0);
        for (auto [e, f] : bad) {
            if (drop[e] || drop[f]) continue;
            auto key = [&](uint32_t x) { return std::make_pair(-int(sg.edges[x].cls), sg.edgeLength(x)); };
            drop[key(e) < key(f) ? e : f] = 1;
        }
        WorkGraph w;
        w.nodes = sg.nodes;
        for (size_t i = 0; i < sg.edges.size(); ++i)
            if (!drop[i]) w.edges.push_back({sg.edges[i].a, sg.edges[i].b, int(sg.edges[i].cls), cw[i]});
        std::vector<uint32_t> ident(w.nodes.size());
        std::iota(ident.begin(), ident.end(), 0u);
        rebuild(w, ident);
        g = std::move(w);
    }
    // Deleting (not contracting) edges that are still short keeps planarity.
    WorkGraph w;
    w.nodes = g.nodes;
    for (const auto& e : g.edges)
        if (glm::length(g.nodes[e.b] - g.nodes[e.a]) >= minSegment) w.edges.push_back(e);
    std::vector<uint32_t> ident(w.nodes.size());
    std::iota(ident.begin(), ident.end(), 0u);
    rebuild(w, ident);
    return toStreetGraph(w, carriageways);
}

}  // namespace vista
