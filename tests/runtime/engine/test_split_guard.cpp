// The split's guard (split_guard.h) on synthetic machines: each frame costs what the test's cost
// function says for the near distance drawn; no timing.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <vector>

#include "runtime/engine/split_guard.h"

using namespace vista;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

int kindOf(double d) { return d <= 0 ? 0 : std::isinf(d) ? 2 : 1; }

struct Drawn {
    std::vector<double> drawn;
    int middle(size_t from = 0) const {
        int n = 0;
        for (size_t f = from; f < drawn.size(); ++f) n += kindOf(drawn[f]) == 1;
        return n;
    }
    int switches(size_t from = 0) const {
        int n = 0;
        for (size_t f = from + 1; f < drawn.size(); ++f) n += kindOf(drawn[f]) != kindOf(drawn[f - 1]);
        return n;
    }
    size_t first(int kind, size_t from = 0) const {
        for (size_t f = from; f < drawn.size(); ++f)
            if (kindOf(drawn[f]) == kind) return f;
        return drawn.size();
    }
};

// The split chooses split(f); the guard filters it; the frame costs machine(drawn, f).
Drawn drive(SplitGuard& g, int frames, const std::function<double(int)>& split,
            const std::function<double(double, int)>& machine) {
    Drawn r;
    for (int f = 0; f < frames; ++f) {
        const double d = g.filter(split(f));
        r.drawn.push_back(d);
        g.record(d, machine(d, f));
    }
    return r;
}

}  // namespace

// The split keeps 100 m (its model underprices it); the middle's frames cost 28, 32 and 30 ms in
// turn against 25 ms for ray casting. The guard measures ray casting, abandons the middle within
// `strikes` middle frames of that, and over 400 frames draws the middle on few frames in few
// switches: each return after a hold that trips again doubles the hold (no oscillation).
TEST(SplitGuard, MiddleCostlierThanAnEndPointIsAbandonedWithinAFewFrames) {
    const SplitGuardOptions o;
    SplitGuard g(o);
    auto machine = [](double d, int f) { return d <= 0 ? 25.0 : 28.0 + 2.0 * (f % 3); };
    const Drawn r = drive(
        g, 400, [](int) { return 100.0; }, machine);
    const size_t measured = r.first(0);
    ASSERT_LE(measured, size_t(o.strikes + 1))
        << "ray casting is measured once the middle has `strikes` frames counted";
    ASSERT_GT(g.trips(), 0);
    // The guard's first hold: the first ray-casting frame after the measurement.
    const size_t held = r.first(0, measured + 1);
    EXPECT_LE(r.middle(measured) - r.middle(held), o.strikes + 1) << "middle frames before the fallback";
    EXPECT_LE(r.middle(held), 20) << "the middle returns only briefly after each hold";
    EXPECT_LE(r.switches(held), 2 * g.trips() + 2) << "no oscillation";
    EXPECT_LE(g.trips(), 6) << "holds of 24, 48, 96, 192, 192 frames";
    EXPECT_NEAR(g.endMs(0), 25.0, 1e-12);
}

// A middle cheaper than the end point is kept (ray casting only measured now and then: once when
// clearly cheaper, every `remeasureEvery` frames while within `doubt` of it); one within the
// margin (2 % dearer) is kept too: the margin is the hysteresis. 6 % dearer trips. (Intervals
// between measurements grow with the frames ray casting's cost rests on, up to endWindow.)
TEST(SplitGuard, CheaperMiddleIsKeptAndTheMarginIsTheHysteresis) {
    const SplitGuardOptions o;
    for (const double middle : {15.0, 25.5, 26.5}) {
        SplitGuard g(o);
        const Drawn r = drive(
            g, 200, [](int) { return 100.0; }, [&](double d, int) { return d <= 0 ? 25.0 : middle; });
        if (middle < o.doubt * 25.0) {
            EXPECT_EQ(g.trips(), 0) << middle;
            EXPECT_GE(r.middle(), 195) << middle;
            EXPECT_LE(r.switches(), 8) << middle;
        } else if (middle < 26.0) {
            EXPECT_EQ(g.trips(), 0) << middle;
            // Measured at frame 4, then 8, 16, 24, 32, 32, ... frames later: 8 frames of 200.
            EXPECT_GE(r.middle(), 190) << middle;
            EXPECT_LE(r.middle(), 195) << "measured again while in doubt";
        } else {
            EXPECT_GE(g.trips(), 1) << middle;
            EXPECT_LE(r.middle(), 30) << middle;
        }
    }
}

// Everything as the end point: measured when the split tries it (every 24th frame here) or the
// guard holds it; a middle dearer than it is abandoned; without a recent measurement (older than
// endMaxAge frames) it is no yardstick.
TEST(SplitGuard, EverythingIsAnEndPointWhileItsMeasurementIsRecent) {
    SplitGuardOptions o;
    o.rayCasting = false;
    SplitGuard g(o);
    const Drawn r = drive(
        g, 200, [](int f) { return f % 24 == 5 ? kInf : 100.0; },
        [](double d, int) { return std::isinf(d) ? 30.0 : 40.0; });
    EXPECT_GE(g.trips(), 1);
    EXPECT_EQ(r.first(0), r.drawn.size()) << "ray casting is off";
    EXPECT_LE(r.middle(10), 30);

    // Everything measured once (30 ms, frame 3: its first frame, 2, is not counted); the middle
    // costs 20 ms, then 40 ms from frame 150, when that measurement is 147 frames old: no
    // yardstick, no trip.
    SplitGuard stale(o);
    drive(
        stale, 200, [](int f) { return f == 2 || f == 3 ? kInf : 100.0; },
        [](double d, int f) { return std::isinf(d) ? 30.0
                                     : f < 150     ? 20.0
                                                   : 40.0; });
    EXPECT_EQ(stale.endMs(1), -1.0) << "measured once, 196 frames ago";
    EXPECT_EQ(stale.trips(), 0);
}

// Deterministic: the same choices and measured times give the same frames; strikes 0 turns the
// guard off (the split's choice passes).
TEST(SplitGuard, SameTimesSameFramesAndOffMeansOff) {
    auto split = [](int f) { return f % 17 == 3 ? 0.0 : 60.0 + f % 3; };
    auto machine = [](double d, int f) { return d <= 0 ? 25.0 : 20.0 + 13.0 * ((f * 7) % 5); };
    SplitGuard a, b;
    EXPECT_EQ(drive(a, 300, split, machine).drawn, drive(b, 300, split, machine).drawn);
    EXPECT_GE(a.trips(), 1);
    SplitGuardOptions off;
    off.strikes = 0;
    SplitGuard c(off);
    const Drawn r = drive(c, 100, split, machine);
    for (int f = 0; f < 100; ++f) EXPECT_EQ(r.drawn[size_t(f)], split(f));
    // Bad times are ignored.
    SplitGuard d;
    d.filter(0.0);
    d.record(0.0, std::nan(""));
    d.record(0.0, -1.0);
    EXPECT_EQ(d.endMs(0), -1.0);
}

// One slow ray-casting frame (a burst of other work on the machine: 36 ms against 25 ms) must not
// stand as the yardstick: the middle costs 28 ms, within `doubt` of that frame, so ray casting is
// measured again within `remeasureEvery` frames, and once the median of its frames is the true
// 25 ms the middle is abandoned, within a few frames of that. With remeasuring off (the guard
// measured only while it had no cost) the middle is kept for endMaxAge frames.
TEST(SplitGuard, OneSlowEndPointFrameIsMeasuredAgainWhileTheMiddleIsClose) {
    for (const int remeasure : {8, 0}) {
        SplitGuardOptions o;
        o.remeasureEvery = remeasure;
        SplitGuard g(o);
        int rayFrames = 0;
        const Drawn r = drive(
            g, 90, [](int) { return 100.0; },
            [&](double d, int) { return d <= 0 ? (rayFrames++ == 0 ? 36.0 : 25.0) : 28.0; });
        const size_t firstMeasure = r.first(0);
        ASSERT_LE(firstMeasure, size_t(o.strikes + 1));
        if (remeasure > 0) {
            // Ray casting's median needs two more frames at 25 ms (of 3: 36, 25, 25).
            const size_t third = r.first(0, r.first(0, firstMeasure + 1) + 1);
            ASSERT_LE(third, firstMeasure + 3 * size_t(remeasure) + 2) << "measured again while in doubt";
            EXPECT_GE(g.trips(), 1);
            const size_t held = r.first(0, third + 1);
            EXPECT_LE(held, third + size_t(o.strikes) + 2) << "abandoned within a few frames";
            EXPECT_LE(r.middle(held), 20) << "the middle returns only briefly after each hold";
        } else {
            EXPECT_EQ(g.trips(), 0) << "one 36 ms frame is ray casting's cost for endMaxAge frames";
            EXPECT_GE(r.middle(), 85);
        }
    }
}

namespace {

constexpr double kFixed = 100.0;  // the near default in the tests below

// The near default as a reference: the guard's options with fixedDistance set.
SplitGuardOptions withFixed() {
    SplitGuardOptions o;
    o.fixedDistance = kFixed;
    return o;
}

int count(const Drawn& r, double d, size_t from = 0) {
    int n = 0;
    for (size_t f = from; f < r.drawn.size(); ++f) n += r.drawn[f] == d;
    return n;
}

// Frames drawn at a distance that is neither an end point nor the fixed distance.
int middleOnly(const Drawn& r, size_t from = 0) {
    int n = 0;
    for (size_t f = from; f < r.drawn.size(); ++f) n += kindOf(r.drawn[f]) == 1 && r.drawn[f] != kFixed;
    return n;
}

// Changes of what is drawn (0, the fixed distance, another middle, everything) from frame `from` on.
int changes(const Drawn& r, size_t from = 0) {
    auto cls = [](double d) { return d == kFixed ? 3 : kindOf(d); };
    int n = 0;
    for (size_t f = from + 1; f < r.drawn.size(); ++f) n += cls(r.drawn[f]) != cls(r.drawn[f - 1]);
    return n;
}

}  // namespace

// The split keeps 150 m (its model underprices it) at 22 ms a frame; the near default (100 m)
// costs 20 ms, ray casting 60 ms, everything 80 ms. The guard measures the near default as it
// measures ray casting, abandons the dearer middle within a few frames of that measurement and
// holds the near default, doubling the hold each time the middle trips again: over 400 frames
// the middle is drawn on few frames, in few changes. Ray casting (the middle far below it) is
// measured only when its measurement has expired (endMaxAge).
TEST(SplitGuard, MiddleDearerThanTheNearDefaultIsAbandonedWithinAFewFrames) {
    const SplitGuardOptions o = withFixed();
    SplitGuard g(o);
    auto machine = [](double d, int) { return d <= 0 ? 60.0 : std::isinf(d) ? 80.0 : d == kFixed ? 20.0 : 22.0; };
    const Drawn r = drive(
        g, 400, [](int) { return 150.0; }, machine);
    size_t measured = 0;
    while (measured < r.drawn.size() && r.drawn[measured] != kFixed) ++measured;
    ASSERT_LT(measured, r.drawn.size());
    ASSERT_LT(measured, r.first(0)) << "the near default is the first yardstick measured";
    ASSERT_LE(measured, size_t(o.strikes + 1)) << "measured once the middle has `strikes` frames counted";
    ASSERT_GT(g.trips(), 0);
    EXPECT_EQ(g.heldEnd(), SplitGuard::kFixed);
    EXPECT_NEAR(g.endMs(SplitGuard::kFixed), 20.0, 1e-12);
    // The first hold starts within a few frames of the measurement.
    size_t held = measured + 1;
    while (held < r.drawn.size() && r.drawn[held] != kFixed) ++held;
    EXPECT_LE(held, measured + size_t(o.strikes) + 2) << "the dearer middle is abandoned within a few frames";
    EXPECT_LE(middleOnly(r, held), 20) << "the middle returns only briefly after each hold";
    EXPECT_LE(changes(r, held), 2 * g.trips() + 4) << "no flapping";
    EXPECT_LE(count(r, 0.0), 400 / o.endMaxAge + 1)
        << "ray casting, far dearer than the middle, is measured only as its measurement expires";
}

// A middle cheaper than the near default is kept (18 ms against 20 ms: in doubt, so the near
// default is measured again now and then, on few frames); one within the margin (20.4 ms, 2 %
// dearer) is kept too; 6 % dearer trips. A middle clearly cheaper (12 ms, below `doubt` times
// the near default) is interrupted only when the references' measurements expire (endMaxAge).
TEST(SplitGuard, MiddleCheaperThanTheNearDefaultIsKept) {
    const SplitGuardOptions o = withFixed();
    for (const double middle : {12.0, 18.0, 20.4, 21.2}) {
        SplitGuard g(o);
        const Drawn r = drive(
            g, 200, [](int) { return 150.0; },
            [&](double d, int) {
                return d <= 0 ? 60.0 : std::isinf(d) ? 80.0 : d == kFixed ? 20.0 : middle;
            });
        if (middle < 20.0 * (1 + o.margin)) {
            EXPECT_EQ(g.trips(), 0) << middle;
            EXPECT_GE(middleOnly(r), middle < o.doubt * 20.0 ? 193 : 186) << middle;
            EXPECT_LE(size_t(changes(r)), 2 * (r.drawn.size() - size_t(middleOnly(r)))) << middle;
        } else {
            EXPECT_GE(g.trips(), 1) << middle;
            EXPECT_LE(middleOnly(r), 30) << middle;
        }
    }
}

// Frame times spread by other work on the machine (each frame x 0.85 .. 1.25, a fixed seed):
// a middle 12 % dearer than the near default is still abandoned for most frames, and the
// holds' doubling keeps the draw from flapping; a middle 12 % cheaper is kept on most frames.
TEST(SplitGuard, NoisyFramesDoNotMakeTheSplitFlap) {
    for (const double middle : {22.4, 17.6}) {
        const SplitGuardOptions o = withFixed();
        SplitGuard g(o);
        std::mt19937 rng(7);
        std::uniform_real_distribution<double> noise(0.85, 1.25);
        const Drawn r = drive(
            g, 400, [](int) { return 150.0; },
            [&](double d, int) {
                const double ms = d <= 0 ? 60.0 : std::isinf(d) ? 80.0 : d == kFixed ? 20.0 : middle;
                return ms * noise(rng);
            });
        if (middle > 20.0) {
            EXPECT_LE(middleOnly(r), 60) << "of 400 frames, the dearer middle's";
        } else {
            EXPECT_GE(middleOnly(r), 300) << "of 400 frames, the cheaper middle's";
        }
        EXPECT_LE(changes(r), 40) << middle << ": no flapping";
    }
}

// The split itself chooses the near default: its frames are the split's middle choice, compared
// with the end points (28 ms against ray casting's 25 ms: ray casting is held), never with
// themselves, and the near default is not measured as a yardstick beside them.
TEST(SplitGuard, TheNearDefaultChosenIsComparedWithTheEndPoints) {
    const SplitGuardOptions o = withFixed();
    SplitGuard g(o);
    const Drawn r = drive(
        g, 200, [](int) { return kFixed; }, [](double d, int) { return d <= 0          ? 25.0
                                                                       : std::isinf(d) ? 80.0
                                                                                       : 28.0; });
    ASSERT_LE(r.first(0), size_t(o.endWindow + 2)) << "ray casting measured";
    EXPECT_GE(g.trips(), 1);
    EXPECT_EQ(g.heldEnd(), SplitGuard::kRayCasting);
    EXPECT_LE(count(r, kFixed, 20), 30) << "the dearer near default returns only briefly after each hold";

    // A near default cheaper than the end points is kept, and no other distance is drawn.
    SplitGuard cheap(o);
    const Drawn k = drive(
        cheap, 200, [](int) { return kFixed; },
        [](double d, int) { return d <= 0          ? 60.0
                                   : std::isinf(d) ? 80.0
                                                   : 20.0; });
    EXPECT_EQ(cheap.trips(), 0);
    EXPECT_GE(count(k, kFixed), 196) << "ray casting measured once per endMaxAge frames";
}

// holding() says that the next filter() returns a held reference, whatever the split chose (a
// caller then skips choosing: the split's probe and pricing cost the held frame nothing).
TEST(SplitGuard, HoldingMeansTheChoiceIsIgnored) {
    SplitGuard g(withFixed());
    int held = 0;
    for (int f = 0; f < 200; ++f) {
        const bool holding = g.holding();
        const double d = g.filter(holding ? std::nan("") : 150.0);
        if (holding) {
            ++held;
            EXPECT_EQ(g.overridden(), 1);
            EXPECT_FALSE(std::isnan(d));
        }
        g.record(d, d <= 0 ? 60.0 : std::isinf(d) ? 80.0 : d == kFixed ? 20.0 : 24.0);
    }
    EXPECT_GE(held, 150);
}
