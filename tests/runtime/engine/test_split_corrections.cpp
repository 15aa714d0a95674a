// The split's price corrected by the frames its guard drew (end points, the near default), and
// the hysteresis that keeps its last choice.
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

namespace vista {
namespace {

// The split and its guard together on a synthetic machine (no timing): every middle distance
// costs `middleMs`, ray casting 25 ms; the model prices ray casting far above the middle (rays
// dear) and the split never tries it on its own (no end tries, no exploration). The guard's
// ray-casting frames are frames of that kind all the same and correct its price: where the
// middle is dearer (30 ms), the split itself chooses ray casting within a few frames of the
// guard's first measurement (drawn for the guard's hold, they were once ignored by the split,
// which kept choosing the middle through every hold); where it is cheaper (20 ms) the middle is
// kept.
TEST(Split, EndPointFramesTheGuardDrewCorrectTheSplitsPrice) {
    ProbeScene ps = probeScene(12);
    const std::vector<SplitObject> objs = squareObjects();
    const Camera c = smallCamera(glm::dvec3(0, -350, 1.7));
    for (const double middleMs : {30.0, 20.0}) {
        AdaptiveSplitOptions o = measuredOnly();
        o.endTryEvery = 0;
        o.everythingNear = false;
        AdaptiveSplit s(objs, ps.rays.get(), o);
        for (int i = 0; i < 10; ++i) {
            const double tris = 20000 + 4000 * i;
            s.record(uint64_t(tris), 1.0 + 1e-5 * tris, 5000, 5000 * 3e-2);  // ray casting: about 90 ms
        }
        SplitGuard g;
        int firstRay = -1, splitRay = 0, drawnMiddle = 0;
        for (int f = 0; f < 200; ++f) {
            const double chosen = s.choose(c, -1);
            const double d = g.filter(chosen);
            if (d <= 0 && firstRay < 0) firstRay = f;
            if (f >= 100) {
                splitRay += chosen <= 0;
                drawnMiddle += d > 0;
            }
            const double ms = d <= 0 ? 25.0 : middleMs;
            s.recordFrame(d, ms);
            g.record(d, ms);
        }
        ASSERT_GE(firstRay, 0) << "the guard measures ray casting";
        if (middleMs > 25.0) {
            EXPECT_LE(firstRay, 6);
            EXPECT_GE(splitRay, 99) << "of the last 100 choices, the split's own for ray casting";
            EXPECT_EQ(drawnMiddle, 0);
        } else {
            EXPECT_EQ(splitRay, 0);
            EXPECT_GE(drawnMiddle, 95) << "the cheaper middle is kept (ray casting measured now and then)";
            EXPECT_EQ(g.trips(), 0);
        }
    }
}

}  // namespace
}  // namespace vista

namespace vista {
namespace {

// The split and its guard with the near default as a reference, on a synthetic machine (no
// timing): the near default (123 m) costs 20 ms, any other middle distance `middleMs`, ray
// casting 60 ms; the model (rays dear) prices the largest distances cheapest and the split never
// tries another kind on its own (no end tries, no exploration). The guard measures the near
// default; its frames are frames of that kind for the split and correct its price: where the
// other middle distances are dearer (30 ms), the split itself chooses the near default within a
// few frames of the guard's first measurement; where they are cheaper (15 ms) they are kept.
TEST(Split, NearDefaultFramesTheGuardDrewCorrectTheSplitsPrice) {
    ProbeScene ps = probeScene(12);
    const std::vector<SplitObject> objs = squareObjects();
    const Camera c = smallCamera(glm::dvec3(0, -350, 1.7));
    constexpr double kFixed = 123.0;
    for (const double middleMs : {30.0, 15.0}) {
        AdaptiveSplitOptions o = measuredOnly();
        o.endTryEvery = 0;
        o.everythingNear = false;
        o.fixedDistance = kFixed;
        AdaptiveSplit s(objs, ps.rays.get(), o);
        for (int i = 0; i < 10; ++i) {
            const double tris = 20000 + 4000 * i;
            s.record(uint64_t(tris), 1.0 + 1e-5 * tris, 5000, 5000 * 3e-2);
        }
        SplitGuardOptions go;
        go.fixedDistance = kFixed;
        SplitGuard g(go);
        int firstFixed = -1, splitFixed = 0, drawnMiddle = 0, splitMiddle = 0;
        for (int f = 0; f < 200; ++f) {
            const double chosen = g.holding() ? s.current() : s.choose(c, -1);
            const double d = g.filter(chosen);
            if (d == kFixed && firstFixed < 0) firstFixed = f;
            if (f >= 100) {
                splitFixed += chosen == kFixed;
                splitMiddle += chosen > 0 && chosen != kFixed;
                drawnMiddle += d > 0 && d != kFixed;
            }
            const double ms = d <= 0 ? 60.0 : d == kFixed ? 20.0 : middleMs;
            s.recordFrame(d, ms);
            g.record(d, ms);
        }
        ASSERT_GE(firstFixed, 0) << "the guard measures the near default";
        if (middleMs > 20.0) {
            EXPECT_LE(firstFixed, 6);
            EXPECT_GE(splitFixed, 99) << "of the last 100 choices, the split's own for the near default";
            EXPECT_EQ(drawnMiddle, 0);
        } else {
            EXPECT_GE(splitMiddle, 99) << "the cheaper middle is kept";
            EXPECT_GE(drawnMiddle, 90) << "the near default measured now and then";
            EXPECT_EQ(g.trips(), 0);
        }
    }
}

}  // namespace
}  // namespace vista

namespace vista {
namespace {

// Hysteresis: a change of the near distance costs the frames after it what no price holds (the
// band between the two distances is in neither the cache nor the last frame's traced pixels), so
// the split keeps its last choice unless another is priced lower by more than switchMargin. A
// walk of 200 frames, 0.5 m a frame, whose frames cost the same wherever the split puts the near
// distance (10 ms, spread by +-4 % as on a busy machine): without the margin the choice follows
// every crossing of two candidates' prices and every wobble of the correction; with it the split
// changes its distance far less often.
TEST(Split, TheLastChoiceIsKeptWithinTheSwitchMargin) {
    ProbeScene ps = probeScene(12);
    const std::vector<SplitObject> objs = squareObjects();
    int changes[2] = {0, 0};
    for (const int withMargin : {0, 1}) {
        AdaptiveSplitOptions o = measuredOnly();
        o.rayCastOnly = o.everythingNear = false;
        o.endTryEvery = 0;
        if (!withMargin) o.switchMargin = 0;
        AdaptiveSplit s(objs, ps.rays.get(), o);
        for (int i = 0; i < 10; ++i) {
            const double tris = 20000 + 4000 * i;
            s.record(uint64_t(tris), 1.0 + 1e-5 * tris, 5000, 5000 * 1e-3);
        }
        double last = -1;
        for (int f = 0; f < 200; ++f) {
            const double d = s.choose(smallCamera(glm::dvec3(0, -350 + 0.5 * f, 1.7)), -1);
            if (f > 0 && d != last) ++changes[withMargin];
            last = d;
            s.recordFrame(d, 10.0 * (1.0 + 0.04 * std::sin(2.3 * f)));
        }
    }
    EXPECT_GE(changes[0], 4) << "without the margin the choice changes at every crossing";
    EXPECT_LE(2 * changes[1], changes[0]) << "the margin keeps the last choice";
}

}  // namespace
}  // namespace vista
