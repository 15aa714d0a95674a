#include "citygen/building_geometry.h"

#include <algorithm>
#include <cmath>

#include "citygen/polygon.h"
#include "foundation/rng.h"

namespace vista {

namespace {

double cross2(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }
double orient(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) { return cross2(b - a, c - a); }
glm::dvec2 leftOf(const glm::dvec2& t) { return {-t.y, t.x}; }

bool finitePoly(const Polygon2& p) {
    for (const auto& q : p)
        if (!std::isfinite(q.x) || !std::isfinite(q.y)) return false;
    return true;
}

// Segment-segment distance (0 when they intersect).
double segmentDistance(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c, const glm::dvec2& d) {
    double o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
    if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0))) return 0.0;
    return std::min(std::min(pointSegmentDistance(a, c, d), pointSegmentDistance(b, c, d)),
                    std::min(pointSegmentDistance(c, a, b), pointSegmentDistance(d, a, b)));
}

}  // namespace

Polygon2 makeCounterClockwise(Polygon2 poly) {
    if (signedArea(poly) < 0) std::reverse(poly.begin(), poly.end());
    return poly;
}

uint64_t stableIdOf(const glm::dvec2& p) {
    auto q = [](double v) { return uint64_t(int64_t(std::llround(std::isfinite(v) ? v * 100.0 : 0.0))); };
    return hashKeys(q(p.x), q(p.y), 0x5eed);
}

OrientedBox orientedBox(const Polygon2& poly) {
    OrientedBox best;
    auto hull = convexHull(poly);
    if (hull.size() < 2 || !finitePoly(hull)) {
        if (!poly.empty() && finitePoly(poly)) best.centre = poly[0];
        return best;
    }
    double bestArea = 1e300;
    for (size_t i = 0; i < hull.size(); ++i) {
        glm::dvec2 e = hull[(i + 1) % hull.size()] - hull[i];
        double len = glm::length(e);
        if (!(len > 1e-12)) continue;
        glm::dvec2 u = e / len, v = leftOf(u);
        double u0 = 1e300, u1 = -1e300, v0 = 1e300, v1 = -1e300;
        for (const auto& q : hull) {
            double a = glm::dot(q, u), b = glm::dot(q, v);
            u0 = std::min(u0, a);
            u1 = std::max(u1, a);
            v0 = std::min(v0, b);
            v1 = std::max(v1, b);
        }
        double area = (u1 - u0) * (v1 - v0);
        if (area < bestArea - 1e-9) {
            bestArea = area;
            best.centre = u * (0.5 * (u0 + u1)) + v * (0.5 * (v0 + v1));
            best.u = u;
            best.v = v;
            best.halfU = 0.5 * (u1 - u0);
            best.halfV = 0.5 * (v1 - v0);
        }
    }
    if (best.halfV > best.halfU) {
        std::swap(best.halfU, best.halfV);
        best.u = best.v;
        best.v = leftOf(best.u);
    }
    return best;
}

bool isSimplePolygon(const Polygon2& p, double eps) {
    size_t n = p.size();
    if (n < 3 || !finitePoly(p)) return false;
    for (size_t i = 0; i < n; ++i)
        if (glm::length(p[(i + 1) % n] - p[i]) <= eps) return false;
    for (size_t i = 0; i < n; ++i) {
        const auto& a = p[i];
        const auto& b = p[(i + 1) % n];
        // Adjacent edge folding back onto this one.
        const auto& c = p[(i + 2) % n];
        if (std::abs(orient(a, b, c)) <= eps * glm::length(c - a) && glm::dot(b - a, c - b) < 0) return false;
        for (size_t j = i + 2; j < n; ++j) {
            if (i == 0 && j == n - 1) continue;
            if (segmentDistance(a, b, p[j], p[(j + 1) % n]) <= eps) return false;
        }
    }
    return true;
}

bool insetPolygonMiter(const Polygon2& p, const std::vector<double>& d, Polygon2& out) {
    size_t n = p.size();
    if (n < 3 || d.size() != n || !finitePoly(p)) return false;
    std::vector<glm::dvec2> t(n);
    for (size_t i = 0; i < n; ++i) {
        glm::dvec2 e = p[(i + 1) % n] - p[i];
        double len = glm::length(e);
        if (!(len > 1e-9) || !(d[i] >= 0) || !std::isfinite(d[i])) return false;
        t[i] = e / len;
    }
    Polygon2 res;
    std::vector<size_t> firstOf(n), lastOf(n);  // output vertex range per input vertex
    for (size_t i = 0; i < n; ++i) {
        size_t ip = (i + n - 1) % n;
        const glm::dvec2 t0 = t[ip], t1 = t[i], n0 = leftOf(t0), n1 = leftOf(t1);
        const double d0 = d[ip], d1 = d[i];
        const glm::dvec2& v = p[i];
        double cr = cross2(t0, t1), dt = glm::dot(t0, t1);
        firstOf[i] = res.size();
        if (std::abs(cr) < 1e-9) {
            if (dt > 0) {
                res.push_back(v + n0 * d0);
                if (std::abs(d0 - d1) > 1e-9) res.push_back(v + n1 * d1);
            } else {  // dead-end tip: square cap
                double e = std::max(d0, d1);
                res.push_back(v + n0 * d0 + t0 * e);
                res.push_back(v + n1 * d1 + t0 * e);
            }
        } else {
            glm::dvec2 a0 = v + n0 * d0, a1 = v + n1 * d1;
            double s = cross2(a1 - a0, t1) / cross2(t0, t1);
            glm::dvec2 m = a0 + t0 * s;
            double e = std::max(d0, d1);
            if (cr > 0 || glm::length(m - v) <= 2.0 * e + 1e-9) {
                res.push_back(m);
            } else {  // sharp reflex corner: bevel
                res.push_back(a0 + t0 * d0);
                res.push_back(a1 - t1 * d1);
            }
        }
        lastOf[i] = res.size() - 1;
    }
    // Edge i of the input becomes lastOf[i] -> firstOf[i+1]; it must keep its direction.
    for (size_t i = 0; i < n; ++i) {
        glm::dvec2 e = res[firstOf[(i + 1) % n]] - res[lastOf[i]];
        if (glm::dot(e, t[i]) <= 1e-9) return false;
    }
    for (size_t k = 0; k < res.size(); ++k)
        for (size_t j = 0; j < n; ++j)
            if (pointSegmentDistance(res[k], p[j], p[(j + 1) % n]) < d[j] * (1.0 - 1e-6) - 1e-7) return false;
    Polygon2 c = cleanPolygon(res, 1e-7);
    if (c.size() < 3 || !(signedArea(c) > 0) || !isSimplePolygon(c)) return false;
    // Every vertex inside the input (catches offsets that jump over a narrow neck).
    for (const auto& q : c)
        if (!pointInPolygon(p, q)) {
            bool on = false;
            for (size_t j = 0; j < n && !on; ++j) on = pointSegmentDistance(q, p[j], p[(j + 1) % n]) <= 1e-7;
            if (!on) return false;
        }
    out = std::move(c);
    return true;
}

std::vector<Polygon2> insetPolygon(const Polygon2& poly, double d) {
    std::vector<Polygon2> out;
    if (poly.size() < 3 || !finitePoly(poly) || !(d >= 0)) return out;
    Polygon2 p = cleanPolygon(makeCounterClockwise(poly), 1e-7);
    if (p.size() < 3) return out;
    if (d == 0) {
        out.push_back(p);
        return out;
    }
    Polygon2 r;
    if (insetPolygonMiter(p, std::vector<double>(p.size(), d), r)) {
        out.push_back(std::move(r));
        return out;
    }
    if (!isSimplePolygon(p)) return out;
    for (auto& q : insetPolygonSkeleton(p, d)) {
        Polygon2 c = cleanPolygon(makeCounterClockwise(q), 1e-7);
        if (c.size() >= 3 && finitePoly(c) && signedArea(c) > 1e-9) out.push_back(std::move(c));
    }
    return out;
}

std::vector<FlaggedPolygon> splitPolygonByLine(const FlaggedPolygon& poly, const glm::dvec2& origin,
                                               const glm::dvec2& dirIn) {
    const auto& P = poly.pts;
    size_t n = P.size();
    std::vector<FlaggedPolygon> out;
    if (n < 3) return out;
    double dl = glm::length(dirIn);
    if (!(dl > 0) || !finitePoly(P)) {
        out.push_back(poly);
        return out;
    }
    glm::dvec2 dir = dirIn / dl, nrm = leftOf(dir);
    std::vector<double> s(n);
    bool pos = false, neg = false;
    for (size_t i = 0; i < n; ++i) {
        s[i] = glm::dot(P[i] - origin, nrm);
        if (std::abs(s[i]) < 1e-7) s[i] = 1e-7;  // treat as positive side
        (s[i] > 0 ? pos : neg) = true;
    }
    if (!pos || !neg) {
        out.push_back(poly);
        return out;
    }
    struct Node {
        glm::dvec2 p;
        uint8_t flag;
        int cross;
    };  // cross: -1 or index into crossings
    std::vector<Node> A;
    std::vector<std::pair<double, size_t>> crossings;  // (t along line, node index)
    for (size_t i = 0; i < n; ++i) {
        size_t j = (i + 1) % n;
        uint8_t f = i < poly.flags.size() ? poly.flags[i] : 0;
        A.push_back({P[i], f, -1});
        if ((s[i] > 0) != (s[j] > 0)) {
            double a = s[i] / (s[i] - s[j]);
            glm::dvec2 q = P[i] + (P[j] - P[i]) * a;
            crossings.push_back({glm::dot(q - origin, dir), A.size()});
            A.push_back({q, f, 0});
        }
    }
    if (crossings.size() < 2 || crossings.size() % 2) {
        out.push_back(poly);
        return out;
    }
    std::sort(crossings.begin(), crossings.end());
    std::vector<size_t> partner(A.size(), SIZE_MAX);
    for (size_t k = 0; k + 1 < crossings.size(); k += 2) {
        partner[crossings[k].second] = crossings[k + 1].second;
        partner[crossings[k + 1].second] = crossings[k].second;
    }
    size_t m = A.size();
    std::vector<bool> visited(m, false);
    for (size_t st = 0; st < m; ++st) {
        if (visited[st] || A[st].cross >= 0) continue;
        FlaggedPolygon piece;
        size_t cur = st;
        bool jumped = false;
        size_t guard = 0;
        do {
            if (A[cur].cross >= 0 && !jumped) {
                piece.pts.push_back(A[cur].p);
                piece.flags.push_back(0);
                visited[cur] = true;
                cur = partner[cur];
                jumped = true;
            } else {
                piece.pts.push_back(A[cur].p);
                piece.flags.push_back(A[cur].flag);
                visited[cur] = true;
                cur = (cur + 1) % m;
                jumped = false;
            }
        } while (cur != st && ++guard < 4 * m);
        // Remove zero-length edges (keep flag of the surviving edge).
        FlaggedPolygon c;
        for (size_t k = 0; k < piece.pts.size(); ++k) {
            const auto& q = piece.pts[k];
            const auto& nx = piece.pts[(k + 1) % piece.pts.size()];
            if (glm::length(nx - q) <= 1e-9) continue;
            c.pts.push_back(q);
            c.flags.push_back(piece.flags[k]);
        }
        if (c.pts.size() >= 3 && std::abs(signedArea(c.pts)) > 1e-9) out.push_back(std::move(c));
    }
    return out;
}

}  // namespace vista
