// Blocks and lots on hand-made street graphs (independent of growStreets).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "citygen/blocks.h"
#include "citygen/building_geometry.h"
#include "citygen/polygon.h"

using namespace vista;

namespace {

struct GraphBuilder {
    StreetGraph g;
    uint32_t node(double x, double y) {
        for (uint32_t i = 0; i < g.nodes.size(); ++i)
            if (glm::length(g.nodes[i] - glm::dvec2(x, y)) < 1e-9) return i;
        g.nodes.emplace_back(x, y);
        return uint32_t(g.nodes.size() - 1);
    }
    void edge(double x0, double y0, double x1, double y1, float width = 8.0f) {
        StreetEdge e;
        e.a = node(x0, y0);
        e.b = node(x1, y1);
        e.width = width;
        g.edges.push_back(e);
    }
};

// n x n cells of side `s` centred on the origin (lines from -n*s/2 to n*s/2).
// Without border streets the outermost lines are left out (the city border bounds those cells).
StreetGraph grid(int n, double s, float width = 8.0f, bool borderStreets = true) {
    GraphBuilder b;
    double h = 0.5 * n * s;
    for (int i = 0; i <= n; ++i) {
        double c = -h + i * s;
        if (!borderStreets && (i == 0 || i == n)) continue;
        for (int j = 0; j < n; ++j) {
            b.edge(c, -h + j * s, c, -h + (j + 1) * s, width);
            b.edge(-h + j * s, c, -h + (j + 1) * s, c, width);
        }
    }
    return b.g;
}

CityParams smallCity(double size) {
    CityParams p;
    p.size_m = size;
    p.sidewalk_m = 3.0;
    p.park_fraction = 0.0;
    return p;
}

bool finitePoly(const Polygon2& p) {
    for (const auto& q : p)
        if (!std::isfinite(q.x) || !std::isfinite(q.y)) return false;
    return true;
}

// Every block: finite, simple, CCW, and at least width/2 from every street centre line.
void expectValidBlocks(const std::vector<Block>& blocks, const StreetGraph& g) {
    for (const auto& b : blocks) {
        ASSERT_TRUE(finitePoly(b.outline));
        EXPECT_GT(signedArea(b.outline), 0.0);
        EXPECT_TRUE(isSimplePolygon(b.outline));
        EXPECT_GE(b.density, 0.0);
        EXPECT_LE(b.density, 1.0);
        for (const auto& e : g.edges) {
            glm::dvec2 a = g.nodes[e.a], c = g.nodes[e.b];
            EXPECT_FALSE(pointInPolygon(b.outline, 0.5 * (a + c)));
            for (const auto& q : b.outline) EXPECT_GE(pointSegmentDistance(q, a, c), 0.5 * e.width - 1e-6);
        }
    }
}

}  // namespace

TEST(Blocks, GridInsetAreasMatchAnalytic) {
    // 4 x 4 cells of 100 m; the streets reach the city border but do not run
    // along it: interior cells lose 2 * (4 + 3) m per side, border cells
    // only on their street sides.
    CityParams p = smallCity(400.0);
    StreetGraph g = grid(4, 100.0, 8.0f, false);
    auto blocks = extractBlocks(g, p, nullptr);
    ASSERT_EQ(blocks.size(), 16u);
    expectValidBlocks(blocks, g);
    const double d = 4.0 + 3.0;
    for (const auto& b : blocks) {
        glm::dvec2 c = centroid(b.outline);
        bool borderX = std::abs(c.x) > 100.0, borderY = std::abs(c.y) > 100.0;
        double w = 100.0 - (borderX ? d : 2 * d), h = 100.0 - (borderY ? d : 2 * d);
        EXPECT_NEAR(signedArea(b.outline), w * h, 1e-6) << c.x << "," << c.y;
    }
}

TEST(Blocks, GridInsideTheBorderGivesInteriorCellsOnly) {
    CityParams p = smallCity(500.0);
    StreetGraph g = grid(3, 100.0);  // does not touch the border: the outer ring face holds the grid as a hole
    auto blocks = extractBlocks(g, p, nullptr);
    ASSERT_EQ(blocks.size(), 9u);
    expectValidBlocks(blocks, g);
    for (const auto& b : blocks) EXPECT_NEAR(signedArea(b.outline), 86.0 * 86.0, 1e-6);
}

TEST(Blocks, PerEdgeWidths) {
    // One cell whose south street is an arterial of 16 m.
    GraphBuilder gb;
    gb.edge(-50, -50, 50, -50, 16.0f);
    gb.edge(50, -50, 50, 50);
    gb.edge(50, 50, -50, 50);
    gb.edge(-50, 50, -50, -50);
    auto blocks = extractBlocks(gb.g, smallCity(400.0), nullptr);
    ASSERT_EQ(blocks.size(), 1u);
    expectValidBlocks(blocks, gb.g);
    EXPECT_NEAR(signedArea(blocks[0].outline), (100.0 - 14.0) * (100.0 - 7.0 - 11.0), 1e-6);
}

TEST(Blocks, TriangleInsetMatchesInradiusScaling) {
    GraphBuilder gb;
    double s = 80.0, h = s * std::sqrt(3.0) / 2;
    gb.edge(-s / 2, -h / 3, s / 2, -h / 3);
    gb.edge(s / 2, -h / 3, 0, 2 * h / 3);
    gb.edge(0, 2 * h / 3, -s / 2, -h / 3);
    auto blocks = extractBlocks(gb.g, smallCity(400.0), nullptr);
    ASSERT_EQ(blocks.size(), 1u);
    expectValidBlocks(blocks, gb.g);
    double r = s / (2 * std::sqrt(3.0)), d = 7.0;
    double area = std::sqrt(3.0) / 4 * s * s;
    EXPECT_NEAR(signedArea(blocks[0].outline), area * (r - d) * (r - d) / (r * r), 1e-6);
}

TEST(Blocks, DeadEndBecomesNotch) {
    GraphBuilder gb;
    gb.edge(-50, -50, 0, -50);
    gb.edge(0, -50, 50, -50);
    gb.edge(50, -50, 50, 50);
    gb.edge(50, 50, -50, 50);
    gb.edge(-50, 50, -50, -50);
    gb.edge(0, -50, 0, -10);  // dead end 40 m into the block
    auto blocks = extractBlocks(gb.g, smallCity(400.0), nullptr);
    ASSERT_EQ(blocks.size(), 1u);
    expectValidBlocks(blocks, gb.g);
    // Notch 14 m wide from the inset south edge (y = -43) to the cap (y = -10 + 7 = -3).
    EXPECT_NEAR(signedArea(blocks[0].outline), 86.0 * 86.0 - 14.0 * 40.0, 1e-6);
}

TEST(Blocks, DeadEndAcrossTheFaceSplitsIt) {
    // The dead end's buffer (cap included) reaches the far street's buffer:
    // the face falls apart into two blocks of 86 x 36 m.
    GraphBuilder gb;
    gb.edge(-50, -50, 50, -50);
    gb.edge(50, -50, 50, 50);
    gb.edge(50, 50, -50, 50);
    gb.edge(-50, 50, -50, 0);
    gb.edge(-50, 0, -50, -50);
    gb.edge(-50, 0, 45, 0);
    auto blocks = extractBlocks(gb.g, smallCity(400.0), nullptr);
    ASSERT_EQ(blocks.size(), 2u);
    expectValidBlocks(blocks, gb.g);
    for (const auto& b : blocks) EXPECT_NEAR(signedArea(b.outline), 86.0 * 36.0, 1e-6);
}

TEST(Blocks, LongDeadEndsAndTreesDoNotCrash) {
    GraphBuilder gb;
    gb.edge(-60, -60, 60, -60);
    gb.edge(60, -60, 60, 60);
    gb.edge(60, 60, -60, 60);
    gb.edge(-60, 60, -60, -60);
    gb.edge(-60, 0, 50, 0);  // almost crosses the block: notch meets the far side
    gb.edge(20, 0, 20, 30);  // branch on the dead end
    gb.edge(20, 30, 35, 45);
    gb.edge(0, 60, 0, 40);  // dead end from the north
    auto blocks = extractBlocks(gb.g, smallCity(400.0), nullptr);
    expectValidBlocks(blocks, gb.g);
    double total = 0;
    for (const auto& b : blocks) total += signedArea(b.outline);
    EXPECT_LT(total, 106.0 * 106.0);
}

TEST(Blocks, TJunction) {
    GraphBuilder gb;
    gb.edge(-50, -50, 50, -50);
    gb.edge(50, -50, 50, 0);
    gb.edge(50, 0, 50, 50);
    gb.edge(50, 50, -50, 50);
    gb.edge(-50, 50, -50, 0);
    gb.edge(-50, 0, -50, -50);
    gb.edge(-50, 0, 0, 0);
    gb.edge(0, 0, 50, 0);
    gb.edge(0, 0, 0, 50);  // T junction in the middle
    auto blocks = extractBlocks(gb.g, smallCity(400.0), nullptr);
    ASSERT_EQ(blocks.size(), 3u);
    expectValidBlocks(blocks, gb.g);
    double total = 0;
    for (const auto& b : blocks) total += signedArea(b.outline);
    EXPECT_NEAR(total, 86.0 * 36.0 + 2 * 36.0 * 36.0, 1e-6);
}

TEST(Blocks, RadialStarAndIrregular) {
    GraphBuilder gb;
    const int k = 10;
    std::vector<glm::dvec2> ring;
    for (int i = 0; i < k; ++i) {
        double a = 2 * M_PI * i / k + 0.1 * std::sin(3.0 * i);
        double r = 300.0 + 40.0 * std::cos(2.0 * i);
        ring.emplace_back(r * std::cos(a), r * std::sin(a));
    }
    for (int i = 0; i < k; ++i) {
        gb.edge(0, 0, ring[i].x, ring[i].y, i % 3 == 0 ? 16.0f : 8.0f);
        gb.edge(ring[i].x, ring[i].y, ring[(i + 1) % k].x, ring[(i + 1) % k].y);
        gb.edge(ring[i].x, ring[i].y, ring[i].x * 1.8, ring[i].y * 1.8);  // spokes run past the border
    }
    CityParams p = smallCity(1000.0);
    auto blocks = extractBlocks(gb.g, p, nullptr);
    EXPECT_GE(blocks.size(), size_t(k));
    expectValidBlocks(blocks, gb.g);
    for (const auto& b : blocks)
        for (const auto& q : b.outline) {
            EXPECT_LE(std::abs(q.x), 500.0 + 1e-9);
            EXPECT_LE(std::abs(q.y), 500.0 + 1e-9);
        }
}

TEST(Blocks, DegenerateInputs) {
    CityParams p = smallCity(400.0);
    EXPECT_TRUE(extractBlocks(StreetGraph(), p, nullptr).empty());
    GraphBuilder one;
    one.edge(-20, 0, 30, 0);
    EXPECT_TRUE(extractBlocks(one.g, p, nullptr).empty());
    GraphBuilder tiny;  // triangle smaller than its inset
    tiny.edge(0, 0, 10, 0);
    tiny.edge(10, 0, 0, 10);
    tiny.edge(0, 10, 0, 0);
    EXPECT_TRUE(extractBlocks(tiny.g, p, nullptr).empty());
    GraphBuilder bad;
    bad.edge(0, 0, std::numeric_limits<double>::quiet_NaN(), 5);
    bad.edge(0, 0, 50, 50);
    EXPECT_TRUE(extractBlocks(bad.g, p, nullptr).empty());
    GraphBuilder dangling;  // an edge index past the node array is ignored
    dangling.edge(-200, 0, 200, 0);
    dangling.g.edges.push_back(StreetEdge{0, 99, RoadClass::Local, 8.0f, 2});
    EXPECT_EQ(extractBlocks(dangling.g, p, nullptr).size(), 2u);
    // A border-to-border street splits the city into two blocks.
    GraphBuilder cut;
    cut.edge(-200, 0, 200, 0);
    auto two = extractBlocks(cut.g, p, nullptr);
    ASSERT_EQ(two.size(), 2u);
    for (const auto& b : two) EXPECT_NEAR(signedArea(b.outline), 400.0 * 193.0, 1e-6);
}

TEST(Blocks, DeterministicAndIndependentOfEdgeOrder) {
    CityParams p = smallCity(800.0);
    p.park_fraction = 0.25;
    StreetGraph g = grid(8, 100.0);
    auto a = extractBlocks(g, p, nullptr);
    std::reverse(g.edges.begin(), g.edges.end());
    for (auto& e : g.edges) std::swap(e.a, e.b);
    auto b = extractBlocks(g, p, nullptr);
    ASSERT_EQ(a.size(), b.size());
    ASSERT_EQ(a.size(), 64u);
    size_t parks = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i].park, b[i].park);
        EXPECT_NEAR(signedArea(a[i].outline), signedArea(b[i].outline), 1e-9);
        EXPECT_LT(glm::length(centroid(a[i].outline) - centroid(b[i].outline)), 1e-9);
        parks += a[i].park;
    }
    EXPECT_EQ(parks, 16u);
    // Parks favour low density: mean park density below the mean block density.
    double dp = 0, da = 0;
    for (const auto& x : a) {
        da += x.density;
        if (x.park) dp += x.density;
    }
    EXPECT_LT(dp / double(parks), da / double(a.size()));
}

// ---------- lots ----------

TEST(Lots, SplitPolygonByLineConcave) {
    // U shape: a horizontal cut through both arms gives three pieces.
    FlaggedPolygon u;
    u.pts = {{0, 0}, {30, 0}, {30, 30}, {20, 30}, {20, 10}, {10, 10}, {10, 30}, {0, 30}};
    u.flags.assign(u.pts.size(), 1);
    auto pieces = splitPolygonByLine(u, {0, 20}, {1, 0});
    ASSERT_EQ(pieces.size(), 3u);
    double total = 0;
    for (const auto& p : pieces) {
        total += std::abs(signedArea(p.pts));
        EXPECT_TRUE(polygonInside(p.pts, u.pts, 1e-9));
        EXPECT_EQ(p.flags.size(), p.pts.size());
    }
    EXPECT_NEAR(total, std::abs(signedArea(u.pts)), 1e-9);
    // Cut edges carry flag 0, the others keep 1.
    size_t zero = 0;
    for (const auto& p : pieces)
        for (auto f : p.flags) zero += f == 0;
    EXPECT_EQ(zero, 4u);  // two cut segments, each bordering two pieces
    // A line missing the polygon returns it unchanged.
    EXPECT_EQ(splitPolygonByLine(u, {0, 50}, {1, 0}).size(), 1u);
}

TEST(Lots, InsideBlocksNoOverlapAndFrontage) {
    CityParams p = smallCity(600.0);
    // Grid plus an L-shaped concave block (one missing street) and a diagonal.
    StreetGraph g = grid(6, 100.0);
    g.edges.erase(std::remove_if(g.edges.begin(), g.edges.end(),
                                 [&](const StreetEdge& e) {
                                     glm::dvec2 a = g.nodes[e.a], b = g.nodes[e.b];
                                     // removes the streets x=0, y in [0,100] and y=100, x in [0,100]: three cells form
                                     // an L
                                     return (a.x == 0 && b.x == 0 && std::min(a.y, b.y) == 0) ||
                                            (a.y == 100 && b.y == 100 && std::min(a.x, b.x) == 0);
                                 }),
                  g.edges.end());
    auto blocks = extractBlocks(g, p, nullptr);
    ASSERT_GE(blocks.size(), 30u);
    bool concave = false;
    for (const auto& b : blocks) concave = concave || b.outline.size() > 4;
    EXPECT_TRUE(concave);
    auto lots = subdivideLots(blocks, p, nullptr);
    ASSERT_GT(lots.size(), blocks.size());
    std::vector<double> lotArea(blocks.size(), 0.0);
    for (size_t i = 0; i < lots.size(); ++i) {
        const Lot& l = lots[i];
        ASSERT_LT(l.block, blocks.size());
        EXPECT_TRUE(l.frontage);
        EXPECT_FALSE(blocks[l.block].park);
        EXPECT_GT(signedArea(l.outline), 0.0);
        EXPECT_TRUE(polygonInside(l.outline, blocks[l.block].outline, 1e-6)) << "lot " << i;
        lotArea[l.block] += signedArea(l.outline);
        // Frontage: some lot edge lies on the block boundary.
        bool touches = false;
        const auto& bo = blocks[l.block].outline;
        for (const auto& q : l.outline)
            for (size_t k = 0; k < bo.size() && !touches; ++k)
                touches = pointSegmentDistance(q, bo[k], bo[(k + 1) % bo.size()]) < 1e-6;
        EXPECT_TRUE(touches);
        for (size_t j = i + 1; j < lots.size() && lots[j].block == l.block; ++j)
            EXPECT_FALSE(polygonsOverlap(l.outline, lots[j].outline, 1e-6)) << i << " vs " << j;
    }
    for (size_t b = 0; b < blocks.size(); ++b) EXPECT_LE(lotArea[b], signedArea(blocks[b].outline) + 1e-6);
    // Deterministic.
    auto again = subdivideLots(blocks, p, nullptr);
    ASSERT_EQ(again.size(), lots.size());
    for (size_t i = 0; i < lots.size(); ++i) EXPECT_EQ(again[i].outline, lots[i].outline);
}

TEST(Lots, DowntownLotsAreBigger) {
    CityParams p = smallCity(400.0);
    Block b;
    b.outline = {{0, 0}, {120, 0}, {120, 120}, {0, 120}};
    std::vector<Block> blocks{b, b};
    blocks[0].density = 0.0;
    blocks[1].density = 1.0;
    auto lots = subdivideLots(blocks, p, nullptr);
    double a0 = 0, a1 = 0;
    int n0 = 0, n1 = 0;
    for (const auto& l : lots) {
        (l.block == 0 ? a0 : a1) += signedArea(l.outline);
        (l.block == 0 ? n0 : n1) += 1;
    }
    ASSERT_GT(n0, 0);
    ASSERT_GT(n1, 0);
    EXPECT_GT(a1 / n1, 2.0 * a0 / n0);
    EXPECT_TRUE(subdivideLots({}, p, nullptr).empty());
}
