// The split's guard against a middle choice dearer than an end point (split_guard.h).
#include "runtime/engine/split_guard.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vista {

SplitGuard::SplitGuard(const SplitGuardOptions& o) : _o(o) {}

double SplitGuard::median(std::vector<double> v) {
    if (v.empty()) return -1.0;
    const auto mid = v.begin() + long(v.size() / 2);
    std::nth_element(v.begin(), mid, v.end());
    return *mid;
}

double SplitGuard::endMs(int end) const {
    if (end < 0 || end > 1 || _end[end].empty() || _frame - _endFrame[end] > _o.endMaxAge) return -1.0;
    return median(_end[end]);
}

double SplitGuard::middleMs() const { return median(_middle); }

double SplitGuard::filter(double chosen) {
    const int frame = _frame++;
    _overridden = 0;
    _last = chosen;
    if (_o.strikes <= 0) return chosen;
    if (_holdLeft > 0) {
        --_holdLeft;
        const bool ok = _holdEnd == 0 ? _o.rayCasting : _o.everything;
        if (ok) {
            _overridden = 1;
            _last = _holdEnd == 0 ? 0.0 : std::numeric_limits<double>::infinity();
            return _last;
        }
    }
    const bool middle = std::isfinite(chosen) && chosen > 0;
    // Ray casting's yardstick: measured while there is none, and again while the middle is close
    // enough to it that one frame's noise could decide (see the header).
    const double rayCost = endMs(0), middleCost = middleMs();
    const int every = rayCost < 0 ? _o.measureEvery
                      : middleCost >= 0 && middleCost >= _o.doubt * rayCost
                          ? _o.remeasureEvery * int(std::max<size_t>(1, _end[0].size()))
                          : 0;
    if (middle && _o.rayCasting && every > 0 && frame - _lastMeasure >= every && int(_middle.size()) >= _o.strikes) {
        _lastMeasure = frame;
        _overridden = 2;
        _last = 0.0;
        return 0.0;
    }
    return chosen;
}

void SplitGuard::record(double nearD, double frameMs) {
    if (!(frameMs >= 0) || std::isnan(nearD) || nearD != _last) return;
    const int frame = _frame - 1;
    // The first frame of the middle and of everything pays one-time costs (the first draw of the
    // chunks, the far field's first frame): not counted. Ray casting draws nothing: counted.
    const int kind = nearD <= 0 ? 0 : std::isinf(nearD) ? 2 : 1;
    if (kind != 0 && !_seen[kind]) {
        _seen[kind] = true;
        return;
    }
    if (nearD <= 0 || std::isinf(nearD)) {
        const int end = nearD <= 0 ? 0 : 1;
        _end[end].push_back(frameMs);
        if (int(_end[end].size()) > std::max(1, _o.endWindow)) _end[end].erase(_end[end].begin());
        _endFrame[end] = frame;
        if (end == 0) _lastMeasure = frame;
        return;
    }
    if (_o.strikes <= 0) return;
    _middle.push_back(frameMs);
    if (int(_middle.size()) > _o.strikes) _middle.erase(_middle.begin());
    if (++_middleSinceTrip < _o.strikes) return;
    // The cheaper comparable end point.
    int end = -1;
    double endCost = 0;
    for (int e = 0; e < 2; ++e) {
        const double c = endMs(e);
        if (c < 0 || !(e == 0 ? _o.rayCasting : _o.everything)) continue;
        if (end < 0 || c < endCost) {
            end = e;
            endCost = c;
        }
    }
    if (end < 0) return;
    if (middleMs() > (1.0 + _o.margin) * endCost) {
        const int hold = std::max(1, _nextHold > 0 ? _nextHold : _o.hold);
        _holdLeft = hold;
        _holdEnd = end;
        _nextHold = std::min(2 * hold, std::max(hold, _o.maxHold));
        _middleSinceTrip = 0;
        ++_trips;
    } else {
        _nextHold = 0;  // the middle held its own: the next trip holds for `hold` again
    }
}

}  // namespace vista
