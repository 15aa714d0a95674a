// Tour: the choice of turns for a route that keeps going. A seeded random walk
// stays near its start (its distance grows with the square root of the
// distance driven), so a long drive keeps coming back through the same
// streets. A tour heads for a goal along the shortest path and, at the goal,
// draws the next one far from where the route has been, so an hour's drive
// crosses the city instead of circling one district.
//
// Contract:
// - The graph is directed: node u has arcs to next(u) with a cost (metres)
//   each; nodes have positions (metres). Nodes without arcs are never goals.
// - Goals: kGoalCandidates nodes with arcs are drawn from the Rng; the goal is
//   the one whose distance to the nearest of the current node and the last
//   kGoalMemory places the route has been (its start, then its goals) is
//   largest (the first drawn on ties), so consecutive legs spread over the
//   city instead of going back and forth. A goal no arc path reaches from the current
//   node is replaced by the next draw (up to kGoalCandidates draws more; then
//   the route takes the first allowed candidate).
// - step(u, allowed): the allowed successor v of u (allowed is a subset of
//   u's arcs given as indices into next(u)) with the least cost(u, v) +
//   distance(v, goal) (the first on ties); reaching the goal draws the next
//   goal first. Distances are Dijkstra's on the reversed graph from the goal,
//   computed once per goal: O(arcs log nodes).
// Deterministic for a given graph and Rng state; not thread-safe.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "foundation/rng.h"

namespace vista {

class Tour {
public:
    struct Arc {
        uint32_t to = 0;
        double cost = 0;  // metres, >= 0
    };
    static constexpr int kGoalCandidates = 16;
    static constexpr int kGoalMemory = 4;

    Tour(std::vector<glm::dvec2> positions, std::vector<std::vector<Arc>> arcs);

    // Index into arcs(u) of the arc to take among `allowed` (indices into
    // arcs(u), not empty).
    size_t step(uint32_t u, const std::vector<size_t>& allowed, Rng& rng);
    // The same with every arc of u allowed (u has arcs).
    size_t step(uint32_t u, Rng& rng);
    // The arc list of u, as given.
    const std::vector<Arc>& arcs(uint32_t u) const { return _arcs[u]; }
    // The current goal (valid after the first step).
    uint32_t goal() const { return _goal; }
    // Goals drawn so far.
    size_t legs() const { return _legs; }

private:
    void drawGoal(uint32_t from, Rng& rng);
    void distancesTo(uint32_t goal);

    std::vector<glm::dvec2> _pos;
    std::vector<std::vector<Arc>> _arcs;
    std::vector<std::vector<Arc>> _reverse;
    std::vector<uint32_t> _withArcs;
    std::vector<double> _dist;  // to the goal; +inf where unreachable
    std::vector<uint32_t> _recent;
    std::vector<size_t> _every;  // scratch: every arc index of a node
    uint32_t _goal = 0;
    bool _haveGoal = false;
    size_t _legs = 0;
};

}  // namespace vista
