#include "bake/appearance.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <boost/math/distributions/fisher_f.hpp>
#include <tbb/parallel_for.h>

#include "citygen/lighting.h"
#include "foundation/rng.h"

namespace vista {
namespace {

inline double luma(const glm::dvec3& c) { return 0.299 * c.x + 0.587 * c.y + 0.114 * c.z; }

glm::u8vec4 toU8(const glm::dvec3& c) {
    auto q = [](double v) { return uint8_t(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)); };
    return {q(c.x), q(c.y), q(c.z), 255};
}

struct TexelAcc {
    glm::dvec3 sum{0.0};
    double l = 0, l2 = 0;
    int n = 0, attempts = 0;
    glm::dvec3 mean() const { return n > 0 ? sum / double(n) : glm::dvec3(0.0); }
    double stdErr() const {
        if (n < 2) return 1e300;
        const double m = l / n;
        const double var = std::max(0.0, (l2 - n * m * m) / (n - 1));
        return std::sqrt(var / n);
    }
};

// Critical values of F(d1, d2) at 1 - alpha, tabulated for the degrees of
// freedom one point can reach (d1 < texels, d2 < texels * maxSamples).
class FTable {
public:
    FTable(double alpha, int maxD1, int maxD2) : _d2(maxD2) {
        if (alpha <= 0) return;
        _q.resize(size_t(maxD1) * size_t(maxD2));
        for (int a = 1; a <= maxD1; ++a)
            for (int b = 1; b <= maxD2; ++b)
                _q[size_t(a - 1) * size_t(maxD2) + size_t(b - 1)] =
                    boost::math::quantile(boost::math::fisher_f(double(a), double(b)), 1.0 - alpha);
    }
    bool enabled() const { return !_q.empty(); }
    double at(int d1, int d2) const { return _q[size_t(d1 - 1) * size_t(_d2) + size_t(d2 - 1)]; }

private:
    int _d2;
    std::vector<double> _q;
};

// One-way ANOVA on the texels' luma: true when the texel means differ more
// than their samples' scatter explains at this level (or the test cannot be
// made: fewer than 2 seen texels or no within-texel degrees of freedom).
bool viewDependent(const std::vector<TexelAcc>& acc, const FTable& table) {
    int k = 0;
    int64_t n = 0;
    double l = 0, ssw = 0, ssb = 0;
    for (const auto& a : acc) {
        if (a.n == 0) continue;
        ++k;
        n += a.n;
        l += a.l;
        ssw += std::max(0.0, a.l2 - a.l * a.l / a.n);
    }
    if (k < 2 || n - k < 1) return true;
    const double grand = l / double(n);
    for (const auto& a : acc)
        if (a.n > 0) ssb += a.n * (a.l / a.n - grand) * (a.l / a.n - grand);
    const double msb = ssb / double(k - 1), msw = ssw / double(n - k);
    if (msw <= 1e-18) return msb > 1e-18;
    return msb / msw > table.at(k - 1, int(n - k));
}

struct PointResult {
    bool visible = false, single = true, noise = false;
    glm::dvec3 mean{0.0};
    std::vector<glm::dvec3> texels;
    int64_t rays = 0, samples = 0;
};

// The sampling plane's texel grid: its corner, extent, texel size and texel count.
struct TexelGrid {
    glm::dvec2 lo, size, texel;
    int nt;
};

// Samples the appearance of one point from the sampling plane into a
// PointResult. Every draw comes from the point's own stream in a fixed order,
// so the result does not depend on threads.
class PointSampler {
public:
    PointSampler(const RayScene& scene, const SamplingSetup& s, const AppearanceParams& p, const TexelGrid& grid,
                 const FTable& fTable, const glm::dvec3& pt, Rng& rng, PointResult& r)
        : _scene(scene),
          _s(s),
          _p(p),
          _grid(grid),
          _fTable(fTable),
          _pt(pt),
          _rng(rng),
          _r(r),
          _acc(static_cast<size_t>(grid.nt)) {}

    // Runs the steps: visibility from the cell, a first pass of samples per
    // texel, a colour from the cell when no plane sample saw the point, else
    // adaptive refinement and the summary of the texels.
    void run(const Box3* cell) {
        const int nt = _grid.nt;
        bool seen = false;
        glm::dvec3 seenFrom(0.0);
        if (cell && _p.cellVisibilityRays > 0) {
            seen = seenFromCell(*cell, seenFrom);
            if (!seen) {
                _r.visible = false;
                return;
            }
        }
        // Pass 1: minSamples visible samples per texel.
        for (int t = 0; t < nt; ++t)
            while (_acc[size_t(t)].n < _p.minSamples && _acc[size_t(t)].attempts < 4 * _p.minSamples) sample(t);
        int64_t n = 0;
        double l = 0, l2 = 0;
        for (const auto& a : _acc) {
            n += a.n;
            l += a.l;
            l2 += a.l2;
        }
        if (n == 0 && !seen) {
            _r.visible = false;
            return;
        }
        if (n == 0) {
            colourFromCell(seenFrom);
            return;
        }
        _r.visible = true;
        const double pooledStd = n > 1 ? std::sqrt(std::max(0.0, (l2 - l * l / double(n)) / double(n - 1))) : 0.0;
        const bool noiseOnly =
            nt > 1 && _fTable.enabled() && !(pooledStd < _p.singleColorThreshold) && !viewDependent(_acc, _fTable);
        refine(pooledStd, noiseOnly);
        summarize(noiseOnly);
    }

private:
    // Casts visibility rays from the cell's corners, centre and random points
    // inside it; returns whether one sees the point (seenFrom: where from).
    bool seenFromCell(const Box3& cell, glm::dvec3& seenFrom) {
        bool seen = false;
        for (int v = 0; v < _p.cellVisibilityRays && !seen; ++v) {
            glm::dvec3 e;
            if (v < 8) e = cell.corner(v);
            else if (v == 8) e = cell.center();
            else
                for (int a = 0; a < 3; ++a) e[a] = _rng.uniform(cell.lo[a], cell.hi[a]);
            glm::dvec3 d = _pt - e;
            const double dist = glm::length(d);
            if (dist < 1e-6) {
                seen = true;
                break;
            }
            d /= dist;
            ++_r.rays;
            seen = !_scene.occluded(glm::vec3(e), glm::vec3(d), 0.0f, float(dist - std::max(0.1, 2e-3 * dist)));
            if (seen) seenFrom = e;
        }
        return seen;
    }

    // Takes one sample for texel t: a jittered viewpoint in the texel, a
    // visibility ray to the point and, if it is seen, one pixel ray's colour.
    void sample(int t) {
        const glm::dvec2 lo = _grid.lo, texel = _grid.texel;
        const int ti = t % _p.texelsX, tj = t / _p.texelsX;
        glm::dvec2 q = lo + glm::dvec2((ti + 0.5) * texel.x, (tj + 0.5) * texel.y);
        q.x += _rng.normal() * _p.viewSigma * texel.x;
        q.y += _rng.normal() * _p.viewSigma * texel.y;
        q = glm::clamp(q, lo, lo + _grid.size);
        const glm::dvec3 sp = _s.toFrame(q);
        glm::dvec3 d = _pt - sp;
        const double dist = glm::length(d);
        TexelAcc& a = _acc[size_t(t)];
        ++a.attempts;
        if (dist < 1e-6) return;
        d /= dist;
        ++_r.rays;
        const double gap = std::max(0.05, 2e-4 * dist);
        if (_scene.occluded(glm::vec3(sp), glm::vec3(d), 0.0f, float(dist - gap))) return;
        glm::dvec3 e1 = glm::cross(d, glm::dvec3(0, 0, 1));
        if (glm::length(e1) < 1e-9) e1 = glm::dvec3(1, 0, 0);
        e1 = glm::normalize(e1);
        const glm::dvec3 e2 = glm::cross(e1, d);
        const double ox = _rng.uniform(-0.5, 0.5) + _rng.normal() * _p.pixelSigma;
        const double oy = _rng.uniform(-0.5, 0.5) + _rng.normal() * _p.pixelSigma;
        const glm::dvec3 dir = glm::normalize(d + _p.pixelAngle * (ox * e1 + oy * e2));
        ++_r.rays;
        const RayHit h = _scene.intersect(glm::vec3(sp), glm::vec3(dir), 0.0f, 1e30f);
        glm::dvec3 c;
        if (h.hit) c = glm::dvec3(_scene.hitColor(h));
        else c = glm::dvec3(glm::vec3(skyColor(std::asin(std::clamp(dir.z, -1.0, 1.0))))) / 255.0;
        a.sum += c;
        const double l = luma(c);
        a.l += l;
        a.l2 += l * l;
        ++a.n;
    }

    // Seen from the cell but from no sampled viewpoint on the plane: gives one
    // colour from pixel rays at the cell position that sees it (never a hole).
    void colourFromCell(const glm::dvec3& seenFrom) {
        glm::dvec3 d = glm::normalize(_pt - seenFrom);
        glm::dvec3 e1 = glm::cross(d, glm::dvec3(0, 0, 1));
        if (glm::length(e1) < 1e-9) e1 = glm::dvec3(1, 0, 0);
        e1 = glm::normalize(e1);
        const glm::dvec3 e2 = glm::cross(e1, d);
        glm::dvec3 sum(0.0);
        const int k = std::max(4, _p.minSamples);
        for (int i = 0; i < k; ++i) {
            const double ox = _rng.uniform(-0.5, 0.5) + _rng.normal() * _p.pixelSigma;
            const double oy = _rng.uniform(-0.5, 0.5) + _rng.normal() * _p.pixelSigma;
            const glm::dvec3 dir = glm::normalize(d + _p.pixelAngle * (ox * e1 + oy * e2));
            ++_r.rays;
            const RayHit h = _scene.intersect(glm::vec3(seenFrom), glm::vec3(dir), 0.0f, 1e30f);
            sum += h.hit ? glm::dvec3(_scene.hitColor(h))
                         : glm::dvec3(glm::vec3(skyColor(std::asin(std::clamp(dir.z, -1.0, 1.0))))) / 255.0;
        }
        _r.visible = true;
        _r.single = true;
        _r.samples = k;
        _r.mean = sum / double(k);
        _r.texels.assign(size_t(_grid.nt), _r.mean);
    }

    // Samples each texel further until its luma is known well enough, when
    // the point looks different from different viewpoints (or has one texel).
    void refine(double pooledStd, bool noiseOnly) {
        const int nt = _grid.nt;
        const int maxAttempts = 4 * _p.maxSamples;
        if (!(pooledStd < _p.singleColorThreshold) && nt > 1 && !noiseOnly) {
            for (int t = 0; t < nt; ++t) {
                TexelAcc& a = _acc[size_t(t)];
                while (a.n < _p.maxSamples && a.attempts < maxAttempts &&
                       !(a.n >= _p.minSamples && a.stdErr() < _p.varianceThreshold))
                    sample(t);
            }
        } else if (nt == 1) {
            TexelAcc& a = _acc[0];
            while (a.n < _p.maxSamples && a.attempts < maxAttempts &&
                   !(a.n >= _p.minSamples && a.stdErr() < _p.varianceThreshold))
                sample(0);
        }
    }

    // Sets the point's mean, texel colours and whether one colour (or noise) stands for it.
    void summarize(bool noiseOnly) {
        const int nt = _grid.nt;
        glm::dvec3 sum(0.0);
        int64_t cnt = 0;
        int seenTexels = 0;
        for (const auto& a : _acc) {
            sum += a.sum;
            cnt += a.n;
            seenTexels += a.n > 0 ? 1 : 0;
        }
        _r.samples = cnt;
        _r.mean = sum / double(cnt);
        // Texel means; unseen texels take the mean of the seen ones.
        glm::dvec3 tm(0.0);
        for (const auto& a : _acc)
            if (a.n > 0) tm += a.mean();
        tm /= double(seenTexels);
        _r.texels.resize(size_t(nt));
        for (int t = 0; t < nt; ++t) _r.texels[size_t(t)] = _acc[size_t(t)].n > 0 ? _acc[size_t(t)].mean() : tm;
        glm::dvec3 var(0.0);
        for (const auto& c : _r.texels) var += (c - tm) * (c - tm);
        var /= double(nt);
        const double maxStd = std::sqrt(std::max(var.x, std::max(var.y, var.z)));
        _r.noise = noiseOnly || (nt > 1 && _fTable.enabled() && !(maxStd < _p.singleColorThreshold) &&
                                 !viewDependent(_acc, _fTable));
        _r.single = nt == 1 || maxStd < _p.singleColorThreshold || _r.noise;
        // One colour: the mean of every sample (noise) or of the texel means.
        if (_r.single && !_r.noise) _r.mean = tm;
    }

    const RayScene& _scene;
    const SamplingSetup& _s;
    const AppearanceParams& _p;
    const TexelGrid& _grid;
    const FTable& _fTable;
    const glm::dvec3 _pt;
    Rng& _rng;
    PointResult& _r;
    std::vector<TexelAcc> _acc;
};

// Writes the visible points' colours and texel blocks to out (in point order)
// and adds every point's rays, samples and kind to stats.
void writeResults(const std::vector<PointResult>& res, const std::vector<glm::vec3>& points, int nt,
                  PointImpostorData& out, AppearanceStats& stats, std::vector<uint32_t>* kept) {
    out.positions.clear();
    out.colors.clear();
    out.block.clear();
    out.texels.clear();
    if (kept) kept->clear();
    for (size_t k = 0; k < points.size(); ++k) {
        const PointResult& r = res[k];
        stats.rays += r.rays;
        stats.samples += r.samples;
        if (!r.visible) {
            ++stats.dropped;
            continue;
        }
        if (kept) kept->push_back(uint32_t(k));
        out.positions.push_back(points[k]);
        out.colors.push_back(toU8(r.mean));
        if (r.single) {
            ++stats.singleColor;
            if (r.noise) ++stats.noiseOnly;
            out.block.push_back(-1);
        } else {
            ++stats.textured;
            out.block.push_back(int32_t(out.texels.size() / size_t(nt)));
            for (const auto& c : r.texels) out.texels.push_back(toU8(c));
        }
    }
}

}  // namespace

void computeAppearance(const RayScene& scene, const SamplingSetup& s, const std::vector<glm::vec3>& points,
                       const AppearanceParams& p, uint64_t seed, uint64_t entity, PointImpostorData& out,
                       AppearanceStats& stats, std::vector<uint32_t>* kept, const Box3* cell) {
    VISTA_CHECK(p.texelsX >= 1 && p.texelsY >= 1 && p.minSamples >= 1 && p.maxSamples >= p.minSamples);
    const int nt = p.texelsX * p.texelsY;
    const glm::dvec2 lo = s.rectLo, size = glm::max(s.rectHi - s.rectLo, glm::dvec2(1e-6));
    const glm::dvec2 texel(size.x / p.texelsX, size.y / p.texelsY);
    const TexelGrid grid{lo, size, texel, nt};
    std::vector<PointResult> res(points.size());
    const FTable fTable(p.significance, std::max(1, nt - 1), std::max(1, nt * p.maxSamples));

    tbb::parallel_for(size_t(0), points.size(), [&](size_t k) {
        Rng rng(seed, hashKeys(entity, k), Stream::Bake);
        PointSampler(scene, s, p, grid, fTable, glm::dvec3(points[k]), rng, res[k]).run(cell);
    });

    out.texelsX = p.texelsX;
    out.texelsY = p.texelsY;
    out.planeOrigin = glm::vec3(s.toFrame(lo));
    out.planeU = glm::vec3(s.U * size.x);
    out.planeV = glm::vec3(s.V * size.y);
    writeResults(res, points, nt, out, stats, kept);
}

}  // namespace vista
