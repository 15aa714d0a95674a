#include "bake/sampling.h"
#include "foundation/units.h"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

namespace vista {

bool Box3::valid() const {
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(lo[a]) || !std::isfinite(hi[a]) || !(hi[a] >= lo[a])) return false;
    return true;
}

double Box3::distance(const glm::dvec3& p) const {
    const glm::dvec3 d = glm::max(glm::max(lo - p, p - hi), glm::dvec3(0.0));
    return glm::length(d);
}

bool Box3::contains(const glm::dvec3& p, double eps) const {
    for (int a = 0; a < 3; ++a)
        if (p[a] < lo[a] - eps || p[a] > hi[a] + eps) return false;
    return true;
}

static double cross2(const glm::dvec2& o, const glm::dvec2& a, const glm::dvec2& b) {
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

std::vector<glm::dvec2> convexHull2D(std::vector<glm::dvec2> pts) {
    std::sort(pts.begin(), pts.end(), [](const glm::dvec2& a, const glm::dvec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
    pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
    if (pts.size() < 3) return pts;
    std::vector<glm::dvec2> h(2 * pts.size());
    size_t k = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
        while (k >= 2 && cross2(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
        h[k++] = pts[i];
    }
    for (size_t i = pts.size() - 1, t = k + 1; i-- > 0;) {
        while (k >= t && cross2(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
        h[k++] = pts[i];
    }
    h.resize(k - 1);
    return h;
}

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
        if (per < best) { best = per; bestA = a; bestB = b; bestT = t; }
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
    s.polygon = convexHull2D(cuts);
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

double outputPixelAngle(const SamplingParams& p) {
    return 2.0 * std::tan(0.5 * p.fovYDeg * kPi / 180.0) / double(p.outHeight);
}

double exactPerspectiveFactor(const SamplingParams& p) {
    const double c = std::cos(0.5 * p.fovYDeg * kPi / 180.0);
    return 1.0 / (c * c);
}

double ldiStep(const SamplingSetup& s, const SamplingParams& p) {
    // The LDI cameras' image planes are parallel to the sampling plane with a
    // uniform step in tangent units, so off-axis pixels already shrink by
    // cos^2: a tangent step a gives samples a*D apart on a plane at depth D in
    // front of every corner, which subtends a seen from the circumcentre. So
    // the step is the output pixel angle itself (no D^2/(R^2+D^2) term),
    // refined by the perspective and diagonal factors.
    double a = outputPixelAngle(p);
    a /= std::max(p.perspective, 1e-6);
    if (p.diagonalFactor) a /= std::sqrt(2.0);
    return a / std::max(p.oversample, 1e-6);
}

double footprint(const LdiCamera& c, const SamplingSetup& s, const glm::dvec3& p, const glm::dvec3& nrm) {
    const glm::dvec3 d = p - c.pos;
    const double dist = glm::length(d);
    if (dist <= 0) return 0;
    const double z = glm::dot(s.n, d);
    const double cosOff = std::max(z / dist, 1e-3);
    const double perp = dist * c.step * cosOff * cosOff;
    const double cosT = std::max(std::abs(glm::dot(nrm, d)) / dist, 0.1);
    return perp / cosT;
}

static bool clipRay(const Box3& b, const glm::dvec3& o, const glm::dvec3& d, double& t0, double& t1) {
    t0 = 0;
    t1 = 1e300;
    for (int a = 0; a < 3; ++a) {
        if (std::abs(d[a]) < 1e-300) {
            if (o[a] < b.lo[a] || o[a] > b.hi[a]) return false;
            continue;
        }
        double ta = (b.lo[a] - o[a]) / d[a], tb = (b.hi[a] - o[a]) / d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    return t1 >= t0;
}

LdiResult sampleLdi(const FarScene& scene, const SamplingSetup& s, const Box3& far, const SamplingParams& p) {
    LdiResult r;
    const double step0 = ldiStep(s, p);
    r.requiredStep = step0;
    const double ext = glm::length(far.hi - far.lo);
    for (int k = 0; k < 3; ++k) {
        LdiCamera& c = r.cams[size_t(k)];
        c.pos = s.cameras[size_t(k)];
        double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
        for (int i = 0; i < 8; ++i) {
            const glm::dvec3 d = far.corner(i) - c.pos;
            const double z = glm::dot(s.n, d);
            VISTA_CHECK(z > 0);
            const double x = glm::dot(s.U, d) / z, y = glm::dot(s.V, d) / z;
            x0 = std::min(x0, x); x1 = std::max(x1, x); y0 = std::min(y0, y); y1 = std::max(y1, y);
        }
        double step = step0;
        double w = std::ceil((x1 - x0) / step), h = std::ceil((y1 - y0) / step);
        if (w * h > double(p.maxRaysPerCamera)) {
            step *= std::sqrt(w * h / double(p.maxRaysPerCamera));
            w = std::ceil((x1 - x0) / step);
            h = std::ceil((y1 - y0) / step);
        }
        c.x0 = x0; c.y0 = y0; c.step = step;
        c.width = std::max(1, int(w));
        c.height = std::max(1, int(h));
    }
    const int layers = std::max(1, p.maxLayers);
    const float gap = float(std::max(0.01, 1e-5 * ext));
    for (int k = 0; k < 3; ++k) {
        const LdiCamera& c = r.cams[size_t(k)];
        std::vector<std::vector<LdiSample>> rows(size_t(c.height));
        std::vector<std::vector<uint32_t>> rowCounts(size_t(c.height));
        tbb::parallel_for(0, c.height, [&](int j) {
            std::vector<FarHit> hits{size_t(layers), FarHit{}};
            auto& out = rows[size_t(j)];
            auto& cnt = rowCounts[size_t(j)];
            cnt.assign(size_t(c.width), 0);
            for (int i = 0; i < c.width; ++i) {
                const glm::dvec3 dd = s.n + (c.x0 + (i + 0.5) * c.step) * s.U + (c.y0 + (j + 0.5) * c.step) * s.V;
                const glm::dvec3 dir = glm::normalize(dd);
                double t0, t1;
                if (!clipRay(far, c.pos, dir, t0, t1)) continue;
                const int n = scene.allHits(glm::vec3(c.pos), glm::vec3(dir), float(std::max(0.0, t0 - 1e-3)), float(t1 + 1e-3),
                                            layers, gap, hits.data());
                for (int h = 0; h < n; ++h) {
                    LdiSample smp;
                    const glm::dvec3 pos = c.pos + dir * double(hits[size_t(h)].t);
                    smp.pos = glm::vec3(pos);
                    smp.normal = hits[size_t(h)].normal;
                    smp.color = hits[size_t(h)].color;
                    smp.camera = uint8_t(k);
                    smp.pixel = uint32_t(j) * uint32_t(c.width) + uint32_t(i);
                    smp.spacing = float(footprint(c, s, pos, glm::dvec3(smp.normal)));
                    out.push_back(smp);
                    ++cnt[size_t(i)];
                }
            }
        });
        r.rays += int64_t(c.width) * c.height;
        auto& st = r.start[size_t(k)];
        st.assign(size_t(c.width) * size_t(c.height) + 1, 0);
        uint32_t acc = uint32_t(r.samples.size());
        for (int j = 0; j < c.height; ++j) {
            for (int i = 0; i < c.width; ++i) {
                st[size_t(j) * size_t(c.width) + size_t(i)] = acc;
                acc += rowCounts[size_t(j)][size_t(i)];
            }
            r.samples.insert(r.samples.end(), rows[size_t(j)].begin(), rows[size_t(j)].end());
        }
        st.back() = acc;
    }
    return r;
}

namespace {

// Output-image tangent offset of a small displacement dX at pos, for a viewer at
// `eye` looking along the sampling-plane normal.
glm::dvec2 projectDelta(const SamplingSetup& s, const glm::dvec3& eye, const glm::dvec3& pos, const glm::dvec3& dX) {
    const glm::dvec3 q = pos - eye;
    const double z = glm::dot(s.n, q);
    if (z <= 1e-9) return glm::dvec2(1e300);
    const double dn = glm::dot(s.n, dX);
    return glm::dvec2(glm::dot(s.U, dX) - glm::dot(s.U, q) / z * dn, glm::dot(s.V, dX) - glm::dot(s.V, q) / z * dn) / z;
}

// Whether camera c samples the surface (normal nrm) at pos finely enough for
// every viewpoint tested: the camera's two pixel steps, moved onto the surface
// plane (exact derivative of the ray-plane intersection), projected into the
// viewer's image (exact derivative of the perspective projection); the longest
// edge of the local sampling triangulation (reduced lattice basis and, with the
// diagonal factor, the shorter diagonal) must be at most `limit` (tangent units).
bool sufficient(const LdiCamera& c, const SamplingSetup& s, const glm::dvec3& pos, const glm::dvec3& nrm,
                const std::array<glm::dvec3, 8>& corners, const glm::dvec3& nearest, double limit, bool diagonal) {
    const glm::dvec3 d = pos - c.pos;
    const double zc = glm::dot(s.n, d);
    if (zc <= 0) return false;
    const glm::dvec3 r = d / zc;  // ray direction with unit depth
    const double rm = glm::dot(r, nrm);
    if (std::abs(rm) < 1e-6) return false;
    const glm::dvec3 du = zc * c.step * (s.U - glm::dot(s.U, nrm) / rm * r);
    const glm::dvec3 dv = zc * c.step * (s.V - glm::dot(s.V, nrm) / rm * r);
    auto ok = [&](const glm::dvec3& eye) {
        glm::dvec2 a = projectDelta(s, eye, pos, du), b = projectDelta(s, eye, pos, dv);
        if (!(std::abs(a.x) < 1e100 && std::abs(b.x) < 1e100)) return false;
        // The projected samples form (locally) the lattice spanned by a and b; its
        // Delaunay triangulation uses the reduced basis (Lagrange-Gauss), not the
        // pixel edges: a sheared lattice (grazing surface seen from a laterally
        // offset viewpoint) has long pixel edges but short triangulation edges.
        for (int it = 0; it < 64; ++it) {
            if (glm::dot(a, a) > glm::dot(b, b)) std::swap(a, b);
            const double aa = glm::dot(a, a);
            if (aa <= 0) break;
            const double mu = std::round(glm::dot(a, b) / aa);
            if (mu == 0) break;
            b -= mu * a;
        }
        double e = std::max(glm::length(a), glm::length(b));
        if (diagonal) e = std::max(e, std::min(glm::length(a + b), glm::length(a - b)));
        return e <= limit;
    };
    if (!ok(nearest)) return false;
    for (const auto& eye : corners)
        if (!ok(eye)) return false;
    return true;
}

}  // namespace

std::vector<uint8_t> removeRedundant(const LdiResult& ldi, const SamplingSetup& s, const Box3& cell, const SamplingParams& p) {
    std::vector<uint8_t> keep(ldi.samples.size(), 1);
    if (!p.removeRedundant) return keep;
    // "Sufficient": every edge of camera m's sampling pattern around the point
    // (pixel edges, and the shorter pixel diagonal when the diagonal factor is on)
    // projects to at most one output pixel (/ fp) from every viewpoint tested.
    double limit = outputPixelAngle(p);
    limit /= std::max(p.perspective, 1e-6);
    limit *= 1.01;  // rounding: on planes parallel to the sampling plane the diagonal is exactly the limit
    std::array<glm::dvec3, 8> corners;
    for (int i = 0; i < 8; ++i) corners[size_t(i)] = cell.corner(i);
    tbb::parallel_for(size_t(0), ldi.samples.size(), [&](size_t idx) {
        const LdiSample& a = ldi.samples[idx];
        const glm::dvec3 pos(a.pos), nrm(a.normal);
        const double dmin = cell.distance(pos);
        if (dmin <= 0) return;
        const double sk = a.spacing;
        for (int m = 0; m < 3; ++m) {
            if (m == a.camera) continue;
            const LdiCamera& c = ldi.cams[size_t(m)];
            const double sm = footprint(c, s, pos, nrm);
            // Footprints within 1 % count as a tie, decided by the camera index (lower
            // wins). On a plane parallel to the sampling plane all three footprints are
            // equal; an exact comparison would let rounding flip the decision from one
            // sample to the next and two cameras remove each other's samples (a hole).
            const bool better = sm < sk * 0.99 || (std::abs(sm - sk) <= 0.01 * sk && m < a.camera);
            if (!better) continue;
            const glm::dvec3 d = pos - c.pos;
            const double z = glm::dot(s.n, d);
            if (z <= 0) continue;
            if (!sufficient(c, s, pos, nrm, corners, glm::clamp(pos, cell.lo, cell.hi), limit, p.diagonalFactor)) continue;
            const double x = glm::dot(s.U, d) / z, y = glm::dot(s.V, d) / z;
            const double fi = (x - c.x0) / c.step, fj = (y - c.y0) / c.step;
            if (fi < 0 || fj < 0 || fi >= c.width || fj >= c.height) continue;
            const size_t pix = size_t(int(fj)) * size_t(c.width) + size_t(int(fi));
            const auto& st = ldi.start[size_t(m)];
            const double tol = 2.0 * sm + 1e-3;
            for (uint32_t q = st[pix]; q < st[pix + 1]; ++q) {
                const LdiSample& b = ldi.samples[q];
                if (glm::length(glm::dvec3(b.pos) - pos) <= tol && std::abs(glm::dot(glm::dvec3(b.normal), nrm)) > 0.7) {
                    keep[idx] = 0;
                    return;
                }
            }
        }
    });
    return keep;
}

}  // namespace vista
