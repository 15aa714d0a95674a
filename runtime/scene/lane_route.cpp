// Car routes through the lane model: see lane_route.h.
#include "runtime/scene/lane_route.h"

#include <algorithm>
#include <cmath>

#include "foundation/units.h"

namespace vista {

namespace {

constexpr double kStreetStep = 1.0;   // centre-line vertex spacing on street roads (straight)
constexpr double kCurveStep = 0.25;   // on link roads and U-turns
constexpr double kTaperWidth = 0.01;  // a lane narrower than this where it ends is a taper
// Vertices closer than this to the previous one are dropped: where two
// pieces meet, their end points agree only to rounding, and the heading of
// so short a segment would be noise (a curvature spike).
constexpr double kMinVertexGap = 0.02;

double compassHeading(const glm::dvec2& d) { return std::atan2(d.x, d.y); }
glm::dvec2 leftNormal(double hdg) { return {-std::sin(hdg), std::cos(hdg)}; }  // of a math heading

const LinkRoad::Lane* linkLane(const LinkRoad& r, int id) {
    if (id < 0 && size_t(-id) <= r.right.size()) return &r.right[size_t(-id - 1)];
    if (id > 0 && size_t(id) <= r.left.size()) return &r.left[size_t(id - 1)];
    return nullptr;
}

// The driving lane of a street road that holds lateral offset t (nearest one
// when t lies outside the carriageway).
int streetLaneAt(const EdgeLanes& L, double t) {
    const double w = L.laneWidth > 0 ? L.laneWidth : 1.0;
    if ((t <= L.offset && L.right > 0) || L.left == 0) {
        const int k = std::clamp(int(std::floor((L.offset - t) / w)) + 1, 1, std::max(L.right, 1));
        return -k;
    }
    return std::clamp(int(std::floor((t - L.offset) / w)) + 1, 1, L.left);
}

}  // namespace

uint64_t streetRoadId(const LaneModel&, uint32_t e) { return e; }
uint64_t linkRoadId(const LaneModel& m, uint32_t k) { return uint64_t(m.edges.size() + m.junctions.size() + k); }

double linkLaneCentre(const LinkRoad& r, int id, double s) {
    const std::vector<LinkRoad::Lane>& side = id < 0 ? r.right : r.left;
    const size_t k = size_t(std::abs(id));
    if (id == 0 || k > side.size()) return 0.0;
    const double sgn = id < 0 ? -1.0 : 1.0;
    double t = r.laneOffset(s);
    for (size_t i = 0; i + 1 < k; ++i) t += sgn * r.width(side[i], s);
    return t + sgn * 0.5 * r.width(side[k - 1], s);
}

double linkLaneWidth(const LinkRoad& r, int id, double s) {
    const LinkRoad::Lane* l = linkLane(r, id);
    return l ? r.width(*l, s) : 0.0;
}

bool projectOnLinkRoad(const LinkRoad& r, const glm::dvec2& p, double& s, double& t) {
    const double L = r.length();
    double bestS = 0, bestD = 1e300;
    bool found = false;
    auto line = [&](double s0, double len) {
        if (!(len > 1e-9)) return;
        const double h = r.heading(s0);
        const glm::dvec2 a = r.point(s0), d(std::cos(h), std::sin(h));
        const double u = glm::dot(p - a, d);
        if (u < -1e-9 || u > len + 1e-9) return;
        const double dist = std::abs(glm::dot(p - a, leftNormal(h)));
        if (dist < bestD) bestD = dist, bestS = s0 + std::clamp(u, 0.0, len), found = true;
    };
    line(0.0, r.line0);
    if (r.arcLength > 1e-9 && std::abs(r.curvature) > 1e-12) {
        const double s0 = r.line0;
        const glm::dvec2 p1 = r.point(s0);
        const glm::dvec2 c = p1 + leftNormal(r.heading(s0)) / r.curvature;
        const glm::dvec2 r0 = p1 - c, q = p - c;
        if (glm::length(q) > 1e-9) {
            const double phi = std::atan2(r0.x * q.y - r0.y * q.x, glm::dot(r0, q));
            const double u = phi / r.curvature;
            if (u >= -1e-9 && u <= r.arcLength + 1e-9) {
                const double dist = std::abs(glm::length(q) - 1.0 / std::abs(r.curvature));
                if (dist < bestD) bestD = dist, bestS = s0 + std::clamp(u, 0.0, r.arcLength), found = true;
            }
        }
    } else if (r.arcLength > 1e-9) {
        line(r.line0, r.arcLength);
    }
    line(r.line0 + r.arcLength, r.line1);
    if (!found) bestS = glm::length(p - r.point(0.0)) <= glm::length(p - r.point(L)) ? 0.0 : L;
    s = bestS;
    t = glm::dot(p - r.point(s), leftNormal(r.heading(s)));
    return found;
}

Result<LaneRoute> LaneRoute::create(const LaneModel& model, uint64_t seed, bool leftHandTraffic, RouteStyle style) {
    LaneRoute route(model, seed);
    route.buildGraph(leftHandTraffic);
    if (style == RouteStyle::Tour) route.makeTour();
    std::vector<uint32_t> starts;
    for (size_t i = 0; i < route._nodes.size(); ++i)
        if (!route._nodes[i].link && !route._nodes[i].next.empty()) starts.push_back(uint32_t(i));
    if (starts.empty())
        return Status::error(
            "cannot make a car path: no lane of the city's roads can be driven without reaching a lane "
            "it cannot leave (no valid street, or only one-way dead ends)");
    route._seq.push_back(starts[size_t(route._rng.range(0, int64_t(starts.size()) - 1))]);
    route.ensure(1.0);
    return route;
}

void LaneRoute::buildGraph(bool lht) {
    const LaneModel& m = _m;
    std::vector<int64_t> streetBase(m.edges.size(), -1);
    std::vector<std::vector<int64_t>> linkRight(m.links.size()), linkLeft(m.links.size());
    for (size_t e = 0; e < m.edges.size(); ++e) {
        const EdgeLanes& L = m.edges[e];
        if (!L.valid) continue;
        streetBase[e] = int64_t(_nodes.size());
        for (int k = 1; k <= L.right; ++k) _nodes.push_back({false, uint32_t(e), -k, !lht, {}});
        for (int k = 1; k <= L.left; ++k) _nodes.push_back({false, uint32_t(e), k, lht, {}});
    }
    for (size_t k = 0; k < m.links.size(); ++k) {
        const LinkRoad& r = m.links[k];
        if (!m.edges[r.in].valid || !m.edges[r.out].valid) continue;
        for (size_t i = 0; i < r.right.size(); ++i) {
            linkRight[k].push_back(r.right[i].sidewalk ? -1 : int64_t(_nodes.size()));
            if (!r.right[i].sidewalk) _nodes.push_back({true, uint32_t(k), -int(i) - 1, !lht, {}});
        }
        for (size_t i = 0; i < r.left.size(); ++i) {
            linkLeft[k].push_back(r.left[i].sidewalk ? -1 : int64_t(_nodes.size()));
            if (!r.left[i].sidewalk) _nodes.push_back({true, uint32_t(k), int(i) + 1, lht, {}});
        }
    }
    auto streetNode = [&](uint32_t e, int id) -> int64_t {
        if (e >= m.edges.size() || streetBase[e] < 0 || id == 0) return -1;
        const EdgeLanes& L = m.edges[e];
        if (id < 0) return -id <= L.right ? streetBase[e] + (-id - 1) : -1;
        return id <= L.left ? streetBase[e] + L.right + id - 1 : -1;
    };
    auto linkNode = [&](uint32_t k, int id) -> int64_t {
        const auto& side = id < 0 ? linkRight[k] : linkLeft[k];
        const size_t i = size_t(std::abs(id)) - 1;
        return i < side.size() ? side[i] : -1;
    };
    // Right-hand traffic successors (the lane links in their direction of travel).
    std::vector<std::pair<uint32_t, uint32_t>> arcs;
    auto arc = [&](size_t u, int64_t v) {
        if (v >= 0) arcs.emplace_back(uint32_t(u), uint32_t(v));
    };
    for (size_t u = 0; u < _nodes.size(); ++u) {
        const Node& n = _nodes[u];
        if (n.link) {
            const LinkRoad& r = m.links[n.index];
            const LinkRoad::Lane* l = linkLane(r, n.lane);
            if (n.lane < 0 && l->to) arc(u, streetNode(r.out, l->to));
            if (n.lane > 0 && l->from) arc(u, streetNode(r.in, l->from));
            continue;
        }
        const EdgeLanes& L = m.edges[n.index];
        const bool atB = n.lane < 0;  // right lanes leave the road at its end b
        const int j = atB ? L.junctionB : L.junctionA;
        if (j >= 0) {
            for (uint32_t k : m.junctions[size_t(j)].links) {
                const LinkRoad& r = m.links[k];
                if (r.in != n.index || r.inEnd != atB) continue;
                for (size_t i = 0; i < r.right.size(); ++i)
                    if (!r.right[i].sidewalk && r.right[i].from == n.lane) arc(u, linkNode(k, -int(i) - 1));
            }
            continue;
        }
        const int k = atB ? L.linkB : L.linkA;
        if (k < 0) continue;
        const LinkRoad& r = m.links[size_t(k)];
        if (r.in == n.index && r.inEnd == atB) {
            for (size_t i = 0; i < r.right.size(); ++i)
                if (!r.right[i].sidewalk && r.right[i].from == n.lane) arc(u, linkNode(uint32_t(k), -int(i) - 1));
        } else {
            for (size_t i = 0; i < r.left.size(); ++i)
                if (!r.left[i].sidewalk && r.left[i].to == n.lane) arc(u, linkNode(uint32_t(k), int(i) + 1));
        }
    }
    for (const auto& [u, v] : arcs) {
        if (lht) _nodes[v].next.push_back(u);
        else _nodes[u].next.push_back(v);
    }
    // Tapers dropped where another successor exists; U-turns at dead ends.
    auto tapers = [&](uint32_t v) {
        const Node& n = _nodes[v];
        if (!n.link) return false;
        const LinkRoad& r = m.links[n.index];
        const LinkRoad::Lane* l = linkLane(r, n.lane);
        return (n.forward ? l->w1 : l->w0) < kTaperWidth;
    };
    _uturn.assign(_nodes.size(), 0);
    for (size_t u = 0; u < _nodes.size(); ++u) {
        Node& n = _nodes[u];
        std::vector<uint32_t> keep;
        for (uint32_t v : n.next)
            if (!tapers(v)) keep.push_back(v);
        if (!keep.empty() || n.link) {
            if (!keep.empty()) n.next = keep;
            continue;
        }
        n.next.clear();
        const int64_t back = streetNode(n.index, n.lane < 0 ? 1 : -1);
        const EdgeLanes& L = m.edges[n.index];
        const double R =
            back >= 0 ? 0.5 * std::abs(L.laneCentre(n.lane) - L.laneCentre(_nodes[size_t(back)].lane)) : 0.0;
        if (back >= 0 && L.length >= 2.0 * R + kUTurnMargin) {
            n.next.push_back(uint32_t(back));
            _uturn[u] = uint32_t(back) + 1;
        }
    }
    keepLargestStronglyConnected();
}

// The largest strongly connected part (Tarjan, iterative); arcs leaving it are dropped.
void LaneRoute::keepLargestStronglyConnected() {
    const size_t N = _nodes.size();
    std::vector<int64_t> index(N, -1), low(N, 0), comp(N, -1);
    std::vector<uint8_t> onStack(N, 0);
    std::vector<uint32_t> stack;
    std::vector<std::pair<uint32_t, size_t>> call;
    int64_t counter = 0, comps = 0, bestComp = -1;
    size_t bestSize = 0;
    for (uint32_t root = 0; root < N; ++root) {
        if (index[root] >= 0) continue;
        call.push_back({root, 0});
        while (!call.empty()) {
            auto& [u, i] = call.back();
            if (i == 0) {
                index[u] = low[u] = counter++;
                stack.push_back(u);
                onStack[u] = 1;
            }
            if (i < _nodes[u].next.size()) {
                const uint32_t v = _nodes[u].next[i++];
                if (index[v] < 0) call.push_back({v, 0});
                else if (onStack[v]) low[u] = std::min(low[u], index[v]);
                continue;
            }
            if (low[u] == index[u]) {
                size_t size = 0;
                uint32_t w;
                do {
                    w = stack.back();
                    stack.pop_back();
                    onStack[w] = 0;
                    comp[w] = comps;
                    ++size;
                } while (w != u);
                if (size > bestSize) bestSize = size, bestComp = comps;
                ++comps;
            }
            const uint32_t done = u;
            call.pop_back();
            if (!call.empty()) low[call.back().first] = std::min(low[call.back().first], low[done]);
        }
    }
    for (size_t u = 0; u < N; ++u) {
        Node& n = _nodes[u];
        if (bestSize < 2 || comp[u] != bestComp) {
            n.next.clear();
            continue;
        }
        std::vector<uint32_t> keep;
        for (uint32_t v : n.next)
            if (comp[v] == bestComp) keep.push_back(v);
        n.next = keep;
    }
}

bool LaneRoute::deadEnd(uint32_t node) const { return _uturn[node] != 0; }

void LaneRoute::makeTour() {
    std::vector<glm::dvec2> pos(_nodes.size());
    std::vector<std::vector<Tour::Arc>> arcs(_nodes.size());
    for (size_t u = 0; u < _nodes.size(); ++u) {
        const Node& n = _nodes[u];
        const double len = n.link ? _m.links[n.index].length() : _m.edges[n.index].length;
        pos[u] = n.link ? _m.links[n.index].point(0.5 * len) : 0.5 * (_m.edges[n.index].start + _m.edges[n.index].end);
        for (uint32_t v : n.next) arcs[u].push_back({v, len});
    }
    _tour = std::make_shared<Tour>(std::move(pos), std::move(arcs));
}

uint32_t LaneRoute::pick(uint32_t u) {
    const std::vector<uint32_t>& cand = _nodes[u].next;
    VISTA_CHECK(!cand.empty());
    if (_tour) return cand[_tour->step(u, _rng)];  // every lane, so that the tour sees each goal it reaches
    if (cand.size() == 1) return cand[0];
    std::vector<double> weight;
    double total = 0;
    for (uint32_t v : cand) {
        double w = 1.0;
        const Node& n = _nodes[v];
        if (n.link) {
            w = std::abs(_m.links[n.index].angle) < 0.5 ? 3.0 : 1.0;
            if (n.next.size() == 1 && deadEnd(n.next[0])) w *= 0.05;
        }
        weight.push_back(w);
        total += w;
    }
    double r = _rng.uniform() * total;
    for (size_t i = 0; i < cand.size(); ++i) {
        if (r < weight[i]) return cand[i];
        r -= weight[i];
    }
    return cand.back();
}

double LaneRoute::laneStart(const Node& n) const {
    const double len = n.link ? _m.links[n.index].length() : _m.edges[n.index].length;
    return n.forward ? 0.0 : len;
}

double LaneRoute::laneEnd(const Node& n) const {
    const double len = n.link ? _m.links[n.index].length() : _m.edges[n.index].length;
    return n.forward ? len : 0.0;
}

// s where the U-turn at the end of street lane node n leaves it (the
// semicircle's centre): its apex kUTurnMargin before the road end.
double LaneRoute::uturnCentre(uint32_t node) const {
    const Node& n = _nodes[node];
    const EdgeLanes& L = _m.edges[n.index];
    const Node& back = _nodes[_uturn[node] - 1];
    const double R = 0.5 * std::abs(L.laneCentre(n.lane) - L.laneCentre(back.lane));
    const double s = n.forward ? L.length - R - kUTurnMargin : R + kUTurnMargin;
    return std::clamp(s, 0.0, L.length);
}

void LaneRoute::ensure(double s) {
    while (_pts.size() < 2 || _cum.back() < s) extend();
}

void LaneRoute::extend() {
    while (_seq.size() < _emitted + 2) _seq.push_back(pick(_seq.back()));
    const uint32_t cur = _seq[_emitted], nxt = _seq[_emitted + 1];
    const Node& n = _nodes[cur];
    Piece p;
    p.node = cur;
    p.s0 = laneStart(n);
    if (_emitted > 0 && _uturn[_seq[_emitted - 1]] == cur + 1) p.s0 = uturnCentre(_seq[_emitted - 1]);
    const bool turn = _uturn[cur] == nxt + 1;
    p.s1 = turn ? uturnCentre(cur) : laneEnd(n);
    p.s1 = n.forward ? std::max(p.s1, p.s0) : std::min(p.s1, p.s0);
    emitPiece(p);
    if (turn) {
        Piece u;
        u.node = cur;
        u.uturn = true;
        u.laneTo = _nodes[nxt].lane;
        u.s0 = u.s1 = p.s1;
        emitPiece(u);
    }
    ++_emitted;
}

void LaneRoute::emitPiece(const Piece& p) {
    const size_t idx = _pieces.size();
    _pieces.push_back(p);
    const Node& n = _nodes[p.node];
    if (p.uturn) {
        const EdgeLanes& L = _m.edges[n.index];
        const double tA = L.laneCentre(n.lane), tB = L.laneCentre(p.laneTo);
        const double R = 0.5 * std::abs(tA - tB);
        const glm::dvec2 d = L.dir * (n.forward ? 1.0 : -1.0);
        const glm::dvec2 c = L.start + L.dir * p.s0 + L.normal() * (0.5 * (tA + tB));
        const glm::dvec2 u = L.normal() * (tA > tB ? 1.0 : -1.0);
        const int steps = std::max(8, int(std::ceil(kPi * R / kCurveStep)));
        for (int i = 0; i <= steps; ++i) {
            const double phi = kPi * i / steps;
            addVertex(c + d * (R * std::sin(phi)) + u * (R * std::cos(phi)), idx);
        }
        return;
    }
    const double len = std::abs(p.s1 - p.s0);
    if (!n.link) {
        const EdgeLanes& L = _m.edges[n.index];
        const double t = L.laneCentre(n.lane);
        const int steps = std::max(1, int(std::ceil(len / kStreetStep)));
        for (int i = 0; i <= steps; ++i) {
            const double s = p.s0 + (p.s1 - p.s0) * i / steps;
            addVertex(L.start + L.dir * s + L.normal() * t, idx);
        }
        return;
    }
    const LinkRoad& r = _m.links[n.index];
    const int steps = std::max(1, int(std::ceil(len / kCurveStep)));
    for (int i = 0; i <= steps; ++i) {
        const double s = p.s0 + (p.s1 - p.s0) * i / steps;
        addVertex(r.point(s) + leftNormal(r.heading(s)) * linkLaneCentre(r, n.lane, s), idx);
    }
}

void LaneRoute::addVertex(const glm::dvec2& q, size_t piece) {
    if (!_pts.empty() && glm::length(q - _pts.back()) < kMinVertexGap) return;
    if (_pts.empty()) {
        _pts.push_back(q);
        _cum.push_back(0.0);
        return;
    }
    const glm::dvec2 d = q - _pts.back();
    const double len = glm::length(d);
    _segHeading.push_back(compassHeading(d));
    _segPiece.push_back(uint32_t(piece));
    const size_t k = _segHeading.size() - 1;  // this segment; its start vertex is k
    if (k == 0) {
        _curv.push_back(0.0);
    } else {
        const double prevLen = _cum.back() - _cum[_cum.size() - 2];
        _curv.push_back(wrapAngle(_segHeading[k] - _segHeading[k - 1]) / (0.5 * (prevLen + len)));
    }
    _pts.push_back(q);
    _cum.push_back(_cum.back() + len);
}

LanePosition LaneRoute::onPiece(const Piece& p, const glm::dvec2& q, bool* inside) const {
    const Node& n = _nodes[p.node];
    LanePosition pos;
    if (!n.link) {
        const EdgeLanes& L = _m.edges[n.index];
        pos.road = streetRoadId(_m, n.index);
        pos.s = glm::dot(q - L.start, L.dir);
        const double t = glm::dot(q - L.start, L.normal());
        pos.lane = p.uturn ? streetLaneAt(L, t) : n.lane;
        pos.tOffset = t - L.laneCentre(pos.lane);
        *inside = pos.s >= -1e-6 && pos.s <= L.length + 1e-6;
        return pos;
    }
    const LinkRoad& r = _m.links[n.index];
    double s = 0, t = 0;
    *inside = projectOnLinkRoad(r, q, s, t);
    pos.road = linkRoadId(_m, n.index);
    pos.lane = n.lane;
    pos.s = s;
    pos.tOffset = t - linkLaneCentre(r, n.lane, s);
    return pos;
}

LanePosition LaneRoute::position(const glm::dvec2& p, size_t seg) const {
    VISTA_CHECK(!_segPiece.empty());
    const size_t piece = _segPiece[std::min(seg, _segPiece.size() - 1)];
    bool inside = false;
    const LanePosition here = onPiece(_pieces[piece], p, &inside);
    if (inside) return here;
    for (size_t other : {piece + 1, piece - 1}) {
        if (other >= _pieces.size()) continue;  // also catches piece - 1 wrapping below 0
        const LanePosition there = onPiece(_pieces[other], p, &inside);
        if (inside) return there;
    }
    return here;
}

}  // namespace vista
