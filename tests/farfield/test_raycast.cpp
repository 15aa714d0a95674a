// RayScene (Embree) tests: hits, colours, packets, instances, precision far
// from the world origin, empty and malformed input.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include "runtime/engine/ray_scene.h"
#include "runtime/scene/scene_graph.h"
#include "tests/farfield/fixtures.h"

using namespace vista;
using namespace vista::test;

namespace {

SceneModel oneBox(double ox = 0, double oy = 0) {
    SceneModel c;
    c.params.origin_x = ox;
    c.params.origin_y = oy;
    SceneMesh m;
    m.origin = glm::dvec3(ox, oy, 0);
    addBox(m, {-5, -10, 0}, {5, 10, 20}, {200, 100, 50, 255});
    c.meshes.push_back(m);
    return c;
}

}  // namespace

TEST(RayScene, HitsBoxFaceWithDistanceColourAndNormal) {
    auto rs = RayScene::build(oneBox());
    ASSERT_TRUE(rs.isOk()) << rs.status().message();
    EXPECT_EQ(rs.value()->triangleCount(), 12u);
    RayHit h = rs.value()->intersect({0, -50, 5}, {0, 1, 0});
    ASSERT_TRUE(h.hit);
    EXPECT_NEAR(h.t, 40.0f, 1e-4f);
    EXPECT_EQ(h.color, glm::u8vec4(200, 100, 50, 255));
    EXPECT_NEAR(h.normal.y, -1.0f, 1e-5f);
    // Pointing away: miss.
    EXPECT_FALSE(rs.value()->intersect({0, -50, 5}, {0, -1, 0}).hit);
    // tfar before the face: miss; occluded agrees.
    EXPECT_FALSE(rs.value()->intersect({0, -50, 5}, {0, 1, 0}, 0.0f, 39.0f).hit);
    EXPECT_FALSE(rs.value()->occluded({0, -50, 5}, {0, 1, 0}, 0.0f, 39.0f));
    EXPECT_TRUE(rs.value()->occluded({0, -50, 5}, {0, 1, 0}, 0.0f, 41.0f));
}

TEST(RayScene, InterpolatesVertexColoursLikeTheRasteriser) {
    SceneModel c;
    SceneMesh m;
    m.positions = {{0, 0, 0}, {10, 0, 0}, {0, 10, 0}};
    m.colors = {{255, 0, 0, 255}, {0, 255, 0, 255}, {0, 0, 255, 255}};
    m.indices = {0, 1, 2};
    c.meshes.push_back(m);
    auto rs = RayScene::build(c);
    ASSERT_TRUE(rs.isOk());
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.2f, 4.5f);
    for (int i = 0; i < 50; ++i) {
        float x = u(rng), y = u(rng);
        RayHit h = rs.value()->intersect({x, y, 10}, {0, 0, -1});
        ASSERT_TRUE(h.hit);
        // Independent barycentrics of (x, y) in the triangle.
        float b1 = x / 10, b2 = y / 10, b0 = 1 - b1 - b2;
        EXPECT_NEAR(h.color.x, 255 * b0, 0.51f + 255 * 1e-5f);
        EXPECT_NEAR(h.color.y, 255 * b1, 0.51f + 255 * 1e-5f);
        EXPECT_NEAR(h.color.z, 255 * b2, 0.51f + 255 * 1e-5f);
    }
}

TEST(RayScene, PacketsAgreeWithSingleRays) {
    SceneModel city = randomCity(3, 60);
    auto rs = RayScene::build(city);
    ASSERT_TRUE(rs.isOk()) << rs.status().message();
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> a(-3.14159f, 3.14159f), e(-0.6f, 0.3f);
    const int n = 203;  // not a multiple of 8
    std::vector<glm::vec3> org(n), dir(n);
    for (int i = 0; i < n; ++i) {
        org[i] = {0, 0, 1.7f};
        float az = a(rng), el = e(rng);
        dir[i] = {std::sin(az) * std::cos(el), std::cos(az) * std::cos(el), std::sin(el)};
    }
    std::vector<RayHit> many(n);
    rs.value()->intersectMany(org.data(), dir.data(), n, many.data());
    int hits = 0;
    for (int i = 0; i < n; ++i) {
        RayHit one = rs.value()->intersect(org[i], dir[i]);
        ASSERT_EQ(one.hit, many[i].hit) << i;
        if (one.hit) {
            ++hits;
            EXPECT_NEAR(one.t, many[i].t, 1e-3f * one.t);
            EXPECT_EQ(one.color, many[i].color);
        }
    }
    EXPECT_GT(hits, n / 4);
}

TEST(RayScene, InstancesUseWorldTransformAndNormals) {
    SceneModel c;
    SceneMesh proto;
    addBox(proto, {-1, -1, 0}, {1, 1, 4}, {10, 150, 20, 255});
    c.prototypes.push_back(proto);
    SceneInstance a;
    a.prototype = 0;
    a.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(0, 30, 0));
    SceneInstance b;
    b.prototype = 0;
    b.transform = glm::rotate(glm::translate(glm::dmat4(1.0), glm::dvec3(30, 0, 0)), 0.5 * M_PI, glm::dvec3(0, 0, 1)) *
                  glm::scale(glm::dmat4(1.0), glm::dvec3(2.0));
    c.instances = {a, b};
    auto rs = RayScene::build(c);
    ASSERT_TRUE(rs.isOk()) << rs.status().message();
    EXPECT_EQ(rs.value()->triangleCount(), 24u);
    RayHit h = rs.value()->intersect({0, 0, 2}, {0, 1, 0});
    ASSERT_TRUE(h.hit);
    EXPECT_NEAR(h.t, 29.0f, 1e-4f);
    EXPECT_NE(h.instId, 0xFFFFFFFFu);
    EXPECT_EQ(h.color, glm::u8vec4(10, 150, 20, 255));
    EXPECT_NEAR(h.normal.y, -1.0f, 1e-4f);
    RayHit g = rs.value()->intersect({0, 0, 2}, {1, 0, 0});  // scaled x2: face at x = 28
    ASSERT_TRUE(g.hit);
    EXPECT_NEAR(g.t, 28.0f, 1e-4f);
    EXPECT_NEAR(g.normal.x, -1.0f, 1e-4f);
    EXPECT_FALSE(rs.value()->intersect({0, 0, 9}, {1, 0, 0}).hit);  // above the scaled box (height 8)
}

TEST(RayScene, PreciseOneThousandKilometresFromOrigin) {
    const double ox = 1.0e6, oy = -1.0e6;
    auto rs = RayScene::build(oneBox(ox, oy));
    ASSERT_TRUE(rs.isOk());
    EXPECT_EQ(rs.value()->frameOrigin(), glm::dvec3(ox, oy, 0));
    // Camera at world (ox + 0.003, oy - 50.0, 5): scene-local org.
    glm::dvec3 eye(ox + 0.003, oy - 50.0, 5.0);
    glm::vec3 org(eye - rs.value()->frameOrigin());
    RayHit h = rs.value()->intersect(org, {0, 1, 0});
    ASSERT_TRUE(h.hit);
    EXPECT_NEAR(h.t, 40.0f, 1e-4f);
    // Grazing the box edge at x = 5 - 0.001: still a hit; just outside: miss.
    EXPECT_TRUE(rs.value()->intersect({4.999f, -50, 5}, {0, 1, 0}).hit);
    EXPECT_FALSE(rs.value()->intersect({5.001f, -50, 5}, {0, 1, 0}).hit);
}

TEST(RayScene, EmptyCityBuildsAndMisses) {
    SceneModel c;
    auto rs = RayScene::build(c);
    ASSERT_TRUE(rs.isOk()) << rs.status().message();
    EXPECT_EQ(rs.value()->triangleCount(), 0u);
    EXPECT_FALSE(rs.value()->intersect({0, 0, 0}, {0, 0, 1}).hit);
    glm::vec3 o(0), d(0, 1, 0);
    RayHit h;
    h.hit = true;
    rs.value()->intersectMany(&o, &d, 1, &h);
    EXPECT_FALSE(h.hit);
}

TEST(RayScene, RejectsMalformedMeshes) {
    SceneModel c = oneBox();
    c.meshes[0].indices.push_back(999);
    c.meshes[0].indices.push_back(0);
    c.meshes[0].indices.push_back(1);
    auto rs = RayScene::build(c);
    ASSERT_FALSE(rs.isOk());
    EXPECT_NE(rs.status().message().find("mesh 0"), std::string::npos);
    SceneModel d = oneBox();
    d.instances.push_back({3, glm::dmat4(1.0)});
    EXPECT_FALSE(RayScene::build(d).isOk());
}

TEST(RayScene, CullsBackFacesLikeTheRasteriser) {
    auto rs = RayScene::build(oneBox());
    ASSERT_TRUE(rs.isOk());
    // From inside the box every face is a back face: nothing is hit.
    EXPECT_FALSE(rs.value()->intersect({0, 0, 5}, {0, 1, 0}).hit);
    EXPECT_FALSE(rs.value()->intersect({0, 0, 5}, {0, 0, 1}).hit);
    EXPECT_FALSE(rs.value()->occluded({0, 0, 5}, {1, 0, 0}, 0.0f, 100.0f));
    // From outside, the far side's back face is skipped and the front face hit.
    RayHit h = rs.value()->intersect({0, 50, 5}, {0, -1, 0});
    ASSERT_TRUE(h.hit);
    EXPECT_NEAR(h.t, 40.0f, 1e-4f);
    EXPECT_NEAR(h.normal.y, 1.0f, 1e-5f);
}

// ---- ray / raster agreement (needs an X display: run under xvfb-run -a) ----
#include <cstdlib>
#include <filesystem>
#include <unistd.h>

#include "citygen/generate.h"
#include "runtime/engine/far_field.h"
#include "runtime/engine/horizon.h"
#include "runtime/engine/metrics.h"
#include "nodes/render/mode_hybrid.h"
#include "nodes/render/offscreen.h"
#include "nodes/far_field_node.h"
#include "nodes/near_far_split.h"

TEST(RayRaster, StillFrameOfHybridAndRaysMatchTheRasteriser) {
    const char* d = std::getenv("DISPLAY");
    if (!d || !*d) GTEST_SKIP() << "no X display: run the rendering tests under xvfb-run -a";
    CityParams p;
    p.size_m = 400;
    p.seed = 3;
    p.origin_x = 250000.0;  // far from the world origin: frames must still line up
    auto city = generateCity(p);
    ASSERT_TRUE(city.isOk()) << city.status().message();
    std::string path = std::filesystem::temp_directory_path() / ("vista_farfield_" + std::to_string(getpid()) + ".osgb");
    ASSERT_TRUE(writeCityFile(*city, path).isOk());
    auto loaded = loadCityFile(path);
    std::filesystem::remove(path);
    ASSERT_TRUE(loaded.isOk()) << loaded.status().message();
    auto rs = RayScene::build(*loaded);
    ASSERT_TRUE(rs.isOk());
    const int W = 160, H = 120;
    auto renderer = OffscreenRenderer::create(W, H);
    ASSERT_TRUE(renderer.isOk()) << "DISPLAY=" << d << " is set, but the renderer did not start: "
                                 << renderer.status().message();
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
        std::printf("camera z=%.1f: PSNR hybrid %.2f dB, rays-only %.2f dB; covered %llu horizon %llu hit %llu miss %llu, "
                    "rays cast %llu\n",
                    c.eye.z, psnrH, psnrR, (unsigned long long)hs.pixels.covered,
                    (unsigned long long)hs.pixels.horizonCulled, (unsigned long long)hs.pixels.rayHit,
                    (unsigned long long)hs.pixels.rayMiss, (unsigned long long)hs.raysCast);
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
    ASSERT_TRUE(renderer.isOk()) << "DISPLAY=" << d << " is set, but the renderer did not start: "
                                 << renderer.status().message();
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
    std::printf("OSG nodes: PSNR %.2f dB, near triangles %llu of %zu\n", psnr, (unsigned long long)split->lastNearTriangles(),
                loaded->triangles);
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
        return std::any_of(s.notes.begin(), s.notes.end(), [&](const std::string& n) { return n.find(what) != std::string::npos; });
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
