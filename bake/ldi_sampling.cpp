#include "bake/ldi_sampling.h"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "foundation/units.h"

namespace vista {

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

LdiResult sampleLdi(const RayScene& scene, const SamplingSetup& s, const Box3& far, const SamplingParams& p) {
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
            x0 = std::min(x0, x);
            x1 = std::max(x1, x);
            y0 = std::min(y0, y);
            y1 = std::max(y1, y);
        }
        double step = step0;
        double w = std::ceil((x1 - x0) / step), h = std::ceil((y1 - y0) / step);
        if (w * h > double(p.maxRaysPerCamera)) {
            step *= std::sqrt(w * h / double(p.maxRaysPerCamera));
            w = std::ceil((x1 - x0) / step);
            h = std::ceil((y1 - y0) / step);
        }
        c.x0 = x0;
        c.y0 = y0;
        c.step = step;
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
            // The row's rays, clipped to the far box, traced together (packets of 8).
            const size_t w = size_t(c.width);
            std::vector<glm::vec3> org(w, glm::vec3(c.pos)), dirs(w);
            std::vector<glm::dvec3> ddirs(w);
            std::vector<float> tn(w, 1.0f), tf(w, 0.0f);  // tn > tf: no ray
            for (int i = 0; i < c.width; ++i) {
                const glm::dvec3 dd = s.n + (c.x0 + (i + 0.5) * c.step) * s.U + (c.y0 + (j + 0.5) * c.step) * s.V;
                ddirs[size_t(i)] = glm::normalize(dd);
                dirs[size_t(i)] = glm::vec3(ddirs[size_t(i)]);
                double t0, t1;
                if (!clipRay(far, c.pos, ddirs[size_t(i)], t0, t1)) continue;
                tn[size_t(i)] = float(std::max(0.0, t0 - 1e-3));
                tf[size_t(i)] = float(t1 + 1e-3);
            }
            std::vector<RayHit> hits(w * size_t(layers));
            std::vector<int> counts(w);
            scene.allHitsMany(org.data(), dirs.data(), c.width, tn.data(), tf.data(), layers, gap, hits.data(),
                              counts.data());
            auto& out = rows[size_t(j)];
            auto& cnt = rowCounts[size_t(j)];
            cnt.assign(w, 0);
            size_t rowHits = 0;
            for (int n : counts) rowHits += size_t(n);
            out.reserve(rowHits);
            for (int i = 0; i < c.width; ++i) {
                for (int h = 0; h < counts[size_t(i)]; ++h) {
                    const RayHit& hit = hits[size_t(i) * size_t(layers) + size_t(h)];
                    LdiSample smp;
                    const glm::dvec3 pos = c.pos + ddirs[size_t(i)] * double(hit.t);
                    smp.pos = glm::vec3(pos);
                    smp.normal = hit.normal;
                    smp.color = scene.hitColor(hit);
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
        size_t add = 0;
        for (const auto& row : rows) add += row.size();
        r.samples.reserve(r.samples.size() + add);
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

}  // namespace vista
