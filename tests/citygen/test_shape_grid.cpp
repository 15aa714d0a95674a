// The lane model's broad phase (citygen/shape_grid.h) against a brute-force
// reference on seeded random quads (small turn pieces and long, thin, turned
// carriageways): a query returns, sorted and once each, every id in its range
// that the filter keeps whose quad's bounding box meets the query's, and no
// id outside the range or refused by the filter; small queries read a small
// part of the set, and only the part of a cell in their range. Non-finite
// quads are neither stored nor found.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "citygen/shape_grid.h"
#include "foundation/units.h"

using namespace vista;

namespace {

Quad randomQuad(std::mt19937_64& rng, double maxHalfLength) {
    std::uniform_real_distribution<double> pos(-80.0, 80.0), angle(0.0, kTwoPi), half(0.05, maxHalfLength),
        side(0.05, 4.0);
    const glm::dvec2 c(pos(rng), pos(rng));
    const double a = angle(rng), hu = half(rng), hv = side(rng);
    const glm::dvec2 u(std::cos(a), std::sin(a)), v(-u.y, u.x);
    return {c - u * hu - v * hv, c + u * hu - v * hv, c + u * hu + v * hv, c - u * hu + v * hv};
}

void bounds(const Quad& q, glm::dvec2& lo, glm::dvec2& hi) {
    lo = glm::dvec2(std::numeric_limits<double>::max());
    hi = -lo;
    for (const auto& p : q) lo = glm::min(lo, p), hi = glm::max(hi, p);
}

bool boxesMeet(const Quad& a, const Quad& b) {
    glm::dvec2 alo, ahi, blo, bhi;
    bounds(a, alo, ahi);
    bounds(b, blo, bhi);
    return alo.x <= bhi.x && blo.x <= ahi.x && alo.y <= bhi.y && blo.y <= ahi.y;
}

}  // namespace

TEST(ShapeGrid, QueryHoldsEveryKeptQuadWhoseBoxMeetsAndNothingElse) {
    std::mt19937_64 rng(20240611);
    std::vector<Quad> quads;
    for (int i = 0; i < 600; ++i) quads.push_back(randomQuad(rng, i % 5 == 0 ? 60.0 : 2.0));
    ShapeGrid grid(8.0);
    for (uint32_t i = 0; i < quads.size(); ++i) grid.insert(quads[i], i);
    const auto keep = [](uint32_t id) { return id % 3 != 1; };
    std::uniform_int_distribution<uint32_t> pick(0, uint32_t(quads.size()));
    std::vector<uint32_t> out;
    size_t returned = 0, inRange = 0, expectedTotal = 0;
    for (int t = 0; t < 400; ++t) {
        const Quad q = randomQuad(rng, t % 4 == 0 ? 30.0 : 1.0);
        uint32_t first = pick(rng), last = pick(rng);
        if (first > last) std::swap(first, last);
        if (t % 10 == 0) first = 0, last = std::numeric_limits<uint32_t>::max();
        grid.query(q, first, last, keep, out);
        ASSERT_TRUE(std::is_sorted(out.begin(), out.end()));
        ASSERT_EQ(std::adjacent_find(out.begin(), out.end()), out.end()) << "an id twice";
        for (uint32_t id : out) {
            ASSERT_LT(id, quads.size());
            EXPECT_TRUE(id >= first && id < last && keep(id)) << "query " << t << " returned " << id;
        }
        for (uint32_t id = 0; id < quads.size(); ++id) {
            if (!(id >= first && id < last && keep(id))) continue;
            ++inRange;
            if (!boxesMeet(q, quads[id])) continue;
            ++expectedTotal;
            EXPECT_TRUE(std::binary_search(out.begin(), out.end(), id)) << "query " << t << " missed " << id;
        }
        returned += out.size();
    }
    EXPECT_GT(expectedTotal, 400u);    // the queries meet quads: the comparison means something
    EXPECT_LT(returned, inRange / 4);  // and the grid reads a small part of the set
}

TEST(ShapeGrid, NonFiniteQuadsAreNeitherStoredNorFound) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const Quad unit{glm::dvec2(0, 0), glm::dvec2(1, 0), glm::dvec2(1, 1), glm::dvec2(0, 1)};
    Quad bad = unit;
    bad[2].x = nan;
    Quad far = unit;
    far[1].y = std::numeric_limits<double>::infinity();
    ShapeGrid grid(8.0);
    grid.insert(unit, 0);
    grid.insert(bad, 1);
    grid.insert(far, 2);
    std::vector<uint32_t> out{7};
    const auto all = [](uint32_t) { return true; };
    grid.query(unit, 0, 10, all, out);
    EXPECT_EQ(out, std::vector<uint32_t>{0});
    grid.query(bad, 0, 10, all, out);
    EXPECT_TRUE(out.empty());
    grid.query(far, 0, 10, all, out);
    EXPECT_TRUE(out.empty());
}

// The lane model's crossing tests ask for a few earlier ids among the
// hundreds of quads of a junction's own turns in the same cells: the query
// reads only the ids in its range (counted through the filter).
TEST(ShapeGrid, QueryReadsOnlyItsRangeOfACell) {
    ShapeGrid grid(8.0);
    const Quad piece{glm::dvec2(1, 1), glm::dvec2(2, 1), glm::dvec2(2, 3), glm::dvec2(1, 3)};
    for (uint32_t i = 0; i < 1000; ++i) grid.insert(piece, i);
    size_t calls = 0;
    const auto counted = [&](uint32_t) { return ++calls, true; };
    std::vector<uint32_t> out;
    grid.query(piece, 990, 995, counted, out);
    EXPECT_EQ(out, (std::vector<uint32_t>{990, 991, 992, 993, 994}));
    EXPECT_EQ(calls, 5u);
    calls = 0;
    grid.query(
        piece, 0, 1000, [&](uint32_t id) { return ++calls, id % 100 == 0; }, out);
    EXPECT_EQ(out.size(), 10u);
    EXPECT_EQ(calls, 1000u);
}
