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

double classSpeedKmh(RoadClass c) { return c == RoadClass::Highway ? 80.0 : c == RoadClass::Arterial ? 50.0 : 30.0; }

glm::dvec2 LinkRoad::point(double s) const {
    s = std::clamp(s, 0.0, length());
    const glm::dvec2 d0(std::cos(hdg), std::sin(hdg));
    if (s <= line0) return start + d0 * s;
    const glm::dvec2 p1 = start + d0 * line0;
    const double u = std::min(s - line0, arcLength);
    glm::dvec2 p2;
    if (std::abs(curvature) < 1e-12) {
        p2 = p1 + d0 * u;
    } else {
        const double h = hdg + curvature * u;
        p2 = p1 + glm::dvec2(std::sin(h) - std::sin(hdg), std::cos(hdg) - std::cos(h)) / curvature;
    }
    const double rest = s - line0 - arcLength;
    if (rest <= 0) return p2;
    const double h2 = hdg + curvature * arcLength;
    return p2 + glm::dvec2(std::cos(h2), std::sin(h2)) * rest;
}

double LinkRoad::heading(double s) const { return hdg + curvature * std::clamp(s - line0, 0.0, arcLength); }

double LinkRoad::blend(double s) const {
    const double L = length();
    if (!(L > 0)) return 1.0;
    const double u = std::clamp(s / L, 0.0, 1.0);
    return u * u * (3.0 - 2.0 * u);
}

double LinkRoad::rightBorder(double s) const {
    double t = laneOffset(s);
    for (const Lane& l : right) t -= width(l, s);
    return t;
}

double LinkRoad::leftBorder(double s) const {
    double t = laneOffset(s);
    for (const Lane& l : left) t += width(l, s);
    return t;
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

bool crossingBand(const EdgeLanes& L, bool atB, double& s0, double& s1) {
    if (!L.valid || (atB ? L.junctionB : L.junctionA) < 0 || !(L.length > 2 * (kStopSetback + kStopDepth)))
        return false;
    const double depth = L.sidewalk > 0 ? L.sidewalk : kCrossingDepth;
    if (atB) {
        s0 = L.length + kCrossingGap;
        s1 = L.length + std::min(L.trimB - 0.5, depth);
    } else {
        s0 = -L.trimA + std::max(0.5, L.trimA - depth);
        s1 = -kCrossingGap;
    }
    return s1 - s0 > 1.0;
}

namespace {

constexpr double kStraightTurn = 0.6108652381980153;  // 35 degrees: gentler turns count as straight on

// Signed angle (left positive) from direction a to direction b.
double turnAngle(const glm::dvec2& a, const glm::dvec2& b) {
    return std::atan2(a.x * b.y - a.y * b.x, a.x * b.x + a.y * b.y);
}

// The street-edge side of a node, seen by a road that arrives at or leaves it.
struct NodeEnd {
    const EdgeLanes* L = nullptr;
    bool atB = false;  // the edge meets the node with its end b
    // Lanes travelling toward / away from the node.
    int toward() const { return atB ? L->right : L->left; }
    int away() const { return atB ? L->left : L->right; }
    // Direction of travel into / out of the node.
    glm::dvec2 dirIn() const { return atB ? L->dir : -L->dir; }
    // Centre lane position in the frame that travels into the node (its
    // negative in the frame that leaves it).
    double centreIn() const { return atB ? L->offset : -L->offset; }
    // OpenDRIVE id of the k-th lane (1 = innermost) travelling toward / away from the node.
    int towardId(int k) const { return atB ? -k : k; }
    int awayId(int k) const { return atB ? k : -k; }
    // Sidewalk on the right of the traffic travelling toward the node.
    bool walkRightOfToward() const { return L->hasWalk(atB ? -1 : 1); }
    bool walkRightOfAway() const { return L->hasWalk(atB ? 1 : -1); }
};

// Lane pairs (incoming lane k, outgoing lane k; 0 = none) of one turn.
struct TurnPlan {
    uint32_t in = 0, out = 0;
    double angle = 0;
    LinkRoad::Turn turn = LinkRoad::Turn::Straight;
    int i0 = 1, i1 = 0;  // incoming lanes taken
    int shift = 0;       // outgoing lane = incoming lane - shift
    int appear = 0;      // outgoing lanes beyond the incoming ones that start inside the link (straight on)
};

// Lateral extent of a link road on the side its turn bends to: how far the
// lanes reach toward the centre of curvature (at the ends, where the
// smoothstep blends make the borders monotone in between).
double turnSideExtent(const LinkRoad& r) {
    const double L = r.length();
    if (r.angle < 0) return std::max({0.0, -r.rightBorder(0), -r.rightBorder(L)});
    return std::max({0.0, r.leftBorder(0), r.leftBorder(L)});
}

// Line, arc and line from the incoming road's end (distance tIn before the
// node) to the outgoing road's start (tOut after it), tangent to both.
void filletGeometry(LinkRoad& r, const glm::dvec2& node, const glm::dvec2& d0, const glm::dvec2& d1, double tIn,
                    double tOut) {
    r.start = node - d0 * tIn;
    r.hdg = std::atan2(d0.y, d0.x);
    r.angle = turnAngle(d0, d1);
    if (std::abs(r.angle) < 1e-9) {
        r.line0 = tIn + tOut;
        r.arcLength = r.curvature = r.line1 = 0;
        return;
    }
    const double t = std::min(tIn, tOut), R = t / std::tan(0.5 * std::abs(r.angle));
    r.line0 = tIn - t;
    r.line1 = tOut - t;
    r.arcLength = R * std::abs(r.angle);
    r.curvature = (r.angle > 0 ? 1.0 : -1.0) / R;
}

// Length of the fillet's tangent that keeps the lanes `extent` metres
// (plus the margin) from the centre of curvature.
double filletTrim(double angle, double extent) {
    if (std::abs(angle) < 1e-9) return 0.0;
    return (extent + kCurvatureMargin) * std::tan(0.5 * std::abs(angle));
}

// The steps of buildLaneModel, in order: lanes per edge, sidewalk sides,
// junctions, turn plans (growing junction radii), transitions at degree-2
// nodes, trims, link-road geometry (dropping what would fold), signals.
class LaneModelBuilder {
public:
    LaneModelBuilder(const StreetGraph& g, const CityParams& params, const std::vector<Block>* blocks)
        : g(g),
          blocks(blocks),
          N(g.nodes.size()),
          sw(params.sidewalk_m > 0.01 ? params.sidewalk_m : 0.0),
          incident(g.nodes.size()),
          wantA(g.edges.size(), 0.0),
          wantB(g.edges.size(), 0.0) {
        m.degree.assign(N, 0);
        m.nodeJunction.assign(N, -1);
        m.edges.resize(g.edges.size());
    }
    LaneModel build() {
        edgeLanes();
        sidewalkSides();
        junctions();
        planTurns();
        planTransitions();
        applyTrims();
        placeLinks();
        placeSignals();
        m.nodeLinks.assign(N, {});
        for (size_t k = 0; k < m.links.size(); ++k) m.nodeLinks[m.links[k].node].push_back(uint32_t(k));
        return std::move(m);
    }

private:
    NodeEnd end(uint32_t e, uint32_t v) const { return NodeEnd{&m.edges[e], g.edges[e].b == v}; }
    // Desired trim of edge e at node v: at least t.
    void want(uint32_t e, uint32_t v, double t) {
        double& w = g.edges[e].a == v ? wantA[e] : wantB[e];
        w = std::max(w, t);
    }
    double trimAt(uint32_t e, uint32_t v) const { return g.edges[e].a == v ? m.edges[e].trimA : m.edges[e].trimB; }
    LinkRoad junctionRoad(int j, const TurnPlan& t) const;
    bool place(LinkRoad& r) const;
    void edgeLanes();
    void sidewalkSides();
    void junctions();
    void planTurns();
    void planTransitions();
    void applyTrims();
    void placeLinks();
    bool addLaneTurn(size_t j, uint32_t in, uint32_t out, int k, int o);
    void connectLeftovers(size_t j);
    void placeSignals();
    void groupApproaches();

    const StreetGraph& g;
    const std::vector<Block>* blocks;
    const size_t N;
    const double sw;  // sidewalk width, 0 = none
    LaneModel m;
    std::vector<std::vector<uint32_t>> incident;  // per node: its valid edges
    std::vector<double> wantA, wantB;             // desired trims per edge at node a / b
    std::vector<std::vector<TurnPlan>> plans;     // per junction
    std::vector<LinkRoad> transitions;            // degree-2 nodes, before placing
};

// Lanes, widths, speed and direction of every valid edge; node degrees.
void LaneModelBuilder::edgeLanes() {
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
        if (E.lanesForward >= 0 || E.lanesBackward >= 0) {
            const int f = E.lanesForward >= 0 ? E.lanesForward : L.right;
            const int b = E.lanesBackward >= 0 ? E.lanesBackward : L.left;
            if (f + b > 0) L.right = f, L.left = b;
        }
        L.laneWidth = carriagewayWidth(E) / (L.right + L.left);
        L.sidewalk = sw;
        L.offset = 0.5 * (L.right - L.left) * L.laneWidth;
        L.speedKmh = std::isfinite(E.maxspeedKmh) && E.maxspeedKmh > 0 ? double(E.maxspeedKmh) : classSpeedKmh(E.cls);
        L.start = A;
        L.end = B;
        L.length = len;
        ++m.degree[E.a];
        ++m.degree[E.b];
        incident[E.a].push_back(uint32_t(e));
        incident[E.b].push_back(uint32_t(e));
    }
}

// Sidewalk sides from the blocks (lanes.h).
void LaneModelBuilder::sidewalkSides() {
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
}

// One junction per node of degree >= 3, arms counter-clockwise.
void LaneModelBuilder::junctions() {
    for (uint32_t v = 0; v < N; ++v) {
        if (m.degree[v] < 3) continue;
        Junction J;
        J.node = v;
        J.arms = incident[v];
        for (uint32_t e : J.arms) J.radius = std::max(J.radius, m.edges[e].halfWidth() + sw);
        auto angle = [&](uint32_t e) {
            const glm::dvec2 d = -end(e, v).dirIn();
            return std::atan2(d.y + 0.0, d.x + 0.0);  // + 0.0: no -0, so west is +pi, not -pi
        };
        std::stable_sort(J.arms.begin(), J.arms.end(), [&](uint32_t x, uint32_t y) { return angle(x) < angle(y); });
        m.nodeJunction[v] = int(m.junctions.size());
        m.junctions.push_back(std::move(J));
    }
}

// Lanes of a junction turn as a link road (geometry still unset).
LinkRoad LaneModelBuilder::junctionRoad(int j, const TurnPlan& t) const {
    const uint32_t v = m.junctions[size_t(j)].node;
    const NodeEnd in = end(t.in, v), out = end(t.out, v);
    LinkRoad r;
    r.junction = j;
    r.node = v;
    r.in = t.in;
    r.out = t.out;
    r.inEnd = in.atB;
    r.outStart = !out.atB;
    r.turn = t.turn;
    r.angle = t.angle;
    const int nOut = out.away();
    int firstOut = 0;
    for (int i = t.i0; i <= t.i1 + t.appear; ++i) {
        LinkRoad::Lane l;
        if (i <= t.i1) l.from = in.towardId(i), l.w0 = in.L->laneWidth;
        const int o = i - t.shift;
        if (o >= 1 && o <= nOut) {
            l.to = out.awayId(o), l.w1 = out.L->laneWidth;
            if (!firstOut) firstOut = o;
        }
        r.right.push_back(l);
    }
    r.offset0 = in.centreIn() - (t.i0 - 1) * in.L->laneWidth;
    r.offset1 = -out.centreIn() - (std::max(firstOut, 1) - 1) * out.L->laneWidth;
    return r;
}

// Turn plans per junction: the straight exit takes every lane, right turns
// the outermost lane, left turns the innermost; lanes no exit takes join the
// nearest turn. Junction radii grow to the trims the turns need.
void LaneModelBuilder::planTurns() {
    plans.assign(m.junctions.size(), {});
    for (size_t j = 0; j < m.junctions.size(); ++j) {
        Junction& J = m.junctions[j];
        const uint32_t v = J.node;
        for (uint32_t inE : J.arms) {
            const NodeEnd in = end(inE, v);
            const int nIn = in.toward();
            if (nIn < 1) continue;
            std::vector<TurnPlan> exits;
            for (uint32_t outE : J.arms) {
                if (outE == inE) continue;
                const NodeEnd out = end(outE, v);
                const int nOut = out.away();
                if (nOut < 1) continue;
                TurnPlan t;
                t.in = inE;
                t.out = outE;
                t.angle = turnAngle(in.dirIn(), -out.dirIn());
                if (std::abs(t.angle) > kMaxTurn) continue;
                if (t.angle < -kStraightTurn) {
                    t.turn = LinkRoad::Turn::Right;
                    t.i0 = t.i1 = nIn, t.shift = nIn - nOut;
                } else if (t.angle > kStraightTurn) {
                    t.turn = LinkRoad::Turn::Left;
                    t.i0 = t.i1 = 1;
                } else {
                    t.i0 = 1, t.i1 = nIn, t.appear = std::max(0, nOut - nIn);
                }
                exits.push_back(t);
            }
            std::stable_sort(exits.begin(), exits.end(),
                             [](const TurnPlan& a, const TurnPlan& b) { return a.angle < b.angle; });
            for (int k = 1; k <= nIn && !exits.empty(); ++k) {
                size_t best = 0;
                int bestDist = 1 << 30;
                for (size_t x = 0; x < exits.size(); ++x) {
                    const int d = k < exits[x].i0 ? exits[x].i0 - k : k > exits[x].i1 ? k - exits[x].i1 : 0;
                    if (d < bestDist) bestDist = d, best = x;
                }
                if (bestDist == 0) continue;
                TurnPlan& t = exits[best];
                if (k < t.i0) t.i0 = k;
                if (k > t.i1) t.i1 = k, t.appear = 0;
            }
            for (const TurnPlan& t : exits) {
                const LinkRoad r = junctionRoad(int(j), t);
                const double need = filletTrim(t.angle, turnSideExtent(r));
                J.radius = std::max(J.radius, need);
                plans[j].push_back(t);
            }
        }
        for (uint32_t e : J.arms) want(e, v, J.radius);
    }
}

void LaneModelBuilder::planTransitions() {
    // Transitions at degree-2 nodes.
    for (uint32_t v = 0; v < N; ++v) {
        if (m.degree[v] != 2) continue;
        const uint32_t inE = incident[v][0], outE = incident[v][1];
        const NodeEnd in = end(inE, v), out = end(outE, v);
        LinkRoad r;
        r.node = v;
        r.in = inE;
        r.out = outE;
        r.inEnd = in.atB;
        r.outStart = !out.atB;
        r.angle = turnAngle(in.dirIn(), -out.dirIn());
        r.turn = r.angle < -kStraightTurn  ? LinkRoad::Turn::Right
                 : r.angle > kStraightTurn ? LinkRoad::Turn::Left
                                           : LinkRoad::Turn::Straight;
        const double wIn = in.L->laneWidth, wOut = out.L->laneWidth;
        // Right: in's lanes toward v continue as out's lanes away from v.
        for (int k = 1, n = std::max(in.toward(), out.away()); k <= n; ++k) {
            LinkRoad::Lane l;
            if (k <= in.toward()) l.from = in.towardId(k), l.w0 = wIn;
            if (k <= out.away()) l.to = out.awayId(k), l.w1 = wOut;
            r.right.push_back(l);
        }
        for (int k = 1, n = std::max(in.away(), out.toward()); k <= n; ++k) {
            LinkRoad::Lane l;
            if (k <= in.away()) l.from = in.awayId(k), l.w0 = wIn;
            if (k <= out.toward()) l.to = out.towardId(k), l.w1 = wOut;
            r.left.push_back(l);
        }
        // Sidewalks: outside the driving lanes, on the sides that have one.
        auto walk = [&](std::vector<LinkRoad::Lane>& side, bool inWalk, bool outWalk, int inId, int outId) {
            if (!inWalk && !outWalk) return;
            LinkRoad::Lane l;
            l.sidewalk = true;
            if (inWalk) l.from = inId, l.w0 = sw;
            if (outWalk) l.to = outId, l.w1 = sw;
            side.push_back(l);
        };
        walk(r.right, in.walkRightOfToward(), out.walkRightOfAway(), in.towardId(in.toward() + 1),
             out.awayId(out.away() + 1));
        walk(r.left, in.walkRightOfAway(), out.walkRightOfToward(), in.awayId(in.away() + 1),
             out.towardId(out.toward() + 1));
        r.offset0 = in.centreIn();
        r.offset1 = -out.centreIn();
        if (std::abs(r.angle) > kMaxTurn) {
            ++m.sharpCorners;
            continue;
        }
        bool taper = std::abs(r.offset0 - r.offset1) > 1e-9;
        for (const auto* side : {&r.right, &r.left})
            for (const LinkRoad::Lane& l : *side) taper = taper || std::abs(l.w0 - l.w1) > 1e-9;
        const double need =
            std::max({filletTrim(r.angle, turnSideExtent(r)), taper ? 0.5 * kTaperLength : 0.0, 0.5 * kMinLinkLength});
        want(inE, v, need);
        want(outE, v, need);
        transitions.push_back(std::move(r));
    }
}

void LaneModelBuilder::applyTrims() {
    // Trims, shrunk in proportion where the edge is too short for both.
    for (size_t e = 0; e < g.edges.size(); ++e) {
        EdgeLanes& L = m.edges[e];
        if (!L.valid) continue;
        const StreetEdge& E = g.edges[e];
        L.junctionA = m.nodeJunction[E.a];
        L.junctionB = m.nodeJunction[E.b];
        double ta = wantA[e], tb = wantB[e];
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
}

// The fillet of a link road with the trims the edges got; false when its
// lanes would reach the centre of curvature.
bool LaneModelBuilder::place(LinkRoad& r) const {
    const NodeEnd in = end(r.in, r.node), out = end(r.out, r.node);
    filletGeometry(r, g.nodes[r.node], in.dirIn(), -out.dirIn(), trimAt(r.in, r.node), trimAt(r.out, r.node));
    if (r.arcLength <= 0) return r.length() > 1e-9;
    return 1.0 / std::abs(r.curvature) > turnSideExtent(r) + 1e-6;
}

// Junction turns and transitions with their geometry; counts what is dropped.
void LaneModelBuilder::placeLinks() {
    for (size_t j = 0; j < m.junctions.size(); ++j) {
        Junction& J = m.junctions[j];
        for (const TurnPlan& t : plans[j]) {
            LinkRoad r = junctionRoad(int(j), t);
            if (!place(r)) {
                ++m.droppedTurns;
                continue;
            }
            J.links.push_back(uint32_t(m.links.size()));
            m.links.push_back(std::move(r));
        }
        connectLeftovers(j);
    }
    for (LinkRoad& r : transitions) {
        if (!place(r)) {
            ++m.sharpCorners;
            continue;
        }
        const int idx = int(m.links.size());
        (g.edges[r.in].a == r.node ? m.edges[r.in].linkA : m.edges[r.in].linkB) = idx;
        (g.edges[r.out].a == r.node ? m.edges[r.out].linkA : m.edges[r.out].linkB) = idx;
        m.links.push_back(std::move(r));
    }
}

// A turn of one lane (incoming lane k of `in` into outgoing lane o of
// `out`) at junction j, placed with the trims the edges got; false when the
// turn is sharper than kMaxTurn or its lane would reach the centre of
// curvature.
bool LaneModelBuilder::addLaneTurn(size_t j, uint32_t in, uint32_t out, int k, int o) {
    Junction& J = m.junctions[j];
    TurnPlan t;
    t.in = in;
    t.out = out;
    t.angle = turnAngle(end(in, J.node).dirIn(), -end(out, J.node).dirIn());
    if (std::abs(t.angle) > kMaxTurn) return false;
    t.turn = t.angle < -kStraightTurn  ? LinkRoad::Turn::Right
             : t.angle > kStraightTurn ? LinkRoad::Turn::Left
                                       : LinkRoad::Turn::Straight;
    t.i0 = t.i1 = k;
    t.shift = k - o;
    LinkRoad r = junctionRoad(int(j), t);
    if (!place(r)) return false;
    J.links.push_back(uint32_t(m.links.size()));
    m.links.push_back(std::move(r));
    return true;
}

// Full-width driving lanes the planned turns leave without a connection get
// one of their own (lanes.h): every incoming lane that no placed turn takes
// joins the exit its arm already turns into (else the straightest exit),
// into an outgoing lane nobody feeds where there is one; then every outgoing
// lane that no incoming lane feeds (tapered lanes appearing inside a turn do
// not count) is fed from the approach that already turns into its arm (else
// the straightest), from the lane on the same side of the road. Lanes left
// without a connection (every candidate turn too sharp or unplaceable) are
// counted in unlinkedLanes / unfedLanes.
void LaneModelBuilder::connectLeftovers(size_t j) {
    const Junction& J = m.junctions[j];
    const uint32_t v = J.node;
    std::map<uint32_t, std::vector<char>> taken, fed;  // per arm, by lane k (1 = innermost)
    for (uint32_t e : J.arms) {
        taken[e].assign(size_t(end(e, v).toward()) + 1, 0);
        fed[e].assign(size_t(end(e, v).away()) + 1, 0);
    }
    std::map<std::pair<uint32_t, uint32_t>, int> shiftOf;  // placed turn in -> out: outgoing lane = k - shift
    auto mark = [&](const LinkRoad& r) {
        for (const LinkRoad::Lane& l : r.right) {
            if (l.from) taken[r.in][size_t(std::abs(l.from))] = 1;
            if (l.from && l.to) {
                fed[r.out][size_t(std::abs(l.to))] = 1;
                shiftOf.emplace(std::pair{r.in, r.out}, std::abs(l.from) - std::abs(l.to));
            }
        }
    };
    for (uint32_t k : J.links) mark(m.links[k]);
    auto angleOf = [&](uint32_t in, uint32_t out) { return turnAngle(end(in, v).dirIn(), -end(out, v).dirIn()); };
    // Candidate partner arms: those with a placed turn first, then by how straight the turn is.
    auto order = [&](uint32_t arm, bool armIsIn) {
        std::vector<uint32_t> c;
        for (uint32_t x : J.arms)
            if (x != arm && (armIsIn ? end(x, v).away() : end(x, v).toward()) > 0) c.push_back(x);
        auto key = [&](uint32_t x) {
            const auto pair = armIsIn ? std::pair{arm, x} : std::pair{x, arm};
            return std::pair{shiftOf.count(pair) ? 0 : 1, std::abs(armIsIn ? angleOf(arm, x) : angleOf(x, arm))};
        };
        std::stable_sort(c.begin(), c.end(), [&](uint32_t a, uint32_t b) { return key(a) < key(b); });
        return c;
    };
    // The lane of a road with n lanes that continues lane k of a road with nk
    // lanes: through the placed turn's shift, else counted from the side the
    // turn bends to (the outermost for right turns, the innermost otherwise).
    auto across = [](int k, int nk, int n, double angle, const int* shift) {
        int x = shift ? k - *shift : angle < -kStraightTurn ? n - (nk - k) : k;
        return std::clamp(x, 1, n);
    };
    for (uint32_t in : J.arms) {
        const int nIn = end(in, v).toward();
        for (int k = 1; k <= nIn; ++k) {
            if (taken[in][size_t(k)]) continue;
            for (uint32_t out : order(in, true)) {
                const int nOut = end(out, v).away();
                auto it = shiftOf.find({in, out});
                const int target = across(k, nIn, nOut, angleOf(in, out), it == shiftOf.end() ? nullptr : &it->second);
                int o = target;
                for (int x = 1, best = 1 << 30; x <= nOut; ++x)  // the nearest outgoing lane nobody feeds
                    if (!fed[out][size_t(x)] && std::abs(x - target) < best) best = std::abs(x - target), o = x;
                if (addLaneTurn(j, in, out, k, o)) {
                    mark(m.links.back());
                    break;
                }
            }
            m.unlinkedLanes += !taken[in][size_t(k)];
        }
    }
    for (uint32_t out : J.arms) {
        const int nOut = end(out, v).away();
        for (int o = 1; o <= nOut; ++o) {
            if (fed[out][size_t(o)]) continue;
            for (uint32_t in : order(out, false)) {
                const int nIn = end(in, v).toward();
                auto it = shiftOf.find({in, out});
                const int minus = it == shiftOf.end() ? 0 : -it->second;
                const int k = across(o, nOut, nIn, angleOf(in, out), it == shiftOf.end() ? nullptr : &minus);
                if (addLaneTurn(j, in, out, k, o)) {
                    mark(m.links.back());
                    break;
                }
            }
            m.unfedLanes += !fed[out][size_t(o)];
        }
    }
}

void LaneModelBuilder::placeSignals() {
    // Signals at junction ends (SignalPlacement).
    for (size_t e = 0; e < g.edges.size(); ++e) {
        const EdgeLanes& L = m.edges[e];
        if (!L.valid) continue;
        for (int atB = 0; atB < 2; ++atB) {
            const int j = atB ? L.junctionB : L.junctionA;
            const int lanes = atB ? L.right : L.left;
            if (j < 0 || lanes < 1 || m.junctions[size_t(j)].links.empty()) continue;
            const Junction& J = m.junctions[size_t(j)];
            int major = 0;
            for (uint32_t a : J.arms) major += g.edges[a].cls != RoadClass::Local;
            SignalPlacement sp;
            if (major >= 3) sp.kind = SignalPlacement::Kind::TrafficLight;
            else if (major >= 1 && g.edges[e].cls == RoadClass::Local)
                sp.kind = J.arms.size() >= 4 ? SignalPlacement::Kind::Stop : SignalPlacement::Kind::Yield;
            else continue;
            const int side = atB ? -1 : 1;
            sp.edge = uint32_t(e);
            sp.atB = atB != 0;
            sp.junction = j;
            sp.lanes = lanes;
            sp.t = L.offset + side * lanes * L.laneWidth + side * (L.hasWalk(side) ? 0.5 * L.sidewalk : 0.5);
            sp.s = atB ? std::max(0.0, L.length - kStopSetback) : std::min(L.length, kStopSetback);
            sp.position = L.start + L.dir * sp.s + L.normal() * sp.t;
            sp.facing = atB ? -L.dir : L.dir;
            m.signals.push_back(sp);
        }
    }
    groupApproaches();
}

// Approach groups of the traffic lights per junction (SignalPlacement).
void LaneModelBuilder::groupApproaches() {
    std::map<int, std::vector<size_t>> byJunction;
    for (size_t i = 0; i < m.signals.size(); ++i)
        if (m.signals[i].kind == SignalPlacement::Kind::TrafficLight) byJunction[m.signals[i].junction].push_back(i);
    for (auto& [j, lights] : byJunction) {
        // Candidate pairs: arms within kOppositeArms of opposite, most opposite first.
        std::vector<std::pair<double, std::pair<size_t, size_t>>> pairs;
        for (size_t x = 0; x < lights.size(); ++x)
            for (size_t y = x + 1; y < lights.size(); ++y) {
                const glm::dvec2 a = m.signals[lights[x]].facing, b = m.signals[lights[y]].facing;
                const double off = std::abs(std::atan2(a.x * b.y - a.y * b.x, -(a.x * b.x + a.y * b.y)));
                if (off <= kOppositeArms) pairs.push_back({off, {x, y}});
            }
        std::stable_sort(pairs.begin(), pairs.end(),
                         [](const auto& p, const auto& q) { return p.first < q.first; });
        std::vector<size_t> partner(lights.size(), lights.size());
        for (const auto& [off, xy] : pairs)
            if (partner[xy.first] == lights.size() && partner[xy.second] == lights.size())
                partner[xy.first] = xy.second, partner[xy.second] = xy.first;
        int next = 0;
        for (size_t x = 0; x < lights.size(); ++x) {
            SignalPlacement& sp = m.signals[lights[x]];
            if (sp.group >= 0) continue;
            sp.group = next++;
            if (partner[x] < lights.size()) m.signals[lights[partner[x]]].group = sp.group;
        }
    }
}

}  // namespace

LaneModel buildLaneModel(const StreetGraph& g, const CityParams& params, const std::vector<Block>* blocks) {
    return LaneModelBuilder(g, params, blocks).build();
}

}  // namespace vista
