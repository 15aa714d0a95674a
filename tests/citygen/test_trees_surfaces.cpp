// Trees (prototypes, placement) and tile surfaces (ground, roads, sidewalks),
// on hand-made cities that do not depend on the street/block/building stages.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "citygen/mesh_builder.h"
#include "citygen/polygon.h"
#include "citygen/lanes.h"
#include "citygen/surfaces.h"
#include "citygen/terrain.h"
#include "citygen/trees.h"

namespace vista {

namespace {

constexpr double kSpacing = 100.0;  // street grid spacing of the test city
constexpr int kGrid = 6;            // nodes per row/column

// A kGrid x kGrid street grid centred on the origin; the middle row is an
// arterial (14 m), the rest local (8 m). Blocks are the cells inset by half
// width + sidewalk; block (1,1) is a park; other blocks get one building
// inset 4 m from the block, and one kiosk deliberately on the sidewalk.
City makeTestCity(double tileSize = 100.0, double hills = 0.0) {
    City c;
    c.params.seed = 7;
    c.params.size_m = 800.0;
    c.params.tile_size_m = tileSize;
    c.params.hills_amplitude_m = hills;
    c.params.hills_wavelength_m = 600.0;
    const double x0 = -0.5 * kSpacing * (kGrid - 1);
    auto id = [](int i, int j) { return uint32_t(j * kGrid + i); };
    for (int j = 0; j < kGrid; ++j)
        for (int i = 0; i < kGrid; ++i) c.streets.nodes.emplace_back(x0 + i * kSpacing, x0 + j * kSpacing);
    const int artRow = kGrid / 2;
    auto width = [&](bool horizontal, int row) { return horizontal && row == artRow ? 14.0 : 8.0; };
    for (int j = 0; j < kGrid; ++j)
        for (int i = 0; i + 1 < kGrid; ++i) {
            StreetEdge e;
            e.a = id(i, j);
            e.b = id(i + 1, j);
            e.cls = j == artRow ? RoadClass::Arterial : RoadClass::Local;
            e.width = float(width(true, j));
            e.lanes = j == artRow ? 4 : 2;
            c.streets.edges.push_back(e);
        }
    for (int i = 0; i < kGrid; ++i)
        for (int j = 0; j + 1 < kGrid; ++j) {
            StreetEdge e;
            e.a = id(i, j);
            e.b = id(i, j + 1);
            e.width = 8.0f;
            c.streets.edges.push_back(e);
        }
    const double sw = c.params.sidewalk_m;
    for (int j = 0; j + 1 < kGrid; ++j)
        for (int i = 0; i + 1 < kGrid; ++i) {
            double xl = x0 + i * kSpacing + 4.0 + sw, xr = x0 + (i + 1) * kSpacing - 4.0 - sw;
            double yb = x0 + j * kSpacing + 0.5 * width(true, j) + sw;
            double yt = x0 + (j + 1) * kSpacing - 0.5 * width(true, j + 1) - sw;
            Block b;
            b.outline = {{xl, yb}, {xr, yb}, {xr, yt}, {xl, yt}};
            b.park = (i == 1 && j == 1);
            c.blocks.push_back(b);
            if (b.park) continue;
            Lot lot;
            lot.block = uint32_t(c.blocks.size() - 1);
            lot.outline = b.outline;
            c.lots.push_back(lot);
            Building bu;
            bu.lot = uint32_t(c.lots.size() - 1);
            bu.footprint = {{xl + 4, yb + 4}, {xr - 4, yb + 4}, {xr - 4, yt - 4}, {xl + 4, yt - 4}};
            bu.height = 12;
            c.buildings.push_back(bu);
        }
    // A kiosk on the sidewalk south of block (2,2): street trees must avoid it.
    {
        double xl = x0 + 2 * kSpacing + 4.0 + sw, yb = x0 + 2 * kSpacing + 4.0 + sw;
        Building k;
        k.footprint = {{xl + 10, yb - sw}, {xl + 60, yb - sw}, {xl + 60, yb}, {xl + 10, yb}};
        k.height = 3;
        c.buildings.push_back(k);
    }
    return c;
}

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Area of triangle t of a mesh.
double triArea(const Mesh& m, size_t t) {
    glm::dvec3 a(m.positions[m.indices[3 * t]]), b(m.positions[m.indices[3 * t + 1]]),
        c(m.positions[m.indices[3 * t + 2]]);
    return 0.5 * glm::length(glm::cross(b - a, c - a));
}
// Area projected on the ground plane.
double triAreaXY(const Mesh& m, size_t t) {
    glm::dvec2 a(m.positions[m.indices[3 * t]]), b(m.positions[m.indices[3 * t + 1]]),
        c(m.positions[m.indices[3 * t + 2]]);
    return 0.5 * std::abs((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
}

void expectWellFormed(const Mesh& m, const char* what) {
    ASSERT_EQ(m.indices.size() % 3, 0u) << what;
    ASSERT_EQ(m.colors.size(), m.positions.size()) << what;
    ASSERT_EQ(m.normals.size(), m.positions.size()) << what;
    for (uint32_t i : m.indices) ASSERT_LT(i, m.positions.size()) << what;
    for (const auto& p : m.positions) ASSERT_TRUE(finite(p)) << what;
    for (const auto& n : m.normals) ASSERT_TRUE(finite(n)) << what;
    for (size_t t = 0; t < m.triangleCount(); ++t) ASSERT_GT(triArea(m, t), 1e-7) << what << " triangle " << t;
}

std::vector<Tile> meshAllTiles(const City& c) {
    TileGrid grid(c.params);
    Lighting light(c.params);
    std::vector<Tile> tiles(size_t(grid.count()));
    for (int t = 0; t < grid.count(); ++t) meshSurfaces(c, grid, t, light, tiles[size_t(t)]);
    return tiles;
}

double materialArea(const std::vector<Tile>& tiles, Material m, bool projected = true) {
    double a = 0;
    for (const auto& t : tiles) {
        const Mesh& mesh = t.meshes[size_t(m)];
        for (size_t i = 0; i < mesh.triangleCount(); ++i) a += projected ? triAreaXY(mesh, i) : triArea(mesh, i);
    }
    return a;
}

// ---------------------------------------------------------------------------
// Prototypes

TEST(TreePrototypes, NineSpeciesVariantsWithinBudget) {
    CityParams p;
    auto protos = makeTreePrototypes(p, Lighting(p));
    ASSERT_EQ(protos.size(), 9u);
    std::map<std::pair<int, int>, int> seen;
    for (const auto& t : protos) {
        SCOPED_TRACE(testing::Message() << "species " << t.species << " variant " << t.variant);
        seen[{t.species, t.variant}]++;
        // Reported in docs/reference/trees-and-surfaces.md (figures come from this line).
        std::printf("prototype species %d variant %d: %zu triangles, %zu vertices, height %.2f m\n", t.species,
                    t.variant, t.mesh.triangleCount(), t.mesh.positions.size(), t.height);
        expectWellFormed(t.mesh, "tree");
        EXPECT_GE(t.mesh.triangleCount(), 400u);
        EXPECT_LE(t.mesh.triangleCount(), 1500u);
        // Heights: instances scale by 0.85..1.15 and must stay within 5..22 m.
        double top = 0, bottom = 1e9;
        for (const auto& q : t.mesh.positions) top = std::max(top, double(q.z)), bottom = std::min(bottom, double(q.z));
        EXPECT_NEAR(t.height, top, 1e-4);
        EXPECT_GE(t.height * 0.85, 5.0);
        EXPECT_LE(t.height * 1.15, 22.0);
        // Trunk base at the origin: the lowest vertices are trunk vertices close to the z axis.
        EXPECT_LE(bottom, 0.0);
        EXPECT_GE(bottom, -0.3);
        size_t trunkLow = 0;
        for (size_t i = 0; i < t.mesh.positions.size(); ++i) {
            const auto& q = t.mesh.positions[i];
            if (q.z < bottom + 0.05) {
                EXPECT_LT(std::hypot(q.x, q.y), 0.6);
                ++trunkLow;
            }
        }
        EXPECT_GE(trunkLow, 5u);
        // Both materials present: distinct colours for bark and leaves.
        bool greenish = false, brownish = false;
        for (const auto& col : t.mesh.colors) {
            greenish = greenish || (col.y > col.x + 10 && col.y > col.z);
            brownish = brownish || (col.x > col.y && col.x > col.z);
        }
        EXPECT_TRUE(greenish);
        EXPECT_TRUE(brownish);
    }
    EXPECT_EQ(seen.size(), 9u);
}

TEST(TreePrototypes, DeterministicAndSeeded) {
    CityParams p;
    auto a = makeTreePrototypes(p, Lighting(p));
    auto b = makeTreePrototypes(p, Lighting(p));
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
        ASSERT_EQ(a[i].mesh.positions.size(), b[i].mesh.positions.size());
        EXPECT_TRUE(std::equal(a[i].mesh.positions.begin(), a[i].mesh.positions.end(), b[i].mesh.positions.begin()));
        EXPECT_EQ(a[i].mesh.indices, b[i].mesh.indices);
    }
    CityParams q = p;
    q.seed = p.seed + 1;
    auto c = makeTreePrototypes(q, Lighting(q));
    bool differs = false;
    for (size_t i = 0; i < a.size(); ++i)
        differs = differs || a[i].mesh.positions.size() != c[i].mesh.positions.size() ||
                  !std::equal(a[i].mesh.positions.begin(), a[i].mesh.positions.end(), c[i].mesh.positions.begin());
    EXPECT_TRUE(differs);
}

// ---------------------------------------------------------------------------
// Placement

TEST(TreePlacement, StreetAndParkTreesRespectRoadsBuildingsParks) {
    City c = makeTestCity(100.0, 15.0);
    c.params.street_tree_spacing_m = 14.0;  // the counts below are stated for these values
    c.params.park_tree_density = 0.004;
    c.treePrototypes = makeTreePrototypes(c.params, Lighting(c.params));
    auto trees = placeTrees(c, nullptr);
    size_t street = 0, park = 0;
    const Block* parkBlock = nullptr;
    for (const auto& b : c.blocks)
        if (b.park) parkBlock = &b;
    ASSERT_NE(parkBlock, nullptr);
    for (const auto& t : trees) {
        glm::dvec2 p(t.position);
        ASSERT_TRUE(std::isfinite(t.position.x) && std::isfinite(t.position.y) && std::isfinite(t.position.z));
        EXPECT_NEAR(t.position.z, terrainHeight(c.params, p), 1e-9);
        EXPECT_LT(t.prototype, c.treePrototypes.size());
        EXPECT_GE(t.scale, 0.85f);
        EXPECT_LE(t.scale, 1.15f);
        for (const auto& e : c.streets.edges)
            EXPECT_GE(pointSegmentDistance(p, c.streets.nodes[e.a], c.streets.nodes[e.b]), 0.5 * e.width)
                << "tree on a carriageway at " << p.x << "," << p.y;
        for (const auto& b : c.buildings) EXPECT_FALSE(pointInPolygon(b.footprint, p)) << "tree in a building";
        if (t.street) {
            ++street;
        } else {
            ++park;
            EXPECT_TRUE(pointInPolygon(parkBlock->outline, p)) << "park tree outside the park";
        }
        EXPECT_LE(std::abs(p.x), 0.5 * c.params.size_m);
        EXPECT_LE(std::abs(p.y), 0.5 * c.params.size_m);
    }
    // Street trees: both sides of 60 edges of 100 m at 14 m spacing, minus
    // intersections and the kiosk: several hundred. Park: 0.004 / m^2.
    EXPECT_GT(street, 400u);
    double parkArea = std::abs(signedArea(parkBlock->outline));
    EXPECT_NEAR(double(park), parkArea * c.params.park_tree_density, 0.35 * parkArea * c.params.park_tree_density);
    // No street tree within 10 m of a 4-way intersection.
    auto deg = c.streets.degrees();
    for (const auto& t : trees)
        for (size_t n = 0; n < c.streets.nodes.size(); ++n)
            if (t.street && deg[n] >= 3) { EXPECT_GE(glm::length(glm::dvec2(t.position) - c.streets.nodes[n]), 10.0); }
    // Crowns do not grow more than 1 m into facades, unless the tree is already
    // the smallest variant at the smallest scale.
    size_t shrunk = 0;
    for (const auto& t : trees) {
        const auto& proto = c.treePrototypes[t.prototype];
        double crown = 0;
        for (const auto& q : proto.mesh.positions) crown = std::max(crown, std::hypot(double(q.x), double(q.y)));
        double room = 1e9;
        for (const auto& b : c.buildings)
            for (size_t k = 0; k < b.footprint.size(); ++k)
                room = std::min(room, pointSegmentDistance(glm::dvec2(t.position), b.footprint[k],
                                                           b.footprint[(k + 1) % b.footprint.size()]));
        if (room > 12.0) continue;  // beyond the search radius
        bool smallest = proto.variant == 0 && t.scale <= 0.85f + 1e-6f;
        EXPECT_TRUE(crown * t.scale <= room + 1.0 + 1e-4 || smallest)
            << "crown " << crown * t.scale << " m, facade at " << room << " m";
        shrunk += proto.variant == 0;
    }
    EXPECT_GT(shrunk, 0u);
    // Canonical order: non-decreasing tile index.
    TileGrid grid(c.params);
    for (size_t i = 1; i < trees.size(); ++i)
        EXPECT_LE(grid.tileOf(glm::dvec2(trees[i - 1].position)), grid.tileOf(glm::dvec2(trees[i].position)));
}

TEST(TreePlacement, DeterministicAndLocal) {
    City c = makeTestCity();
    c.treePrototypes = makeTreePrototypes(c.params, Lighting(c.params));
    auto a = placeTrees(c, nullptr);
    auto b = placeTrees(c, nullptr);
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i].position, b[i].position);
        EXPECT_EQ(a[i].prototype, b[i].prototype);
        EXPECT_EQ(a[i].yaw, b[i].yaw);
        EXPECT_EQ(a[i].scale, b[i].scale);
    }
    // An unrelated change (another building in the north-east, the edge
    // list in reverse order) leaves every tree farther than 40 m from it as it was.
    City d = c;
    std::reverse(d.streets.edges.begin(), d.streets.edges.end());
    Building extra;
    glm::dvec2 at(200.0, 200.0);
    extra.footprint = {at + glm::dvec2(-46, -46), at + glm::dvec2(46, -46), at + glm::dvec2(46, 46),
                       at + glm::dvec2(-46, 46)};
    d.buildings.push_back(extra);
    auto e = placeTrees(d, nullptr);
    auto key = [](const TreeInstance& t) { return std::make_pair(t.position.x, t.position.y); };
    std::map<std::pair<double, double>, TreeInstance> byPos;
    for (const auto& t : e) byPos[key(t)] = t;
    size_t compared = 0;
    for (const auto& t : a) {
        if (glm::length(glm::dvec2(t.position) - at) < 40.0 + 46.0 * std::sqrt(2.0)) continue;
        auto it = byPos.find(key(t));
        ASSERT_NE(it, byPos.end()) << "tree at " << t.position.x << "," << t.position.y << " disappeared";
        EXPECT_EQ(it->second.prototype, t.prototype);
        EXPECT_EQ(it->second.yaw, t.yaw);
        EXPECT_EQ(it->second.scale, t.scale);
        ++compared;
    }
    EXPECT_GT(compared, a.size() / 2);
    EXPECT_LT(e.size(), a.size());  // the new building displaced some trees
}

TEST(TreePlacement, ZeroSpacingAndDensityGiveNoTrees) {
    City c = makeTestCity();
    c.params.street_tree_spacing_m = 0;
    c.params.park_tree_density = 0;
    EXPECT_TRUE(placeTrees(c, nullptr).empty());
    City empty;
    EXPECT_TRUE(placeTrees(empty, nullptr).empty());
}

// ---------------------------------------------------------------------------
// Surfaces

TEST(Surfaces, RoadPiecesDrawnExactlyOnceAcrossTiles) {
    City many = makeTestCity(100.0);  // 64 tiles
    City one = makeTestCity(800.0);   // a single tile
    auto tilesMany = meshAllTiles(many);
    auto tilesOne = meshAllTiles(one);
    ASSERT_EQ(tilesOne.size(), 1u);
    for (const auto& t : tilesMany)
        for (int m = 0; m < kMaterialCount; ++m) expectWellFormed(t.meshes[size_t(m)], materialName(Material(m)));
    double aMany = materialArea(tilesMany, Material::Road), aOne = materialArea(tilesOne, Material::Road);
    EXPECT_NEAR(aMany, aOne, 1e-4 * aOne);
    // Analytic: carriageway pieces sum to length x width. A junction polygon
    // contains the first stretch of its widest arm (half width r, length
    // r + sidewalk along the arm, both sides: >= 2 r^2) and lies within the
    // disc through the corners a sidewalk and a turn's straight lead-in
    // (lanes.h kCrossingLeadIn) further along: pi ((r + sw + lead)^2 + r^2).
    double pieces = 0;
    for (size_t e = 0; e < many.streets.edges.size(); ++e)
        pieces += many.streets.edgeLength(e) * many.streets.edges[e].width;
    std::vector<double> r(many.streets.nodes.size(), 0.0);
    for (const auto& e : many.streets.edges) {
        r[e.a] = std::max(r[e.a], 0.5 * e.width);
        r[e.b] = std::max(r[e.b], 0.5 * e.width);
    }
    const double swj = many.params.sidewalk_m;
    double jLo = 0, jHi = 0;
    const double lead = kCrossingLeadIn;
    for (double x : r) jLo += 2 * x * x, jHi += M_PI * ((x + swj + lead) * (x + swj + lead) + x * x);
    EXPECT_GE(aMany, pieces + jLo - 1e-3 * pieces);
    EXPECT_LE(aMany, pieces + jHi + 1e-3 * pieces);
    // Ground covers the city square exactly once.
    EXPECT_NEAR(materialArea(tilesMany, Material::Ground), many.params.size_m * many.params.size_m, 1.0);
    // Parks: the lawn covers the park block exactly once.
    double parkArea = 0;
    for (const auto& b : many.blocks)
        if (b.park) parkArea += std::abs(signedArea(b.outline));
    EXPECT_NEAR(materialArea(tilesMany, Material::Grass), parkArea, 1e-3 * parkArea);
    EXPECT_NEAR(materialArea(tilesMany, Material::Sidewalk), materialArea(tilesOne, Material::Sidewalk),
                1e-4 * materialArea(tilesOne, Material::Sidewalk));
    // Markings (lane model: centre lines, dividers, stop lines, crossings)
    // are drawn exactly once across tiles, and only on carriageways.
    EXPECT_GT(materialArea(tilesMany, Material::Marking), 10.0);
    EXPECT_NEAR(materialArea(tilesMany, Material::Marking), materialArea(tilesOne, Material::Marking),
                1e-4 * materialArea(tilesOne, Material::Marking));
    for (const auto& t : tilesMany)
        for (const auto& q : t.meshes[size_t(Material::Marking)].positions) {
            glm::dvec2 w = glm::dvec2(q) + glm::dvec2(t.origin);
            bool onRoad = false;
            for (const auto& e : many.streets.edges)
                onRoad = onRoad || pointSegmentDistance(w, many.streets.nodes[e.a], many.streets.nodes[e.b]) <=
                                       0.5 * e.width + 1e-3;
            EXPECT_TRUE(onRoad) << "marking at " << w.x << "," << w.y;
        }
    // Sidewalk tops (projected; kerb faces are vertical): perimeter x width per
    // rectangular block plus four round corners of three 30-degree wedges.
    const double sw = many.params.sidewalk_m;
    double walk = 0;
    for (const auto& b : many.blocks) {
        for (size_t i = 0; i < b.outline.size(); ++i)
            walk += glm::length(b.outline[(i + 1) % b.outline.size()] - b.outline[i]) * sw;
        walk += 4 * 3 * 0.5 * sw * sw * std::sin(M_PI / 6);
    }
    EXPECT_NEAR(materialArea(tilesMany, Material::Sidewalk), walk, 1e-6 * walk);
}

TEST(Surfaces, FollowTerrainAboveGround) {
    City c = makeTestCity(100.0, 20.0);
    auto tiles = meshAllTiles(c);
    TileGrid grid(c.params);
    size_t roadVerts = 0, walkVerts = 0;
    for (const auto& t : tiles) {
        for (int m = 0; m < kMaterialCount; ++m) expectWellFormed(t.meshes[size_t(m)], materialName(Material(m)));
        auto check = [&](Material m, double lo, double hi, size_t& count) {
            for (const auto& q : t.meshes[size_t(m)].positions) {
                glm::dvec3 w = glm::dvec3(q) + t.origin;
                double g = terrainHeight(c.params, glm::dvec2(w));
                EXPECT_GE(w.z - g, lo - 1e-3);
                EXPECT_LE(w.z - g, hi + 1e-3);
                ++count;
            }
        };
        size_t dummy = 0;
        check(Material::Road, 0.015, 0.025, roadVerts);
        check(Material::Sidewalk, 0.0, 0.12, walkVerts);
        check(Material::Ground, 0.0, 0.0, dummy);
        check(Material::Grass, 0.05, 0.05, dummy);
        check(Material::Marking, 0.03, 0.03, dummy);
    }
    EXPECT_GT(roadVerts, 0u);
    EXPECT_GT(walkVerts, 0u);
    // Hills subdivide the ground into cells of at most 25 m.
    size_t groundTris = 0;
    for (const auto& t : tiles) groundTris += t.meshes[size_t(Material::Ground)].triangleCount();
    EXPECT_GE(groundTris, size_t(2 * (800 / 25) * (800 / 25)));
}

TEST(Surfaces, ConcaveParkCoveredOnce) {
    // A U-shaped park across several tiles, flat and hilly: the lawn covers it exactly once.
    for (double hills : {0.0, 20.0}) {
        City c = makeTestCity(100.0, hills);
        for (auto& b : c.blocks) b.park = false;
        Block u;
        u.park = true;
        u.outline = {{-180, -170}, {170, -170}, {170, 160},  {90, 160},
                     {90, -60},    {-110, -60}, {-110, 160}, {-180, 160}};
        c.blocks.push_back(u);
        auto tiles = meshAllTiles(c);
        for (const auto& t : tiles) expectWellFormed(t.meshes[size_t(Material::Grass)], "grass");
        double area = std::abs(signedArea(u.outline));
        EXPECT_NEAR(materialArea(tiles, Material::Grass), area, 1e-6 * area) << "hills " << hills;
    }
}

TEST(Surfaces, IndexGivesIdenticalMeshes) {
    for (double hills : {0.0, 20.0}) {
        City c = makeTestCity(100.0, hills);
        TileGrid grid(c.params);
        Lighting light(c.params);
        SurfaceIndex index = buildSurfaceIndex(c, grid);
        size_t total = 0;
        for (int t = 0; t < grid.count(); ++t) {
            Tile a, b;
            meshSurfaces(c, grid, t, light, a);
            meshSurfaces(c, grid, t, light, b, &index);
            for (int m = 0; m < kMaterialCount; ++m) {
                const Mesh& ma = a.meshes[size_t(m)];
                const Mesh& mb = b.meshes[size_t(m)];
                ASSERT_EQ(ma.positions.size(), mb.positions.size()) << "tile " << t << " " << materialName(Material(m));
                EXPECT_TRUE(std::equal(ma.positions.begin(), ma.positions.end(), mb.positions.begin()));
                EXPECT_EQ(ma.indices, mb.indices);
                total += ma.triangleCount();
            }
        }
        EXPECT_GT(total, 0u);
    }
}

TEST(Surfaces, DegenerateInputIsHarmless) {
    City c = makeTestCity(200.0);
    // A zero-length edge, an edge with zero width, a degenerate block and a
    // block with a repeated vertex.
    c.streets.nodes.push_back(c.streets.nodes[0]);
    StreetEdge z;
    z.a = 0;
    z.b = uint32_t(c.streets.nodes.size() - 1);
    c.streets.edges.push_back(z);
    StreetEdge w;
    w.a = 1;
    w.b = 2;
    w.width = 0.0f;
    c.streets.edges.push_back(w);
    Block flat;
    flat.outline = {{0, 0}, {10, 0}, {20, 0}};
    c.blocks.push_back(flat);
    Block rep;
    rep.outline = {{300, 300}, {300, 300}, {330, 300}, {330, 330}, {300, 330}};
    c.blocks.push_back(rep);
    // Non-finite input (outside the contract) is skipped, never turned into NaN triangles.
    c.streets.nodes.emplace_back(std::nan(""), 0.0);
    StreetEdge bad;
    bad.a = 3;
    bad.b = uint32_t(c.streets.nodes.size() - 1);
    c.streets.edges.push_back(bad);
    Block nanPark;
    nanPark.park = true;
    nanPark.outline = {{-300, -300}, {-280, -300}, {std::nan(""), -280}};
    c.blocks.push_back(nanPark);
    auto tiles = meshAllTiles(c);
    for (const auto& t : tiles)
        for (int m = 0; m < kMaterialCount; ++m) expectWellFormed(t.meshes[size_t(m)], materialName(Material(m)));
    c.treePrototypes = makeTreePrototypes(c.params, Lighting(c.params));
    for (const auto& t : placeTrees(c, nullptr)) EXPECT_TRUE(std::isfinite(t.position.x + t.position.y + t.position.z));
}

}  // namespace
}  // namespace vista
