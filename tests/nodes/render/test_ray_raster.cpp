// Ray / raster agreement (needs an X display: run under xvfb-run -a): still frames of the
// hybrid mode and of rays against the rasteriser, the far field composited inside an OSG frame.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <unistd.h>

#include <glm/gtc/matrix_transform.hpp>

#include "citygen/generate.h"
#include "runtime/engine/far_field.h"
#include "runtime/engine/horizon.h"
#include "runtime/engine/metrics.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/scene/scene_graph.h"
#include "nodes/render/mode_hybrid.h"
#include "nodes/render/offscreen.h"
#include "nodes/far_field_node.h"
#include "nodes/near_far_split.h"
#include "tests/runtime/engine/fixtures.h"

using namespace vista;
using namespace vista::test;

TEST(RayRaster, StillFrameOfHybridAndRaysMatchTheRasteriser) {
    const char* d = std::getenv("DISPLAY");
    if (!d || !*d) GTEST_SKIP() << "no X display: run the rendering tests under xvfb-run -a";
    CityParams p;
    p.size_m = 400;
    p.seed = 3;
    p.origin_x = 250000.0;  // far from the world origin: frames must still line up
    auto city = generateCity(p);
    ASSERT_TRUE(city.isOk()) << city.status().message();
    std::string path =
        std::filesystem::temp_directory_path() / ("vista_farfield_" + std::to_string(getpid()) + ".osgb");
    ASSERT_TRUE(writeCityFile(*city, path).isOk());
    auto loaded = loadCityFile(path);
    std::filesystem::remove(path);
    ASSERT_TRUE(loaded.isOk()) << loaded.status().message();
    auto rs = RayScene::build(*loaded);
    ASSERT_TRUE(rs.isOk());
    const int W = 160, H = 120;
    auto renderer = OffscreenRenderer::create(W, H);
    ASSERT_TRUE(renderer.isOk()) << "DISPLAY=" << d
                                 << " is set, but the renderer did not start: " << renderer.status().message();
    ModeContext ctx;
    ctx.city = &*loaded;
    ctx.scene = sceneRoot(*loaded);
    ctx.renderer = renderer->get();
    ctx.rays = rs->get();
    ctx.options.nearDistance = 60;
    ctx.options.pixelBudget = -1;
    auto hybrid = makeHybridMode(ctx);
    ASSERT_TRUE(hybrid.isOk()) << hybrid.status().message();
    // A street-level view along the first street edge, and an elevated one.
    const auto& g = loaded->streets;
    ASSERT_FALSE(g.nodes.empty());
    std::vector<Camera> cams;
    for (int k = 0; k < 2; ++k) {
        Camera c;
        const auto& n = g.nodes[size_t(k * 7) % g.nodes.size()];
        c.eye = glm::dvec3(p.origin_x + n.x, p.origin_y + n.y, k == 0 ? 1.7 : 25.0);
        c.heading = 0.4 + k;
        c.pitch = k == 0 ? 0.0 : -0.15;
        c.width = W;
        c.height = H;
        c.fovY = 60.0 * M_PI / 180.0;
        cams.push_back(c);
    }
    HeightGrid grid = HeightGrid::build(*loaded, rs.value()->frameOrigin(), 256);
    for (const Camera& c : cams) {
        Image full, hyb, rays;
        FrameStats fs, hs, rsStats;
        ASSERT_TRUE(renderer.value()->render(sceneRoot(*loaded), c, 0.0, &full, nullptr, fs).isOk());
        ASSERT_TRUE(hybrid.value()->renderFrame(c, hyb, hs).isOk());
        FarFieldOptions o;
        o.nearDistance = 0;
        FarField ff(*rs.value(), &grid, o);
        ff.render(c, nullptr, rays, rsStats);
        const double psnrH = lumaPsnr(hyb, full), psnrR = lumaPsnr(rays, full);
        EXPECT_GE(psnrH, 40.0) << "hybrid vs full";
        EXPECT_GE(psnrR, 35.0) << "all rays vs full";
        // The hybrid's GL pass draws no sky layer (RenderMode::drawsSky): the
        // far field must write every pixel it leaves uncovered. Where `full`
        // (drawn over the sky layer) shows bare sky, the hybrid shows the
        // same sky, and no pixel keeps the black clear colour.
        ASSERT_TRUE(hybrid.value()->drawsSky());
        Image sky;
        renderSky(c, sky);
        size_t bareSky = 0, sameSky = 0, black = 0;
        for (size_t i = 0; i < size_t(W) * H; ++i) {
            const uint8_t* f = &full.rgba[4 * i];
            const uint8_t* h = &hyb.rgba[4 * i];
            const uint8_t* s = &sky.rgba[4 * i];
            if (h[0] == 0 && h[1] == 0 && h[2] == 0) ++black;
            if (f[0] != s[0] || f[1] != s[1] || f[2] != s[2]) continue;
            ++bareSky;
            if (h[0] == s[0] && h[1] == s[1] && h[2] == s[2]) ++sameSky;
        }
        EXPECT_EQ(black, 0u);
        EXPECT_GT(bareSky, 0u);
        EXPECT_GE(double(sameSky), 0.99 * double(bareSky)) << "sky pixels of full that the hybrid shows otherwise";
        // The far field was really traced, not only blended in: hybrid pixels
        // beyond the near field hit far geometry, every ray is counted.
        EXPECT_GT(hs.pixels.covered, 0u);
        EXPECT_GT(hs.pixels.rayHit, 0u);
        EXPECT_TRUE(hs.stages.ran(Stage::Rays));
        EXPECT_GE(hs.raysCast, hs.pixels.rayHit + hs.pixels.rayMiss);
        EXPECT_EQ(hs.pixels.total(), uint64_t(W) * H);
        EXPECT_GT(rsStats.pixels.rayHit, 0u);
        EXPECT_EQ(rsStats.raysCast, rsStats.pixels.rayHit + rsStats.pixels.rayMiss);  // no near field: no seam rays
        std::printf(
            "camera z=%.1f: PSNR hybrid %.2f dB, rays-only %.2f dB; covered %llu horizon %llu hit %llu miss %llu, "
            "rays cast %llu\n",
            c.eye.z, psnrH, psnrR, (unsigned long long)hs.pixels.covered, (unsigned long long)hs.pixels.horizonCulled,
            (unsigned long long)hs.pixels.rayHit, (unsigned long long)hs.pixels.rayMiss,
            (unsigned long long)hs.raysCast);
    }
}

TEST(RayRaster, OsgNodesCompositeTheFarFieldInsideAnOsgFrame) {
    const char* d = std::getenv("DISPLAY");
    if (!d || !*d) GTEST_SKIP() << "no X display: run the rendering tests under xvfb-run -a";
    CityParams p;
    p.size_m = 400;
    p.seed = 5;
    auto city = generateCity(p);
    ASSERT_TRUE(city.isOk()) << city.status().message();
    std::string path = std::filesystem::temp_directory_path() / ("vista_farnode_" + std::to_string(getpid()) + ".osgb");
    ASSERT_TRUE(writeCityFile(*city, path).isOk());
    auto loaded = loadCityFile(path);
    std::filesystem::remove(path);
    ASSERT_TRUE(loaded.isOk());
    auto rs = RayScene::build(*loaded);
    ASSERT_TRUE(rs.isOk());
    HeightGrid grid = HeightGrid::build(*loaded, rs.value()->frameOrigin(), 256);
    HybridSceneOptions ho;
    ho.nearDistance = 50;
    NearFarSplit* split = nullptr;
    FarFieldNode* far = nullptr;
    osg::ref_ptr<osg::Group> hybrid = buildHybridScene(*loaded, *rs.value(), grid, ho, &split, &far);
    ASSERT_TRUE(split && far);
    EXPECT_GT(split->getNumChildren(), 4u);
    auto renderer = OffscreenRenderer::create(160, 120);
    ASSERT_TRUE(renderer.isOk()) << "DISPLAY=" << d
                                 << " is set, but the renderer did not start: " << renderer.status().message();
    Camera c;
    const auto& n = loaded->streets.nodes[3 % loaded->streets.nodes.size()];
    c.eye = glm::dvec3(n.x, n.y, 1.7);
    c.heading = 1.1;
    c.width = 160;
    c.height = 120;
    c.fovY = 60.0 * M_PI / 180.0;
    Image full, hyb;
    FrameStats fs, hs;
    ASSERT_TRUE(renderer.value()->render(sceneRoot(*loaded), c, 0.0, &full, nullptr, fs).isOk());
    ASSERT_TRUE(renderer.value()->render(hybrid.get(), c, 0.0, &hyb, nullptr, hs).isOk());
    // The split drew only part of the city; the far field filled the rest.
    EXPECT_LT(split->lastNearTriangles(), loaded->triangles);
    FrameStats st = far->lastStats();
    const uint64_t N = 160 * 120;
    EXPECT_EQ(st.pixels.covered + st.pixels.horizonCulled + st.pixels.cache + st.pixels.rayHit + st.pixels.rayMiss, N);
    EXPECT_GT(st.pixels.covered, 0u);
    EXPECT_GT(st.pixels.rayHit, 0u);  // far geometry was traced, not only the near field drawn
    EXPECT_GE(st.raysCast, st.pixels.rayHit + st.pixels.rayMiss);
    const double psnr = lumaPsnr(hyb, full);
    std::printf("OSG nodes: PSNR %.2f dB, near triangles %llu of %zu\n", psnr,
                (unsigned long long)split->lastNearTriangles(), loaded->triangles);
    EXPECT_GE(psnr, 40.0);
    // The viewer hides the sky layer under the hybrid (RenderMode::drawsSky):
    // the far-field node writes every uncovered pixel, so the picture is the same.
    Image noSky;
    ASSERT_TRUE(renderer.value()->render(hybrid.get(), c, 0.0, &noSky, nullptr, hs, /*skyLayer=*/false).isOk());
    EXPECT_EQ(noSky.rgba, hyb.rgba);
    // The node began that frame at cull time for the very camera its draw saw: the
    // horizon was traced during the near field's draw, and last frame's traced pixels
    // were cast ahead (FarField::beginFrame).
    auto noted = [](const FrameStats& s, const std::string& what) {
        return std::any_of(s.notes.begin(), s.notes.end(),
                           [&](const std::string& n) { return n.find(what) != std::string::npos; });
    };
    st = far->lastStats();
    EXPECT_TRUE(noted(st, "horizon overlapped"));
    EXPECT_TRUE(noted(st, "speculative rays: "));
    // Budget split: nearest children up to the budget.
    split->setTriangleBudget(1);
    ASSERT_TRUE(renderer.value()->render(hybrid.get(), c, 0.0, &hyb, nullptr, hs).isOk());
    EXPECT_EQ(split->lastNearCount(), 1u);
    EXPECT_GE(lumaPsnr(hyb, full), 35.0);
}
