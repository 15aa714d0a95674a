// Street graph: invariants of growStreets(), planarize() hard cases against a
// brute-force check, determinism, centre stability, JSON / GeoJSON.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <numeric>

#include <nlohmann/json.hpp>

#include "foundation/rng.h"
#include "citygen/streets.h"

using namespace vista;

namespace {

// Brute-force O(n^2) crossing count with plain long-double orientation tests
// (independent of the grid + CGAL code in checkPlanarGraph). Counts pairs of
// edges without a shared node that cross properly (orientations beyond a
// 1e-9 m^2 tolerance) or whose endpoint lies on the other edge (closer than 1e-12 m: below double rounding of the exact
// intersection points, which may leave a node 1e-14 m beside an edge).
double segDist(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b) {
    glm::dvec2 d = b - a;
    double t = glm::dot(p - a, d) / glm::dot(d, d);
    t = std::clamp(t, 0.0, 1.0);
    return glm::length(p - (a + t * d));
}
long double orient(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
    return (long double)(b.x - a.x) * (c.y - a.y) - (long double)(b.y - a.y) * (c.x - a.x);
}
int bruteForceConflicts(const StreetGraph& g) {
    int bad = 0;
    for (size_t i = 0; i < g.edges.size(); ++i)
        for (size_t j = i + 1; j < g.edges.size(); ++j) {
            const auto& e = g.edges[i];
            const auto& f = g.edges[j];
            if (e.a == f.a || e.a == f.b || e.b == f.a || e.b == f.b) continue;
            glm::dvec2 a = g.nodes[e.a], b = g.nodes[e.b], c = g.nodes[f.a], d = g.nodes[f.b];
            long double o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
            const long double t = 1e-9L;  // orientation noise of this inexact test is ~1e-13 m^2
            bool cross = ((o1 > t && o2 < -t) || (o1 < -t && o2 > t)) && ((o3 > t && o4 < -t) || (o3 < -t && o4 > t));
            double near = std::min({segDist(a, c, d), segDist(b, c, d), segDist(c, a, b), segDist(d, a, b)});
            if (cross || near < 1e-12) bad++;
        }
    return bad;
}

size_t largestComponent(const StreetGraph& g) {
    std::vector<uint32_t> p(g.nodes.size());
    std::iota(p.begin(), p.end(), 0u);
    std::function<uint32_t(uint32_t)> find = [&](uint32_t x) { return p[x] == x ? x : p[x] = find(p[x]); };
    for (const auto& e : g.edges) p[find(e.a)] = find(e.b);
    std::map<uint32_t, size_t> size;
    size_t best = 0;
    for (uint32_t v = 0; v < g.nodes.size(); ++v) best = std::max(best, ++size[find(v)]);
    return best;
}

CityParams cityParams(uint64_t seed, double size) {
    CityParams p;
    p.seed = seed;
    p.size_m = size;
    return p;
}

}  // namespace

TEST(StreetGraph, ClassDefaults) {
    EXPECT_STREQ(roadClassName(RoadClass::Highway), "highway");
    EXPECT_GT(roadWidth(RoadClass::Highway), roadWidth(RoadClass::Arterial));
    EXPECT_GT(roadWidth(RoadClass::Arterial), roadWidth(RoadClass::Local));
    EXPECT_GE(roadLanes(RoadClass::Highway), 4);
    EXPECT_EQ(roadLanes(RoadClass::Local), 2);
}

TEST(StreetGraph, CheckDetectsViolations) {
    StreetGraph g;
    g.nodes = {{0, 0}, {100, 0}, {50, -50}, {50, 50}};
    g.edges = {{0, 1, RoadClass::Local, 7.5f, 2}, {2, 3, RoadClass::Local, 7.5f, 2}};
    EXPECT_FALSE(checkPlanarGraph(g, 1.0).isOk());  // crossing without shared node
    g.edges.pop_back();
    EXPECT_TRUE(checkPlanarGraph(g, 1.0).isOk());
    EXPECT_FALSE(checkPlanarGraph(g, 200.0).isOk());  // too short
    g.edges.push_back({1, 0, RoadClass::Local, 7.5f, 2});
    EXPECT_FALSE(checkPlanarGraph(g, 1.0).isOk());  // duplicate
    g.edges.pop_back();
    g.nodes.push_back({50, 0});  // T-junction without shared node
    g.edges.push_back({4, 3, RoadClass::Local, 7.5f, 2});
    EXPECT_FALSE(checkPlanarGraph(g, 1.0).isOk());
    g.edges.pop_back();
    g.edges.push_back({0, 4, RoadClass::Local, 7.5f, 2});  // collinear overlap at shared node
    EXPECT_FALSE(checkPlanarGraph(g, 1.0).isOk());
    g.edges.pop_back();
    g.nodes[3].x = std::nan("");
    EXPECT_FALSE(checkPlanarGraph(g, 1.0).isOk());
}

TEST(GrowStreets, InvariantsOverSeedsAndSizes) {
    for (uint64_t seed : {1ull, 7ull, 12345ull})
        for (double size : {500.0, 2000.0, 3500.0}) {
            CityParams p = cityParams(seed, size);
            StreetGraph g = growStreets(p, nullptr);
            SCOPED_TRACE("seed " + std::to_string(seed) + " size " + std::to_string(size));
            Status s = checkPlanarGraph(g, p.min_segment_m);
            EXPECT_TRUE(s.isOk()) << s.message();
            ASSERT_GT(g.edges.size(), 10u);
            for (const auto& n : g.nodes) {
                EXPECT_LE(std::abs(n.x), 0.5 * size + 1e-9);
                EXPECT_LE(std::abs(n.y), 0.5 * size + 1e-9);
            }
            EXPECT_GE(double(largestComponent(g)), 0.9 * double(g.nodes.size()));
        }
}

TEST(GrowStreets, DefaultDensityAndHierarchy) {
    CityParams p;  // size 2000
    StreetGraph g = growStreets(p, nullptr);
    int cnt[3] = {0, 0, 0};
    for (const auto& e : g.edges) cnt[int(e.cls)]++;
    EXPECT_GT(cnt[0], 0);
    EXPECT_GT(cnt[1], 0);
    EXPECT_GT(cnt[2], cnt[1]);
    EXPECT_GE(g.edges.size(), 800u);
    EXPECT_LE(g.edges.size(), 5000u);
}

TEST(GrowStreets, Deterministic) {
    CityParams p = cityParams(99, 1500);
    EXPECT_EQ(streetGraphToJson(growStreets(p, nullptr)), streetGraphToJson(growStreets(p, nullptr)));
}

TEST(GrowStreets, CentreStableWhenSizeGrows) {
    // Edges of the 1000 m city fully inside the central 800 m square: the share
    // that reappear (both ends within 1 m) in the 2000 m city of the same seed.
    for (uint64_t seed : {1ull, 5ull}) {
        StreetGraph small = growStreets(cityParams(seed, 1000), nullptr);
        StreetGraph big = growStreets(cityParams(seed, 2000), nullptr);
        auto key = [](glm::dvec2 p) { return std::make_pair(std::llround(p.x), std::llround(p.y)); };
        std::map<std::pair<long long, long long>, std::vector<glm::dvec2>> bigNodes;
        for (const auto& n : big.nodes) bigNodes[key(n)].push_back(n);
        auto findNode = [&](glm::dvec2 p) {
            for (int dx = -1; dx <= 1; ++dx)
                for (int dy = -1; dy <= 1; ++dy) {
                    auto it = bigNodes.find({std::llround(p.x) + dx, std::llround(p.y) + dy});
                    if (it == bigNodes.end()) continue;
                    for (auto q : it->second)
                        if (glm::length(q - p) < 1.0) return q;
                }
            return glm::dvec2(1e18);
        };
        std::map<std::pair<std::pair<long long, long long>, std::pair<long long, long long>>, int> bigEdges;
        for (const auto& e : big.edges) {
            auto a = key(big.nodes[e.a]), b = key(big.nodes[e.b]);
            bigEdges[{std::min(a, b), std::max(a, b)}] = 1;
        }
        int inside = 0, matched = 0;
        for (const auto& e : small.edges) {
            glm::dvec2 a = small.nodes[e.a], b = small.nodes[e.b];
            if (std::max({std::abs(a.x), std::abs(a.y), std::abs(b.x), std::abs(b.y)}) > 400) continue;
            inside++;
            glm::dvec2 qa = findNode(a), qb = findNode(b);
            if (qa.x > 1e17 || qb.x > 1e17) continue;
            auto ka = key(qa), kb = key(qb);
            if (bigEdges.count({std::min(ka, kb), std::max(ka, kb)})) matched++;
        }
        ASSERT_GT(inside, 50);
        EXPECT_GE(double(matched), 0.85 * inside) << "seed " << seed << ": " << matched << " of " << inside;
    }
}

TEST(Planarize, RandomSoupsMatchBruteForce) {
    for (uint64_t trial = 0; trial < 12; ++trial) {
        Rng rng(42, trial, Stream::Streets);
        std::vector<RawSegment> segs;
        for (int k = 0; k < 60; ++k) {
            glm::dvec2 a(rng.uniform(-200, 200), rng.uniform(-200, 200));
            glm::dvec2 b(rng.uniform(-200, 200), rng.uniform(-200, 200));
            segs.push_back({a, b, RoadClass(uint8_t(rng.range(0, 2)))});
            int kind = int(rng.range(0, 5));
            if (kind == 0)
                segs.push_back({a + 0.3 * (b - a), b + 0.4 * (b - a), RoadClass::Local});  // collinear overlap
            if (kind == 1)
                segs.push_back({a + glm::dvec2(1e-3, -1e-3), b + glm::dvec2(rng.uniform(-5, 5), 3), RoadClass::Local});
            if (kind == 2) {  // tiny-angle crossing (~0.5 degrees) through the midpoint
                glm::dvec2 m = 0.5 * (a + b), d = b - a;
                double ang = 0.5 * 3.14159265358979 / 180.0;
                glm::dvec2 r(d.x * std::cos(ang) - d.y * std::sin(ang), d.x * std::sin(ang) + d.y * std::cos(ang));
                segs.push_back({m - 0.5 * r, m + 0.5 * r, RoadClass::Arterial});
            }
            if (kind == 3) segs.push_back({a, a, RoadClass::Local});    // zero length
            if (kind == 4) segs.push_back({b, a, RoadClass::Highway});  // exact duplicate reversed
        }
        const double snap = trial % 3 == 0 ? 0.0 : 2.0, minSeg = trial % 2 ? 1.0 : 5.0;
        StreetGraph g = planarize(segs, snap, minSeg);
        SCOPED_TRACE("trial " + std::to_string(trial));
        Status s = checkPlanarGraph(g, minSeg);
        EXPECT_TRUE(s.isOk()) << s.message();
        EXPECT_EQ(bruteForceConflicts(g), 0);
        EXPECT_GT(g.edges.size(), 60u);  // split at crossings, not emptied
        for (const auto& n : g.nodes) EXPECT_TRUE(std::isfinite(n.x) && std::isfinite(n.y));
        // The input soup itself does have crossings (the check is not vacuous).
        StreetGraph raw;
        for (const auto& sg : segs) {
            if (sg.a == sg.b) continue;
            raw.nodes.push_back(sg.a);
            raw.nodes.push_back(sg.b);
            raw.edges.push_back({uint32_t(raw.nodes.size() - 2), uint32_t(raw.nodes.size() - 1), sg.cls, 7.5f, 2});
        }
        EXPECT_GT(bruteForceConflicts(raw), 0);
    }
}

TEST(Planarize, CrossingSplitsAndHighestClassWins) {
    std::vector<RawSegment> segs = {
        {{-100, 0}, {100, 0}, RoadClass::Local},
        {{0, -100}, {0, 100}, RoadClass::Local},
        {{-50, 0}, {50, 0}, RoadClass::Highway},  // overlaps the first
        {{1e-7, 1e-7}, {1e-7, 1e-7}, RoadClass::Local},
    };
    StreetGraph g = planarize(segs, 1.0, 5.0);
    ASSERT_TRUE(checkPlanarGraph(g, 5.0).isOk());
    // Expected: centre node of degree 4; horizontal pieces (-100,-50),(-50,0),(0,50),(50,100); vertical 2.
    EXPECT_EQ(g.edges.size(), 6u);
    int highway = 0;
    for (const auto& e : g.edges) highway += e.cls == RoadClass::Highway;
    EXPECT_EQ(highway, 2);
}

// A dual carriageway: two chains 8 m apart (closer than the snap radius) joined by a 8 m
// cross street (shorter than the minimum segment). Without carriageways they snap into one
// line; as two carriageways every node stays, the connector stays, and each output edge
// names the carriageway it came from (the connector none).
TEST(Planarize, CarriagewaysStayApart) {
    auto segments = [](uint32_t north, uint32_t south) {
        std::vector<RawSegment> s;
        for (int k = 0; k < 4; ++k) {
            s.push_back({{-150.0 + 100 * k, 4}, {-50.0 + 100 * k, 4}, RoadClass::Arterial, north});
            s.push_back({{-50.0 + 100 * k, -4}, {-150.0 + 100 * k, -4}, RoadClass::Arterial, south});
        }
        s.push_back({{50, -4}, {50, 4}, RoadClass::Local, 0});
        return s;
    };
    const StreetGraph merged = planarize(segments(0, 0), 14.0, 12.0);
    EXPECT_TRUE(checkPlanarGraph(merged, 12.0).isOk()) << checkPlanarGraph(merged, 12.0).message();
    EXPECT_LE(merged.edges.size(), 4u);

    std::vector<uint32_t> cw;
    const StreetGraph g = planarize(segments(1, 2), 14.0, 12.0, &cw);
    EXPECT_TRUE(checkPlanarGraph(g, kCarriagewayMerge_m).isOk()) << checkPlanarGraph(g, kCarriagewayMerge_m).message();
    ASSERT_EQ(cw.size(), g.edges.size());
    EXPECT_EQ(g.nodes.size(), 10u);
    int north = 0, south = 0, connector = 0;
    for (size_t e = 0; e < g.edges.size(); ++e) {
        const glm::dvec2 a = g.nodes[g.edges[e].a], b = g.nodes[g.edges[e].b];
        if (std::abs(a.y - 4) < 1e-9 && std::abs(b.y - 4) < 1e-9) {
            ++north;
            EXPECT_EQ(cw[e], 1u);
        } else if (std::abs(a.y + 4) < 1e-9 && std::abs(b.y + 4) < 1e-9) {
            ++south;
            EXPECT_EQ(cw[e], 2u);
        } else {
            ++connector;
            EXPECT_EQ(cw[e], 0u);
            EXPECT_NEAR(g.edgeLength(e), 8.0, 1e-9);
        }
    }
    EXPECT_EQ(north, 4);
    EXPECT_EQ(south, 4);
    EXPECT_EQ(connector, 1);

    // One carriageway and free segments: its nodes snap as before.
    std::vector<uint32_t> one;
    const StreetGraph h = planarize(segments(1, 0), 14.0, 12.0, &one);
    EXPECT_LE(h.edges.size(), 4u);
}

TEST(Planarize, NearCoincidentAndDegenerateInput) {
    std::vector<RawSegment> segs;
    for (int k = 0; k < 20; ++k) {
        double e = k * 1e-4;  // near-coincident fan of almost-equal segments
        segs.push_back({{e, 0}, {100 + e, e}, RoadClass::Local});
        segs.push_back({{50, -50 + e}, {50 - e, 50}, RoadClass::Local});
    }
    segs.push_back({{std::nan(""), 0}, {1, 1}, RoadClass::Local});
    segs.push_back({{0, 0}, {INFINITY, 1}, RoadClass::Local});
    StreetGraph g = planarize(segs, 0.5, 2.0);
    Status s = checkPlanarGraph(g, 2.0);
    EXPECT_TRUE(s.isOk()) << s.message();
    EXPECT_GE(g.edges.size(), 4u);
    EXPECT_TRUE(planarize({}, 1, 1).edges.empty());
}

TEST(StreetGraphJson, RoundTripAndCorruptRejected) {
    StreetGraph g = growStreets(cityParams(3, 800), nullptr);
    std::string text = streetGraphToJson(g);
    auto r = streetGraphFromJson(text);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    EXPECT_EQ(streetGraphToJson(r.value()), text);
    ASSERT_EQ(r.value().nodes.size(), g.nodes.size());
    for (size_t i = 0; i < g.nodes.size(); ++i) EXPECT_EQ(r.value().nodes[i], g.nodes[i]);

    for (const char* bad :
         {"", "{", "[]", "{\"nodes\":[]}", "{\"nodes\":[[0,0]],\"edges\":[[0,0,2,7.5,2]]}",
          "{\"nodes\":[[0,0],[1,1]],\"edges\":[[0,5,2,7.5,2]]}", "{\"nodes\":[[0,0],[1,1]],\"edges\":[[0,1,9,7.5,2]]}",
          "{\"nodes\":[[0,\"x\"]],\"edges\":[]}", "{\"nodes\":[[0,0],[1,1]],\"edges\":[[0,1,2,-1,2]]}",
          "{\"nodes\":[[0,0],[1,1]],\"edges\":[[0,1,2,7.5]]}"}) {
        auto rb = streetGraphFromJson(bad);
        EXPECT_FALSE(rb.isOk()) << bad;
        if (!rb.isOk()) { EXPECT_FALSE(rb.status().message().empty()); }
    }
    // Truncations of a real graph never crash and are rejected.
    for (size_t cut : {size_t(1), text.size() / 3, text.size() / 2, text.size() - 1}) {
        EXPECT_FALSE(streetGraphFromJson(text.substr(0, cut)).isOk());
    }
}

TEST(StreetGraphJson, GeoJsonFeatureCount) {
    StreetGraph g = growStreets(cityParams(4, 700), nullptr);
    auto j = nlohmann::json::parse(streetGraphToGeoJson(g, 1000.0, -500.0));
    EXPECT_EQ(j["type"], "FeatureCollection");
    ASSERT_EQ(j["features"].size(), g.edges.size());
    const auto& f = j["features"][0];
    EXPECT_EQ(f["geometry"]["type"], "LineString");
    EXPECT_DOUBLE_EQ(f["geometry"]["coordinates"][0][0].get<double>(), g.nodes[g.edges[0].a].x + 1000.0);
    EXPECT_EQ(f["properties"]["class"], roadClassName(g.edges[0].cls));
}
