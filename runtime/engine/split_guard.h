// SplitGuard: keeps the near/far split (adaptive_split.h) from a middle choice
// that costs more than a reference it can compare with: an end point, or the
// near default that `hybrid-fixed` draws.
//
// The split prices its choices from a cost model corrected by measured
// frames; where the model is wrong about how the cost changes with the near
// distance (on fly-overs, far rays that do not fall with the near distance
// as the probe predicts; on a CPU rasteriser, a raster that costs by the
// fragment more than by the triangle), it can keep a middle distance that
// costs more than ray casting, drawing everything, or the near default. The
// guard looks at measured frame times only, not at the model (the first
// frame of the middle and of everything is not counted: one-time costs, the
// first draw of the chunks, the far field's first frame):
//   - the references: ray casting (near distance 0, the `raycast` frame),
//     everything (+infinity, the `full` frame) and, when fixedDistance > 0,
//     the fixed distance (the near default, `hybrid-fixed`'s frame). A
//     reference's measured cost is the median of its last `endWindow`
//     frames' ms, while its newest frame is at most `endMaxAge` frames old
//     (older: not comparable). The fixed distance shares the far field's
//     one-time costs with the middle: the first frame of the two is not
//     counted, the other's first frame is;
//   - the middle: any other finite positive near distance. After each middle
//     frame, once `strikes` frames the split chose (middle or fixed) have been
//     recorded since the guard last held a reference, the median of the last
//     `strikes` middle frames is compared with the cheapest comparable
//     reference's cost: above (1 + margin) times it, the guard holds that
//     reference for `hold` frames (filter() returns it whatever the split
//     chose); the hold doubles, up to `maxHold`, each time the guard trips
//     again on the first frames after a hold, and returns to `hold` once a
//     median is within the margin. The margin is the hysteresis: a middle
//     within it of a reference is kept. When the split itself chooses the
//     fixed distance, the median of the last `strikes` fixed frames is
//     compared with the end points in the same way (the fixed distance is
//     then the split's middle choice);
//   - measuring: while the split keeps choosing the middle, ray casting and
//     the fixed distance are measured by the guard: filter() returns one of
//     them for one frame, every `measureEvery` frames while it has no
//     comparable cost (never measured, or older than endMaxAge frames; 0 =
//     never), so that the yardstick exists where the model prices it out of
//     reach. While it has one and the middle is in doubt (the middle's median
//     at least `doubt` times that cost, not yet above the margin), the
//     reference is measured again, remeasureEvery times the frames its cost
//     rests on (at most endWindow) frames after its newest frame (0 = never):
//     one frame, slowed or sped by other work on the machine, must not stand
//     as the yardstick for endMaxAge frames (a frame's time varies by a
//     factor of up to 1.5 on a loaded machine: against one slow ray-casting
//     frame a middle 10 % dearer than ray casting would be kept for endMaxAge
//     frames, a whole bench run), and the reference's cost follows the path.
//     The interval grows as the median gathers frames, so a middle that stays
//     in doubt pays one measuring frame per reference in endWindow *
//     remeasureEvery, each at most 1 / doubt times a middle frame; a middle
//     clearly cheaper (below doubt times the reference) is not interrupted.
//     When both are due, the one measured longer ago goes first (the fixed
//     distance on a tie: its frame costs about a middle frame). Ray casting's
//     cost is bounded by the pixels; everything is measured only when the
//     split chooses or tries it.
// Call filter() once per frame with the split's choice and draw what it
// returns, then record() that frame's whole ms. While holding() the split's
// choice is ignored: a caller may skip making one (filter() then takes any
// value). Deterministic: the same choices and measured times give the same
// results. Not thread-safe. Bad input: a negative or NaN time is ignored.
#pragma once
#include <vector>

namespace vista {

struct SplitGuardOptions {
    int strikes = 3;         // middle frames whose median is compared (0 = no guard: filter() passes the choice)
    double margin = 0.03;    // the middle must cost more than (1 + margin) times the reference
    int hold = 24;           // frames a reference is held for, the first time
    int maxHold = 192;       // ... and at most
    int endWindow = 4;       // a reference's cost: the median of its last endWindow frames
    int endMaxAge = 96;      // ... while its newest frame is at most this many frames old
    int measureEvery = 48;   // ray casting / the fixed distance measured once per this many frames while it has no cost
                             // (0 = never)
    int remeasureEvery = 8;  // ... and again, this many x its frames on, while the middle is in doubt (0 = never)
    double doubt = 0.7;      // in doubt: the middle's median at least this times the reference's cost
    bool rayCasting = true;  // ray casting (0) may be held / measured
    bool everything = true;  // everything (+inf) may be held
    double fixedDistance = 0;  // the near default (metres, `hybrid-fixed`'s choice) as a reference (0 = none)
};

class SplitGuard {
public:
    // References (endMs(), the held one).
    static constexpr int kRayCasting = 0, kEverything = 1, kFixed = 2;

    explicit SplitGuard(const SplitGuardOptions& o = {});
    // The near distance to draw this frame: `chosen` (the split's choice), or a reference the
    // guard holds or measures.
    double filter(double chosen);
    // The next filter() returns a held reference whatever it is given.
    bool holding() const;
    // Why filter() overrode the choice last: 0 = it did not, 1 = holding a reference, 2 = measuring ray casting or
    // the fixed distance (no comparable cost, or the middle within `doubt` of it).
    int overridden() const { return _overridden; }
    // The whole frame's ms of the frame drawn at nearD (what filter() returned last).
    void record(double nearD, double frameMs);
    // A reference's measured cost (kRayCasting, kEverything, kFixed), ms; -1 = not comparable.
    double endMs(int end) const;
    double middleMs() const;  // median of the last `strikes` middle frames; -1 = none
    int trips() const { return _trips; }
    int holdLeft() const { return _holdLeft; }
    int heldEnd() const { return _holdEnd; }  // the reference held last

private:
    static constexpr int kRefs = 3;
    static double median(std::vector<double> v);
    // The reference nearD stands for (kRayCasting, kEverything, kFixed), -1 for the middle.
    int referenceOf(double nearD) const;
    bool allowed(int ref) const;
    double valueOf(int ref) const;
    // The split's choice (middle or fixed) cost `cost` over its last frames: trips to the cheapest
    // comparable reference other than `exclude` when dearer by more than the margin.
    void compare(double cost, int exclude);
    SplitGuardOptions _o;
    std::vector<double> _end[kRefs];                           // per reference: its last frames' ms
    int _endFrame[kRefs] = {-1, -1, -1};                       // per reference: the frame of its newest measurement
    int _lastMeasure[kRefs] = {-1000000, -1000000, -1000000};  // per reference: the frame it last ran
    std::vector<double> _middle;                               // the last middle frames' ms
    int _middleSinceTrip = 0;
    int _frame = 0;  // filter() calls
    int _holdLeft = 0, _nextHold = 0, _holdEnd = 0;
    int _overridden = 0;
    double _last = 0;  // what filter() returned last
    int _trips = 0;
    bool _seen[3] = {false, false, false};  // per kind (0, middle or fixed, everything): its first frame was recorded
};

}  // namespace vista
