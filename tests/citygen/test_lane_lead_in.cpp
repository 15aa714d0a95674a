// Junction turns begin and end straight (lanes.h, kCrossingLeadIn): on a
// generated city with sidewalks, nearly every bending junction turn keeps a
// straight line of kCrossingLeadIn at both ends, and the zebra crossing at
// each of its ends (crossingBand, the band the meshes draw and the OpenDRIVE
// writer declares) lies within that straight part, so a vehicle crosses it
// heading along the arm rather than turning.
#include <gtest/gtest.h>

#include <vector>

#include "citygen/blocks.h"
#include "citygen/generate.h"
#include "citygen/lanes.h"

using namespace vista;

namespace {

// How far the zebra crossing at the junction end of edge L (its end b when
// atB, else its start) reaches into the junction from the trimmed end; false
// when that end has no crossing.
bool crossingDepth(const EdgeLanes& L, bool atB, double& depth) {
    double s0 = 0, s1 = 0;
    if (!crossingBand(L, atB, s0, s1)) return false;
    depth = atB ? s1 - L.length : -s0;
    return true;
}

}  // namespace

TEST(LaneLeadIn, CrosswalksLieAcrossTheStraightPartOfJunctionTurns) {
    CityParams params;
    params.size_m = 800.0;
    params.seed = 11;
    params.detail = 0;
    auto city = generateCity(params);
    ASSERT_TRUE(city) << city.status().message();
    const std::vector<Block> blocks = extractBlocks(city->streets, params, nullptr);
    const LaneModel m = buildLaneModel(city->streets, params, &blocks);
    size_t bends = 0, led = 0, bands = 0, bandsOnTheTurn = 0;
    for (const LinkRoad& r : m.links) {
        if (r.junction < 0 || !(r.arcLength > 0)) continue;
        ++bends;
        const double eps = 1e-6;
        if (r.line0 >= kCrossingLeadIn - eps && r.line1 >= kCrossingLeadIn - eps) ++led;
        double depth = 0;
        // The incoming arm meets the junction with its end b when inEnd; the
        // outgoing arm leaves it with its start a when outStart.
        if (crossingDepth(m.edges[r.in], r.inEnd, depth)) {
            ++bands;
            bandsOnTheTurn += depth > r.line0 + eps;
        }
        if (crossingDepth(m.edges[r.out], !r.outStart, depth)) {
            ++bands;
            bandsOnTheTurn += depth > r.line1 + eps;
        }
    }
    ASSERT_GT(bends, 50u);
    ASSERT_GT(bands, 50u);
    EXPECT_GE(double(led), 0.9 * double(bends)) << led << " of " << bends << " bending junction turns lead in straight";
    EXPECT_LE(double(bandsOnTheTurn), 0.1 * double(bands))
        << bandsOnTheTurn << " of " << bands << " crossings reach the arc of their turn";
}
