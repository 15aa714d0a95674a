// The lane model: see lanes.h.
#include "citygen/lanes.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include "citygen/polygon.h"

namespace vista {

double carriagewayWidth(const StreetEdge& e) {
    double w = double(e.width);
    return std::isfinite(w) && w > 0.5 ? w : roadWidth(e.cls);
}

namespace {

// Point-in-block queries over a uniform grid of block bounding boxes.
class BlockLookup {
public:
    explicit BlockLookup(const std::vector<Block>& blocks) : _blocks(blocks) {
        for (size_t b = 0; b < blocks.size(); ++b) {
            const Polygon2& o = blocks[b].outline;
            if (o.size() < 3) continue;
            glm::dvec2 lo(1e300), hi(-1e300);
            for (const auto& q : o) lo = glm::min(lo, q), hi = glm::max(hi, q);
            if (!std::isfinite(lo.x + lo.y + hi.x + hi.y)) continue;
            for (long y = cell(lo.y); y <= cell(hi.y); ++y)
                for (long x = cell(lo.x); x <= cell(hi.x); ++x) _grid[{x, y}].push_back(uint32_t(b));
        }
    }
    bool inside(const glm::dvec2& p) const {
        auto it = _grid.find({cell(p.x), cell(p.y)});
        if (it == _grid.end()) return false;
        for (uint32_t b : it->second)
            if (pointInPolygon(_blocks[b].outline, p)) return true;
        return false;
    }

private:
    static long cell(double v) { return long(std::floor(v / 64.0)); }
    const std::vector<Block>& _blocks;
    std::map<std::pair<long, long>, std::vector<uint32_t>> _grid;
};

}  // namespace

LaneModel buildLaneModel(const StreetGraph& g, const CityParams& params, const std::vector<Block>* blocks) {
    LaneModel m;
    const size_t N = g.nodes.size();
    m.degree.assign(N, 0);
    m.nodeJunction.assign(N, -1);
    m.edges.resize(g.edges.size());
    const double sw = params.sidewalk_m > 0.01 ? params.sidewalk_m : 0.0;
    std::vector<std::vector<uint32_t>> incident(N);
    for (size_t e = 0; e < g.edges.size(); ++e) {
        const StreetEdge& E = g.edges[e];
        EdgeLanes& L = m.edges[e];
        if (E.a >= N || E.b >= N || E.a == E.b) continue;
        const glm::dvec2 A = g.nodes[E.a], B = g.nodes[E.b];
        if (!std::isfinite(A.x + A.y + B.x + B.y)) continue;
        const double len = glm::length(B - A);
        if (!(len > 1e-6)) continue;
        L.valid = true;
        L.dir = (B - A) / len;
        const int n = std::max<int>(E.lanes, 2);
        L.right = (n + 1) / 2;
        L.left = n / 2;
        L.laneWidth = carriagewayWidth(E) / n;
        L.sidewalk = sw;
        L.offset = 0.5 * (L.right - L.left) * L.laneWidth;
        L.start = A;
        L.end = B;
        L.length = len;
        ++m.degree[E.a];
        ++m.degree[E.b];
        incident[E.a].push_back(uint32_t(e));
        incident[E.b].push_back(uint32_t(e));
    }
    for (uint32_t v = 0; v < N; ++v) {
        if (m.degree[v] < 3) continue;
        Junction J;
        J.node = v;
        J.arms = incident[v];
        for (uint32_t e : J.arms) J.radius = std::max(J.radius, m.edges[e].halfWidth() + sw);
        auto angle = [&](uint32_t e) {
            const EdgeLanes& L = m.edges[e];
            glm::dvec2 d = g.edges[e].a == v ? L.dir : -L.dir;
            return std::atan2(d.y + 0.0, d.x + 0.0);  // + 0.0: no -0, so west is +pi, not -pi
        };
        std::stable_sort(J.arms.begin(), J.arms.end(), [&](uint32_t x, uint32_t y) { return angle(x) < angle(y); });
        m.nodeJunction[v] = int(m.junctions.size());
        m.junctions.push_back(std::move(J));
    }
    for (size_t e = 0; e < g.edges.size(); ++e) {
        EdgeLanes& L = m.edges[e];
        if (!L.valid) continue;
        const StreetEdge& E = g.edges[e];
        L.junctionA = m.nodeJunction[E.a];
        L.junctionB = m.nodeJunction[E.b];
        double ta = L.junctionA >= 0 ? m.junctions[size_t(L.junctionA)].radius : 0.0;
        double tb = L.junctionB >= 0 ? m.junctions[size_t(L.junctionB)].radius : 0.0;
        const double len = L.length, room = std::max(0.0, len - kMinRoadLength);
        if (ta + tb > room) {
            const double f = ta + tb > 0 ? room / (ta + tb) : 0.0;
            ta *= f;
            tb *= f;
        }
        L.trimA = ta;
        L.trimB = tb;
        const glm::dvec2 A = g.nodes[E.a];
        L.start = A + L.dir * ta;
        L.end = A + L.dir * (len - tb);
        L.length = len - ta - tb;
    }
    if (blocks && sw > 0) {
        const BlockLookup lookup(*blocks);
        for (size_t e = 0; e < g.edges.size(); ++e) {
            EdgeLanes& L = m.edges[e];
            if (!L.valid) continue;
            const glm::dvec2 mid = 0.5 * (g.nodes[g.edges[e].a] + g.nodes[g.edges[e].b]);
            const double reach = L.halfWidth() + sw + 1.0;
            L.walkLeft = lookup.inside(mid + L.normal() * reach);
            L.walkRight = lookup.inside(mid - L.normal() * reach);
        }
    }
    return m;
}

}  // namespace vista
