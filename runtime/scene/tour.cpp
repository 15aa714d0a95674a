#include "runtime/scene/tour.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <utility>

namespace vista {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}

Tour::Tour(std::vector<glm::dvec2> positions, std::vector<std::vector<Arc>> arcs)
    : _pos(std::move(positions)), _arcs(std::move(arcs)) {
    _reverse.resize(_arcs.size());
    for (size_t u = 0; u < _arcs.size(); ++u) {
        if (!_arcs[u].empty()) _withArcs.push_back(uint32_t(u));
        for (const Arc& a : _arcs[u]) _reverse[a.to].push_back({uint32_t(u), a.cost});
    }
}

void Tour::distancesTo(uint32_t goal) {
    _dist.assign(_arcs.size(), kInf);
    using Item = std::pair<double, uint32_t>;
    std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
    _dist[goal] = 0;
    open.push({0.0, goal});
    while (!open.empty()) {
        const auto [d, v] = open.top();
        open.pop();
        if (d > _dist[v]) continue;
        for (const Arc& a : _reverse[v]) {
            const double nd = d + a.cost;
            if (nd < _dist[a.to]) {
                _dist[a.to] = nd;
                open.push({nd, a.to});
            }
        }
    }
}

void Tour::drawGoal(uint32_t from, Rng& rng) {
    if (_withArcs.empty()) return;
    if (!_haveGoal) _recent.push_back(from);  // the start counts as where the route has been
    // Spread: the candidate farthest from the current node and the recent goals.
    auto spread = [&](uint32_t c) {
        double d = glm::length(_pos[c] - _pos[from]);
        for (uint32_t g : _recent) d = std::min(d, glm::length(_pos[c] - _pos[g]));
        return d;
    };
    auto draw = [&] { return _withArcs[size_t(rng.range(0, int64_t(_withArcs.size()) - 1))]; };
    uint32_t best = draw();
    double bestSpread = spread(best);
    for (int i = 1; i < kGoalCandidates; ++i) {
        const uint32_t c = draw();
        const double s = spread(c);
        if (s > bestSpread) best = c, bestSpread = s;
    }
    _goal = best;
    distancesTo(_goal);
    for (int i = 0; i < kGoalCandidates && !(_dist[from] < kInf); ++i) {
        _goal = draw();
        distancesTo(_goal);
    }
    _haveGoal = true;
    ++_legs;
    _recent.push_back(_goal);
    if (_recent.size() > size_t(kGoalMemory)) _recent.erase(_recent.begin());
}

size_t Tour::step(uint32_t u, const std::vector<size_t>& allowed, Rng& rng) {
    if (!_haveGoal || u == _goal) drawGoal(u, rng);
    size_t best = allowed.front();
    double bestCost = kInf;
    for (size_t i : allowed) {
        const Arc& a = _arcs[u][i];
        const double c = a.cost + _dist[a.to];
        if (c < bestCost) best = i, bestCost = c;
    }
    return best;
}

size_t Tour::step(uint32_t u, Rng& rng) {
    _every.resize(_arcs[u].size());
    for (size_t i = 0; i < _every.size(); ++i) _every[i] = i;
    return step(u, _every, rng);
}

}  // namespace vista
