// Buildings: placement on hand-made street graphs and mesh properties.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <limits>

#include "citygen/blocks.h"
#include "citygen/building_geometry.h"
#include "citygen/buildings.h"
#include "citygen/generate.h"
#include "citygen/polygon.h"
#include "citygen/terrain.h"

using namespace vista;

namespace {

StreetGraph gridGraph(int n, double s, double jitter) {
    StreetGraph g;
    double h = 0.5 * n * s;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            bool border = i == 0 || j == 0 || i == n || j == n;
            double dx = border ? 0 : jitter * std::sin(1.7 * i + 3.1 * j),
                   dy = border ? 0 : jitter * std::cos(2.3 * i - 1.3 * j);
            g.nodes.emplace_back(-h + i * s + dx, -h + j * s + dy);
        }
    auto id = [&](int i, int j) { return uint32_t(j * (n + 1) + i); };
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            StreetEdge e;
            e.width = (i == n / 2 || j == n / 2) ? 16.0f : 8.0f;
            if (i < n) {
                e.a = id(i, j);
                e.b = id(i + 1, j);
                g.edges.push_back(e);
            }
            if (j < n) {
                e.a = id(i, j);
                e.b = id(i, j + 1);
                g.edges.push_back(e);
            }
        }
    return g;
}

CityParams testCity() {
    CityParams p;
    p.size_m = 800.0;
    p.density_radius_m = 300.0;
    p.park_fraction = 0.05;
    p.hills_amplitude_m = 12.0;
    p.hills_wavelength_m = 400.0;
    return p;
}

struct Pipeline {
    CityParams p = testCity();
    StreetGraph g;
    std::vector<Block> blocks;
    std::vector<Lot> lots;
    std::vector<Building> buildings;
    Pipeline() : Pipeline(gridGraph(8, 100.0, 8.0)) { run(); }
    explicit Pipeline(StreetGraph graph) : g(std::move(graph)) {}
    void run() {
        blocks = extractBlocks(g, p, nullptr);
        lots = subdivideLots(blocks, p, nullptr);
        buildings = placeBuildings(lots, blocks, p, nullptr);
    }
};

const Pipeline& pipeline() {
    static Pipeline pl;
    return pl;
}

Building box(double w, double d, int floors, RoofType roof = RoofType::Flat, double roofHeight = 0) {
    Building b;
    b.footprint = {{-w / 2, -d / 2}, {w / 2, -d / 2}, {w / 2, d / 2}, {-w / 2, d / 2}};
    b.floors = floors;
    b.height = 3.2 * floors;
    b.base_z = 5.0;
    b.roof = roof;
    b.roof_height = roofHeight;
    return b;
}

struct Meshes {
    Mesh walls, windows, roofs;
    size_t triangles() const { return walls.triangleCount() + windows.triangleCount() + roofs.triangleCount(); }
};

Meshes meshOf(const Building& b, int detail, glm::dvec3 origin = glm::dvec3(0.0)) {
    CityParams p;
    p.detail = detail;
    Lighting light(p);
    Meshes m;
    meshBuilding(b, 7, p, light, origin, BuildingMeshes{&m.walls, &m.windows, &m.roofs});
    return m;
}

struct Tri {
    glm::dvec3 a, b, c;
    glm::dvec3 normal() const { return glm::cross(b - a, c - a); }
    glm::dvec3 centre() const { return (a + b + c) / 3.0; }
    double area() const { return 0.5 * glm::length(normal()); }
};

std::vector<Tri> trianglesOf(const Mesh& m, glm::dvec3 origin = glm::dvec3(0.0)) {
    std::vector<Tri> t;
    for (size_t i = 0; i + 2 < m.indices.size(); i += 3)
        t.push_back({glm::dvec3(m.positions[m.indices[i]]) + origin, glm::dvec3(m.positions[m.indices[i + 1]]) + origin,
                     glm::dvec3(m.positions[m.indices[i + 2]]) + origin});
    return t;
}

void expectWellFormed(const Mesh& m) {
    ASSERT_EQ(m.indices.size() % 3, 0u);
    ASSERT_EQ(m.colors.size(), m.positions.size());
    ASSERT_EQ(m.normals.size(), m.positions.size());
    for (uint32_t i : m.indices) ASSERT_LT(i, m.positions.size());
    for (const auto& p : m.positions) ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
    for (size_t i = 0; i + 2 < m.indices.size(); i += 3) {
        Tri t{glm::dvec3(m.positions[m.indices[i]]), glm::dvec3(m.positions[m.indices[i + 1]]),
              glm::dvec3(m.positions[m.indices[i + 2]])};
        EXPECT_GT(t.area(), 1e-7) << "degenerate triangle " << i / 3;
        // Stored vertex normal agrees with the winding.
        glm::dvec3 n = glm::normalize(t.normal());
        EXPECT_GT(glm::dot(n, glm::dvec3(m.normals[m.indices[i]])), 0.99);
    }
}

}  // namespace

void expectPipelineInvariants(const Pipeline& pl) {
    ASSERT_GT(pl.buildings.size(), 50u);
    for (size_t i = 0; i < pl.buildings.size(); ++i) {
        const Building& b = pl.buildings[i];
        ASSERT_LT(b.lot, pl.lots.size());
        EXPECT_TRUE(polygonInside(b.footprint, pl.lots[b.lot].outline, 1e-6)) << i;
        EXPECT_GT(signedArea(b.footprint), 0.0);
        EXPECT_TRUE(isSimplePolygon(b.footprint));
        for (const auto& e : pl.g.edges) {
            glm::dvec2 a = pl.g.nodes[e.a], c = pl.g.nodes[e.b];
            EXPECT_FALSE(pointInPolygon(b.footprint, 0.5 * (a + c)));
            for (const auto& q : b.footprint)
                ASSERT_GE(pointSegmentDistance(q, a, c), 0.5 * e.width) << "building " << i << " on a road";
        }
        glm::dvec2 ci = centroid(b.footprint);
        for (size_t j = i + 1; j < pl.buildings.size(); ++j) {
            if (glm::length(centroid(pl.buildings[j].footprint) - ci) > 250.0) continue;
            EXPECT_FALSE(polygonsOverlap(b.footprint, pl.buildings[j].footprint, 1e-6)) << i << " vs " << j;
        }
    }
    for (const auto& l : pl.lots) EXPECT_TRUE(polygonInside(l.outline, pl.blocks[l.block].outline, 1e-6));
}

TEST(Buildings, FootprintsInsideLotsNoOverlapNoRoad) { expectPipelineInvariants(pipeline()); }

TEST(Buildings, IrregularGraphWithDeadEnds) {
    // Radial star with a ring, dead ends into the sectors, a T junction and a dense centre.
    Pipeline pl(StreetGraph{});
    StreetGraph& g = pl.g;
    auto node = [&](double x, double y) {
        g.nodes.emplace_back(x, y);
        return uint32_t(g.nodes.size() - 1);
    };
    auto edge = [&](uint32_t a, uint32_t b, float w) {
        StreetEdge e;
        e.a = a;
        e.b = b;
        e.width = w;
        g.edges.push_back(e);
    };
    uint32_t c = node(0, 0);
    const int k = 7;
    std::vector<uint32_t> ring, mid;
    for (int i = 0; i < k; ++i) {
        double a = 2 * M_PI * i / k;
        ring.push_back(node(330 * std::cos(a), 330 * std::sin(a)));
        mid.push_back(node(160 * std::cos(a), 160 * std::sin(a)));
    }
    for (int i = 0; i < k; ++i) {
        edge(c, mid[i], 16.0f);
        edge(mid[i], ring[i], 12.0f);
        edge(mid[i], mid[(i + 1) % k], 8.0f);
        double a = 2 * M_PI * (i + 0.5) / k;  // dead end from the outer ring inwards, with a branch (T junction)
        glm::dvec2 r0 = 0.5 * (g.nodes[ring[i]] + g.nodes[ring[(i + 1) % k]]);
        uint32_t p0 = node(r0.x, r0.y);  // the ring edge is split at p0
        edge(ring[i], p0, 8.0f);
        edge(p0, ring[(i + 1) % k], 8.0f);
        uint32_t p1 = node(230 * std::cos(a), 230 * std::sin(a));
        edge(p0, p1, 8.0f);
        uint32_t p2 = node(230 * std::cos(a) + 30 * std::sin(a), 230 * std::sin(a) - 30 * std::cos(a));
        edge(p1, p2, 8.0f);
    }
    pl.run();
    ASSERT_GE(pl.blocks.size(), size_t(2 * k));
    ASSERT_GT(pl.buildings.size(), 20u);
    expectPipelineInvariants(pl);
}

TEST(Buildings, FloorsHeightsAndBase) {
    const Pipeline& pl = pipeline();
    int towers = 0, houses = 0;
    for (const auto& b : pl.buildings) {
        EXPECT_GE(b.floors, pl.p.min_floors);
        EXPECT_LE(b.floors, pl.p.max_floors);
        EXPECT_NEAR(b.height, b.floors * pl.p.floor_height_m, 1e-9);
        double zmin = 1e300;
        for (const auto& q : b.footprint) zmin = std::min(zmin, terrainHeight(pl.p, q));
        EXPECT_DOUBLE_EQ(b.base_z, zmin);
        EXPECT_GE(b.roof_height, 0.0);
        if (b.roof == RoofType::Flat) { EXPECT_EQ(b.roof_height, 0.0); }
        double dens = pl.blocks[pl.lots[b.lot].block].density;
        if (dens < 0.3) {
            EXPECT_LE(b.floors, 3);
            ++houses;
        }
        if (b.floors > 20) ++towers;
    }
    EXPECT_GT(houses, 0);
    // Deterministic.
    auto again = placeBuildings(pl.lots, pl.blocks, pl.p, nullptr);
    ASSERT_EQ(again.size(), pl.buildings.size());
    for (size_t i = 0; i < again.size(); ++i) {
        EXPECT_EQ(again[i].footprint, pl.buildings[i].footprint);
        EXPECT_EQ(again[i].floors, pl.buildings[i].floors);
        EXPECT_EQ(again[i].roof, pl.buildings[i].roof);
    }
    (void)towers;
}

TEST(Buildings, DenseCentreIsTaller) {
    const Pipeline& pl = pipeline();
    double hi = 0, lo = 0;
    int nhi = 0, nlo = 0;
    for (const auto& b : pl.buildings) {
        double d = pl.blocks[pl.lots[b.lot].block].density;
        if (d > 0.6) {
            hi += b.floors;
            ++nhi;
        }
        if (d < 0.3) {
            lo += b.floors;
            ++nlo;
        }
    }
    ASSERT_GT(nhi, 0);
    ASSERT_GT(nlo, 0);
    EXPECT_GT(hi / nhi, 3.0 * lo / nlo);
}

TEST(Buildings, Detail0BoxTriangleCount) {
    Meshes m = meshOf(box(20, 12, 3), 0);
    EXPECT_EQ(m.walls.triangleCount(), 8u);
    EXPECT_EQ(m.roofs.triangleCount(), 2u);
    EXPECT_EQ(m.windows.triangleCount(), 0u);
}

TEST(Buildings, TriangleCountGrowsWithDetail) {
    Building b = box(24, 14, 8);
    size_t prev = 0;
    for (int d = 0; d <= 3; ++d) {
        Meshes m = meshOf(b, d);
        EXPECT_GT(m.triangles(), prev) << "detail " << d;
        prev = m.triangles();
        if (d >= 1) { EXPECT_GT(m.windows.triangleCount(), 0u); }
    }
}

TEST(Buildings, BoxMeshNormalsOutwardAndFacadesClosed) {
    const double w = 20, dep = 12;
    for (int detail = 0; detail <= 3; ++detail) {
        for (RoofType roof : {RoofType::Flat, RoofType::Gabled, RoofType::Hipped}) {
            Building b = box(w, dep, roof == RoofType::Flat ? 6 : 2, roof, roof == RoofType::Flat ? 0.0 : 4.0);
            glm::dvec3 origin(-3.0, 4.0, 1.0);  // tile origin: positions are stored relative to it
            Meshes m = meshOf(b, detail, origin);
            expectWellFormed(m.walls);
            expectWellFormed(m.windows);
            expectWellFormed(m.roofs);
            CityParams p;
            const double depth = p.window_recess_m;
            std::vector<Tri> all;
            for (const Mesh* mm : {&m.walls, &m.windows, &m.roofs})
                for (const auto& t : trianglesOf(*mm, origin)) all.push_back(t);
            double facadeArea[4] = {0, 0, 0, 0};  // +x, -x, +y, -y
            const double zTop = b.base_z + b.height;
            for (const auto& t : all) {
                glm::dvec3 n = glm::normalize(t.normal()), c = t.centre();
                EXPECT_GE(c.z, b.base_z - 1e-4);
                if (std::abs(n.z) > 0.999 && c.z >= zTop - 1e-4) { EXPECT_GT(n.z, 0) << "roof faces down"; }
                // Facade-parallel triangles close to a facade plane face outwards.
                if (std::abs(n.x) > 0.999 && std::abs(c.x) > w / 2 - depth - 1e-4 && c.z < zTop) {
                    EXPECT_GT(n.x * c.x, 0) << "detail " << detail;
                    if (detail <= 2) facadeArea[n.x > 0 ? 0 : 1] += t.area();
                }
                if (std::abs(n.y) > 0.999 && std::abs(c.y) > dep / 2 - depth - 1e-4 && c.z < zTop) {
                    EXPECT_GT(n.y * c.y, 0) << "detail " << detail;
                    if (detail <= 2) facadeArea[n.y > 0 ? 2 : 3] += t.area();
                }
                if (detail <= 1 && std::abs(n.z) < 0.999) {
                    glm::dvec2 h(n.x, n.y);
                    EXPECT_GT(glm::dot(h, glm::dvec2(c)), 0) << "wall faces inward";
                }
            }
            if (detail <= 2) {
                // Walls plus window backs cover each facade exactly once: no holes, no overlaps.
                EXPECT_NEAR(facadeArea[0], dep * b.height, 1e-3) << detail;
                EXPECT_NEAR(facadeArea[1], dep * b.height, 1e-3) << detail;
                EXPECT_NEAR(facadeArea[2], w * b.height, 1e-3) << detail;
                EXPECT_NEAR(facadeArea[3], w * b.height, 1e-3) << detail;
            }
            // Roof covers the footprint: projected area of upward triangles at or above the eaves.
            double up = 0;
            for (const auto& t : all) {
                glm::dvec3 n = t.normal();
                if (n.z > 1e-9 && t.centre().z >= zTop - 1e-4) up += 0.5 * n.z;
            }
            double parapet = (detail >= 2 && roof == RoofType::Flat) ? 1 : 0;
            EXPECT_NEAR(up, w * dep, 1e-3 + parapet * 1e-3) << "detail " << detail << " roof " << int(roof);
        }
    }
}

TEST(Buildings, HippedRoofOfRectangleIsAnalytic) {
    const double L = 24, W = 10, rh = 3.5;
    Building b = box(L, W, 2, RoofType::Hipped, rh);
    Meshes m = meshOf(b, 0);
    ASSERT_GT(m.roofs.triangleCount(), 2u);
    double zTop = b.base_z + b.height, zmax = -1e300;
    for (const auto& p : m.roofs.positions) zmax = std::max(zmax, double(p.z));
    EXPECT_NEAR(zmax, zTop + rh, 1e-4);
    // Ridge: the vertices at the top span L - W along the long axis, at y = 0.
    double x0 = 1e300, x1 = -1e300;
    for (const auto& p : m.roofs.positions)
        if (std::abs(p.z - zmax) < 1e-4) {
            x0 = std::min(x0, double(p.x));
            x1 = std::max(x1, double(p.x));
            EXPECT_NEAR(p.y, 0.0, 1e-4);
        }
    EXPECT_NEAR(x1 - x0, L - W, 1e-4);
    // Four roof planes, all of the same slope rh / (W / 2).
    for (const auto& t : trianglesOf(m.roofs)) {
        glm::dvec3 n = glm::normalize(t.normal());
        ASSERT_GT(n.z, 0);
        EXPECT_NEAR(std::sqrt(n.x * n.x + n.y * n.y) / n.z, rh / (W / 2), 1e-4);
    }
    // Direct skeleton check on an L-shaped footprint: faces cover the footprint.
    Polygon2 ell{{0, 0}, {20, 0}, {20, 8}, {8, 8}, {8, 20}, {0, 20}};
    std::vector<std::vector<glm::dvec3>> faces;
    double maxT = 0;
    ASSERT_TRUE(hippedRoofFaces(ell, faces, maxT));
    EXPECT_NEAR(maxT, 4.0, 1e-6);
    double area = 0;
    for (const auto& f : faces) {
        Polygon2 q;
        for (const auto& v : f) q.emplace_back(v.x, v.y);
        area += signedArea(q);
    }
    EXPECT_NEAR(area, signedArea(ell), 1e-6);
}

TEST(Buildings, GabledRoofHeightsAndGableWalls) {
    const double L = 16, W = 9, rh = 3.0;
    Building b = box(L, W, 2, RoofType::Gabled, rh);
    Meshes m = meshOf(b, 0);
    double zTop = b.base_z + b.height, zmax = -1e300;
    for (const auto& p : m.roofs.positions) zmax = std::max(zmax, double(p.z));
    EXPECT_NEAR(zmax, zTop + rh, 1e-4);
    // 4 wall quads + 2 gable triangles, 2 roof planes (2 triangles each).
    EXPECT_EQ(m.walls.triangleCount(), 10u);
    EXPECT_EQ(m.roofs.triangleCount(), 4u);
    double ridge0 = 1e300, ridge1 = -1e300;
    for (const auto& p : m.roofs.positions)
        if (std::abs(p.z - zmax) < 1e-4) {
            ridge0 = std::min(ridge0, double(p.x));
            ridge1 = std::max(ridge1, double(p.x));
        }
    EXPECT_NEAR(ridge1 - ridge0, L, 1e-4);  // ridge along the longer axis
}

TEST(Buildings, DegenerateBuildingsAddNothing) {
    Building b = box(10, 10, 2);
    b.footprint.resize(2);
    EXPECT_EQ(meshOf(b, 2).triangles(), 0u);
    b = box(10, 10, 2);
    b.height = std::numeric_limits<double>::quiet_NaN();
    EXPECT_EQ(meshOf(b, 2).triangles(), 0u);
    // Self-intersecting footprint with a hipped roof: no crash, nothing added.
    b = box(10, 10, 2, RoofType::Hipped, 3.0);
    b.footprint = {{0, 0}, {10, 10}, {10, 0}, {0, 10}};
    EXPECT_EQ(meshOf(b, 2).triangles(), 0u);
    // A sliver footprint whose skeleton is degenerate still gives a finite mesh.
    b.footprint = {{0, 0}, {10, 0}, {10, 1e-4}, {0, 1e-4}};
    Meshes m = meshOf(b, 2);
    expectWellFormed(m.roofs);
    expectWellFormed(m.walls);
    // Tiny facade edges get plain wall.
    EXPECT_EQ(meshOf(box(1.0, 1.0, 3), 2).windows.triangleCount(), 0u);
    // Lots too small for a building give none; no lots give no buildings.
    CityParams p;
    Lot tiny;
    tiny.outline = {{0, 0}, {5, 0}, {5, 5}, {0, 5}};
    EXPECT_TRUE(placeBuildings({tiny}, {}, p, nullptr).empty());
    EXPECT_TRUE(placeBuildings({}, {}, p, nullptr).empty());
}

TEST(Buildings, PipelineMeshesAreFinite) {
    const Pipeline& pl = pipeline();
    CityParams p = pl.p;
    Lighting light(p);
    Meshes m;
    size_t n = std::min<size_t>(pl.buildings.size(), 400);
    for (size_t i = 0; i < n; ++i)
        meshBuilding(pl.buildings[i], uint32_t(i), p, light, glm::dvec3(0.0),
                     BuildingMeshes{&m.walls, &m.windows, &m.roofs});
    expectWellFormed(m.walls);
    expectWellFormed(m.windows);
    expectWellFormed(m.roofs);
    EXPECT_GT(m.windows.triangleCount(), 0u);
}

// Triangle budget of the default city per detail level (docs/reference/buildings.md).
// Disabled in CI (it generates the default 2000 m city four times); run with
//   test_citygen --gtest_filter='*BuildingBudget*' --gtest_also_run_disabled_tests
TEST(BuildingBudget, DISABLED_DefaultCityPerDetail) {
    size_t prev = 0;
    for (int detail = 0; detail <= 3; ++detail) {
        CityParams p;
        p.detail = detail;
        auto r = generateCity(p);
        ASSERT_TRUE(r.isOk()) << r.status().message();
        const City& c = *r;
        size_t per[kMaterialCount] = {};
        for (const auto& t : c.tiles)
            for (int m = 0; m < kMaterialCount; ++m) per[m] += t.meshes[size_t(m)].triangleCount();
        size_t b = per[int(Material::Wall)] + per[int(Material::Window)] + per[int(Material::Roof)];
        double meshSeconds = 0;
        for (const auto& s : c.stageTimes)
            if (s.name == "meshes") meshSeconds = s.seconds;
        size_t tallest = 0;
        for (const auto& bd : c.buildings) tallest = std::max(tallest, size_t(bd.floors));
        std::printf(
            "detail %d: %zu blocks, %zu lots, %zu buildings (tallest %zu floors); building triangles %zu "
            "(walls %zu, windows %zu, roofs %zu); city total %zu; meshes stage %.2f s\n",
            detail, c.blocks.size(), c.lots.size(), c.buildings.size(), tallest, b, per[int(Material::Wall)],
            per[int(Material::Window)], per[int(Material::Roof)], countCity(c).triangles, meshSeconds);
        EXPECT_GT(b, prev);
        prev = b;
    }
}

TEST(BuildingGeometry, InsetFallsBackToSkeletonWhenAnEdgeVanishes) {
    // 40 x 20 rectangle with a 0.5 m chamfer at one corner. Inset by 3 m the chamfer
    // edge vanishes (its leg shrinks by 2 d (sqrt 2 - 1) > 0.5): the miter result is
    // rejected and the straight skeleton gives the plain 34 x 14 rectangle.
    Polygon2 p{{0, 0}, {40, 0}, {40, 19.5}, {39.5, 20}, {0, 20}};
    Polygon2 miter;
    EXPECT_FALSE(insetPolygonMiter(p, std::vector<double>(p.size(), 3.0), miter));
    auto r = insetPolygon(p, 3.0);
    ASSERT_EQ(r.size(), 1u);
    EXPECT_NEAR(signedArea(r[0]), 34.0 * 14.0, 1e-6);
    EXPECT_TRUE(polygonInside(r[0], p, 1e-9));
    // A small inset keeps the chamfer: area from the offset formula A - d P + d^2 sum(tan(theta/2)).
    auto s = insetPolygon(p, 0.1);
    ASSERT_EQ(s.size(), 1u);
    EXPECT_EQ(s[0].size(), 5u);
    double perim = 0;
    for (size_t i = 0; i < p.size(); ++i) perim += glm::length(p[(i + 1) % p.size()] - p[i]);
    double sumTan = 3 * 1.0 + 2 * std::tan(M_PI / 8);  // three right angles, two 45-degree turns
    EXPECT_NEAR(signedArea(s[0]), signedArea(p) - 0.1 * perim + 0.01 * sumTan, 1e-9);
    // Too large an inset leaves nothing.
    EXPECT_TRUE(insetPolygon(p, 11.0).empty());
}

TEST(BuildingGeometry, OrientedBoxOfRotatedRectangle) {
    const double a = 0.4, L = 30, W = 12;
    glm::dvec2 u(std::cos(a), std::sin(a)), v(-u.y, u.x), c(5, -7);
    Polygon2 r{c - u * (L / 2) - v * (W / 2), c + u * (L / 2) - v * (W / 2), c + u * (L / 2) + v * (W / 2),
               c - u * (L / 2) + v * (W / 2)};
    OrientedBox b = orientedBox(r);
    EXPECT_NEAR(b.halfU, L / 2, 1e-9);
    EXPECT_NEAR(b.halfV, W / 2, 1e-9);
    EXPECT_NEAR(std::abs(glm::dot(b.u, u)), 1.0, 1e-9);
    EXPECT_LT(glm::length(b.centre - c), 1e-9);
}

TEST(BuildingMesh, CourtyardAndLiftedBuildingAreClosed) {
    // 30 x 30 m with a 10 x 10 m courtyard, walls from 3 m (min_height) to 12 m, flat roof.
    Building b = box(30, 30, 3);
    b.holes = {{{-5, -5}, {-5, 5}, {5, 5}, {5, -5}}};  // clockwise
    b.min_height = 3.0;
    b.height = 12.0;
    b.source = BuildingSource::OsmWay;
    b.lot = kNoLot;
    for (int detail : {0, 2}) {
        const Meshes m = meshOf(b, detail);
        expectWellFormed(m.walls);
        expectWellFormed(m.windows);
        expectWellFormed(m.roofs);
        // Roof: up-facing at the top, area = outer - courtyard, nothing over the courtyard.
        double roofArea = 0;
        for (const auto& t : trianglesOf(m.roofs)) {
            EXPECT_GT(glm::normalize(t.normal()).z, 0.999);
            EXPECT_NEAR(t.centre().z, b.base_z + 12.0, 1e-4);
            EXPECT_FALSE(std::abs(t.centre().x) < 5 && std::abs(t.centre().y) < 5);
            roofArea += t.area();
        }
        EXPECT_NEAR(roofArea, 900.0 - 100.0, 1e-3);
        // Underside at min_height, facing down, same area; no wall below it.
        double under = 0, courtyardWall = 0;
        for (const auto& t : trianglesOf(m.walls)) {
            for (const auto* p : {&t.a, &t.b, &t.c}) EXPECT_GE(p->z, b.base_z + 3.0 - 1e-4);
            const glm::dvec3 n = glm::normalize(t.normal());
            if (n.z < -0.999 && std::abs(t.centre().z - (b.base_z + 3.0)) < 1e-4) under += t.area();
            // Courtyard walls (on the inner ring) face into the courtyard.
            const glm::dvec2 c(t.centre());
            if (std::abs(n.z) < 1e-3 && std::max(std::abs(c.x), std::abs(c.y)) > 5 - 1e-4 &&
                std::max(std::abs(c.x), std::abs(c.y)) < 5 + 1e-4) {
                EXPECT_LT(glm::dot(glm::dvec2(n), c), 0.0);
                courtyardWall += t.area();
            }
        }
        EXPECT_NEAR(under, 800.0, 1e-3);
        if (detail == 0) {
            EXPECT_NEAR(courtyardWall, 4 * 10.0 * 9.0, 1e-3);  // 4 walls 10 m wide, 9 m high
        } else {
            EXPECT_GT(courtyardWall, 0.0);
        }
    }
}
