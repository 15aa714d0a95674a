// Far-field shortcuts that must give the frame they replace: early horizon, speculative
// rays, lattice rays blending only within one surface.
#include <gtest/gtest.h>

#include <algorithm>
#include <iterator>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <string>

#include "citygen/lighting.h"
#include "runtime/engine/far_field.h"
#include "runtime/engine/far_field_rays.h"
#include "runtime/engine/frame_raycast.h"
#include "runtime/engine/horizon.h"
#include "runtime/engine/metrics.h"
#include "runtime/engine/ray_scene.h"
#include "tests/runtime/engine/fixtures.h"
#include "tests/runtime/engine/far_field_fixtures.h"

using namespace vista;
using namespace vista::test;
namespace {
// A fake near-field depth covering the bottom third of the camera's pixels.
std::vector<float> bottomThirdCovered(const Camera& c) {
    const size_t N = size_t(c.width) * size_t(c.height);
    std::vector<float> depth(N, 1.0f);
    for (size_t i = N * 2 / 3; i < N; ++i) depth[i] = 0.5f;
    return depth;
}

// Options for two FarFields whose frames are compared: no cache, and no horizon pause (it
// follows measured times, so the two could classify differently).
FarFieldOptions twoFieldOptions(double nearDistance) {
    FarFieldOptions o;
    o.nearDistance = nearDistance;
    o.cache = false;
    o.horizonAdaptive = false;
    return o;
}

}  // namespace

// The horizon traced ahead of the frame (FarField::beginFrame, overlapping the
// near-field draw) gives the very frame the in-frame horizon gives; a
// beginFrame for another camera is not used.
TEST(FarFieldFrame, EarlyHorizonGivesTheSameFrame) {
    const TestCity t = testCity(9, 60);
    ASSERT_TRUE(t.rays);
    Camera c = cam(glm::dvec3(0, -190, 1.7), 0.2);
    const std::vector<float> depth = bottomThirdCovered(c);
    FarFieldOptions o = twoFieldOptions(0);
    o.speculate = false;  // speculative rays add rays to raysCast (tested below): the horizon alone here
    FarField early(*t.rays, &t.grid, o), plain(*t.rays, &t.grid, o);
    for (int f = 0; f < 3; ++f) {
        c.eye.x += 3.0;
        Image a, b;
        FrameStats sa, sb;
        early.beginFrame(c);
        early.render(c, depth.data(), a, sa);
        plain.render(c, depth.data(), b, sb);
        EXPECT_TRUE(has(sa, "horizon overlapped"));
        EXPECT_FALSE(has(sb, "horizon overlapped"));
        EXPECT_GT(sa.pixels.horizonCulled, 0u);
        EXPECT_EQ(sa.pixels.horizonCulled, sb.pixels.horizonCulled);
        EXPECT_EQ(sa.raysCast, sb.raysCast);
        EXPECT_EQ(a.rgba, b.rgba);
        EXPECT_EQ(early.classification(), plain.classification());
    }
    // Begun for one camera, rendered for another: traced in the frame as usual.
    Camera other = c;
    other.heading += 0.3;
    early.beginFrame(c);
    Image a, b;
    FrameStats sa, sb;
    early.render(other, depth.data(), a, sa);
    plain.render(other, depth.data(), b, sb);
    EXPECT_FALSE(has(sa, "horizon overlapped"));
    EXPECT_EQ(a.rgba, b.rgba);
}

// Speculative rays (FarFieldOptions::speculate): last frame's traced pixels,
// cast ahead for the new camera, give the very frame the plain ray stage
// gives; the ray stage takes exactly those of them it traces this frame and
// casts only the rest, and every speculative ray counts in raysCast.
TEST(FarFieldFrame, SpeculativeRaysGiveTheSameFrame) {
    const TestCity t = testCity(9, 60);
    ASSERT_TRUE(t.rays);
    Camera c = cam(glm::dvec3(0, -190, 1.7), 0.2);
    const std::vector<float> depth = bottomThirdCovered(c);
    const FarFieldOptions o = twoFieldOptions(20);
    FarFieldOptions po = o;
    po.speculate = false;
    FarField spec(*t.rays, &t.grid, o), plain(*t.rays, &t.grid, po);
    std::vector<uint32_t> last;
    for (int f = 0; f < 4; ++f) {
        c.eye.x += 3.0;
        c.heading += 0.02;
        spec.beginFrame(c);
        spec.awaitSpeculation();
        plain.beginFrame(c);
        Image a, b;
        FrameStats sa, sb;
        spec.render(c, depth.data(), a, sa);
        plain.render(c, depth.data(), b, sb);
        EXPECT_EQ(a.rgba, b.rgba) << "frame " << f;
        EXPECT_EQ(spec.classification(), plain.classification());
        EXPECT_EQ(sa.pixels.rayHit, sb.pixels.rayHit);
        EXPECT_EQ(sa.pixels.rayMiss, sb.pixels.rayMiss);
        EXPECT_EQ(spec.lastTraced(), plain.lastTraced());
        EXPECT_FALSE(has(sb, "speculative rays"));
        std::vector<uint32_t> both;
        std::set_intersection(last.begin(), last.end(), spec.lastTraced().begin(), spec.lastTraced().end(),
                              std::back_inserter(both));
        if (f == 0) {
            EXPECT_FALSE(has(sa, "speculative rays"));  // nothing was traced before
            EXPECT_EQ(sa.raysCast, sb.raysCast);
        } else {
            EXPECT_GT(both.size(), last.size() / 2) << "frame " << f;
            EXPECT_LT(both.size(), spec.lastTraced().size()) << "frame " << f;  // the view moved: some are new
            EXPECT_TRUE(has(sa, "speculative rays: " + std::to_string(last.size()) + " cast during the draw, " +
                                    std::to_string(both.size()) + " used"));
            EXPECT_EQ(sa.raysCast, sb.raysCast - both.size() + last.size());
            EXPECT_EQ(sa.speculativeRays, last.size());
            EXPECT_EQ(sa.speculativeUsed, both.size());
        }
        last = spec.lastTraced();
    }
    // Begun for one camera, rendered for another: none used, the same frame.
    Camera other = c;
    other.heading += 0.3;
    spec.beginFrame(c);
    spec.awaitSpeculation();
    Image a, b;
    FrameStats sa, sb;
    spec.render(other, depth.data(), a, sa);
    plain.render(other, depth.data(), b, sb);
    EXPECT_TRUE(has(sa, "speculative rays: " + std::to_string(last.size()) + " cast during the draw, 0 used"));
    EXPECT_EQ(a.rgba, b.rgba);
    // A frame the near field covers whole runs no ray stage: the rays are counted, none used.
    const std::vector<uint32_t> before = spec.lastTraced();
    ASSERT_FALSE(before.empty());
    const std::vector<float> covered(size_t(c.width) * size_t(c.height), 0.5f);
    spec.beginFrame(other);
    spec.awaitSpeculation();
    FrameStats sc;
    spec.render(other, covered.data(), a, sc);
    EXPECT_EQ(sc.speculativeRays, before.size());
    EXPECT_EQ(sc.speculativeUsed, 0u);
    EXPECT_EQ(sc.raysCast, before.size());
    EXPECT_FALSE(sc.stages.ran(Stage::Rays));
}

// rayStep 2 (the lattice): fewer rays, the frame close to the exact one, and
// where the lattice neighbours show one flat-coloured triangle, or sky, the
// blend equals the exact pixel.
TEST(FarFieldFrame, LatticeRaysBlendOnlyWithinOneSurface) {
    const TestCity t = testCity(12, 60);
    ASSERT_TRUE(t.rays);
    FarFieldOptions o;
    o.nearDistance = 0;
    o.cache = false;
    FarFieldOptions o2 = o;
    o2.rayStep = 2;
    for (double pitch : {0.0, -0.3}) {
        Camera c = cam(glm::dvec3(0, -190, 25.0), 0.2, pitch, 161, 121);
        const size_t N = size_t(c.width) * size_t(c.height);
        FarField exact(*t.rays, &t.grid, o), lattice(*t.rays, &t.grid, o2);
        Image a, b;
        FrameStats sa, sb;
        exact.render(c, nullptr, a, sa);
        lattice.render(c, nullptr, b, sb);
        EXPECT_EQ(sb.pixels.total(), N);
        EXPECT_EQ(sa.pixels.interpolated, 0u);
        EXPECT_GT(sb.pixels.interpolated, 0u);
        EXPECT_EQ(sb.raysCast + sb.pixels.interpolated, sa.raysCast);  // every far pixel: a ray or a blend
        EXPECT_LT(double(sb.raysCast), 0.7 * double(sa.raysCast));
        EXPECT_GE(lumaPsnr(a, b), 35.0) << "pitch " << pitch;
        // Lattice pixels are cast exactly as before.
        for (int y = 0; y < c.height; y += 2)
            for (int x = 0; x < c.width; x += 2) {
                const size_t i = size_t(y) * size_t(c.width) + size_t(x);
                if (lattice.classification()[i] == kFarRayHit || lattice.classification()[i] == kFarRayMiss) {
                    ASSERT_EQ(channelDiff(a, b, i), 0) << x << "," << y;
                }
            }
    }
    // One flat-coloured wall filling the view, and sky above it: every blended
    // pixel equals the exact one (the blend of equal colours, the sky of its own direction).
    SceneModel wall;
    SceneMesh m;
    addBox(m, {-500, 100, 0}, {500, 110, 40}, {90, 120, 150, 255});
    wall.meshes.push_back(m);
    auto rs = RayScene::build(wall);
    ASSERT_TRUE(rs.isOk());
    HeightGrid g = HeightGrid::build(wall, rs.value()->frameOrigin(), 64);
    Camera c = cam(glm::dvec3(0, 0, 20.0), 0.0, 0.0, 121, 81);
    FarField exact(*rs.value(), &g, o), lattice(*rs.value(), &g, o2);
    Image a, b;
    FrameStats sa, sb;
    exact.render(c, nullptr, a, sa);
    lattice.render(c, nullptr, b, sb);
    EXPECT_GT(sb.pixels.interpolated, sa.raysCast / 2);
    int worst = 0;
    for (size_t i = 0; i < size_t(c.width) * size_t(c.height); ++i) worst = std::max(worst, channelDiff(a, b, i));
    EXPECT_LE(worst, 1);
}
