// Side-by-side street edges narrowed to the room between them: see side_by_side.h.
#include "citygen/side_by_side.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "citygen/lanes.h"
#include "citygen/shape_grid.h"

namespace vista {

namespace {

// The carriageway of edge segment a-b with half width h, as a quadrilateral.
Quad carriageway(const glm::dvec2& a, const glm::dvec2& b, double h) {
    const glm::dvec2 d = glm::normalize(b - a), n(-d.y, d.x);
    return {a - n * h, b - n * h, b + n * h, a + n * h};
}

// True when two convex quadrilaterals share area (separating axis test;
// touching counts as apart).
bool overlap(const Quad& p, const Quad& q) {
    for (const Quad* s : {&p, &q}) {
        for (size_t i = 0; i < 4; ++i) {
            const glm::dvec2 e = (*s)[(i + 1) % 4] - (*s)[i];
            const double len = glm::length(e);
            if (!(len > 1e-12)) continue;
            const glm::dvec2 axis(-e.y / len, e.x / len);
            double p0 = 1e300, p1 = -1e300, q0 = 1e300, q1 = -1e300;
            for (const glm::dvec2& x : p) p0 = std::min(p0, glm::dot(x, axis)), p1 = std::max(p1, glm::dot(x, axis));
            for (const glm::dvec2& x : q) q0 = std::min(q0, glm::dot(x, axis)), q1 = std::max(q1, glm::dot(x, axis));
            if (p1 <= q0 + 1e-9 || q1 <= p0 + 1e-9) return false;
        }
    }
    return true;
}

// Driving lanes of an edge per direction, as the lane model derives them (lanes.h).
void laneSplit(const StreetEdge& e, int& forward, int& backward) {
    const int n = std::max<int>(e.lanes, 2);
    forward = (n + 1) / 2;
    backward = n / 2;
    if (e.lanesForward >= 0 || e.lanesBackward >= 0) {
        const int f = e.lanesForward >= 0 ? e.lanesForward : forward;
        const int b = e.lanesBackward >= 0 ? e.lanesBackward : backward;
        if (f + b > 0) forward = f, backward = b;
    }
}

}  // namespace

SideBySideStats narrowSideBySide(StreetGraph& g) {
    SideBySideStats st;
    const size_t N = g.nodes.size(), E = g.edges.size();
    std::vector<char> valid(E, 0);
    std::vector<double> half(E, 0.0), factor(E, 1.0);
    std::vector<glm::dvec2> dir(E, glm::dvec2(1.0, 0.0));
    ShapeGrid grid(32.0);
    for (size_t e = 0; e < E; ++e) {
        const StreetEdge& s = g.edges[e];
        if (s.a >= N || s.b >= N || s.a == s.b) continue;
        const glm::dvec2 a = g.nodes[s.a], b = g.nodes[s.b];
        if (!std::isfinite(a.x + a.y + b.x + b.y) || !(glm::length(b - a) > 1e-6)) continue;
        valid[e] = 1;
        half[e] = 0.5 * carriagewayWidth(s);
        dir[e] = glm::normalize(b - a);
        grid.insert(carriageway(a, b, half[e]), uint32_t(e));
    }
    const double parallel = std::cos(kSideBySideAngle);
    std::vector<uint32_t> near;
    for (size_t e = 0; e < E; ++e) {
        if (!valid[e]) continue;
        const StreetEdge& s = g.edges[e];
        const glm::dvec2 a = g.nodes[s.a], b = g.nodes[s.b];
        auto candidate = [&](uint32_t f) {
            const StreetEdge& t = g.edges[f];
            return t.a != s.a && t.a != s.b && t.b != s.a && t.b != s.b &&
                   std::abs(glm::dot(dir[e], dir[f])) >= parallel;
        };
        grid.query(carriageway(a, b, half[e]), uint32_t(e + 1), uint32_t(E), candidate, near);
        for (uint32_t f : near) {
            const glm::dvec2 c = g.nodes[g.edges[f].a], d = g.nodes[g.edges[f].b];
            const double gap = 0.5 * kSideBySideClearance;
            auto apart = [&](double k) {
                return !overlap(carriageway(a, b, k * half[e] + gap), carriageway(c, d, k * half[f] + gap));
            };
            if (apart(1.0)) continue;
            if (!apart(0.0)) continue;  // the centre segments touch: no width parts them
            ++st.pairs;
            double lo = 0.0, hi = 1.0;  // apart at lo, not at hi
            for (int it = 0; it < 40 && hi - lo > 1e-6; ++it) {
                const double mid = 0.5 * (lo + hi);
                (apart(mid) ? lo : hi) = mid;
            }
            factor[e] = std::min(factor[e], lo);
            factor[f] = std::min(factor[f], lo);
        }
    }
    for (size_t e = 0; e < E; ++e) {
        if (!(factor[e] < 1.0)) continue;
        StreetEdge& s = g.edges[e];
        const double width = factor[e] * carriagewayWidth(s);
        int fwd = 0, bwd = 0;
        laneSplit(s, fwd, bwd);
        const int f0 = fwd, b0 = bwd;
        while (width / (fwd + bwd) < kMinLaneWidth) {
            if (fwd >= bwd && fwd > 1) --fwd;
            else if (bwd > 1) --bwd;
            else if (fwd > 1) --fwd;
            else break;
        }
        st.lanesDropped += size_t(f0 - fwd + b0 - bwd);
        if (fwd != f0 || bwd != b0) {
            s.lanesForward = int8_t(fwd);
            s.lanesBackward = int8_t(bwd);
            s.lanes = uint8_t(fwd + bwd);
            if (fwd != f0) s.turnForward.clear();
            if (bwd != b0) s.turnBackward.clear();
        }
        s.width = float(width);
        ++st.edgesNarrowed;
    }
    return st;
}

}  // namespace vista
