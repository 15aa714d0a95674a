// Slight bends next to a junction straightened: see short_bends.h.
#include "citygen/short_bends.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "citygen/polygon.h"

namespace vista {

namespace {

// The edge read from node `from` to its other node: a and b, the directions'
// lane counts and turn lanes swapped where it runs the other way.
StreetEdge along(const StreetEdge& e, uint32_t from) {
    if (e.a == from) return e;
    StreetEdge r = e;
    std::swap(r.a, r.b);
    std::swap(r.lanesForward, r.lanesBackward);
    std::swap(r.turnForward, r.turnBackward);
    return r;
}

bool sameRoad(const StreetEdge& x, const StreetEdge& y) {
    return x.cls == y.cls && x.width == y.width && x.lanes == y.lanes && x.lanesForward == y.lanesForward &&
           x.lanesBackward == y.lanesBackward && x.maxspeedKmh == y.maxspeedKmh && x.turnForward == y.turnForward &&
           x.turnBackward == y.turnBackward;
}

double cross(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

// True when p lies inside or on triangle a, b, c.
bool inTriangle(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
    const double d0 = cross(b - a, p - a), d1 = cross(c - b, p - b), d2 = cross(a - c, p - c);
    const bool neg = d0 < 0 || d1 < 0 || d2<0, pos = d0> 0 || d1 > 0 || d2 > 0;
    return !(neg && pos);
}

}  // namespace

size_t straightenShortBends(StreetGraph& g) {
    const size_t N = g.nodes.size();
    for (const StreetEdge& e : g.edges)
        if (e.a >= N || e.b >= N) return 0;
    for (const glm::dvec2& p : g.nodes)
        if (!std::isfinite(p.x + p.y)) return 0;
    std::vector<std::vector<uint32_t>> incident(N);
    for (uint32_t k = 0; k < g.edges.size(); ++k)
        incident[g.edges[k].a].push_back(k), incident[g.edges[k].b].push_back(k);
    std::vector<char> removedEdge(g.edges.size(), 0), removedNode(N, 0);
    std::vector<std::vector<glm::dvec2>> dropped(g.edges.size());  // nodes dropped inside each edge
    const double cosMax = std::cos(kShortBendAngle);
    size_t count = 0;
    for (bool changed = true; changed;) {
        changed = false;
        for (uint32_t t = 0; t < N; ++t) {
            if (removedNode[t] || incident[t].size() != 2) continue;
            for (int side = 0; side < 2; ++side) {
                const uint32_t ei = incident[t][size_t(side)], fi = incident[t][size_t(1 - side)];
                const uint32_t j = g.edges[ei].a == t ? g.edges[ei].b : g.edges[ei].a;
                const uint32_t x = g.edges[fi].a == t ? g.edges[fi].b : g.edges[fi].a;
                if (j == x || incident[j].size() < 3) continue;
                const glm::dvec2 J = g.nodes[j], T = g.nodes[t], X = g.nodes[x];
                const double le = glm::length(T - J), lf = glm::length(X - T), lc = glm::length(X - J);
                if (!(le > 0 && lf > 0 && lc > 0) || le > kShortBendArm) continue;
                if (glm::dot(T - J, X - T) < cosMax * le * lf) continue;
                StreetEdge e = along(g.edges[ei], j), f = along(g.edges[fi], t);
                if (!sameRoad(e, f)) continue;
                bool ok = pointSegmentDistance(T, J, X) <= kShortBendDeviation;
                for (uint32_t k : {ei, fi})
                    for (const glm::dvec2& p : dropped[k])
                        ok = ok && pointSegmentDistance(p, J, X) <= kShortBendDeviation;
                for (uint32_t k : incident[j]) {
                    const uint32_t o = g.edges[k].a == j ? g.edges[k].b : g.edges[k].a;
                    ok = ok && o != x;
                }
                for (uint32_t v = 0; v < N && ok; ++v)
                    if (v != j && v != t && v != x && !removedNode[v] && !incident[v].empty())
                        ok = !inTriangle(g.nodes[v], J, T, X);
                if (!ok) continue;
                f.a = j;
                if (f.lanesForward == 0 && f.lanesBackward > 0) f = along(f, x);  // along its traffic
                dropped[fi].push_back(T);
                dropped[fi].insert(dropped[fi].end(), dropped[ei].begin(), dropped[ei].end());
                g.edges[fi] = std::move(f);
                removedEdge[ei] = 1;
                removedNode[t] = 1;
                incident[j].erase(std::find(incident[j].begin(), incident[j].end(), ei));
                incident[j].push_back(fi);
                incident[t].clear();
                ++count;
                changed = true;
                break;
            }
        }
    }
    if (!count) return 0;
    std::vector<uint32_t> newIndex(N, 0);
    StreetGraph out;
    for (uint32_t v = 0; v < N; ++v) {
        newIndex[v] = uint32_t(out.nodes.size());
        if (!removedNode[v]) out.nodes.push_back(g.nodes[v]);
    }
    for (size_t k = 0; k < g.edges.size(); ++k) {
        if (removedEdge[k]) continue;
        StreetEdge e = std::move(g.edges[k]);
        e.a = newIndex[e.a];
        e.b = newIndex[e.b];
        out.edges.push_back(std::move(e));
    }
    g = std::move(out);
    return count;
}

}  // namespace vista
