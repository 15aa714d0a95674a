// subdivideLots(): recursive oriented-bounding-box splitting (Parish & Mueller 2001,
// with the street-access rule of Vanegas et al. 2012).
//
// Every block edge is a street side except edges on the city border. A polygon
// is split by a line perpendicular to the long side of its minimum-area OBB,
// near its middle (seeded jitter, Rng(seed, path key, Stream::Lots)). When that
// cut would leave a piece without street frontage, the perpendicular cut is
// tried and taken if every piece keeps frontage. Splitting stops when the OBB
// is no longer than the target width (lot_width_m * (1 + 3 density)), or when
// the street frontage is narrow enough and the lot not too deep. Lots without
// frontage, tiny or thin lots are discarded. Polygon cuts are exact
// line/polygon splits (concave blocks may give several pieces), so every lot
// lies inside its block.
#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "citygen/blocks.h"
#include "citygen/building_geometry.h"
#include "citygen/polygon.h"
#include "foundation/rng.h"

namespace vista {

namespace {

constexpr double kMinLotArea = 40.0;
constexpr double kMinLotWidth = 4.0;
constexpr double kMinFrontage = 2.0;
constexpr int kMaxDepth = 24;

double frontageLength(const FlaggedPolygon& p) {
    double f = 0;
    for (size_t i = 0; i < p.pts.size(); ++i)
        if (p.flags[i]) f += glm::length(p.pts[(i + 1) % p.pts.size()] - p.pts[i]);
    return f;
}

struct LotSplitter {
    const CityParams& params;
    double target;
    std::vector<Polygon2>& out;

    void emit(const FlaggedPolygon& p) {
        if (frontageLength(p) < kMinFrontage) return;
        Polygon2 poly = cleanPolygon(makeCounterClockwise(p.pts), 1e-7);  // drops near-duplicate cut points
        if (poly.size() < 3 || !(signedArea(poly) >= kMinLotArea)) return;
        if (2.0 * orientedBox(poly).halfV < kMinLotWidth) return;
        out.push_back(std::move(poly));
    }

    static bool allFront(const std::vector<FlaggedPolygon>& pieces) {
        for (const auto& q : pieces)
            if (frontageLength(q) < kMinFrontage) return false;
        return true;
    }

    void split(const FlaggedPolygon& p, uint64_t key, int depth) {
        double area = std::abs(signedArea(p.pts));
        if (!(area >= 0.5 * kMinLotArea)) return;
        OrientedBox box = orientedBox(p.pts);
        double len = 2.0 * box.halfU, wid = 2.0 * box.halfV;
        double front = frontageLength(p);
        if (depth >= kMaxDepth || len <= target) {
            emit(p);
            return;
        }
        if (front >= kMinFrontage && front <= 1.25 * target && len <= 2.5 * target) {
            emit(p);
            return;
        }
        Rng rng(params.seed, key, Stream::Lots);
        double j1 = rng.uniform(-0.12, 0.12), j2 = rng.uniform(-0.12, 0.12);
        auto pieces = splitPolygonByLine(p, box.centre + box.u * (len * j1), box.v);
        if (front >= kMinFrontage && !allFront(pieces) && wid > 0.8 * target) {
            auto alt = splitPolygonByLine(p, box.centre + box.v * (wid * j2), box.u);
            if (alt.size() > 1 && allFront(alt)) pieces = std::move(alt);
        }
        if (pieces.size() <= 1) {
            emit(p);
            return;
        }
        for (size_t k = 0; k < pieces.size(); ++k) split(pieces[k], hashKeys(key, k + 1), depth + 1);
    }
};

}  // namespace

std::vector<Lot> subdivideLots(const std::vector<Block>& blocks, const CityParams& params, Progress* progress) {
    const double half = 0.5 * params.size_m;
    std::vector<std::vector<Polygon2>> per(blocks.size());
    tbb::parallel_for(size_t(0), blocks.size(), [&](size_t bi) {
        const Block& b = blocks[bi];
        if (b.park || b.outline.size() < 3) return;
        FlaggedPolygon fp;
        fp.pts = cleanPolygon(makeCounterClockwise(b.outline), 1e-9);
        if (fp.pts.size() < 3) return;
        for (size_t i = 0; i < fp.pts.size(); ++i) {
            glm::dvec2 a = fp.pts[i], c = fp.pts[(i + 1) % fp.pts.size()];
            auto onBorder = [&](double u, double v) {
                return std::abs(u) >= half - 1e-6 && std::abs(v) >= half - 1e-6 && u * v > 0;
            };
            bool border = onBorder(a.x, c.x) || onBorder(a.y, c.y);
            fp.flags.push_back(border ? 0 : 1);
        }
        double target = params.lot_width_m * (1.0 + 3.0 * std::clamp((b.density - 0.4) / 0.6, 0.0, 1.0));
        LotSplitter s{params, target, per[bi]};
        s.split(fp, stableIdOf(centroid(fp.pts)), 0);
    });
    std::vector<Lot> lots;
    for (size_t bi = 0; bi < per.size(); ++bi)
        for (auto& p : per[bi]) {
            Lot l;
            l.block = uint32_t(bi);
            l.outline = std::move(p);
            l.frontage = true;
            lots.push_back(std::move(l));
        }
    if (progress) progress->update(1.0);
    return lots;
}

}  // namespace vista
