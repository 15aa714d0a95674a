// Horizon tracing tests: the horizon is never below true geometry (checked
// against brute-force 3D ray casting through every pixel of a column), also at
// grid boundaries, axis-parallel rays, far from the origin, inside buildings;
// it switches off for rolled cameras and for zenith/nadir views.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "foundation/units.h"
#include "runtime/engine/horizon.h"
#include "runtime/engine/ray_scene.h"
#include "tests/runtime/engine/fixtures.h"

using namespace vista;
using namespace vista::test;

namespace {

// Brute force: for each column, the first row (from the top) whose centre ray
// hits geometry farther than `nearDistance` (H if none). The horizon row must
// never exceed it.
// maxEyeDepth: hits deeper (eye-plane depth) than this do not count (haze).
std::vector<int> bruteForceTopHit(const RayScene& rs, const Camera& cam, double nearDistance,
                                  double maxEyeDepth = 1e300) {
    std::vector<int> top(size_t(cam.width), cam.height);
    glm::vec3 org(cam.eye - rs.frameOrigin());
    for (int x = 0; x < cam.width; ++x)
        for (int y = 0; y < cam.height; ++y) {
            const glm::dvec3 dd = cam.rayDirection(x + 0.5, y + 0.5);
            glm::vec3 d(dd);
            RayHit h = rs.intersect(org, d, 0.0f, float(std::min(1e30, maxEyeDepth / glm::dot(dd, cam.forward()))));
            if (h.hit && h.t >= nearDistance) {
                top[size_t(x)] = y;
                break;
            }
        }
    return top;
}

// Counts columns where the horizon is above the true top hit (violations) and
// the culled pixel total (to check the test is not vacuous).
struct Check {
    int violations = 0;
    long culled = 0;
};
Check compare(const HorizonResult& hr, const std::vector<int>& top) {
    Check c;
    for (size_t x = 0; x < top.size(); ++x) {
        if (hr.row[x] > top[x]) ++c.violations;
        c.culled += hr.row[x];
    }
    return c;
}

Camera cameraAt(const glm::dvec3& eye, double heading, double pitch, int w = 61, int h = 41) {
    return testCamera(eye, heading, pitch, w, h, 0.9);
}

}  // namespace

TEST(Horizon, NeverBelowGeometryOnRandomScenes) {
    long culledTotal = 0;
    for (uint32_t seed = 1; seed <= 6; ++seed) {
        const double ox = seed % 2 ? 0.0 : 2.5e5, oy = seed % 3 ? 0.0 : -1.0e5;
        SceneModel city = randomCity(seed, 80, 400.0, ox, oy);
        auto rs = RayScene::build(city);
        ASSERT_TRUE(rs.isOk());
        std::mt19937 rng(seed * 77);
        std::uniform_real_distribution<double> pos(-220, 220), hd(-M_PI, M_PI), pt(-0.35, 0.35), hz(1.0, 40.0);
        for (int grid : {7, 32, 128}) {
            HeightGrid hg = HeightGrid::build(city, rs.value()->frameOrigin(), grid);
            for (int k = 0; k < 4; ++k) {
                Camera cam = cameraAt(glm::dvec3(ox + pos(rng), oy + pos(rng), hz(rng)), hd(rng), pt(rng));
                for (double nearD : {0.0, 60.0}) {
                    HorizonOptions opt;
                    opt.nearDistance = nearD;
                    HorizonResult hr = traceHorizon(hg, cam, opt);
                    ASSERT_TRUE(hr.active) << hr.reason;
                    Check c = compare(hr, bruteForceTopHit(*rs.value(), cam, nearD));
                    EXPECT_EQ(c.violations, 0) << "seed " << seed << " grid " << grid << " near " << nearD;
                    culledTotal += c.culled;
                }
            }
        }
    }
    EXPECT_GT(culledTotal, 0);  // the horizon does cull sky
}

// Haze: with an eye-plane depth limit the horizon stays conservative against
// brute force with the same limit, and culls at least as much as one
// horizontal limit for the whole view (the corner pixels' reach) would.
TEST(Horizon, EyeDepthLimitIsConservativeAndTighterThanOneDistance) {
    long culledDepth = 0, culledDistance = 0;
    for (uint32_t seed = 1; seed <= 4; ++seed) {
        SceneModel city = randomCity(seed, 120, 800.0);
        auto rs = RayScene::build(city);
        ASSERT_TRUE(rs.isOk());
        HeightGrid hg = HeightGrid::build(city, rs.value()->frameOrigin(), 64);
        std::mt19937 rng(seed * 31);
        std::uniform_real_distribution<double> pos(-300, 300), hd(-M_PI, M_PI), pt(-0.5, 0.3), hz(1.0, 120.0);
        for (int k = 0; k < 4; ++k) {
            Camera cam = cameraAt(glm::dvec3(pos(rng), pos(rng), hz(rng)), hd(rng), pt(rng));
            for (double depth : {60.0, 200.0}) {
                HorizonOptions opt;
                opt.nearDistance = 20.0;
                opt.maxEyeDepth = depth;
                HorizonResult hr = traceHorizon(hg, cam, opt);
                ASSERT_TRUE(hr.active) << hr.reason;
                Check c = compare(hr, bruteForceTopHit(*rs.value(), cam, opt.nearDistance, depth));
                EXPECT_EQ(c.violations, 0) << "seed " << seed << " depth " << depth;
                culledDepth += c.culled;
                // One limit for the view: the largest horizontal reach of any pixel.
                double reach = 0;
                for (double px : {0.5, cam.width - 0.5})
                    for (double py : {0.5, cam.height - 0.5}) {
                        const glm::dvec3 d = cam.rayDirection(px, py);
                        reach = std::max(reach, depth * std::hypot(d.x, d.y) / glm::dot(d, cam.forward()));
                    }
                HorizonOptions one;
                one.nearDistance = 20.0;
                one.maxDistance = reach;
                HorizonResult h1 = traceHorizon(hg, cam, one);
                for (size_t x = 0; x < hr.row.size(); ++x) {
                    EXPECT_GE(hr.row[x], h1.row[x]) << "column " << x;
                    culledDistance += h1.row[x];
                }
            }
        }
    }
    EXPECT_GT(culledDepth, culledDistance);  // strictly tighter somewhere
}

TEST(Horizon, ConservativeWithCameraOnGridLinesAndAxisParallelRays) {
    // Thin walls lying exactly on grid lines, camera exactly on grid lines and
    // at grid corners, looking along the axes (odd width: the centre column's
    // ray is exactly axis-parallel).
    SceneModel city;
    SceneMesh m;
    addGround(m, {-100, -100}, {100, 100}, 0, {80, 80, 80, 255});
    addBox(m, {-100, -100, 0}, {100, -99.999f, 2}, {200, 0, 0, 255});  // marks the grid extent
    addBox(m, {0, 20, 0}, {0.0005f, 60, 30}, {0, 200, 0, 255});        // wall on x = 0
    addBox(m, {20, 0, 0}, {60, 0.0005f, 25}, {0, 0, 200, 255});        // wall on y = 0
    city.meshes.push_back(m);
    auto rs = RayScene::build(city);
    ASSERT_TRUE(rs.isOk());
    for (int grid : {8, 16, 50}) {
        HeightGrid hg = HeightGrid::build(city, rs.value()->frameOrigin(), grid);
        const double s = hg.cellSize();
        const glm::dvec2 g0 = hg.gridMin();
        for (int lx : {grid / 2, grid / 2 + 1})
            for (int ly : {grid / 2, grid / 2 - 1}) {
                glm::dvec3 eye(g0.x + lx * s, g0.y + ly * s, 1.7);  // exactly on a grid corner
                for (double heading : {0.0, 0.5 * M_PI, M_PI, -0.5 * M_PI, 0.25 * M_PI}) {
                    Camera cam = cameraAt(eye, heading, 0.0, 41, 31);
                    HorizonResult hr = traceHorizon(hg, cam);
                    Check c = compare(hr, bruteForceTopHit(*rs.value(), cam, 0.0));
                    EXPECT_EQ(c.violations, 0) << "grid " << grid << " heading " << heading;
                }
            }
        // Camera on the wall's line, looking straight along it.
        Camera along = cameraAt(glm::dvec3(0, 0, 1.7), 0.0, 0.0, 41, 31);
        Check c = compare(traceHorizon(hg, along), bruteForceTopHit(*rs.value(), along, 0.0));
        EXPECT_EQ(c.violations, 0);
    }
    // Single-ray level: a ray exactly along x = 0 sees the wall on the line.
    HeightGrid hg = HeightGrid::build(city, rs.value()->frameOrigin(), 16);
    double b = hg.traceRay(glm::dvec3(0, 0, 1.7), 0.0, 0.0);
    EXPECT_GE(b, (30.0 - 1.7) / 60.0);
}

// The block walk returns exactly the flat walk's bound (the max over the same
// touched cells) on random scenes, random eyes and azimuths, eyes on cell and
// block corners, rays through block corners (45 degrees from a block corner)
// and along grid lines, with and without a near distance and a distance limit.
TEST(Horizon, BlockWalkEqualsTheFlatWalk) {
    long compared = 0, nonTrivial = 0;
    for (uint32_t seed = 1; seed <= 4; ++seed) {
        SceneModel city = randomCity(seed, 120, 400.0);
        auto rs = RayScene::build(city);
        ASSERT_TRUE(rs.isOk());
        std::mt19937 rng(seed * 31);
        std::uniform_real_distribution<double> pos(-250, 250), az(-M_PI, M_PI), hz(0.5, 60.0);
        for (int grid : {7, 64, 130}) {
            HeightGrid hg = HeightGrid::build(city, rs.value()->frameOrigin(), grid);
            const double s = hg.cellSize();
            const glm::dvec2 g0 = hg.gridMin();
            std::vector<glm::dvec3> eyes;
            for (int k = 0; k < 6; ++k) eyes.push_back({pos(rng), pos(rng), hz(rng)});
            const int B = HeightGrid::kBlock;
            eyes.push_back({g0.x + B * s, g0.y + B * s, 1.7});              // on a block corner
            eyes.push_back({g0.x + (B + 3) * s, g0.y + 5 * s, 20.0});       // on a cell corner
            eyes.push_back({g0.x + (grid / 2) * s, g0.y + 0.37 * s, 3.0});  // on a grid line
            for (const glm::dvec3& e : eyes) {
                std::vector<double> azimuths = {0.0,         0.5 * M_PI,  M_PI,        -0.5 * M_PI,
                                                0.25 * M_PI, 0.75 * M_PI, -0.25 * M_PI};
                for (int k = 0; k < 40; ++k) azimuths.push_back(az(rng));
                for (double a : azimuths)
                    for (double nearD : {0.0, 45.0})
                        for (double maxD : {std::numeric_limits<double>::infinity(), 150.0}) {
                            const double flat = hg.traceRayFlat(e, a, nearD, maxD),
                                         block = hg.traceRay(e, a, nearD, maxD);
                            EXPECT_EQ(block, flat) << "seed " << seed << " grid " << grid << " eye " << e.x << ","
                                                   << e.y << " azimuth " << a << " near " << nearD << " max " << maxD;
                            ++compared;
                            if (std::isfinite(flat)) ++nonTrivial;
                        }
            }
        }
    }
    EXPECT_GT(nonTrivial, compared / 2);  // most rays see something: the comparison has teeth
    // A ray entering a block through a cell corner, where the only cell that
    // beats the best so far touches the ray at that corner alone: grid of 1 m
    // cells over [0, 64]^2; eye on the corner (0, 3), ray at 45 degrees
    // (y = x + 3) enters block (1, 1) at the corner (8, 11); the tower in
    // cell (8, 10) touches the ray only there, and the tower in cell (1, 4)
    // makes the block before it (ground only) one to pass over.
    {
        SceneModel city;
        SceneMesh m;
        addGround(m, {0, 0}, {64, 64}, 0, {80, 80, 80, 255});
        addBox(m, {1.3f, 4.3f, 0}, {1.7f, 4.7f, 10}, {200, 0, 0, 255});
        addBox(m, {8.3f, 10.3f, 0}, {8.7f, 10.7f, 200}, {0, 200, 0, 255});
        city.meshes.push_back(m);
        auto rs = RayScene::build(city);
        ASSERT_TRUE(rs.isOk());
        HeightGrid hg = HeightGrid::build(city, rs.value()->frameOrigin(), 64);
        const glm::dvec2 g0 = hg.gridMin();
        const glm::dvec3 eye(g0.x, g0.y + 3 * hg.cellSize(), 1.7);
        const double flat = hg.traceRayFlat(eye, 0.25 * M_PI, 0.0), block = hg.traceRay(eye, 0.25 * M_PI, 0.0);
        EXPECT_GT(flat, 15.0);  // the corner cell's tower: (200 - 1.7) / |(8, 7)|
        EXPECT_EQ(block, flat);
    }
}

TEST(Horizon, OffForRolledCameraAndZenithOrNadirViews) {
    SceneModel city = randomCity(2, 20);
    HeightGrid hg = HeightGrid::build(city, glm::dvec3(0), 32);
    Camera c = cameraAt(glm::dvec3(0, 0, 2), 0, 0);
    c.roll = 0.1;
    HorizonResult r = traceHorizon(hg, c);
    EXPECT_FALSE(r.active);
    EXPECT_NE(r.reason.find("rolled"), std::string::npos);
    for (int v : r.row) EXPECT_EQ(v, 0);  // nothing culled
    c.roll = 0;
    c.pitch = 0.5 * M_PI;  // straight up
    r = traceHorizon(hg, c);
    EXPECT_FALSE(r.active);
    EXPECT_NE(r.reason.find("zenith"), std::string::npos);
    c.pitch = -0.5 * M_PI;  // straight down
    r = traceHorizon(hg, c);
    EXPECT_FALSE(r.active);
    EXPECT_NE(r.reason.find("nadir"), std::string::npos);
}

TEST(Horizon, EmptyCityIsAllSkyAndInsideBuildingCullsNothing) {
    SceneModel empty;
    HeightGrid e = HeightGrid::build(empty, glm::dvec3(0), 64);
    EXPECT_TRUE(e.empty());
    Camera c = cameraAt(glm::dvec3(0, 0, 2), 0.3, 0.1);
    HorizonResult r = traceHorizon(e, c);
    ASSERT_TRUE(r.active);
    for (int v : r.row) EXPECT_EQ(v, c.height);
    // Camera inside a tall box: geometry above the eye at distance 0 -> nothing culled.
    SceneModel city;
    SceneMesh m;
    addBox(m, {-10, -10, 0}, {10, 10, 50}, {100, 100, 100, 255});
    city.meshes.push_back(m);
    HeightGrid hg = HeightGrid::build(city, glm::dvec3(0), 16);
    r = traceHorizon(hg, c);
    for (int v : r.row) EXPECT_EQ(v, 0);
}

// Looking out of the city from its edge: no geometry beyond the near distance
// in any column's wedge, so every pixel is sky without a ray (a bound of -inf
// once gave a NaN limit and culled nothing). Looking back in culls less.
TEST(Horizon, LookingOutOfTheCityIsAllSky) {
    SceneModel city = randomCity(7, 40, 400.0);
    SceneMesh ground;
    addGround(ground, {-200, -200}, {200, 200}, 0.0f, {90, 90, 90, 255});
    city.meshes.push_back(ground);
    auto rs = RayScene::build(city);
    ASSERT_TRUE(rs.isOk());
    HeightGrid hg = HeightGrid::build(city, glm::dvec3(0), 64);
    // At the south edge (y = -195), heading south (pi), eye 1.5 m above the ground.
    const Camera out = cameraAt(glm::dvec3(0, -195, 1.5), kPi, 0.0);
    HorizonOptions o;
    o.nearDistance = 30.0;
    HorizonResult r = traceHorizon(hg, out, o);
    ASSERT_TRUE(r.active);
    for (int v : r.row) EXPECT_EQ(v, out.height);
    EXPECT_EQ(compare(r, bruteForceTopHit(*rs.value(), out, o.nearDistance)).violations, 0);
    const Camera in = cameraAt(glm::dvec3(0, -195, 1.5), 0.0, 0.0);
    r = traceHorizon(hg, in, o);
    const Check c = compare(r, bruteForceTopHit(*rs.value(), in, o.nearDistance));
    EXPECT_EQ(c.violations, 0);
    EXPECT_LT(c.culled, long(in.width) * in.height);
}

TEST(Horizon, ViewportExtremes) {
    SceneModel city = randomCity(5, 40);
    auto rs = RayScene::build(city);
    ASSERT_TRUE(rs.isOk());
    HeightGrid hg = HeightGrid::build(city, glm::dvec3(0), 64);
    Camera one = cameraAt(glm::dvec3(0, -250, 2), 0.2, 0.05, 1, 1);
    HorizonResult r = traceHorizon(hg, one);
    ASSERT_EQ(r.row.size(), 1u);
    EXPECT_GE(r.row[0], 0);
    EXPECT_LE(r.row[0], 1);
    EXPECT_EQ(compare(r, bruteForceTopHit(*rs.value(), one, 0)).violations, 0);
    Camera big = cameraAt(glm::dvec3(0, -250, 2), 0.2, 0.05, 4096, 2160);
    r = traceHorizon(hg, big);
    ASSERT_EQ(r.row.size(), 4096u);
    for (int v : r.row) {
        ASSERT_GE(v, 0);
        ASSERT_LE(v, 2160);
    }
    // Spot-check every 64th column of the big image against brute force.
    glm::vec3 org(big.eye);
    for (int x = 0; x < 4096; x += 64)
        for (int y = 0; y < r.row[size_t(x)]; y += 7)
            ASSERT_FALSE(rs.value()->intersect(org, glm::vec3(big.rayDirection(x + 0.5, y + 0.5))).hit)
                << x << "," << y;
}

TEST(Horizon, SubsamplingNeverCullsMoreThanOnItsOwnLattice) {
    // Subsampled horizon = max of the neighbouring samples: per column it is
    // at least as high (row <= ) as the exact one at the sampled rays only,
    // and it culls something in an open scene.
    SceneModel city = randomCity(9, 60);
    HeightGrid hg = HeightGrid::build(city, glm::dvec3(0), 64);
    Camera c = cameraAt(glm::dvec3(10, -230, 3), 0.1, 0.0, 121, 81);
    HorizonOptions o1, o4;
    o4.subsample = 4;
    HorizonResult exact = traceHorizon(hg, c, o1), sub = traceHorizon(hg, c, o4);
    EXPECT_LT(sub.raysTraced, exact.raysTraced);
    long culled = 0;
    for (size_t x = 0; x < exact.row.size(); ++x) culled += sub.row[x];
    EXPECT_GT(culled, 0);
}

TEST(Horizon, AutomaticGridResolutionFollowsTheCityExtent) {
    // About 4 m cells, 512 .. 2048 a side: independent arithmetic on the extents.
    EXPECT_EQ(HeightGrid::autoCells(100.0), 512);
    EXPECT_EQ(HeightGrid::autoCells(2100.0), 525);
    EXPECT_EQ(HeightGrid::autoCells(8000.0), 2000);
    EXPECT_EQ(HeightGrid::autoCells(32000.0), 2048);
    EXPECT_EQ(HeightGrid::autoCells(0.0), 512);
    EXPECT_EQ(HeightGrid::autoCells(std::nan("")), 512);
    // build(..., 0) picks autoCells of the geometry's extent; an explicit count is kept.
    SceneModel city = randomCity(3, 40, 3000.0);
    auto rs = RayScene::build(city);
    ASSERT_TRUE(rs.isOk());
    const HeightGrid a = HeightGrid::build(city, rs.value()->frameOrigin(), 0);
    const double extent = std::max(a.boundsMax().x - a.boundsMin().x, a.boundsMax().y - a.boundsMin().y);
    EXPECT_GT(extent, 1000.0);
    EXPECT_EQ(a.cells(), HeightGrid::autoCells(extent + 4 * HeightGrid::kCellMargin));
    EXPECT_NEAR(a.cellSize(), (extent + 4 * HeightGrid::kCellMargin) / a.cells(), 1e-9);
    EXPECT_EQ(HeightGrid::build(city, rs.value()->frameOrigin(), 64).cells(), 64);
    // The automatic grid is as conservative as any: never above the brute-force top hit.
    const Camera cam = cameraAt(glm::dvec3(0, -200, 1.7), 0.3, 0.05);
    const HorizonResult hr = traceHorizon(a, cam);
    EXPECT_TRUE(hr.active) << hr.reason;
    const Check c = compare(hr, bruteForceTopHit(*rs.value(), cam, 0.0));
    EXPECT_EQ(c.violations, 0);
    EXPECT_GT(c.culled, 0);  // not vacuous: the sky above the skyline is culled
}
