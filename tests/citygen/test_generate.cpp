// Whole-pipeline properties of generateCity(): determinism, invariants, hard cases.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "citygen/generate.h"
#include "citygen/polygon.h"
#include "foundation/rng.h"

using namespace vista;

namespace {

uint64_t hashBytes(uint64_t h, const void* data, size_t n) {
    const auto* p = static_cast<const uint8_t*>(data);
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 0x100000001B3ull;
    return h;
}

// Hash of everything the generator outputs (geometry, graph, instances).
uint64_t hashCity(const City& c) {
    uint64_t h = 0xCBF29CE484222325ull;
    for (const auto& n : c.streets.nodes) h = hashBytes(h, &n, sizeof n);
    for (const auto& e : c.streets.edges) {
        uint32_t v[3] = {e.a, e.b, uint32_t(e.cls)};
        h = hashBytes(h, v, sizeof v);
        h = hashBytes(h, &e.width, sizeof e.width);
    }
    for (const auto& b : c.buildings) {
        for (const auto& p : b.footprint) h = hashBytes(h, &p, sizeof p);
        h = hashBytes(h, &b.height, sizeof b.height);
    }
    for (const auto& t : c.trees) h = hashBytes(h, &t.position, sizeof t.position);
    for (const auto& tile : c.tiles)
        for (const auto& m : tile.meshes) {
            h = hashBytes(h, m.positions.data(), m.positions.size() * sizeof(glm::vec3));
            h = hashBytes(h, m.colors.data(), m.colors.size() * sizeof(glm::u8vec4));
            h = hashBytes(h, m.indices.data(), m.indices.size() * sizeof(uint32_t));
        }
    return h;
}

CityParams small(uint64_t seed, double size = 700) {
    CityParams p;
    p.seed = seed;
    p.size_m = size;
    return p;
}

}  // namespace

TEST(Generate, DeterministicAcrossThreadCounts) {
    CityParams p = small(11);
    p.threads = 1;
    auto a = generateCity(p);
    p.threads = 2;
    auto b = generateCity(p);
    auto c = generateCity(p);
    ASSERT_TRUE(a.isOk() && b.isOk() && c.isOk());
    EXPECT_EQ(hashCity(*a), hashCity(*b));
    EXPECT_EQ(hashCity(*b), hashCity(*c));
}

TEST(Generate, DifferentSeedsDiffer) {
    auto a = generateCity(small(1));
    auto b = generateCity(small(2));
    ASSERT_TRUE(a.isOk() && b.isOk());
    ASSERT_FALSE(a->streets.edges.empty());
    EXPECT_NE(hashCity(*a), hashCity(*b));
}

TEST(Generate, CityInvariants) {
    for (uint64_t seed : {3u, 4u}) {
        auto r = generateCity(small(seed, 900));
        ASSERT_TRUE(r.isOk()) << r.status().message();
        const City& c = *r;
        EXPECT_TRUE(checkPlanarGraph(c.streets, c.params.min_segment_m * 0.999).isOk())
            << checkPlanarGraph(c.streets, c.params.min_segment_m * 0.999).message();
        for (const auto& lot : c.lots) {
            ASSERT_LT(lot.block, c.blocks.size());
            EXPECT_TRUE(polygonInside(lot.outline, c.blocks[lot.block].outline, 1e-6));
        }
        for (const auto& b : c.buildings) {
            ASSERT_LT(b.lot, c.lots.size());
            EXPECT_TRUE(polygonInside(b.footprint, c.lots[b.lot].outline, 1e-6));
            EXPECT_TRUE(std::isfinite(b.height) && b.height > 0);
            // No footprint reaches onto a carriageway.
            glm::dvec2 cen = centroid(b.footprint);
            for (const auto& e : c.streets.edges) {
                const auto &pa = c.streets.nodes[e.a], &pb = c.streets.nodes[e.b];
                if (pointSegmentDistance(cen, pa, pb) > 400) continue;
                for (const auto& q : b.footprint) ASSERT_GE(pointSegmentDistance(q, pa, pb), e.width * 0.5 - 1e-6);
            }
        }
        for (const auto& tile : c.tiles)
            for (const auto& m : tile.meshes) {
                ASSERT_EQ(m.colors.size(), m.positions.size());
                for (const auto& p : m.positions)
                    ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
                for (uint32_t i : m.indices) ASSERT_LT(i, m.positions.size());
                // Tile-local floats stay small: within two tile sizes of the tile origin.
                for (const auto& p : m.positions)
                    ASSERT_LT(std::abs(p.x) + std::abs(p.y), 4 * c.params.tile_size_m + 200);
            }
    }
}

TEST(Generate, NoBuildingOverlapsAnother) {
    auto r = generateCity(small(5, 800));
    ASSERT_TRUE(r.isOk());
    const auto& bs = r->buildings;
    // Uniform grid over centroids keeps this near-linear.
    for (size_t i = 0; i < bs.size(); ++i)
        for (size_t j = i + 1; j < bs.size(); ++j) {
            if (glm::length(centroid(bs[i].footprint) - centroid(bs[j].footprint)) > 300) continue;
            ASSERT_FALSE(polygonsOverlap(bs[i].footprint, bs[j].footprint, 1e-6)) << i << " " << j;
        }
}

TEST(Generate, FarOriginKeepsGeometryRelativeToOrigin) {
    CityParams p = small(7, 500);
    auto a = generateCity(p);
    p.origin_x = 1.0e6;
    p.origin_y = -1.0e6;
    auto b = generateCity(p);
    ASSERT_TRUE(a.isOk() && b.isOk());
    // The city frame is origin-relative, so the geometry must be identical.
    EXPECT_EQ(hashCity(*a), hashCity(*b));
}

TEST(Generate, RejectsInvalidParams) {
    CityParams p;
    p.size_m = 0;
    auto r = generateCity(p);
    ASSERT_FALSE(r.isOk());
    EXPECT_NE(r.status().message().find("size_m"), std::string::npos);
}

TEST(Generate, SmallestCityWorks) {
    auto r = generateCity(small(9, 100));
    ASSERT_TRUE(r.isOk()) << r.status().message();
    for (const auto& n : r->streets.nodes) EXPECT_TRUE(std::isfinite(n.x) && std::isfinite(n.y));
}

TEST(Generate, CountsAddUp) {
    auto r = generateCity(small(12, 600));
    ASSERT_TRUE(r.isOk());
    CityCounts n = countCity(*r);
    size_t tri = 0;
    for (const auto& t : r->tiles)
        for (const auto& m : t.meshes) tri += m.triangleCount();
    for (const auto& t : r->trees) tri += r->treePrototypes[t.prototype].mesh.triangleCount();
    EXPECT_EQ(n.triangles, tri);
    // Stored: tile meshes plus each prototype once (trees are instanced).
    size_t stored = 0;
    for (const auto& t : r->tiles)
        for (const auto& m : t.meshes) stored += m.triangleCount();
    for (const auto& p : r->treePrototypes) stored += p.mesh.triangleCount();
    EXPECT_EQ(n.storedTriangles, stored);
    ASSERT_FALSE(r->trees.empty());
    EXPECT_LT(n.storedTriangles, n.triangles) << "instancing stores fewer triangles than are drawn";
}

TEST(Generate, StoredTriangleEstimateFromTheLayout) {
    // The estimate meshes a sample of the laid-out city's tiles before the meshes stage
    // (beforeMeshing); compared with the counted triangles of the finished city.
    for (double size : {500.0, 2000.0}) {
        CityParams p = small(11, size);
        p.detail = 1;
        size_t estimate = 0;
        GenerateOptions o;
        o.beforeMeshing = [&](const City& layout) {
            EXPECT_TRUE(layout.tiles.empty());
            EXPECT_FALSE(layout.buildings.empty());
            estimate = estimateStoredTriangles(layout);
            return Status::ok();
        };
        auto c = generateCity(p, o);
        ASSERT_TRUE(c.isOk()) << c.status().message();
        const size_t counted = countCity(*c).storedTriangles;
        ASSERT_GT(counted, 0u);
        if (size == 500.0) {
            EXPECT_EQ(estimate, counted);  // a small city: every tile sampled, exact
        } else {
            EXPECT_NEAR(double(estimate) / double(counted), 1.0, 0.35) << estimate << " vs " << counted;
        }
    }
    // An error from the hook stops generation before the meshes and is returned.
    GenerateOptions stop;
    stop.beforeMeshing = [](const City&) { return Status::error("budget says no"); };
    auto c = generateCity(small(3), stop);
    ASSERT_FALSE(c.isOk());
    EXPECT_EQ(c.status().message(), "budget says no");
}
