// Tour: each step follows a shortest path to the goal (checked against an
// independent breadth-first search), goals are reached and redrawn, and a long
// drive through a generated city keeps going instead of circling its start.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <map>
#include <set>

#include "citygen/params.h"
#include "citygen/streets.h"
#include "foundation/units.h"
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

namespace {

// A street grid of n x n nodes `spacing` metres apart (two-way streets 8 m wide).
StreetGraph streetGrid(int n, double spacing) {
    StreetGraph g;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) g.nodes.push_back({i * spacing, j * spacing});
    auto add = [&](int a, int b) {
        StreetEdge e;
        e.a = uint32_t(a);
        e.b = uint32_t(b);
        e.width = 8.0f;
        g.edges.push_back(e);
    };
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            if (i + 1 < n) add(j * n + i, j * n + i + 1);
            if (j + 1 < n) add(j * n + i, (j + 1) * n + i);
        }
    return g;
}

// How often each street edge was driven: a pass is a run of consecutive
// samples in the middle fifth of the same edge (its nearest edge, the
// projection between 40 % and 60 % of its length), so that the samples near
// junctions, nearest to a crossing street, count for neither.
std::vector<int> edgePasses(const StreetGraph& g, const Path& path) {
    std::vector<int> passes(g.edges.size(), 0);
    int last = -1;
    for (const auto& s : path.samples) {
        const glm::dvec2 p(s.position);
        int best = -1;
        double bestD = 1e300, bestT = 0;
        for (size_t k = 0; k < g.edges.size(); ++k) {
            const glm::dvec2 a = g.nodes[g.edges[k].a], b = g.nodes[g.edges[k].b];
            const double t = std::clamp(glm::dot(p - a, b - a) / glm::dot(b - a, b - a), 0.0, 1.0);
            const double d = glm::length(p - (a + t * (b - a)));
            if (d < bestD) bestD = d, best = int(k), bestT = t;
        }
        const int mid = bestT >= 0.4 && bestT <= 0.6 ? best : -1;
        if (mid >= 0 && mid != last) ++passes[size_t(mid)];
        if (mid >= 0 || bestT < 0.3 || bestT > 0.7) last = mid;
    }
    return passes;
}

}  // namespace

// On a large grid (8 km a side), a long car drive by tour keeps going: it
// gets far from its start compared with the distance it drives, and drives
// few street edges twice; the same seed gives the same bytes; the speed and
// yaw-rate limits hold; the car drives its lanes (LaneRoute, lane positions).
TEST(Tour, LongDriveOnALargeGridKeepsGoingWithinTheLimits) {
    const StreetGraph g = streetGrid(41, 200.0);
    CityParams p;
    p.size_m = 8000;
    p.hills_amplitude_m = 0.0;
    PathOptions o;
    o.seed = 7;
    o.kind = PathKind::Car;
    o.duration = 1200;
    o.dt = 0.5;
    o.route = RouteStyle::Tour;
    auto a = generatePath(g, p, o), b = generatePath(g, p, o);
    ASSERT_TRUE(a.isOk()) << a.status().message();
    ASSERT_TRUE(b.isOk());
    ASSERT_EQ(a->samples.size(), b->samples.size());
    for (size_t i = 0; i < a->samples.size(); ++i) {
        ASSERT_EQ(a->samples[i].position, b->samples[i].position) << i;
        ASSERT_EQ(a->samples[i].heading, b->samples[i].heading) << i;
    }
    ASSERT_EQ(a->lanes.size(), a->samples.size()) << "the car does not drive its lanes";

    double driven = 0, reach = 0;
    const glm::dvec2 start(a->samples[0].position);
    for (size_t i = 1; i < a->samples.size(); ++i) {
        const auto &s = a->samples[i], &q = a->samples[i - 1];
        const double step = glm::length(glm::dvec2(s.position - q.position));
        EXPECT_LE(step / o.dt, o.maxSpeed + 1e-9) << i;
        EXPECT_LE(std::abs(std::remainder(s.heading - q.heading, 2 * kPi)), o.maxYawRate * o.dt + 1e-9) << i;
        driven += step;
        reach = std::max(reach, glm::length(glm::dvec2(s.position) - start));
    }
    const std::vector<int> passes = edgePasses(g, *a);
    int once = 0, twice = 0;
    for (int n : passes) once += n >= 1, twice += n >= 2;
    const double repeated = double(twice) / double(std::max(once, 1));
    std::printf(
        "tour on an 8 km grid: %.0f m driven, reach %.0f m (%.2f of the distance), %d edges driven, "
        "%.3f of them more than once\n",
        driven, reach, reach / driven, once, repeated);
    // 20 minutes drive more than 10 km; goals far apart take the car most of
    // the way across the city.
    EXPECT_GT(driven, 10000.0);
    EXPECT_GE(reach, 0.3 * std::min(driven, p.size_m));
    EXPECT_GT(once, 50);
    EXPECT_LT(repeated, 0.1);
}
