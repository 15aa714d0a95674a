#include "citygen/polygon.h"

#include <algorithm>
#include <cmath>

namespace vista {

double signedArea(const std::vector<glm::dvec2>& p) {
    double a = 0;
    for (size_t i = 0, n = p.size(); i < n; ++i) {
        const auto& u = p[i];
        const auto& v = p[(i + 1) % n];
        a += u.x * v.y - v.x * u.y;
    }
    return 0.5 * a;
}

glm::dvec2 centroid(const std::vector<glm::dvec2>& p) {
    if (p.empty()) return glm::dvec2(0.0);
    glm::dvec2 ref = p[0];
    double a = 0;
    glm::dvec2 c(0.0);
    for (size_t i = 0, n = p.size(); i < n; ++i) {
        glm::dvec2 u = p[i] - ref, v = p[(i + 1) % n] - ref;
        double cr = u.x * v.y - v.x * u.y;
        a += cr;
        c += (u + v) * cr;
    }
    if (std::abs(a) < 1e-12) {
        glm::dvec2 m(0.0);
        for (const auto& q : p) m += q;
        return m / double(p.size());
    }
    return ref + c / (3.0 * a);
}

bool pointInPolygon(const std::vector<glm::dvec2>& p, const glm::dvec2& q) {
    bool in = false;
    for (size_t i = 0, j = p.size() - 1, n = p.size(); i < n; j = i++) {
        if (((p[i].y > q.y) != (p[j].y > q.y)) &&
            (q.x < (p[j].x - p[i].x) * (q.y - p[i].y) / (p[j].y - p[i].y) + p[i].x))
            in = !in;
    }
    return in;
}

double pointSegmentDistance(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b) {
    glm::dvec2 d = b - a;
    double l2 = glm::dot(d, d);
    double t = l2 > 0 ? std::clamp(glm::dot(p - a, d) / l2, 0.0, 1.0) : 0.0;
    return glm::length(p - (a + t * d));
}

namespace {
double orient(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}
// Proper crossing of segments ab and cd (interiors intersect at one point), with tolerance.
bool properCross(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c, const glm::dvec2& d, double eps) {
    double o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
    double s1 = eps * glm::length(b - a), s2 = eps * glm::length(d - c);
    return ((o1 > s1 && o2 < -s1) || (o1 < -s1 && o2 > s1)) && ((o3 > s2 && o4 < -s2) || (o3 < -s2 && o4 > s2));
}
bool insideOrOn(const std::vector<glm::dvec2>& poly, const glm::dvec2& q, double eps) {
    if (pointInPolygon(poly, q)) return true;
    for (size_t i = 0; i < poly.size(); ++i)
        if (pointSegmentDistance(q, poly[i], poly[(i + 1) % poly.size()]) <= eps) return true;
    return false;
}
}  // namespace

bool polygonInside(const std::vector<glm::dvec2>& inner, const std::vector<glm::dvec2>& outer, double eps) {
    for (const auto& q : inner)
        if (!insideOrOn(outer, q, eps)) return false;
    for (size_t i = 0; i < inner.size(); ++i)
        for (size_t j = 0; j < outer.size(); ++j)
            if (properCross(inner[i], inner[(i + 1) % inner.size()], outer[j], outer[(j + 1) % outer.size()], eps))
                return false;
    return true;
}

bool polygonsOverlap(const std::vector<glm::dvec2>& a, const std::vector<glm::dvec2>& b, double eps) {
    if (a.size() < 3 || b.size() < 3) return false;
    for (size_t i = 0; i < a.size(); ++i)
        for (size_t j = 0; j < b.size(); ++j)
            if (properCross(a[i], a[(i + 1) % a.size()], b[j], b[(j + 1) % b.size()], eps)) return true;
    // No crossings: overlap iff one contains an interior point of the other.
    auto interiorPoint = [](const std::vector<glm::dvec2>& p) {
        auto tris = triangulate(p);
        if (tris.empty()) return centroid(p);
        return (p[tris[0]] + p[tris[1]] + p[tris[2]]) / 3.0;
    };
    auto strictlyInside = [&](const std::vector<glm::dvec2>& poly, const glm::dvec2& q) {
        if (!pointInPolygon(poly, q)) return false;
        for (size_t i = 0; i < poly.size(); ++i)
            if (pointSegmentDistance(q, poly[i], poly[(i + 1) % poly.size()]) <= eps) return false;
        return true;
    };
    return strictlyInside(b, interiorPoint(a)) || strictlyInside(a, interiorPoint(b));
}

std::vector<glm::dvec2> cleanPolygon(const std::vector<glm::dvec2>& poly, double eps) {
    std::vector<glm::dvec2> p;
    for (const auto& q : poly)
        if (p.empty() || glm::length(q - p.back()) > eps) p.push_back(q);
    while (p.size() > 1 && glm::length(p.front() - p.back()) <= eps) p.pop_back();
    bool changed = true;
    while (changed && p.size() >= 3) {
        changed = false;
        for (size_t i = 0; i < p.size() && p.size() >= 3; ++i) {
            const auto& a = p[(i + p.size() - 1) % p.size()];
            const auto& b = p[i];
            const auto& c = p[(i + 1) % p.size()];
            if (std::abs(orient(a, b, c)) <= eps * glm::length(c - a)) {
                p.erase(p.begin() + long(i));
                changed = true;
                break;
            }
        }
    }
    return p.size() >= 3 ? p : std::vector<glm::dvec2>{};
}

std::vector<uint32_t> triangulate(const std::vector<glm::dvec2>& poly) {
    std::vector<uint32_t> out;
    size_t n = poly.size();
    if (n < 3) return out;
    std::vector<uint32_t> idx(n);
    bool ccw = signedArea(poly) > 0;
    for (size_t i = 0; i < n; ++i) idx[i] = uint32_t(ccw ? i : n - 1 - i);
    auto isEar = [&](size_t i) {
        size_t m = idx.size();
        const auto& a = poly[idx[(i + m - 1) % m]];
        const auto& b = poly[idx[i]];
        const auto& c = poly[idx[(i + 1) % m]];
        if (orient(a, b, c) <= 0) return false;
        for (size_t k = 0; k < m; ++k) {
            if (k == i || k == (i + 1) % m || k == (i + m - 1) % m) continue;
            const auto& q = poly[idx[k]];
            if (q == a || q == b || q == c) continue;
            if (orient(a, b, q) >= 0 && orient(b, c, q) >= 0 && orient(c, a, q) >= 0) return false;
        }
        return true;
    };
    size_t guard = 0;
    while (idx.size() > 3 && guard < 4 * n * n + 16) {
        bool found = false;
        for (size_t i = 0; i < idx.size(); ++i) {
            if (isEar(i)) {
                size_t m = idx.size();
                out.push_back(idx[(i + m - 1) % m]);
                out.push_back(idx[i]);
                out.push_back(idx[(i + 1) % m]);
                idx.erase(idx.begin() + long(i));
                found = true;
                break;
            }
        }
        if (!found) {  // numerically degenerate remainder: fan it (keeps output valid, never loops)
            for (size_t i = 1; i + 1 < idx.size(); ++i) {
                if (std::abs(orient(poly[idx[0]], poly[idx[i]], poly[idx[i + 1]])) < 1e-12) continue;
                out.push_back(idx[0]);
                out.push_back(idx[i]);
                out.push_back(idx[i + 1]);
            }
            return out;
        }
        ++guard;
    }
    if (idx.size() == 3 && std::abs(orient(poly[idx[0]], poly[idx[1]], poly[idx[2]])) > 0) {
        out.push_back(idx[0]);
        out.push_back(idx[1]);
        out.push_back(idx[2]);
    }
    return out;
}

std::vector<glm::dvec2> convexHull(std::vector<glm::dvec2> pts, double collinearEps) {
    std::sort(pts.begin(), pts.end(),
              [](const glm::dvec2& a, const glm::dvec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
    pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
    if (pts.size() < 3) return pts;
    auto turn = [](const glm::dvec2& o, const glm::dvec2& a, const glm::dvec2& b) {
        return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
    };
    std::vector<glm::dvec2> h(2 * pts.size());
    size_t k = 0;
    for (size_t i = 0; i < pts.size(); ++i) {  // lower hull
        while (k >= 2 && turn(h[k - 2], h[k - 1], pts[i]) <= collinearEps) --k;
        h[k++] = pts[i];
    }
    for (size_t i = pts.size() - 1, t = k + 1; i-- > 0;) {  // upper hull
        while (k >= t && turn(h[k - 2], h[k - 1], pts[i]) <= collinearEps) --k;
        h[k++] = pts[i];
    }
    h.resize(k - 1);
    return h;
}

}  // namespace vista
