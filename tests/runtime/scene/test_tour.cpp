// Tour: each step follows a shortest path to the goal (checked against an
// independent breadth-first search), goals are reached and redrawn, and a long
// drive through a generated city keeps going instead of circling its start.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <deque>
#include <map>
#include <set>

#include "citygen/params.h"
#include "citygen/streets.h"
#include "runtime/scene/paths.h"
#include "runtime/scene/tour.h"

using namespace vista;

namespace {

// A w x h grid, arcs both ways between 4-neighbours, each costing 1; node
// (i, j) = j * w + i at position (i, j). Nodes in `blocked` have no arcs.
struct Grid {
    int w, h;
    std::vector<glm::dvec2> pos;
    std::vector<std::vector<Tour::Arc>> arcs;
    Grid(int w_, int h_, const std::set<int>& blocked = {}) : w(w_), h(h_) {
        arcs.resize(size_t(w * h));
        for (int j = 0; j < h; ++j)
            for (int i = 0; i < w; ++i) {
                pos.push_back({double(i), double(j)});
                const int u = j * w + i;
                if (blocked.count(u)) continue;
                const int di[4] = {1, -1, 0, 0}, dj[4] = {0, 0, 1, -1};
                for (int k = 0; k < 4; ++k) {
                    const int a = i + di[k], b = j + dj[k];
                    if (a < 0 || b < 0 || a >= w || b >= h || blocked.count(b * w + a)) continue;
                    arcs[size_t(u)].push_back({uint32_t(b * w + a), 1.0});
                }
            }
    }
    // Hops from every node to `goal` (breadth-first on the arcs reversed; -1 unreachable).
    std::vector<int> hopsTo(uint32_t goal) const {
        std::vector<int> d(arcs.size(), -1);
        std::vector<std::vector<uint32_t>> rev(arcs.size());
        for (size_t u = 0; u < arcs.size(); ++u)
            for (const auto& a : arcs[u]) rev[a.to].push_back(uint32_t(u));
        std::deque<uint32_t> q{goal};
        d[goal] = 0;
        while (!q.empty()) {
            const uint32_t v = q.front();
            q.pop_front();
            for (uint32_t u : rev[v])
                if (d[u] < 0) d[u] = d[v] + 1, q.push_back(u);
        }
        return d;
    }
};

}  // namespace

TEST(Tour, EveryStepShortensTheWayToTheGoalByOneArc) {
    const Grid grid(12, 9, {14, 15, 16, 40, 52, 64, 76});
    Tour tour(grid.pos, grid.arcs);
    Rng rng(5, 0, Stream::Paths);
    uint32_t u = 0;
    size_t reached = 0;
    for (int step = 0; step < 2000; ++step) {
        const size_t legsBefore = tour.legs();
        const size_t i = tour.step(u, rng);
        const uint32_t v = grid.arcs[u][i].to;
        const std::vector<int> hops = grid.hopsTo(tour.goal());
        ASSERT_GE(hops[u], 0) << "goal " << tour.goal() << " unreachable from " << u;
        if (tour.legs() > legsBefore && step > 0) ++reached;
        // v lies on a shortest path: one hop nearer the goal than u.
        EXPECT_EQ(hops[v], hops[u] - 1) << "step " << step << " from " << u << " to " << v;
        u = v;
    }
    // 2000 unit steps on a 12 x 9 grid cross it many times: many goals reached.
    EXPECT_GE(reached, 50u);
}

TEST(Tour, GoalsSpreadOverTheGraph) {
    const Grid grid(20, 20);
    Tour tour(grid.pos, grid.arcs);
    Rng rng(9, 0, Stream::Paths);
    uint32_t u = 0, lastGoal = 0;
    std::vector<double> legLength;
    for (int step = 0; step < 4000; ++step) {
        const size_t i = tour.step(u, rng);
        if (tour.goal() != lastGoal || step == 0)
            legLength.push_back(glm::length(grid.pos[tour.goal()] - grid.pos[u])), lastGoal = tour.goal();
        u = grid.arcs[u][i].to;
    }
    ASSERT_GE(legLength.size(), 20u);
    // The best of 16 random goals by spread: legs average well over the mean
    // distance between two random points of the square (about 0.52 of its side, 19).
    double mean = 0;
    for (double d : legLength) mean += d;
    mean /= double(legLength.size());
    EXPECT_GT(mean, 0.6 * 19.0);
}

TEST(Tour, OnlyAllowedArcsAreTaken) {
    const Grid grid(5, 5);
    Tour tour(grid.pos, grid.arcs);
    Rng rng(2, 0, Stream::Paths);
    for (uint32_t u = 0; u < 25; ++u) {
        const auto& a = grid.arcs[u];
        for (size_t k = 0; k < a.size(); ++k) EXPECT_EQ(tour.step(u, {k}, rng), k);
    }
}

// A long drive by tour goes far from its start and spends little of its
// length on streets it has driven before; the random walk on the same city
// and seed stays nearer its start.
TEST(Tour, LongCarDriveKeepsGoing) {
    CityParams p;
    p.size_m = 3000;
    p.seed = 4;
    const StreetGraph g = growStreets(p, nullptr);
    auto drive = [&](RouteStyle style) {
        PathOptions o;
        o.seed = 3;
        o.kind = PathKind::Car;
        o.duration = 900;
        o.dt = 0.5;
        o.route = style;
        auto path = generatePath(g, p, o);
        EXPECT_TRUE(path.isOk()) << path.status().message();
        return path.isOk() ? path.value() : Path{};
    };
    auto reach = [](const Path& path) {
        double r = 0;
        for (const auto& s : path.samples)
            r = std::max(r, glm::length(glm::dvec2(s.position) - glm::dvec2(path.samples[0].position)));
        return r;
    };
    // Share of the drive spent in 50 m cells already visited earlier in the
    // drive (a cell counts as revisited after the car has left it for 60 s).
    auto revisited = [](const Path& path) {
        std::map<std::pair<int64_t, int64_t>, double> lastSeen;
        size_t again = 0;
        for (const auto& s : path.samples) {
            const auto key =
                std::make_pair(int64_t(std::floor(s.position.x / 50)), int64_t(std::floor(s.position.y / 50)));
            auto it = lastSeen.find(key);
            if (it != lastSeen.end() && s.t - it->second > 60.0) ++again;
            lastSeen[key] = s.t;
        }
        return double(again) / double(path.samples.size());
    };
    const Path tour = drive(RouteStyle::Tour), wander = drive(RouteStyle::Wander);
    ASSERT_FALSE(tour.samples.empty());
    ASSERT_FALSE(wander.samples.empty());
    // 15 minutes at up to 14 m/s cross the 3 km city several times.
    EXPECT_GT(reach(tour), 0.5 * p.size_m) << "tour reach " << reach(tour);
    EXPECT_LT(revisited(tour), 0.5) << "tour revisits " << revisited(tour);
    std::printf("tour: reach %.0f m, revisited %.2f; wander: reach %.0f m, revisited %.2f\n", reach(tour),
                revisited(tour), reach(wander), revisited(wander));
}
