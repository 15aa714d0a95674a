#include <gtest/gtest.h>

#include "citygen/polygon.h"
#include "foundation/units.h"
#include "foundation/rng.h"

using namespace vista;

TEST(Polygon, AreaAndCentroidOfSquare) {
    std::vector<glm::dvec2> sq{{0, 0}, {2, 0}, {2, 2}, {0, 2}};
    EXPECT_DOUBLE_EQ(signedArea(sq), 4.0);
    auto c = centroid(sq);
    EXPECT_NEAR(c.x, 1.0, 1e-12);
    EXPECT_NEAR(c.y, 1.0, 1e-12);
}

TEST(Polygon, TriangulationCoversAreaOfRandomStarPolygons) {
    for (uint64_t k = 0; k < 200; ++k) {
        Rng rng(5, k, Stream::Blocks);
        int n = int(rng.range(3, 24));
        std::vector<glm::dvec2> p;
        for (int i = 0; i < n; ++i) {
            double a = kTwoPi * i / n, r = rng.uniform(0.3, 1.0);
            p.push_back({r * std::cos(a), r * std::sin(a)});
        }
        auto tris = triangulate(p);
        ASSERT_EQ(tris.size(), size_t(3 * (n - 2))) << k;
        double sum = 0;
        for (size_t i = 0; i < tris.size(); i += 3) {
            std::vector<glm::dvec2> t{p[tris[i]], p[tris[i + 1]], p[tris[i + 2]]};
            double a = signedArea(t);
            EXPECT_GT(a, 0) << k;
            sum += a;
        }
        EXPECT_NEAR(sum, signedArea(p), 1e-9) << k;
    }
}

TEST(Polygon, DegenerateInputsGiveNoTriangles) {
    EXPECT_TRUE(triangulate({{0, 0}, {1, 1}}).empty());
    EXPECT_TRUE(cleanPolygon({{0, 0}, {1, 0}, {2, 0}}).empty());
    EXPECT_EQ(signedArea({}), 0.0);
}

TEST(Polygon, InsideAndOverlap) {
    std::vector<glm::dvec2> outer{{0, 0}, {10, 0}, {10, 10}, {0, 10}};
    std::vector<glm::dvec2> inner{{1, 1}, {9, 1}, {9, 9}, {1, 9}};
    std::vector<glm::dvec2> shifted{{5, 5}, {15, 5}, {15, 15}, {5, 15}};
    std::vector<glm::dvec2> touching{{10, 0}, {20, 0}, {20, 10}, {10, 10}};
    EXPECT_TRUE(polygonInside(inner, outer));
    EXPECT_FALSE(polygonInside(shifted, outer));
    EXPECT_TRUE(polygonsOverlap(inner, outer));
    EXPECT_TRUE(polygonsOverlap(shifted, outer));
    EXPECT_FALSE(polygonsOverlap(touching, outer));
}
