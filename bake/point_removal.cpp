#include "bake/point_removal.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <tbb/parallel_for.h>

namespace vista {

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

std::vector<uint8_t> removeRedundant(const LdiResult& ldi, const SamplingSetup& s, const Box3& cell,
                                     const SamplingParams& p, const std::vector<uint8_t>* only) {
    std::vector<uint8_t> keep(ldi.samples.size(), 1);
    if (only)
        for (size_t i = 0; i < keep.size(); ++i) keep[i] = i < only->size() && (*only)[i] ? 1 : 0;
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
        if (!keep[idx]) return;
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
            if (!sufficient(c, s, pos, nrm, corners, glm::clamp(pos, cell.lo, cell.hi), limit, p.diagonalFactor))
                continue;
            const double x = glm::dot(s.U, d) / z, y = glm::dot(s.V, d) / z;
            const double fi = (x - c.x0) / c.step, fj = (y - c.y0) / c.step;
            if (fi < 0 || fj < 0 || fi >= c.width || fj >= c.height) continue;
            const size_t pix = size_t(int(fj)) * size_t(c.width) + size_t(int(fi));
            const auto& st = ldi.start[size_t(m)];
            const double tol = 2.0 * sm + 1e-3;
            for (uint32_t q = st[pix]; q < st[pix + 1]; ++q) {
                const LdiSample& b = ldi.samples[q];
                if (glm::length(glm::dvec3(b.pos) - pos) <= tol &&
                    std::abs(glm::dot(glm::dvec3(b.normal), nrm)) > 0.7) {
                    keep[idx] = 0;
                    return;
                }
            }
        }
    });
    return keep;
}

}  // namespace vista
