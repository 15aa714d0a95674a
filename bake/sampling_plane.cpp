#include "bake/sampling_plane.h"
#include "citygen/polygon.h"

#include <algorithm>
#include <cmath>

#include "foundation/units.h"

namespace vista {

double trianglePerimeter(const std::array<glm::dvec2, 3>& t) {
    return glm::length(t[1] - t[0]) + glm::length(t[2] - t[1]) + glm::length(t[0] - t[2]);
}

namespace {

// Triangle from the top line y = top and two side lines with outward normals at
// angles a (left, in (pi, 1.5pi)) and b (right, in (1.5pi, 2pi)), each touching poly.
bool triangleFor(const std::vector<glm::dvec2>& poly, double top, double a, double b, std::array<glm::dvec2, 3>& out) {
    const glm::dvec2 nl(std::cos(a), std::sin(a)), nr(std::cos(b), std::sin(b));
    double hl = -1e300, hr = -1e300;
    for (const auto& p : poly) {
        hl = std::max(hl, glm::dot(nl, p));
        hr = std::max(hr, glm::dot(nr, p));
    }
    if (std::abs(nl.x) < 1e-12 || std::abs(nr.x) < 1e-12) return false;
    const glm::dvec2 tl((hl - nl.y * top) / nl.x, top), tr((hr - nr.y * top) / nr.x, top);
    const double det = nl.x * nr.y - nl.y * nr.x;
    if (std::abs(det) < 1e-12) return false;
    const glm::dvec2 bot((hl * nr.y - nl.y * hr) / det, (nl.x * hr - hl * nr.x) / det);
    if (!(bot.y < top) || !(tr.x > tl.x)) return false;
    out = {tl, tr, bot};
    return true;
}

}  // namespace

std::array<glm::dvec2, 3> boundingTriangle(const std::vector<glm::dvec2>& poly) {
    VISTA_CHECK(!poly.empty());
    double top = -1e300, w = 0;
    glm::dvec2 lo(1e300), hi(-1e300);
    for (const auto& p : poly) {
        top = std::max(top, p.y);
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    w = std::max(hi.x - lo.x, hi.y - lo.y);
    // A degenerate polygon (point, segment) gets a tiny margin so the triangle exists.
    const double eps = std::max(1e-6, 1e-6 * w);
    std::vector<glm::dvec2> q = poly;
    if (hi.y - lo.y < eps || hi.x - lo.x < eps) {
        q.clear();
        for (const auto& p : poly)
            for (int i = 0; i < 4; ++i) q.push_back(p + glm::dvec2((i & 1) ? eps : -eps, (i & 2) ? eps : -eps));
        top += eps;
    }
    const double m = 1e-4;
    double bestA = 1.25 * kPi, bestB = 1.75 * kPi, best = 1e300;
    std::array<glm::dvec2, 3> bestT{};
    auto eval = [&](double a, double b) {
        std::array<glm::dvec2, 3> t;
        if (!triangleFor(q, top, a, b, t)) return;
        const double per = trianglePerimeter(t);
        if (per < best) {
            best = per;
            bestA = a;
            bestB = b;
            bestT = t;
        }
    };
    const int n0 = 48;
    for (int i = 0; i <= n0; ++i)
        for (int j = 0; j <= n0; ++j)
            eval(kPi + m + (0.5 * kPi - 2 * m) * i / n0, 1.5 * kPi + m + (0.5 * kPi - 2 * m) * j / n0);
    double win = 0.5 * kPi / n0;
    for (int round = 0; round < 6; ++round) {
        const double a0 = bestA, b0 = bestB;
        for (int i = -8; i <= 8; ++i)
            for (int j = -8; j <= 8; ++j) {
                const double a = std::clamp(a0 + win * i / 8.0, kPi + m, 1.5 * kPi - m);
                const double b = std::clamp(b0 + win * j / 8.0, 1.5 * kPi + m, 2 * kPi - m);
                eval(a, b);
            }
        win /= 4.0;
    }
    VISTA_CHECK(best < 1e300);
    return bestT;
}

Result<SamplingSetup> setupSampling(const Box3& cell, const Box3& far) {
    if (!cell.valid()) return Status::error("sampling: view cell box is empty or not finite");
    if (!far.valid()) return Status::error("sampling: far-field box is empty or not finite");
    SamplingSetup s;
    glm::dvec3 d = far.center() - cell.center();
    d.z = 0;
    if (glm::length(d) < 1e-9) return Status::error("sampling: far-field box is centred above the view cell");
    s.n = glm::normalize(d);
    s.U = glm::normalize(glm::cross(s.n, glm::dvec3(0, 0, 1)));
    s.V = glm::cross(s.U, s.n);
    s.planeD = -1e300;
    for (int i = 0; i < 8; ++i) s.planeD = std::max(s.planeD, glm::dot(s.n, cell.corner(i)));
    double dn = 1e300, df = -1e300;
    for (int i = 0; i < 8; ++i) {
        const double z = glm::dot(s.n, far.corner(i)) - s.planeD;
        dn = std::min(dn, z);
        df = std::max(df, z);
    }
    const double scale = std::max(1.0, glm::length(far.hi - far.lo) + glm::length(cell.hi - cell.lo));
    if (!(dn > 1e-7 * scale))
        return Status::error("sampling: the far-field box is not in front of the view cell (gap " + std::to_string(dn) +
                             " m along the sampling-plane normal; it must be > 0)");
    s.dNear = dn;
    s.dFar = df;
    std::vector<glm::dvec2> cuts;
    for (int i = 0; i < 8; ++i) {
        const glm::dvec3 c = cell.corner(i);
        const double da = glm::dot(s.n, c) - s.planeD;  // <= 0
        for (int j = 0; j < 8; ++j) {
            const glm::dvec3 b = far.corner(j);
            const double db = glm::dot(s.n, b) - s.planeD;  // > 0
            const double t = -da / (db - da);
            const glm::dvec3 x = c + t * (b - c);
            cuts.emplace_back(glm::dot(s.U, x), glm::dot(s.V, x));
        }
    }
    s.polygon = convexHull(cuts);
    s.rectLo = glm::dvec2(1e300);
    s.rectHi = glm::dvec2(-1e300);
    for (const auto& p : s.polygon) {
        s.rectLo = glm::min(s.rectLo, p);
        s.rectHi = glm::max(s.rectHi, p);
    }
    s.tri = boundingTriangle(s.polygon);
    for (int k = 0; k < 3; ++k) s.cameras[size_t(k)] = s.toFrame(s.tri[size_t(k)]);
    // Circumcentre of the triangle (plane coordinates).
    const glm::dvec2 a = s.tri[0], b = s.tri[1], c = s.tri[2];
    const double dd = 2.0 * (a.x * (b.y - c.y) + b.x * (c.y - a.y) + c.x * (a.y - b.y));
    if (std::abs(dd) < 1e-18) return Status::error("sampling: degenerate bounding triangle");
    const double a2 = glm::dot(a, a), b2 = glm::dot(b, b), c2 = glm::dot(c, c);
    s.circumcentre = glm::dvec2((a2 * (b.y - c.y) + b2 * (c.y - a.y) + c2 * (a.y - b.y)) / dd,
                                (a2 * (c.x - b.x) + b2 * (a.x - c.x) + c2 * (b.x - a.x)) / dd);
    s.circumradius = glm::length(a - s.circumcentre);
    return s;
}

}  // namespace vista
