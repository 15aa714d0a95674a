// The lane model: see lanes.h.
#include "citygen/lanes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "citygen/polygon.h"
#include "citygen/shape_grid.h"

namespace vista {

double carriagewayWidth(const StreetEdge& e) {
    double w = double(e.width);
    return std::isfinite(w) && w > 0.5 ? w : roadWidth(e.cls);
}

double classSpeedKmh(RoadClass c) { return c == RoadClass::Highway ? 80.0 : c == RoadClass::Arterial ? 50.0 : 30.0; }

double minTurnRadius(RoadClass c) {
    return c == RoadClass::Highway    ? kMinTurnRadiusHighway
           : c == RoadClass::Arterial ? kMinTurnRadiusArterial
                                      : kMinTurnRadiusLocal;
}

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
    if (!L.valid || !stopLine(L, atB) || !(L.length > 2 * (kStopSetback + kStopDepth))) return false;
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
constexpr double kRadiusSlack = 1e-3;                 // asked beyond a turning radius or margin, so rounding keeps it
constexpr double kOutlineStep = 0.25;                 // sampling of link-road outlines for the crossing test (metres)
constexpr double kOverlapSlack = 5e-3;  // outlines overlapping less deep than this count as apart (metres)

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
// lanes reach toward the centre of curvature (at the ends, from the end
// values, where the smoothstep blends make the borders monotone in between;
// the geometry, and so the blend, may not be placed yet).
double turnSideExtent(const LinkRoad& r) {
    double ext = 0.0;
    for (int atEnd = 0; atEnd < 2; ++atEnd) {
        double t = atEnd ? r.offset1 : r.offset0;
        if (r.angle < 0) {
            for (const LinkRoad::Lane& l : r.right) t -= atEnd ? l.w1 : l.w0;
            ext = std::max(ext, -t);
        } else {
            for (const LinkRoad::Lane& l : r.left) t += atEnd ? l.w1 : l.w0;
            ext = std::max(ext, t);
        }
    }
    return ext;
}

double cross2(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

// Line, arc and line from the incoming road's end (distance tIn before its
// node nodeIn) to the outgoing road's start (tOut after its node nodeOut),
// tangent to both. Where the two nodes differ (a joined junction) the corner
// is the point where the two roads' lines meet; false when it does not lie
// ahead of both ends (or, for parallel roads, the two lines differ), or lies
// farther than the two trims and the nodes' distance allow. The arc starts
// and ends at least `lead` from the two ends (false when the trims leave no
// arc then).
bool filletGeometry(LinkRoad& r, const glm::dvec2& nodeIn, const glm::dvec2& d0, const glm::dvec2& nodeOut,
                    const glm::dvec2& d1, double tIn, double tOut, double lead) {
    r.start = nodeIn - d0 * tIn;
    r.hdg = std::atan2(d0.y, d0.x);
    r.angle = turnAngle(d0, d1);
    if (nodeIn != nodeOut) {
        const glm::dvec2 w = nodeOut + d1 * tOut - r.start;
        const double reach = 2.0 * (tIn + tOut + glm::length(nodeOut - nodeIn));
        if (std::abs(r.angle) < 1e-9) {
            if (std::abs(cross2(d0, w)) > 1e-6 || !(glm::dot(w, d0) > 0)) return false;
            r.line0 = glm::dot(w, d0);
            r.arcLength = r.curvature = r.line1 = 0;
            return true;
        }
        const double den = cross2(d0, d1);
        tIn = cross2(w, d1) / den;
        tOut = cross2(d0, w) / den;
        if (!(tIn >= 0 && tOut >= 0 && tIn + tOut <= reach)) return false;
    }
    if (std::abs(r.angle) < 1e-9) {
        r.line0 = tIn + tOut;
        r.arcLength = r.curvature = r.line1 = 0;
        return true;
    }
    const double t = std::min(tIn, tOut) - lead;
    if (!(t > 1e-9)) return false;
    const double R = t / std::tan(0.5 * std::abs(r.angle));
    r.line0 = tIn - t;
    r.line1 = tOut - t;
    r.arcLength = R * std::abs(r.angle);
    r.curvature = (r.angle > 0 ? 1.0 : -1.0) / R;
    return true;
}

// Length of the fillet's tangent that keeps the lanes `extent` metres
// (plus the margin) from the centre of curvature.
double filletTrim(double angle, double extent) {
    if (std::abs(angle) < 1e-9) return 0.0;
    return (extent + kCurvatureMargin + kRadiusSlack) * std::tan(0.5 * std::abs(angle));
}

// Length of the fillet's tangent that keeps every lane centre at least
// `radius` metres from the centre of curvature, when the lane centres reach
// `extent` metres toward it.
double radiusTrim(double angle, double extent, double radius) {
    if (std::abs(angle) < 1e-9) return 0.0;
    return (extent + radius + kRadiusSlack) * std::tan(0.5 * std::abs(angle));
}

// How far the lane centres of a junction's link road reach toward the centre
// of curvature (at the ends, where the smoothstep blends make each centre
// monotone in between; a lane of width 0 at an end counts with its border).
double turnCentreExtent(const LinkRoad& r) {
    double ext = -1e300;
    for (int atEnd = 0; atEnd < 2; ++atEnd) {
        double t = atEnd ? r.offset1 : r.offset0;
        for (const LinkRoad::Lane& l : r.right) {
            const double w = atEnd ? l.w1 : l.w0;
            ext = std::max(ext, r.angle < 0 ? -(t - 0.5 * w) : t - 0.5 * w);
            t -= w;
        }
    }
    return r.right.empty() ? 0.0 : ext;
}

// The surface of a street road leaving a junction node, as the rectangle of
// its carriageway and sidewalks from `trim` to `length` along `dir`.
struct ArmStrip {
    glm::dvec2 node{0.0}, dir{1.0, 0.0};
    double right = 0, left = 0;  // lateral extents (left of dir positive)
    double length = 0;
    std::array<glm::dvec2, 4> corners(double trim) const {
        const glm::dvec2 n(-dir.y, dir.x);
        return {node + dir * trim - n * right, node + dir * length - n * right, node + dir * length + n * left,
                node + dir * trim + n * left};
    }
};

// True when two convex quadrilaterals overlap deeper than `slack` metres
// (separating axis test; touching counts as apart).
bool quadsOverlap(const Quad& a, const Quad& b, double slack = 1e-9) {
    for (const Quad* q : {&a, &b}) {
        for (size_t i = 0; i < 4; ++i) {
            const glm::dvec2 e = (*q)[(i + 1) % 4] - (*q)[i];
            const double len = glm::length(e);
            if (!(len > 1e-12)) continue;
            const glm::dvec2 axis(-e.y / len, e.x / len);
            double a0 = 1e300, a1 = -1e300, b0 = 1e300, b1 = -1e300;
            for (const glm::dvec2& p : a) a0 = std::min(a0, glm::dot(p, axis)), a1 = std::max(a1, glm::dot(p, axis));
            for (const glm::dvec2& p : b) b0 = std::min(b0, glm::dot(p, axis)), b1 = std::max(b1, glm::dot(p, axis));
            if (a1 <= b0 + slack || b1 <= a0 + slack) return false;
        }
    }
    return true;
}

// The driving lanes of a link road as quadrilaterals between samples at most
// kOutlineStep apart (and at the arc's ends).
std::vector<Quad> linkOutline(const LinkRoad& r) {
    const double L = r.length();
    const int n = std::max(1, int(std::ceil(L / kOutlineStep)));
    std::vector<double> ss;
    for (int i = 0; i <= n; ++i) ss.push_back(L * i / n);
    for (double s : {r.line0, r.line0 + r.arcLength})
        if (s > 0 && s < L) ss.push_back(s);
    std::sort(ss.begin(), ss.end());
    std::vector<Quad> out;
    glm::dvec2 pl(0.0), pr(0.0);
    for (size_t i = 0; i < ss.size(); ++i) {
        const double s = ss[i], h = r.heading(s);
        double tl = r.laneOffset(s), tr = tl;
        for (const LinkRoad::Lane& l : r.left) tl += l.sidewalk ? 0.0 : r.width(l, s);
        for (const LinkRoad::Lane& l : r.right) tr -= l.sidewalk ? 0.0 : r.width(l, s);
        const glm::dvec2 c = r.point(s), nl(-std::sin(h), std::cos(h));
        const glm::dvec2 ql = c + nl * tl, qr = c + nl * tr;
        if (i > 0 && ss[i] - ss[i - 1] > 1e-9) out.push_back({pr, qr, ql, pl});
        pl = ql, pr = qr;
    }
    return out;
}

// Street carriageways and placed junction turns, for the crossing test of
// the turns connectLeftovers adds.
class CrossIndex {
public:
    void addStreet(const EdgeLanes& L, uint32_t e) {
        const glm::dvec2 n = L.normal() * L.halfWidth();
        add({L.start - n, L.end - n, L.end + n, L.start + n}, long(e));
    }
    void addTurn(const LinkRoad& r) {
        for (const Quad& q : linkOutline(r)) add(q, -long(r.junction) - 1);
    }
    // The first road r's driving lanes would cross (shapes closer than
    // kOverlapSlack count as apart): a street edge other than r.in and r.out
    // (>= 0), a turn of another junction (-(junction + 1)), or none (kNone).
    static constexpr long kNone = std::numeric_limits<long>::min();
    long crossed(const LinkRoad& r) const {
        std::vector<uint32_t> near;
        auto other = [&](uint32_t i) {
            const long o = _owner[i];
            return o != long(r.in) && o != long(r.out) && o != -long(r.junction) - 1;
        };
        for (const Quad& q : linkOutline(r)) {
            _grid.query(q, 0, std::numeric_limits<uint32_t>::max(), other, near);
            for (uint32_t i : near)
                if (quadsOverlap(q, _quads[i], kOverlapSlack)) return _owner[i];
        }
        return kNone;
    }

private:
    void add(const Quad& q, long owner) {
        _grid.insert(q, uint32_t(_quads.size()));
        _quads.push_back(q);
        _owner.push_back(owner);
    }
    std::vector<Quad> _quads;
    std::vector<long> _owner;
    ShapeGrid _grid{8.0};
};

// Smallest trim (the same on both arms) beyond which two arms' strips share
// no area, plus kArmClearance; `limit` when even that is not enough.
double separatingTrim(const ArmStrip& a, const ArmStrip& b, double limit) {
    if (!quadsOverlap(a.corners(0.0), b.corners(0.0))) return 0.0;
    if (quadsOverlap(a.corners(limit), b.corners(limit))) return limit;
    double lo = 0.0, hi = limit;
    for (int it = 0; it < 40 && hi - lo > 1e-4; ++it) {
        const double mid = 0.5 * (lo + hi);
        (quadsOverlap(a.corners(mid), b.corners(mid)) ? lo : hi) = mid;
    }
    return std::min(limit, hi + kArmClearance);
}

// The steps of buildLaneModel, in order: lanes per edge, sidewalk sides,
// junctions, turn plans (growing junction radii), transitions at degree-2
// nodes, trims, link-road geometry (dropping what would fold), signals.
class LaneModelBuilder {
public:
    // joined: per node, the first node of the junction it is joined into
    // (empty: no junction joined).
    LaneModelBuilder(const StreetGraph& g, const CityParams& params, const std::vector<Block>* blocks,
                     const std::vector<uint32_t>& joined, const std::vector<double>& minTrimA,
                     const std::vector<double>& minTrimB, const std::vector<uint8_t>& noThrough)
        : growTrimA(minTrimA),
          growTrimB(minTrimB),
          noThrough(noThrough),
          g(g),
          blocks(blocks),
          N(g.nodes.size()),
          sw(params.sidewalk_m > 0.01 ? params.sidewalk_m : 0.0),
          incident(g.nodes.size()),
          rep(joined),
          nodeRadius(g.nodes.size(), 0.0),
          wantA(g.edges.size(), 0.0),
          wantB(g.edges.size(), 0.0),
          leastA(g.edges.size(), 0.0),
          leastB(g.edges.size(), 0.0) {
        m.degree.assign(N, 0);
        m.nodeJunction.assign(N, -1);
        m.edges.resize(g.edges.size());
        if (rep.size() != N) {
            rep.resize(N);
            for (uint32_t v = 0; v < N; ++v) rep[v] = v;
        }
    }
    // The model; `conflicts` receives the junction pairs (j, k) where a turn of
    // j kept as a lane's only way on crosses a street road ending at k or a
    // turn of k (j == k: a road of its own).
    LaneModel build(std::vector<std::pair<int, int>>& conflicts) {
        growTrimA.resize(g.edges.size(), 0.0);
        growTrimB.resize(g.edges.size(), 0.0);
        edgeLanes();
        joinEdges();
        sidewalkSides();
        junctions();
        planTurns();
        planTransitions();
        applyTrims();
        placeLinks();
        placeSignals();
        m.nodeLinks.assign(N, {});
        for (size_t k = 0; k < m.links.size(); ++k) {
            const LinkRoad& r = m.links[k];
            if (r.junction < 0) m.nodeLinks[r.node].push_back(uint32_t(k));
            else
                for (uint32_t v : m.junctions[size_t(r.junction)].nodes) m.nodeLinks[v].push_back(uint32_t(k));
        }
        conflicts = std::move(keptCrossings);
        return std::move(m);
    }

    // Per edge, the trim at node a / b that a kept crossing asks for (at
    // least the minimum trims given): the next round's minimum trims.
    std::vector<double> growTrimA, growTrimB;
    // Per node: 1 = no through junction there (its turns did not fit before).
    std::vector<uint8_t> noThrough;
    // Nodes of through junctions a turn of which folds or misses its radius:
    // the next round links them by a transition.
    std::vector<uint32_t> failedThrough;

private:
    // True when edge e meets node v (or v's joined junction) with its end b.
    bool meetsAtB(uint32_t e, uint32_t v) const { return rep[g.edges[e].b] == rep[v]; }
    // The node of edge e at v's (joined) junction.
    uint32_t nodeOf(uint32_t e, uint32_t v) const { return meetsAtB(e, v) ? g.edges[e].b : g.edges[e].a; }
    NodeEnd end(uint32_t e, uint32_t v) const { return NodeEnd{&m.edges[e], meetsAtB(e, v)}; }
    // Desired trim of edge e at node v: at least t.
    void want(uint32_t e, uint32_t v, double t) {
        double& w = meetsAtB(e, v) ? wantB[e] : wantA[e];
        w = std::max(w, t);
    }
    double trimAt(uint32_t e, uint32_t v) const { return meetsAtB(e, v) ? m.edges[e].trimB : m.edges[e].trimA; }
    // Smallest lane-centre radius of a turn between two street edges: the
    // smaller of their classes' (the turn is taken at the slower road's pace).
    double turnRadius(uint32_t in, uint32_t out) const {
        return std::min(minTurnRadius(g.edges[in].cls), minTurnRadius(g.edges[out].cls));
    }
    ArmStrip strip(uint32_t e, uint32_t v) const;
    void separateArms(size_t j);
    bool meetsRadius(const LinkRoad& r) const;
    std::vector<bool> crossingTurns(const std::vector<LinkRoad>& turns, std::vector<long>& crossed) const;
    void noteKeptCrossing(const LinkRoad& r, long owner);
    void noteShortArm(int j, uint32_t e);
    void fitTurns(size_t j, std::vector<LinkRoad>& turns, std::vector<TurnPlan>& turnPlans);
    LinkRoad junctionRoad(int j, const TurnPlan& t) const;
    bool place(LinkRoad& r) const;
    void edgeLanes();
    void sidewalkSides();
    void joinEdges();
    bool lanesAppear(uint32_t v) const;
    void junctions();
    void planTurns();
    void planTransitions();
    void applyTrims();
    void placeLinks();
    bool addLaneTurn(size_t j, uint32_t in, uint32_t out, int k, int o, bool mayCross, bool mayBeTight);
    void connectLeftovers(size_t j);
    void placeSignals();
    void groupApproaches();

    const StreetGraph& g;
    const std::vector<Block>* blocks;
    const size_t N;
    const double sw;  // sidewalk width, 0 = none
    LaneModel m;
    std::vector<std::vector<uint32_t>> incident;  // per node: its valid edges
    std::vector<uint32_t> rep;                    // per node: the first node of its joined junction (itself if none)
    std::vector<double> nodeRadius;               // per junction node: the radius of its own arms
    std::vector<double> wantA, wantB;             // desired trims per edge at node a / b
    // Per edge, the least trim the transition at node a / b can do with (its
    // fillet clear of folding, the two edges' surfaces apart); 0: no transition.
    std::vector<double> leastA, leastB;
    std::vector<std::vector<TurnPlan>> plans;  // per junction
    std::vector<LinkRoad> transitions;         // degree-2 nodes, before placing
    struct ArmPair {
        uint32_t a, b, node;
        double trim;  // both arms need at least this trim at node
    };
    std::vector<ArmPair> armPairs;                   // arm pairs whose surfaces overlap within their junction radius
    std::vector<std::pair<int, int>> keptCrossings;  // see build()
    CrossIndex cross;                                // streets and placed turns (placeLinks)
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

// Edges between two nodes of one joined junction carry no lanes.
void LaneModelBuilder::joinEdges() {
    for (size_t e = 0; e < g.edges.size(); ++e) {
        EdgeLanes& L = m.edges[e];
        if (L.valid && rep[g.edges[e].a] == rep[g.edges[e].b]) {
            L.valid = false;
            ++m.joinedEdges;
        }
    }
}

// True when, at degree-2 node v, more lanes leave than arrive in a direction
// of travel that has lanes arriving (a lane appears that a lane before it can
// feed), every direction with lanes leaving has lanes arriving (a junction
// cannot feed lanes that start where nothing arrives), the corner is one a
// link road can take (|turn| <= kMaxTurn) and no earlier round found its
// turns folding or below their radius (noThrough): a through junction
// (lanes.h).
bool LaneModelBuilder::lanesAppear(uint32_t v) const {
    if (incident[v].size() != 2) return false;
    const NodeEnd a = end(incident[v][0], v), b = end(incident[v][1], v);
    const bool appear = (b.away() > a.toward() && a.toward() > 0) || (a.away() > b.toward() && b.toward() > 0);
    const bool deadStart = (b.away() > 0 && a.toward() == 0) || (a.away() > 0 && b.toward() == 0);
    return appear && !deadStart && !(v < noThrough.size() && noThrough[v]) &&
           std::abs(turnAngle(a.dirIn(), -b.dirIn())) <= kMaxTurn;
}

// One junction per node of degree >= 3, joined group of them or through
// junction, arms counter-clockwise.
void LaneModelBuilder::junctions() {
    m.junctions.clear();
    m.nodeJunction.assign(N, -1);
    std::vector<std::vector<uint32_t>> members(N);
    for (uint32_t v = 0; v < N; ++v)
        if (rep[v] != v) members[rep[v]].push_back(v);
    for (uint32_t v = 0; v < N; ++v) {
        const bool through = members[v].empty() && m.degree[v] == 2 && lanesAppear(v);
        if (rep[v] != v || (members[v].empty() && m.degree[v] < 3 && !through)) continue;
        Junction J;
        J.node = v;
        J.through = through;
        J.nodes.push_back(v);
        J.nodes.insert(J.nodes.end(), members[v].begin(), members[v].end());
        for (uint32_t u : J.nodes) {
            nodeRadius[u] = 0.0;
            for (uint32_t e : incident[u]) {
                if (!m.edges[e].valid) continue;  // joined into this junction
                J.arms.push_back(e);
                nodeRadius[u] = std::max(nodeRadius[u], m.edges[e].halfWidth() + sw);
            }
            J.radius = std::max(J.radius, nodeRadius[u]);
        }
        auto angle = [&](uint32_t e) {
            const glm::dvec2 d = -end(e, v).dirIn();
            return std::atan2(d.y + 0.0, d.x + 0.0);  // + 0.0: no -0, so west is +pi, not -pi
        };
        std::stable_sort(J.arms.begin(), J.arms.end(), [&](uint32_t x, uint32_t y) { return angle(x) < angle(y); });
        for (uint32_t u : J.nodes) m.nodeJunction[u] = int(m.junctions.size());
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
                const double need = std::max(filletTrim(t.angle, turnSideExtent(r)),
                                             radiusTrim(t.angle, turnCentreExtent(r), turnRadius(t.in, t.out))) +
                                    kCrossingLeadIn;
                // A turn between two nodes of a joined junction bends where
                // its arms' lines meet, not at a node: fitTurns decides.
                const uint32_t u = nodeOf(t.in, v);
                if (u == nodeOf(t.out, v)) nodeRadius[u] = std::max(nodeRadius[u], need);
                plans[j].push_back(t);
            }
        }
        for (uint32_t u : J.nodes) J.radius = std::max(J.radius, nodeRadius[u]);
        for (uint32_t e : J.arms) want(e, v, nodeRadius[nodeOf(e, v)]);
        separateArms(j);
    }
}

ArmStrip LaneModelBuilder::strip(uint32_t e, uint32_t v) const {
    const EdgeLanes& L = m.edges[e];
    const bool atA = !meetsAtB(e, v);
    const double left = L.halfWidth() + (L.hasWalk(1) ? L.sidewalk : 0.0);
    const double right = L.halfWidth() + (L.hasWalk(-1) ? L.sidewalk : 0.0);
    ArmStrip s;
    s.node = g.nodes[nodeOf(e, v)];
    s.dir = atA ? L.dir : -L.dir;
    s.left = atA ? left : right;
    s.right = atA ? right : left;
    s.length = L.length;
    return s;
}

// Arms of junction j whose surfaces (carriageway and sidewalks) would share
// area beyond the junction radius are both trimmed back until they do not.
void LaneModelBuilder::separateArms(size_t j) {
    const Junction& J = m.junctions[j];
    for (size_t x = 0; x < J.arms.size(); ++x) {
        for (size_t y = x + 1; y < J.arms.size(); ++y) {
            const uint32_t a = J.arms[x], b = J.arms[y];
            const ArmStrip sa = strip(a, J.node), sb = strip(b, J.node);
            const double need = separatingTrim(sa, sb, std::min(sa.length, sb.length));
            if (need <= std::min(nodeRadius[nodeOf(a, J.node)], nodeRadius[nodeOf(b, J.node)])) continue;
            want(a, J.node, need);
            want(b, J.node, need);
            armPairs.push_back({a, b, J.node, need});
        }
    }
}

void LaneModelBuilder::planTransitions() {
    // Transitions at degree-2 nodes.
    for (uint32_t v = 0; v < N; ++v) {
        if (m.degree[v] != 2 || m.nodeJunction[v] >= 0) continue;  // through junctions have turns
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
        // Both edges are cut back until their surfaces part, linked or not.
        const ArmStrip sa = strip(inE, v), sb = strip(outE, v);
        const double apart = separatingTrim(sa, sb, std::min(sa.length, sb.length));
        want(inE, v, apart);
        want(outE, v, apart);
        if (std::abs(r.angle) > kMaxTurn) {
            ++m.sharpCorners;
            continue;
        }
        bool taper = std::abs(r.offset0 - r.offset1) > 1e-9;
        for (const auto* side : {&r.right, &r.left})
            for (const LinkRoad::Lane& l : *side) taper = taper || std::abs(l.w0 - l.w1) > 1e-9;
        const double need = std::max({filletTrim(r.angle, turnSideExtent(r)),
                                      radiusTrim(r.angle, turnCentreExtent(r), turnRadius(inE, outE)),
                                      taper ? 0.5 * kTaperLength : 0.0, 0.5 * kMinLinkLength});
        want(inE, v, need);
        want(outE, v, need);
        const double least = std::max({filletTrim(r.angle, turnSideExtent(r)), apart, 0.5 * kMinLinkLength});
        for (uint32_t e : {inE, outE}) {
            double& l = meetsAtB(e, v) ? leastB[e] : leastA[e];
            l = std::max(l, least);
        }
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
        L.throughA = L.junctionA >= 0 && m.junctions[size_t(L.junctionA)].through;
        L.throughB = L.junctionB >= 0 && m.junctions[size_t(L.junctionB)].through;
        double ta = std::max(wantA[e], growTrimA[e]), tb = std::max(wantB[e], growTrimB[e]);
        const double len = L.length, room = std::max(0.0, len - kMinRoadLength);
        if (ta + tb > room) {
            // A junction end keeps its trim, up to what the transition at the
            // other end needs at least (lanes.h); else both shrink in proportion.
            if (L.junctionA >= 0 && leastB[e] > 0 && room > leastB[e]) {
                tb = std::max(leastB[e], room - ta);
                ta = room - tb;
            } else if (L.junctionB >= 0 && leastA[e] > 0 && room > leastA[e]) {
                ta = std::max(leastA[e], room - tb);
                tb = room - ta;
            } else {
                const double f = ta + tb > 0 ? room / (ta + tb) : 0.0;
                ta *= f;
                tb *= f;
            }
        }
        L.trimA = ta;
        L.trimB = tb;
        const glm::dvec2 A = g.nodes[E.a];
        L.start = A + L.dir * ta;
        L.end = A + L.dir * (len - tb);
        L.length = len - ta - tb;
    }
    for (const ArmPair& p : armPairs)
        m.overlappingArms += trimAt(p.a, p.node) < p.trim - 1e-9 || trimAt(p.b, p.node) < p.trim - 1e-9;
}

// The fillet of a link road with the trims the edges got; false when its
// lanes would reach the centre of curvature.
bool LaneModelBuilder::place(LinkRoad& r) const {
    const NodeEnd in = end(r.in, r.node), out = end(r.out, r.node);
    auto fillet = [&](double lead) {
        if (!filletGeometry(r, g.nodes[nodeOf(r.in, r.node)], in.dirIn(), g.nodes[nodeOf(r.out, r.node)], -out.dirIn(),
                            trimAt(r.in, r.node), trimAt(r.out, r.node), lead))
            return false;
        if (r.arcLength <= 0) return r.length() > 1e-9;
        return 1.0 / std::abs(r.curvature) >= turnSideExtent(r) + kCurvatureMargin;
    };
    // A junction turn runs straight for kCrossingLeadIn at both ends where
    // the trims allow it with its turning radius kept (lanes.h).
    if (r.junction >= 0 && fillet(kCrossingLeadIn) && meetsRadius(r)) return true;
    return fillet(0.0);
}

// True when every lane centre of a placed junction turn keeps its class's
// turning radius (lanes.h).
bool LaneModelBuilder::meetsRadius(const LinkRoad& r) const {
    if (r.arcLength <= 0 || std::abs(r.curvature) < 1e-12) return true;
    return 1.0 / std::abs(r.curvature) >= turnCentreExtent(r) + turnRadius(r.in, r.out) - 1e-6;
}

// Junction turns and transitions with their geometry; counts what is dropped.
void LaneModelBuilder::placeLinks() {
    std::vector<LinkRoad> turns;
    std::vector<TurnPlan> turnPlans;
    for (size_t j = 0; j < m.junctions.size(); ++j) fitTurns(j, turns, turnPlans);
    // Turns crossing other roads go, unless one of their lanes has no other turn.
    std::vector<long> crossed;
    const std::vector<bool> crossing = crossingTurns(turns, crossed);
    std::map<std::pair<int, uint32_t>, std::vector<int>> cover;  // (junction, incoming arm) -> turns per lane
    for (size_t k = 0; k < turns.size(); ++k) {
        auto& c = cover[{turns[k].junction, turnPlans[k].in}];
        c.resize(size_t(end(turnPlans[k].in, turns[k].node).toward()) + 1, 0);
        for (int i = turnPlans[k].i0; i <= turnPlans[k].i1; ++i) ++c[size_t(i)];
    }
    std::vector<bool> drop(turns.size(), false);
    for (size_t k = 0; k < turns.size(); ++k) {
        if (!crossing[k]) continue;
        auto& c = cover[{turns[k].junction, turnPlans[k].in}];
        bool last = false;
        for (int i = turnPlans[k].i0; i <= turnPlans[k].i1; ++i) last = last || c[size_t(i)] == 1;
        if (last) {
            ++m.crossingTurnsKept;
            noteKeptCrossing(turns[k], crossed[k]);
            continue;
        }
        for (int i = turnPlans[k].i0; i <= turnPlans[k].i1; ++i) --c[size_t(i)];
        drop[k] = true;
        ++m.crossingTurns;
    }
    for (size_t e = 0; e < m.edges.size(); ++e)
        if (m.edges[e].valid) cross.addStreet(m.edges[e], uint32_t(e));
    for (size_t t = 0; t < turns.size(); ++t)
        if (!drop[t]) cross.addTurn(turns[t]);
    size_t k = 0;
    for (size_t j = 0; j < m.junctions.size(); ++j) {
        Junction& J = m.junctions[j];
        for (; k < turns.size() && turns[k].junction == int(j); ++k) {
            if (drop[k]) continue;
            J.links.push_back(uint32_t(m.links.size()));
            m.links.push_back(std::move(turns[k]));
        }
        connectLeftovers(j);
        for (uint32_t l : J.links) {
            const LinkRoad& r = m.links[l];
            if (r.arcLength > 0 && std::abs(r.curvature) > 1e-12) {
                const double rad = 1.0 / std::abs(r.curvature) - turnCentreExtent(r);
                m.minTurnRadius = m.minTurnRadius > 0 ? std::min(m.minTurnRadius, rad) : rad;
            }
        }
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
// turn is sharper than kMaxTurn, its lane would reach the centre of
// curvature, it misses its turning radius (unless mayBeTight: then kept and
// counted in tightTurnsKept) or it crosses another road (unless mayCross).
bool LaneModelBuilder::addLaneTurn(size_t j, uint32_t in, uint32_t out, int k, int o, bool mayCross, bool mayBeTight) {
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
    const bool tight = !meetsRadius(r);
    if (tight && !mayBeTight) return false;
    if (const long o = cross.crossed(r); o != CrossIndex::kNone) {
        if (!mayCross) return false;
        ++m.crossingTurnsKept;
        noteKeptCrossing(r, o);
    }
    if (tight) {
        ++m.tightTurnsKept;
        noteShortArm(int(j), in);
        noteShortArm(int(j), out);
    }
    cross.addTurn(r);
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
// the straightest), from the lane on the same side of the road. Turns that
// keep their turning radius and cross no other road come first, then those
// that cross one, then those below the radius (counted in tightTurnsKept). Lanes left
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
            for (int pass = 0; pass < 4 && !taken[in][size_t(k)]; ++pass) {
                for (uint32_t out : order(in, true)) {
                    const int nOut = end(out, v).away();
                    auto it = shiftOf.find({in, out});
                    const int target =
                        across(k, nIn, nOut, angleOf(in, out), it == shiftOf.end() ? nullptr : &it->second);
                    int o = target;
                    for (int x = 1, best = 1 << 30; x <= nOut; ++x)  // the nearest outgoing lane nobody feeds
                        if (!fed[out][size_t(x)] && std::abs(x - target) < best) best = std::abs(x - target), o = x;
                    if (addLaneTurn(j, in, out, k, o, pass & 1, pass >= 2)) {
                        mark(m.links.back());
                        break;
                    }
                }
            }
            m.unlinkedLanes += !taken[in][size_t(k)];
            if (!taken[in][size_t(k)])
                for (uint32_t e : J.arms) noteShortArm(int(j), e);
        }
    }
    for (uint32_t out : J.arms) {
        const int nOut = end(out, v).away();
        for (int o = 1; o <= nOut; ++o) {
            for (int pass = 0; pass < 4 && !fed[out][size_t(o)]; ++pass) {
                for (uint32_t in : order(out, false)) {
                    const int nIn = end(in, v).toward();
                    auto it = shiftOf.find({in, out});
                    const int minus = it == shiftOf.end() ? 0 : -it->second;
                    const int k = across(o, nOut, nIn, angleOf(in, out), it == shiftOf.end() ? nullptr : &minus);
                    if (addLaneTurn(j, in, out, k, o, pass & 1, pass >= 2)) {
                        mark(m.links.back());
                        break;
                    }
                }
            }
            m.unfedLanes += !fed[out][size_t(o)];
            if (!fed[out][size_t(o)])
                for (uint32_t e : J.arms) noteShortArm(int(j), e);
        }
    }
}

// The turns of junction j on the final trims, appended to turns/plans: a
// turn whose lanes would fold or that misses its turning radius is dropped,
// its lanes joining the nearest turn of their arm that still meets the
// radius with them; a lane no such turn can take keeps its own turn below
// the radius (counted in tightTurnsKept) so that it is not left without a
// turn, unless that turn folds (the lane is then unlinked).
void LaneModelBuilder::fitTurns(size_t j, std::vector<LinkRoad>& turns, std::vector<TurnPlan>& turnPlans) {
    std::vector<TurnPlan> ps = plans[j];
    std::vector<LinkRoad> rs;
    enum State { Ok, Folds, Tight };
    std::vector<State> state;
    auto fit = [&](const TurnPlan& t, LinkRoad& r) {
        r = junctionRoad(int(j), t);
        return !place(r) ? Folds : !meetsRadius(r) ? Tight : Ok;
    };
    for (const TurnPlan& t : ps) {
        rs.emplace_back();
        state.push_back(fit(t, rs.back()));
    }
    for (size_t x = 0; x < ps.size(); ++x) {
        if (state[x] == Ok) continue;
        if (m.junctions[j].through) failedThrough.push_back(m.junctions[j].node);
        for (int lane = ps[x].i0; lane <= ps[x].i1; ++lane) {
            auto covers = [&](size_t y) {
                return state[y] == Ok && ps[y].in == ps[x].in && ps[y].i0 <= lane && lane <= ps[y].i1;
            };
            bool covered = false;
            for (size_t y = 0; y < ps.size() && !covered; ++y) covered = covers(y);
            if (covered) continue;
            // Nearest turn of the same arm (by lane distance) that takes the lane and keeps its radius.
            std::vector<std::pair<int, size_t>> order;
            for (size_t y = 0; y < ps.size(); ++y)
                if (state[y] == Ok && ps[y].in == ps[x].in)
                    order.push_back({lane < ps[y].i0 ? ps[y].i0 - lane : lane - ps[y].i1, y});
            std::stable_sort(order.begin(), order.end());
            for (const auto& o : order) {
                TurnPlan t = ps[o.second];
                if (lane < t.i0) t.i0 = lane;
                if (lane > t.i1) t.i1 = lane, t.appear = 0;
                LinkRoad r;
                if (fit(t, r) != Ok) continue;
                ps[o.second] = t;
                rs[o.second] = std::move(r);
                covered = true;
                break;
            }
            if (!covered) break;  // this turn stays: below its radius, but the lane's only way on
        }
        bool needed = false;
        for (int lane = ps[x].i0; lane <= ps[x].i1; ++lane) {
            bool covered = false;
            for (size_t y = 0; y < ps.size() && !covered; ++y)
                covered = state[y] == Ok && ps[y].in == ps[x].in && ps[y].i0 <= lane && lane <= ps[y].i1;
            needed = needed || !covered;
        }
        if (state[x] == Folds) {
            ++m.droppedTurns;  // no lane may fold: a lane no other turn takes is left unlinked
        } else if (needed) {
            state[x] = Ok;
            ++m.tightTurnsKept;
            noteShortArm(int(j), ps[x].in);
            noteShortArm(int(j), ps[x].out);
        } else {
            ++m.tightTurns;
        }
    }
    for (size_t x = 0; x < ps.size(); ++x) {
        if (state[x] != Ok) continue;
        turns.push_back(std::move(rs[x]));
        turnPlans.push_back(ps[x]);
    }
}

// A turn kept as a lane's only way on although its driving lanes cross
// `owner` (CrossIndex::crossed): the junction pair goes to keptCrossings
// (junction joining); a street road that is an arm of the turn's own
// junction asks to be cut back past the turn (growTrimA/B, next round).
void LaneModelBuilder::noteKeptCrossing(const LinkRoad& r, long owner) {
    if (owner == CrossIndex::kNone) return;
    if (owner < 0) {
        keptCrossings.emplace_back(r.junction, int(-owner - 1));
        return;
    }
    const uint32_t e = uint32_t(owner);
    const EdgeLanes& L = m.edges[e];
    for (int x : {L.junctionA, L.junctionB})
        if (x >= 0) keptCrossings.emplace_back(r.junction, x);
    const uint32_t v = m.junctions[size_t(r.junction)].node;
    if (L.junctionA != r.junction && L.junctionB != r.junction) return;
    const bool atB = meetsAtB(e, v);
    const glm::dvec2 node = g.nodes[nodeOf(e, v)], d = atB ? -L.dir : L.dir, n(-d.y, d.x);
    const double half = L.halfWidth() + kOverlapSlack;
    double need = 0.0;
    for (const Quad& q : linkOutline(r))
        for (const glm::dvec2& p : q)
            if (std::abs(glm::dot(p - node, n)) < half) need = std::max(need, glm::dot(p - node, d) + kArmClearance);
    double& grow = atB ? growTrimB[e] : growTrimA[e];
    grow = std::max(grow, need);
}

// Junction j failed a lane across arm e (a turn kept below its radius, a lane
// left without a connection): when e is shrunk to kMinRoadLength between j and
// another junction, that pair goes to keptCrossings (joined like a crossing).
void LaneModelBuilder::noteShortArm(int j, uint32_t e) {
    const EdgeLanes& L = m.edges[e];
    if (!L.valid || L.length > kMinRoadLength + 1e-9) return;
    for (int x : {L.junctionA, L.junctionB})
        if (x >= 0 && x != j) keptCrossings.emplace_back(j, x);
}

// Junction turns (placed, by junction) whose driving lanes would share area
// with a street road other than the two they join, or with a kept turn of
// another junction (the later of two such turns goes). Outlines: street
// carriageways as rectangles, turns as quadrilaterals between samples
// kOutlineStep apart; shapes closer than kOverlapSlack count as apart.
std::vector<bool> LaneModelBuilder::crossingTurns(const std::vector<LinkRoad>& turns,
                                                  std::vector<long>& crossed) const {
    struct Shape {
        Quad q;
        long owner;  // >= 0: street edge; < 0: turn -(owner + 1)
    };
    std::vector<Shape> shapes;
    for (size_t e = 0; e < m.edges.size(); ++e) {
        const EdgeLanes& L = m.edges[e];
        if (!L.valid) continue;
        const glm::dvec2 n = L.normal() * L.halfWidth();
        shapes.push_back({{L.start - n, L.end - n, L.end + n, L.start + n}, long(e)});
    }
    std::vector<std::pair<size_t, size_t>> turnShapes(turns.size());  // [begin, end) into shapes
    for (size_t k = 0; k < turns.size(); ++k) {
        turnShapes[k].first = shapes.size();
        for (const Quad& q : linkOutline(turns[k])) shapes.push_back({q, -long(k) - 1});
        turnShapes[k].second = shapes.size();
    }
    const uint32_t streets = uint32_t(turnShapes.empty() ? shapes.size() : turnShapes[0].first);
    ShapeGrid grid(8.0);
    for (size_t i = 0; i < shapes.size(); ++i) grid.insert(shapes[i].q, uint32_t(i));
    // Turns come by junction: the turns of other junctions before turn k are those before its junction's first.
    std::vector<uint32_t> junctionFirst(turns.size());
    for (size_t k = 0; k < turns.size(); ++k)
        junctionFirst[k] =
            uint32_t(k > 0 && turns[k].junction == turns[k - 1].junction ? junctionFirst[k - 1] : turnShapes[k].first);
    std::vector<bool> drop(turns.size(), false);
    crossed.assign(turns.size(), CrossIndex::kNone);
    std::vector<uint32_t> near;
    for (int pass = 0; pass < 2; ++pass) {  // street roads first, then other junctions' turns
        for (size_t k = 0; k < turns.size(); ++k) {
            const LinkRoad& r = turns[k];
            // Street roads other than the turn's own two (pass 0); turns
            // before this one, of other junctions, still kept (pass 1).
            auto candidate = [&](uint32_t o) {
                const long owner = shapes[o].owner;
                if (pass == 0) return owner >= 0 && owner != long(r.in) && owner != long(r.out);
                if (owner >= 0) return false;
                const size_t d = size_t(-owner - 1);
                return d < k && !drop[d] && turns[d].junction != r.junction;
            };
            const uint32_t first = pass == 0 ? 0 : streets, last = pass == 0 ? streets : junctionFirst[k];
            for (size_t i = turnShapes[k].first; i < turnShapes[k].second && !drop[k]; ++i) {
                grid.query(shapes[i].q, first, last, candidate, near);
                for (uint32_t o : near) {
                    const Shape& s = shapes[o];
                    if (quadsOverlap(shapes[i].q, s.q, kOverlapSlack)) {
                        drop[k] = true;
                        crossed[k] = s.owner >= 0 ? s.owner : -long(turns[size_t(-s.owner - 1)].junction) - 1;
                        break;
                    }
                }
            }
        }
    }
    return drop;
}

void LaneModelBuilder::placeSignals() {
    // Signals at junction ends (SignalPlacement).
    for (size_t e = 0; e < g.edges.size(); ++e) {
        const EdgeLanes& L = m.edges[e];
        if (!L.valid) continue;
        for (int atB = 0; atB < 2; ++atB) {
            const int j = atB ? L.junctionB : L.junctionA;
            const int lanes = atB ? L.right : L.left;
            if (j < 0 || lanes < 1 || m.junctions[size_t(j)].links.empty() || m.junctions[size_t(j)].through) continue;
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
        std::stable_sort(pairs.begin(), pairs.end(), [](const auto& p, const auto& q) { return p.first < q.first; });
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

namespace {

// Junction joining (lanes.h) where a turn kept as a lane's only way on
// crosses a road: the two junctions of each such conflict, when an edge too
// short for both their trims (shrunk to kMinRoadLength) joins them, become
// one in `rep` (per node: the first node of its junction), unless fewer than
// three arms would remain. True when anything was joined.
bool joinConflicts(const StreetGraph& g, const LaneModel& m, const std::vector<std::pair<int, int>>& conflicts,
                   std::vector<uint32_t>& rep) {
    const size_t N = g.nodes.size();
    if (rep.size() != N) {
        rep.resize(N);
        for (uint32_t v = 0; v < N; ++v) rep[v] = v;
    }
    std::vector<std::pair<int, int>> pairs;
    for (const auto& [a, b] : conflicts)
        if (a != b) pairs.emplace_back(std::min(a, b), std::max(a, b));
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    std::vector<std::vector<uint32_t>> members(N);  // by first node: the nodes of its junction
    for (uint32_t v = 0; v < N; ++v) members[rep[v]].push_back(v);
    std::vector<std::vector<uint32_t>> incident(N);
    for (uint32_t e = 0; e < g.edges.size(); ++e)
        if (m.edges[e].valid) incident[g.edges[e].a].push_back(e), incident[g.edges[e].b].push_back(e);
    bool joined = false;
    for (uint32_t e = 0; e < g.edges.size(); ++e) {
        const EdgeLanes& L = m.edges[e];
        if (!L.valid || L.junctionA < 0 || L.junctionB < 0 || L.junctionA == L.junctionB) continue;
        if (L.length > kMinRoadLength + 1e-9) continue;
        const std::pair<int, int> p{std::min(L.junctionA, L.junctionB), std::max(L.junctionA, L.junctionB)};
        if (!std::binary_search(pairs.begin(), pairs.end(), p)) continue;
        const uint32_t a = g.edges[e].a, b = g.edges[e].b;
        if (rep[a] == rep[b]) continue;
        const uint32_t ra = std::min(rep[a], rep[b]), rb = std::max(rep[a], rep[b]);
        std::vector<uint32_t> both = members[ra];
        both.insert(both.end(), members[rb].begin(), members[rb].end());
        size_t arms = 0;
        for (uint32_t u : both)
            for (uint32_t x : incident[u]) {
                const uint32_t o = g.edges[x].a == u ? g.edges[x].b : g.edges[x].a;
                arms += rep[o] != ra && rep[o] != rb;
            }
        if (arms < 3) continue;
        for (uint32_t u : members[rb]) rep[u] = ra;
        std::sort(both.begin(), both.end());
        members[ra] = std::move(both);
        members[rb].clear();
        joined = true;
    }
    return joined;
}

constexpr int kJoinPasses = 4;     // joining rounds (a joined junction may need joining again)
constexpr int kThroughRounds = 3;  // rounds that turn failed through junctions back into transitions

}  // namespace

LaneModel buildLaneModel(const StreetGraph& g, const CityParams& params, const std::vector<Block>* blocks) {
    std::vector<uint32_t> rep;
    std::vector<std::pair<int, int>> conflicts;
    const std::vector<double> none(g.edges.size(), 0.0);
    // Through junctions whose turns fold or miss their radius are links by
    // transitions instead (lanes.h), decided in up to kThroughRounds rounds.
    std::vector<uint8_t> noThrough(g.nodes.size(), 0);
    LaneModel m;
    std::vector<double> trimA, trimB, askedA = none, askedB = none;
    for (int round = 0; round < kThroughRounds; ++round) {
        LaneModelBuilder first(g, params, blocks, rep, none, none, noThrough);
        m = first.build(conflicts);
        trimA = first.growTrimA, trimB = first.growTrimB;
        if (first.failedThrough.empty()) break;
        for (uint32_t v : first.failedThrough) noThrough[v] = 1;
    }
    for (int pass = 0; pass < kJoinPasses; ++pass) {
        const bool joined = joinConflicts(g, m, conflicts, rep);
        bool grown = false;  // an arm asks for more than the last round gave it
        for (size_t e = 0; e < g.edges.size() && !grown; ++e)
            grown = trimA[e] > askedA[e] + 1e-6 || trimB[e] > askedB[e] + 1e-6;
        if (!joined && !grown) break;
        askedA = trimA, askedB = trimB;
        LaneModelBuilder next(g, params, blocks, rep, trimA, trimB, noThrough);
        m = next.build(conflicts);
        trimA = next.growTrimA, trimB = next.growTrimB;
    }
    return m;
}

}  // namespace vista
