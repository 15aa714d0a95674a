// The split's guard against a middle choice dearer than a reference (split_guard.h).
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

int SplitGuard::referenceOf(double nearD) const {
    if (nearD <= 0) return kRayCasting;
    if (std::isinf(nearD)) return kEverything;
    return _o.fixedDistance > 0 && nearD == _o.fixedDistance ? kFixed : -1;
}

bool SplitGuard::allowed(int ref) const {
    return ref == kRayCasting   ? _o.rayCasting
           : ref == kEverything ? _o.everything
                                : _o.fixedDistance > 0 && std::isfinite(_o.fixedDistance);
}

double SplitGuard::valueOf(int ref) const {
    return ref == kRayCasting ? 0.0 : ref == kEverything ? std::numeric_limits<double>::infinity() : _o.fixedDistance;
}

double SplitGuard::endMs(int end) const {
    if (end < 0 || end >= kRefs || _end[end].empty() || _frame - _endFrame[end] > _o.endMaxAge) return -1.0;
    return median(_end[end]);
}

double SplitGuard::middleMs() const { return median(_middle); }

bool SplitGuard::holding() const { return _o.strikes > 0 && _holdLeft > 0 && allowed(_holdEnd); }

double SplitGuard::filter(double chosen) {
    const int frame = _frame++;
    _overridden = 0;
    _last = chosen;
    if (_o.strikes <= 0) return chosen;
    if (_holdLeft > 0) {
        --_holdLeft;
        if (allowed(_holdEnd)) {
            _overridden = 1;
            _last = valueOf(_holdEnd);
            return _last;
        }
    }
    if (!(std::isfinite(chosen) && chosen > 0)) return chosen;
    // The split's middle choice: a middle distance, or the fixed distance itself (then compared with the end
    // points only). Its cost: the median of its last `strikes` frames.
    const bool atFixed = referenceOf(chosen) == kFixed;
    double chosenCost = middleMs();
    size_t chosenFrames = _middle.size();
    if (atFixed) {
        const size_t n = std::min(_end[kFixed].size(), size_t(_o.strikes));
        chosenCost = median(std::vector<double>(_end[kFixed].end() - long(n), _end[kFixed].end()));
        chosenFrames = n;
    }
    if (int(chosenFrames) < std::min(_o.strikes, atFixed ? std::max(1, _o.endWindow) : _o.strikes)) return chosen;
    // The yardsticks: measured while there is none, and again while the middle is close enough to one that one
    // frame's noise could decide (see the header). Of two due, the one measured longer ago (the fixed distance
    // on a tie).
    int due = -1;
    for (const int ref : {kFixed, kRayCasting}) {
        if (!allowed(ref) || (ref == kFixed && atFixed)) continue;
        const double cost = endMs(ref);
        const int every = cost < 0 ? _o.measureEvery
                          : chosenCost >= 0 && chosenCost >= _o.doubt * cost
                              ? _o.remeasureEvery * int(std::max<size_t>(1, _end[ref].size()))
                              : 0;
        if (every > 0 && frame - _lastMeasure[ref] >= every && (due < 0 || _lastMeasure[ref] < _lastMeasure[due]))
            due = ref;
    }
    if (due < 0) return chosen;
    _lastMeasure[due] = frame;
    _overridden = 2;
    _last = valueOf(due);
    return _last;
}

void SplitGuard::compare(double cost, int exclude) {
    if (++_middleSinceTrip < _o.strikes) return;
    // The cheapest comparable reference.
    int end = -1;
    double endCost = 0;
    for (int e = 0; e < kRefs; ++e) {
        const double c = endMs(e);
        if (e == exclude || c < 0 || !allowed(e)) continue;
        if (end < 0 || c < endCost) {
            end = e;
            endCost = c;
        }
    }
    if (end < 0) return;
    if (cost > (1.0 + _o.margin) * endCost) {
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

void SplitGuard::record(double nearD, double frameMs) {
    if (!(frameMs >= 0) || std::isnan(nearD) || nearD != _last) return;
    const int frame = _frame - 1;
    const int ref = referenceOf(nearD);
    // The first frame of the middle (or the fixed distance: the same far field) and of everything pays
    // one-time costs (the first draw of the chunks, the far field's first frame): not counted. Ray casting
    // draws nothing: counted.
    const int kind = ref == kRayCasting ? 0 : ref == kEverything ? 2 : 1;
    if (kind != 0 && !_seen[kind]) {
        _seen[kind] = true;
        return;
    }
    if (ref >= 0) {
        _end[ref].push_back(frameMs);
        if (int(_end[ref].size()) > std::max(1, _o.endWindow)) _end[ref].erase(_end[ref].begin());
        _endFrame[ref] = frame;
        _lastMeasure[ref] = frame;
        // The fixed distance the split chose is its middle choice: compared with the end points.
        if (ref == kFixed && _overridden == 0 && _o.strikes > 0) {
            const size_t n = std::min(_end[kFixed].size(), size_t(_o.strikes));
            compare(median(std::vector<double>(_end[kFixed].end() - long(n), _end[kFixed].end())), kFixed);
        }
        return;
    }
    if (_o.strikes <= 0) return;
    _middle.push_back(frameMs);
    if (int(_middle.size()) > _o.strikes) _middle.erase(_middle.begin());
    compare(middleMs(), -1);
}

}  // namespace vista
