// SplitGuard: keeps the near/far split (adaptive_split.h) from a middle choice
// that costs more than an end point it can compare with.
//
// The split prices its choices from a cost model corrected by measured
// frames; where the model is wrong about how the cost changes with the near
// distance (on fly-overs, far rays that do not fall with the near distance
// as the probe predicts), it can keep a middle distance that costs more than
// ray casting or drawing everything. The guard looks at measured frame times
// only, not at the model (the first frame of the middle and of everything is
// not counted: one-time costs, the first draw of the chunks, the far field's
// first frame):
//   - the end points: ray casting (near distance 0, the `raycast` frame) and
//     everything (+infinity, the `full` frame). An end point's measured cost
//     is the median of its last `endWindow` frames' ms, while its newest
//     frame is at most `endMaxAge` frames old (older: not comparable);
//   - the middle: any finite positive near distance. After each middle
//     frame, once `strikes` middle frames have been recorded since the guard
//     last held an end point, the median of the last `strikes` is compared
//     with the cheaper comparable end point's cost: above (1 + margin) times
//     it, the guard holds that end point for `hold` frames (filter() returns
//     it whatever the split chose); the hold doubles, up to `maxHold`, each
//     time the guard trips again on the first middle frames after a hold, and
//     returns to `hold` once a median is within the margin. The margin is the
//     hysteresis: a middle within it of an end point is kept.
//   - measuring: while the split keeps choosing the middle and ray casting has
//     no comparable cost (never measured, or older than endMaxAge frames),
//     filter() returns 0 for one frame every `measureEvery` frames (0 = never),
//     so that the yardstick exists where the model prices ray casting out of
//     reach. While it has one and the middle is in doubt (its median at least
//     `doubt` times that cost, not yet above the margin), ray casting is
//     measured again, remeasureEvery times the frames its cost rests on (at
//     most endWindow) frames after its newest frame (0 = never): one
//     ray-casting frame, slowed or sped by other work on the machine, must not
//     stand as the yardstick for endMaxAge frames (a frame's time varies by a
//     factor of up to 1.5 on a loaded machine: against one slow frame a middle
//     10 % dearer than ray casting would be kept for endMaxAge frames, a whole
//     bench run), and the end point's cost follows the path. The interval
//     grows as the median gathers frames, so a middle that stays in doubt pays
//     one measuring frame in endWindow * remeasureEvery, each at most
//     1 / doubt times a middle frame; a middle clearly cheaper (below doubt
//     times ray casting, a street view) is not interrupted. Ray casting's cost
//     is bounded by the pixels; everything is measured only when the split
//     chooses or tries it.
// Call filter() once per frame with the split's choice and draw what it
// returns, then record() that frame's whole ms. Deterministic: the same
// choices and measured times give the same results. Not thread-safe. Bad
// input: a negative or NaN time is ignored.
#pragma once
#include <vector>

namespace vista {

struct SplitGuardOptions {
    int strikes = 3;         // middle frames whose median is compared (0 = no guard: filter() passes the choice)
    double margin = 0.03;    // the middle must cost more than (1 + margin) times the end point
    int hold = 24;           // frames an end point is held for, the first time
    int maxHold = 192;       // ... and at most
    int endWindow = 4;       // an end point's cost: the median of its last endWindow frames
    int endMaxAge = 96;      // ... while its newest frame is at most this many frames old
    int measureEvery = 48;   // ray casting measured once per this many frames while it has no cost (0 = never)
    int remeasureEvery = 8;  // ... and again, this many x its frames on, while the middle is in doubt (0 = never)
    double doubt = 0.7;      // in doubt: the middle's median at least this times ray casting's cost
    bool rayCasting = true;  // ray casting (0) may be held / measured
    bool everything = true;  // everything (+inf) may be held
};

class SplitGuard {
public:
    explicit SplitGuard(const SplitGuardOptions& o = {});
    // The near distance to draw this frame: `chosen` (the split's choice), or an end point the
    // guard holds or measures.
    double filter(double chosen);
    // Why filter() overrode the choice last: 0 = it did not, 1 = holding an end point, 2 = measuring ray casting
    // (no comparable cost, or the middle within `doubt` of it).
    int overridden() const { return _overridden; }
    // The whole frame's ms of the frame drawn at nearD (what filter() returned last).
    void record(double nearD, double frameMs);
    // An end point's measured cost (0 = ray casting, 1 = everything), ms; -1 = not comparable.
    double endMs(int end) const;
    double middleMs() const;  // median of the last `strikes` middle frames; -1 = none
    int trips() const { return _trips; }
    int holdLeft() const { return _holdLeft; }

private:
    static double median(std::vector<double> v);
    SplitGuardOptions _o;
    std::vector<double> _end[2];  // per end point: its last frames' ms
    int _endFrame[2] = {-1, -1};  // per end point: the frame of its newest measurement
    std::vector<double> _middle;  // the last middle frames' ms
    int _middleSinceTrip = 0;
    int _frame = 0;  // filter() calls
    int _holdLeft = 0, _nextHold = 0, _holdEnd = 0;
    int _lastMeasure = -1000000;  // the frame of the last ray-casting measurement
    int _overridden = 0;
    double _last = 0;  // what filter() returned last
    int _trips = 0;
    bool _seen[3] = {false, false, false};  // per kind (0, middle, everything): its first frame was recorded
};

}  // namespace vista
