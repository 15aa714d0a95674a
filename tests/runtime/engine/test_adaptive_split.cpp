// Near/far split selection and the adaptive near distance.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <random>

#include "foundation/status.h"
#include "runtime/engine/adaptive_split.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/engine/split_guard.h"
#include "tests/runtime/engine/fixtures.h"
#include "tests/runtime/engine/split_fixtures.h"

using namespace vista;
using namespace vista::test;

TEST(Split, DistanceSelectionDrawsStraddlingObjectsWhole) {
    std::vector<SplitObject> objs = {
        splitBox({10, -1, 0}, {20, 1, 5}, 10),    // 10 m away
        splitBox({95, -1, 0}, {120, 1, 5}, 20),   // straddles 100 m
        splitBox({101, -1, 0}, {130, 1, 5}, 30),  // just beyond
        splitBox({-5, -5, 0}, {5, 5, 50}, 40),    // contains the eye
    };
    auto sel = selectNearField(objs, glm::dvec3(0, 0, 2), 100.0);
    EXPECT_EQ(sel, (std::vector<uint32_t>{0, 1, 3}));
    // Every object with a point within the near distance is selected (independent check).
    for (uint32_t i = 0; i < objs.size(); ++i) {
        bool inside = false;
        for (double x = objs[i].lo.x; x <= objs[i].hi.x; x += 0.25) inside |= std::abs(x) <= 100.0;
        EXPECT_EQ(inside, std::find(sel.begin(), sel.end(), i) != sel.end()) << i;
    }
    auto byBudget = selectNearFieldByBudget(objs, glm::dvec3(0, 0, 2), 55);
    EXPECT_EQ(byBudget, (std::vector<uint32_t>{0, 3}));  // nearest first: 3 (0 m, 40) + 0 (10 m, 10) = 50; +20 > 55
    EXPECT_EQ(selectNearFieldByBudget(objs, glm::dvec3(0, 0, 2), 1).size(), 1u);  // nearest always drawn
}

TEST(Split, AdaptiveChoiceFollowsTheMeasuredCosts) {
    SceneModel city = randomCity(12, 150, 800.0);
    auto rs = RayScene::build(city);
    ASSERT_TRUE(rs.isOk());
    const std::vector<SplitObject> objs = squareObjects();
    Camera c = smallCamera(glm::dvec3(0, -350, 1.7));
    const AdaptiveSplitOptions o = measuredOnly();
    AdaptiveSplit cheapRays(objs, rs.value().get(), o), cheapTris(objs, rs.value().get(), o);
    {
        // Nothing measured yet: the ends (0, everything) are not offered on the priors.
        AdaptiveSplit fresh(objs, rs.value().get(), o);
        const double d = fresh.choose(c, -1);
        EXPECT_GE(d, o.minDistance);
        EXPECT_TRUE(std::isfinite(d));
    }
    // Rays expensive, triangles nearly free -> a large near field.
    for (int i = 0; i < 10; ++i) {
        cheapTris.record(uint64_t(20000 + 4000 * i), 1.0 + 1e-7 * (20000 + 4000 * i), 5000, 5000 * 0.01);
        cheapRays.record(uint64_t(20000 + 4000 * i), 1.0 + 1e-2 * (20000 + 4000 * i), 5000, 5000 * 1e-6);
    }
    double dT = cheapTris.choose(c, -1), dR = cheapRays.choose(c, -1);
    EXPECT_GT(dT, dR);
    EXPECT_NEAR(cheapTris.msPerTriangle(), 1e-7, 1e-9);  // the fit separates fixed and per-triangle cost
    // Ray casting never draws more than the smallest geometric candidate.
    EXPECT_LE(cheapRays.predictedTriangles(c.eye, dR), cheapRays.predictedTriangles(c.eye, o.minDistance));
    // The ends, from outside the city (every box 300 m or more away): rays nearly free -> 0 (ray
    // casting); triangles nearly free and boxes beyond 800 m -> everything rasterised.
    Camera out = c;
    out.eye = glm::dvec3(0, -700, 1.7);
    AdaptiveSplit endRays(objs, rs.value().get(), o), endTris(objs, rs.value().get(), o);
    for (int i = 0; i < 10; ++i) {
        endTris.record(uint64_t(20000 + 4000 * i), 1.0 + 1e-7 * (20000 + 4000 * i), 5000, 5000 * 0.01);
        endRays.record(uint64_t(20000 + 4000 * i), 1.0 + 1e-2 * (20000 + 4000 * i), 5000, 5000 * 1e-6);
    }
    EXPECT_EQ(endRays.choose(out, -1), 0.0);
    EXPECT_TRUE(std::isinf(endTris.choose(out, -1)));
    // Without the ends, the choice stays within the geometric candidates.
    AdaptiveSplitOptions inner = o;
    inner.rayCastOnly = inner.everythingNear = false;
    AdaptiveSplit innerTris(objs, rs.value().get(), inner), innerRays(objs, rs.value().get(), inner);
    for (int i = 0; i < 10; ++i) {
        innerTris.record(uint64_t(20000 + 4000 * i), 1.0 + 1e-7 * (20000 + 4000 * i), 5000, 5000 * 0.01);
        innerRays.record(uint64_t(20000 + 4000 * i), 1.0 + 1e-2 * (20000 + 4000 * i), 5000, 5000 * 1e-6);
    }
    const double iT = innerTris.choose(c, -1), iR = innerRays.choose(c, -1);
    EXPECT_GT(iT, iR);
    EXPECT_GE(iR, o.minDistance);
    EXPECT_LE(iT, o.maxDistance * 1.0001);
    // The far cost is fitted as c' + b * far pixels: a fixed 0.5 ms per frame does not count as
    // per-pixel cost (the mean ms per pixel would be about 3.5 times b here).
    AdaptiveSplit fitted(objs, rs.value().get(), o);
    double sumMs = 0, sumPx = 0;
    for (int i = 0; i < 12; ++i) {
        const double px = 8000 + 2500 * i, ms = 0.5 + 1e-5 * px;
        sumMs += ms;
        sumPx += px;
        fitted.record(uint64_t(20000 + 4000 * i), 1.0 + 1e-6 * (20000 + 4000 * i), uint64_t(px), ms);
    }
    EXPECT_NEAR(fitted.msPerRay(), 1e-5, 1e-7);
    EXPECT_LT(fitted.msPerRay(), 0.5 * sumMs / sumPx);
    // The far field's fixed cost is paid by every middle candidate, not by the ends: a large one
    // (same per-triangle and per-ray costs) tips the choice to rasterising everything (ray
    // casting left out here: it pays neither F nor c).
    AdaptiveSplitOptions noRayCasting = o;
    noRayCasting.rayCastOnly = false;
    AdaptiveSplit noFixed(objs, rs.value().get(), noRayCasting), bigFixed(objs, rs.value().get(), noRayCasting);
    for (int i = 0; i < 10; ++i) {
        noFixed.record(uint64_t(20000 + 4000 * i), 1.0 + 1e-5 * (20000 + 4000 * i), 5000, 5000 * 1e-4, 0.0);
        bigFixed.record(uint64_t(20000 + 4000 * i), 1.0 + 1e-5 * (20000 + 4000 * i), 5000, 5000 * 1e-4, 1e4);
    }
    EXPECT_NEAR(bigFixed.farFixedMs(), 1e4, 1e-6);
    EXPECT_TRUE(std::isinf(bigFixed.choose(out, -1)));
    EXPECT_TRUE(std::isfinite(noFixed.choose(out, -1)));
    // Predictions: more distance, more triangles, fewer rays.
    EXPECT_LE(cheapTris.predictedTriangles(c.eye, 50), cheapTris.predictedTriangles(c.eye, 400));
    EXPECT_GE(cheapTris.predictedRays(50), cheapTris.predictedRays(400));
}

// A candidate that draws no triangle needs no GL pass (the hybrid skips it), so
// it saves the raster's fixed cost c (clear, read-back), fitted as the
// intercept of raster ms = c + a * triangles. From outside the city (every
// box 300 m or more away) with triangles cheap and rays dear, a small c keeps
// the choice at rasterising the city; a large one (same a and b) makes the
// split cast rays instead, with nothing drawn.
TEST(Split, RayCastingSavesTheRasterFixedCost) {
    ProbeScene ps = probeScene(12);
    const std::vector<SplitObject> objs = squareObjects();
    const Camera out = smallCamera(glm::dvec3(0, -700, 1.7));
    const AdaptiveSplitOptions o = measuredOnly();
    AdaptiveSplit smallC(objs, ps.rays.get(), o), largeC(objs, ps.rays.get(), o);
    for (int i = 0; i < 10; ++i) {
        const double tris = 20000 + 4000 * i;
        smallC.record(uint64_t(tris), 0.01 + 1e-6 * tris, 2000, 2000 * 0.01);
        largeC.record(uint64_t(tris), 1e4 + 1e-6 * tris, 2000, 2000 * 0.01);
    }
    EXPECT_NEAR(smallC.rasterFixedMs(), 0.01, 1e-6);
    EXPECT_NEAR(largeC.rasterFixedMs(), 1e4, 1e-3);
    EXPECT_NEAR(largeC.msPerTriangle(), 1e-6, 1e-9);
    const double dSmall = smallC.choose(out, -1), dLarge = largeC.choose(out, -1);
    EXPECT_GT(smallC.predictedTriangles(out.eye, dSmall), 0u) << dSmall;
    EXPECT_EQ(largeC.predictedTriangles(out.eye, dLarge), 0u) << dLarge;
    EXPECT_LT(dLarge, dSmall);
}

// predictedRays(d) against an independent count: every s-th pixel cast one
// at a time (RayScene::intersect), where s follows from probeStride and
// probeRays (a 1280x720 image: sqrt(921600 / 2400) = 19.6 -> every 20th
// pixel); a probe pixel needs a ray when its hit lies beyond d or it misses
// below the horizon.
TEST(Split, ProbePredictsTheRaysOfAnIndependentCount) {
    ProbeScene ps = probeScene(7);
    RayScene* rays = ps.rays.get();
    const std::vector<SplitObject>& objs = ps.objs;
    Camera c;
    c.eye = glm::dvec3(10, -300, 12.0);
    c.pitch = -0.05;
    c.width = 1280;
    c.height = 720;
    AdaptiveSplitOptions o;
    o.timeProbe = false;
    AdaptiveSplit split(objs, rays, o);
    const int s = 20;
    const double ds[5] = {0.0, 30.0, 100.0, 300.0, std::numeric_limits<double>::infinity()};
    auto check = [&](const Camera& cam, const char* what) {
        const glm::vec3 org(cam.eye - rays->frameOrigin());
        std::vector<double> need(5, 0.0);
        double probes = 0;
        for (int y = s / 2; y < cam.height; y += s)
            for (int x = s / 2; x < cam.width; x += s) {
                const glm::vec3 dir(cam.rayDirection(x + 0.5, y + 0.5));
                const RayHit h = rays->intersect(org, dir);
                probes += 1;
                for (int k = 0; k < 5; ++k)
                    need[size_t(k)] += h.hit ? (double(h.t) > ds[k]) : (dir.z < 0 && !std::isinf(ds[k]));
            }
        const double scale = double(cam.width) * cam.height / probes;
        EXPECT_NEAR(probes, 2400.0, 200.0) << what;
        for (int k = 0; k < 5; ++k)
            EXPECT_NEAR(split.predictedRays(ds[k]), need[size_t(k)] * scale, 0.002 * cam.width * cam.height)
                << what << ", d = " << ds[k];
    };
    split.choose(c, -1);  // the first choice probes
    check(c, "first view");
    // A jump (200 m away, turned half a turn) within the probe interval: probed again at once.
    Camera c2 = c;
    c2.eye = glm::dvec3(150, 100, 30.0);
    c2.heading = c.heading + 3.0;
    split.choose(c2, -1);
    check(c2, "after a jump");
    EXPECT_EQ(split.predictedRays(std::numeric_limits<double>::infinity()), 0.0);
    EXPECT_GT(split.predictedRays(30.0), split.predictedRays(300.0));
}

// The probe's timed rate (one thread, between frames) caps b only while the
// frames' far-cost fit is ill-conditioned (b is then the mean ms per pixel,
// which counts each frame's fixed cost); a well-conditioned fit is the price
// of a far pixel in the frame, even above the probe's rate.
TEST(Split, ProbeRateCapsOnlyTheFallbackToTheMean) {
    ProbeScene ps = probeScene(5);
    RayScene* rays = ps.rays.get();
    const std::vector<SplitObject>& objs = ps.objs;
    Camera c;
    c.eye = glm::dvec3(0, -300, 1.7);
    c.width = 320;
    c.height = 240;
    AdaptiveSplitOptions o;
    o.timeProbe = true;
    o.minDistance = 1.0;  // nearly every probe ray is a far ray, so the probe is timed
    AdaptiveSplit fitted(objs, rays, o), flat(objs, rays, o);
    fitted.choose(c, -1);
    flat.choose(c, -1);
    // 10 ms per 1000 far pixels plus 1 ms a frame: far dearer than any Embree ray.
    for (int i = 0; i < 12; ++i) {
        const double px = 2000 + 1000 * i;
        fitted.record(uint64_t(10000 + 1000 * i), 2.0 + 1e-4 * (10000 + 1000 * i), uint64_t(px), 1.0 + 1e-2 * px);
        flat.record(uint64_t(10000 + 1000 * i), 2.0 + 1e-4 * (10000 + 1000 * i), 5000, 1.0 + 1e-2 * 5000);
    }
    EXPECT_NEAR(fitted.msPerRay(), 1e-2, 1e-4);
    // Same far pixels every frame: no slope, the mean (1.02e-2) capped by the probe's rate.
    EXPECT_GT(flat.msPerRay(), 0.0);
    EXPECT_LT(flat.msPerRay(), 1e-2);
}

// The raster-cost fit is robust: frames slowed down by another process (one
// in four here, 3x to 8x their cost) do not move the fitted ms per triangle
// off the line the other frames lie on (a least-squares fit would: it is
// pulled towards the outliers' slope).
TEST(Split, RasterCostFitIgnoresFramesSlowedByOtherWork) {
    std::vector<SplitObject> objs = {splitBox({0, 0, 0}, {10, 10, 10}, 1000)};
    AdaptiveSplitOptions o;
    o.timeProbe = false;
    AdaptiveSplit clean(objs, nullptr, o), noisy(objs, nullptr, o);
    const double c = 8.0, a = 2e-4;  // ms, ms per triangle
    for (int i = 0; i < 40; ++i) {
        const uint64_t tris = uint64_t(10000 + 2500 * (i % 9));
        const double ms = c + a * double(tris);
        clean.record(tris, ms, 0, 0);
        // Every fourth frame slowed 3x .. 8x, more so for the larger draws.
        noisy.record(tris, i % 4 == 3 ? ms * (3.0 + double(i % 9) * 5.0 / 8.0) : ms, 0, 0);
    }
    EXPECT_NEAR(clean.msPerTriangle(), a, 1e-9);
    EXPECT_NEAR(noisy.msPerTriangle(), a, 0.15 * a) << "the outliers moved the fit";
    // The same samples under least squares would be off by more than that tolerance:
    // the test would fail with the previous estimator.
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0;
    for (int i = 0; i < 40; ++i) {
        const double x = double(10000 + 2500 * (i % 9)), base = c + a * x;
        const double y = i % 4 == 3 ? base * (3.0 + double(i % 9) * 5.0 / 8.0) : base;
        sx += x, sy += y, sxx += x * x, sxy += x * y, ++n;
    }
    const double ls = (sxy / n - sx / n * sy / n) / (sxx / n - sx / n * sx / n);
    EXPECT_GT(std::abs(ls - a), 0.15 * a);
}

TEST(Split, GridIndexSelectsExactlyWhatTheLinearScanSelects) {
    // Random boxes: mostly chunk-sized, some wider than a cell (per-tile large chunks), some flat
    // points, spread over 3 km with a few far outliers; eyes inside, at the edge and far outside.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> pos(-1500.0, 1500.0), ext(0.0, 45.0), big(60.0, 900.0), h(0.0, 80.0);
    std::vector<SplitObject> objs;
    for (int i = 0; i < 4000; ++i) {
        const glm::dvec3 lo(pos(rng), pos(rng), 0.0);
        const bool wide = i % 97 == 0, point = i % 89 == 0;
        const glm::dvec3 size = point ? glm::dvec3(0.0) : glm::dvec3(wide ? big(rng) : ext(rng), ext(rng), h(rng));
        objs.push_back(splitBox(lo, lo + size, uint64_t(1 + i % 13)));
    }
    objs.push_back(splitBox({40000, 40000, 0}, {40030, 40030, 10}, 5));
    for (double cell : {16.0, 64.0, 500.0}) {
        SplitIndex index(objs, cell);
        uint64_t total = 0;
        for (const auto& o : objs) total += o.triangles;
        EXPECT_EQ(index.totalTriangles(), total);
        std::uniform_real_distribution<double> eyeXY(-2500.0, 2500.0);
        for (int e = 0; e < 40; ++e) {
            const glm::dvec3 eye =
                e == 0 ? glm::dvec3(40010, 40010, 2) : glm::dvec3(eyeXY(rng), eyeXY(rng), e % 3 == 0 ? 300.0 : 1.7);
            for (double d : {0.0, 15.0, 100.0, 333.3, 800.0, 5000.0, std::numeric_limits<double>::infinity()}) {
                ASSERT_EQ(index.within(eye, d), selectNearField(objs, eye, d))
                    << "cell " << cell << " eye " << e << " d " << d;
                std::vector<std::pair<double, uint64_t>> near;
                index.distances(eye, d, near);
                uint64_t sum = 0;
                for (uint32_t i : selectNearField(objs, eye, d)) sum += objs[i].triangles;
                uint64_t got = 0;
                for (const auto& [t, n] : near) {
                    EXPECT_LE(t, d);
                    got += n;
                }
                EXPECT_EQ(got, sum);
            }
        }
    }
    // An empty object list, and an AdaptiveSplit's predicted triangles against the linear sum.
    std::vector<SplitObject> none;
    EXPECT_TRUE(SplitIndex(none).within(glm::dvec3(0.0), 100.0).empty());
    AdaptiveSplitOptions o;
    o.timeProbe = false;
    AdaptiveSplit split(objs, nullptr, o);
    for (double d : {15.0, 120.0, 800.0, std::numeric_limits<double>::infinity()}) {
        uint64_t sum = 0;
        for (uint32_t i : selectNearField(objs, glm::dvec3(10, 20, 1.7), d)) sum += objs[i].triangles;
        EXPECT_EQ(split.predictedTriangles(glm::dvec3(10, 20, 1.7), d), sum) << d;
    }
}

// Each kind of choice (ray casting, a middle distance, everything) is corrected
// by what its own frames cost: the model prices ray casting cheapest, its frames
// measure 1000 ms, and the split leaves it; frames at the middle that cost what
// the model says change nothing there. An end not chosen for endTryEvery frames
// is tried again when its price is within endTryRatio of the best.
TEST(Split, EachChoiceLearnsItsOwnFixedCost) {
    ProbeScene ps = probeScene(12);
    const std::vector<SplitObject> objs = squareObjects();
    const Camera out = smallCamera(glm::dvec3(0, -700, 1.7));
    AdaptiveSplitOptions o = measuredOnly();
    o.endTryEvery = 0;
    AdaptiveSplit s(objs, ps.rays.get(), o);
    for (int i = 0; i < 10; ++i) {
        const double tris = 20000 + 4000 * i;
        s.record(uint64_t(tris), 1.0 + 1e-2 * tris, 5000, 5000 * 1e-6);  // rays nearly free
    }
    ASSERT_EQ(s.choose(out, -1), 0.0);
    s.recordFrame(0.0, 5000.0);  // one slow frame: the lower quartile of the kind's frames is its correction
    ASSERT_EQ(s.choose(out, -1), 0.0);
    s.recordFrame(0.0, 1000.0);
    EXPECT_GT(s.correctionMs(0), 900.0);
    const double d = s.choose(out, -1);
    EXPECT_GT(d, 0.0) << "a measured 1000 ms ray-casting frame must move the split";
    s.recordFrame(d + 1.0, 5000.0);  // not the distance chosen: ignored
    EXPECT_EQ(s.correctionMs(1), 0.0);
    EXPECT_EQ(s.correctionMs(2), 0.0);

    // End tries: the model's price of ray casting is dear here (rays dear), but it is tried when
    // within a factor 1e9 of the best; never with endTryRatio 0.
    for (const double ratio : {1e9, 0.0}) {
        AdaptiveSplitOptions t = measuredOnly();
        t.endTryEvery = 5;
        t.endTryRatio = ratio;
        t.everythingNear = false;
        AdaptiveSplit tr(objs, ps.rays.get(), t);
        for (int i = 0; i < 10; ++i) {
            const double tris = 20000 + 4000 * i;
            tr.record(uint64_t(tris), 1.0 + 1e-7 * tris, 5000, 5000 * 10.0);  // rays dear
        }
        int zeros = 0;
        for (int f = 0; f < 20; ++f) zeros += tr.choose(out, -1) == 0.0;
        if (ratio > 0) {
            // Never measured (no frame recorded): tried every third frame from frame 3.
            EXPECT_GE(zeros, 3) << "tried";
            EXPECT_LE(zeros, 6);
        } else {
            EXPECT_EQ(zeros, 0);
        }
    }
}

namespace vista {
namespace {

// The fixed near distance is a kind of its own: when the frames at the
// model's middle distances cost far more than the model says (here 1000 ms
// against a price of a few ms) and the fixed distance's frames cost what the
// model says, the split settles on the fixed distance, and that kind's
// correction stays small (its frames are measured apart from the middle's).
TEST(Split, FixedDistanceIsAFallbackWhenTheMiddleDoesNotPay) {
    ProbeScene ps = probeScene(12);
    const std::vector<SplitObject> objs = squareObjects();
    const Camera c = smallCamera(glm::dvec3(0, -350, 1.7));
    AdaptiveSplitOptions o = measuredOnly();
    o.rayCastOnly = o.everythingNear = false;
    o.endTryEvery = 4;
    o.endTryRatio = 1e9;  // every kind is re-measured every fourth frame
    o.fixedDistance = 123.0;
    AdaptiveSplit s(objs, ps.rays.get(), o);
    for (int i = 0; i < 10; ++i) {
        const double tris = 20000 + 4000 * i;
        s.record(uint64_t(tris), 1.0 + 1e-4 * tris, 5000, 5000 * 1e-4);
    }
    int fixedChoices = 0;
    for (int f = 0; f < 60; ++f) {
        const double d = s.choose(c, -1);
        ASSERT_TRUE(std::isfinite(d) && d > 0) << d;
        // Frames at the fixed distance cost about the model's price; any other distance 1000 ms.
        s.recordFrame(d, d == o.fixedDistance ? 5.0 : 1000.0);
        if (f >= 40) fixedChoices += d == o.fixedDistance;
    }
    EXPECT_GT(s.correctionMs(1), 500.0) << "the middle's frames were measured dear";
    EXPECT_GE(fixedChoices, 15) << "the last 20 choices settle on the fixed distance (tries aside)";
    EXPECT_LT(std::abs(s.correctionMs(3)), 50.0) << "the fixed distance's own frames cost what the model says";
}

// A kind's correction is taken from its own frames, re-priced by the model
// as it stands: frames slowed by other work on the machine (here half of
// them, at 50 times the others) do not move it, and once the model has
// learned a new price the corrected price of the same choice is still what
// its frames measured.
TEST(Split, CorrectionIgnoresFramesSlowedByOtherWork) {
    ProbeScene ps = probeScene(12);
    const std::vector<SplitObject> objs = squareObjects();
    const Camera c = smallCamera(glm::dvec3(0, -350, 1.7));
    AdaptiveSplitOptions o = measuredOnly();
    o.rayCastOnly = o.everythingNear = false;
    o.endTryEvery = 0;
    o.exploreEvery = 0;
    AdaptiveSplit s(objs, ps.rays.get(), o);
    for (int i = 0; i < 10; ++i) {
        const double tris = 20000 + 4000 * i;
        s.record(uint64_t(tris), 1.0 + 1e-4 * tris, 5000, 5000 * 1e-4);
    }
    double d = s.choose(c, -1);
    s.recordFrame(d, 1000.0);  // the kind's first frame: one-time costs, not counted
    for (int f = 0; f < 8; ++f) {
        d = s.choose(c, -1);
        s.recordFrame(d, f % 2 == 1 ? 500.0 : 10.0);
    }
    EXPECT_LT(s.correctionMs(1), 10.0) << "the slowed frames priced the middle out of reach";

    // Its frames measured 20 ms; then the raster fit learns a steeper slope.
    AdaptiveSplit t(objs, ps.rays.get(), o);
    auto fit = [&](double perTri) {
        for (int i = 0; i < 60; ++i) {
            const double tris = 20000 + 4000 * (i % 10);
            t.record(uint64_t(tris), 1.0 + perTri * tris, 5000, 0.5);
        }
    };
    fit(1e-4);
    d = t.choose(c, -1);
    t.recordFrame(d, 1000.0);
    uint64_t tris = 0;
    for (int f = 0; f < 8; ++f) {
        d = t.choose(c, -1);
        tris = t.chosenTriangles();
        t.recordFrame(d, 20.0);
    }
    auto price = [&] {
        return t.rasterFixedMs() + t.msPerTriangle() * double(tris) + t.msPerRay() * t.predictedRays(d) +
               t.farFixedMs();
    };
    EXPECT_NEAR(price() + t.correctionMs(1), 20.0, 1e-6);
    const double before = price();
    fit(4e-4);
    ASSERT_GT(price(), before + 1.0) << "the model learned a new price";
    EXPECT_NEAR(price() + t.correctionMs(1), 20.0, 1e-6) << "the measured frames still price the choice";
}

}  // namespace
}  // namespace vista

namespace vista {
namespace {

// A middle distance is corrected by the middle frames that drew and traced about what it does.
// On a synthetic machine (no timing) whose middle frames cost 30 ms at every distance while the
// model (rays dear) prices the distances far apart, and ray casting costs 25 ms, one kind-wide
// lower quartile of (frame ms - price) over frames at several distances (tries and
// explorations) prices the distances the model favours below every middle frame, and the split
// returns to them in bursts: 55 of the last 300 frames here. Corrected by frames like their own,
// the middle distances are priced at what they cost: the middle runs in explorations and tries.
TEST(Split, AMiddleDistanceIsCorrectedByFramesThatDrewAboutAsMuch) {
    ProbeScene ps = probeScene(12);
    const std::vector<SplitObject> objs = squareObjects();
    const Camera c = smallCamera(glm::dvec3(0, -350, 1.7));
    AdaptiveSplitOptions o = measuredOnly();
    o.exploreEvery = 7;
    o.endTryEvery = 24;
    o.everythingNear = false;
    AdaptiveSplit s(objs, ps.rays.get(), o);
    for (int i = 0; i < 10; ++i) {
        const double tris = 20000 + 4000 * i;
        s.record(uint64_t(tris), 1.0 + 1e-5 * tris, 5000, 5000 * 1e-2);
    }
    int middle = 0;
    for (int f = 0; f < 400; ++f) {
        const double d = s.choose(c, -1);
        if (f >= 100) middle += d > 0;
        s.recordFrame(d, d <= 0 ? 25.0 : 30.0);
    }
    EXPECT_LE(middle, 40) << "of the last 300 frames, the middle's (30 ms against ray casting's 25 ms)";
}

}  // namespace
}  // namespace vista
