// The offscreen renderer and render modes without the bench: sky, colour/depth/orientation,
// bad sizes, OSG impostor sprites, the viewer's camera from OSG matrices, raycast against
// full, hybrid with an empty near field.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <unistd.h>

#include <osg/Geode>
#include <osg/Geometry>
#include <osg/MatrixTransform>
#include <glm/gtc/type_ptr.hpp>
#include <nlohmann/json.hpp>

#include "citygen/lighting.h"
#include "foundation/units.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_graph.h"
#include "runtime/engine/metrics.h"
#include "nodes/far_field_node.h"
#include "nodes/render/offscreen.h"
#include "nodes/render/render_mode.h"
#include "runtime/scene/paths.h"
#include "runtime/engine/ray_scene.h"
#include "tests/nodes/render/render_fixtures.h"

using namespace vista;
namespace fs = std::filesystem;
namespace {
Camera testCamera(int w = 96, int h = 72) {
    Camera c;
    c.width = w;
    c.height = h;
    c.fovY = 60.0 * kPi / 180.0;
    c.eye = kWorld + glm::dvec3(0, 0, 1.7);
    return c;
}

}  // namespace

TEST(Offscreen, SkyBackgroundMatchesTheCpuSkyExactly) {
    REQUIRE_DISPLAY();
    auto r = OffscreenRenderer::create(96, 72);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    osg::ref_ptr<osg::Group> empty = new osg::Group;
    Camera cam = testCamera();
    cam.pitch = 0.15;  // horizon below the centre: rows differ top to bottom
    Image img, sky;
    FrameStats st;
    ASSERT_TRUE(r.value()->render(empty.get(), cam, 0.0, &img, nullptr, st).isOk());
    renderSky(cam, sky);
    EXPECT_EQ(lumaPsnr(img, sky), kPsnrCapDb);
    EXPECT_NE(img.at(0, 0), img.at(0, 71));  // the gradient is there, row 0 at the top
    EXPECT_EQ(st.triangles, 0u);             // the background is not counted
}

TEST(Offscreen, ColourDepthOrientationAndCounts) {
    REQUIRE_DISPLAY();
    auto r = OffscreenRenderer::create(96, 72);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    // A red wall 50 m ahead (north) covering the upper half of a level view
    // (from eye height up), in a tile far from the world origin.
    SceneMesh wall;
    wall.origin = kWorld + glm::dvec3(0, 50, 0);
    addQuad(wall, {-500, 0, 1.7f}, {500, 0, 1.7f}, {500, 0, 900}, {-500, 0, 900}, {255, 0, 0, 255});
    auto scene = sceneOf({wall});
    Camera cam = testCamera();
    Image img;
    std::vector<float> depth;
    FrameStats st;
    ASSERT_TRUE(r.value()->render(scene.get(), cam, 0.0, &img, &depth, st).isOk());
    EXPECT_EQ(img.at(48, 0), glm::u8vec4(255, 0, 0, 255));                           // top: wall
    EXPECT_EQ(img.at(48, 71), skyColor(std::asin(cam.rayDirection(48.5, 71.5).z)));  // bottom: sky
    ASSERT_EQ(depth.size(), size_t(96 * 72));
    // Infinite far plane: window depth = 1 - zNear / distance.
    double d0 = depth[size_t(0 * 96 + 48)];
    double dist = 50.0 / glm::dot(cam.rayDirection(48.5, 0.5), cam.forward()) *
                  glm::dot(cam.rayDirection(48.5, 0.5), cam.forward());
    EXPECT_NEAR(d0, 1.0 - cam.zNear / dist, 1e-5);
    EXPECT_EQ(depth[size_t(71 * 96 + 48)], 1.0f);
    EXPECT_EQ(st.triangles, 2u);
    EXPECT_EQ(st.drawCalls, 1u);
    EXPECT_GT(st.frameMs, 0.0);

    // Near plane at 40 m: the wall at 50 m is gone.
    ASSERT_TRUE(r.value()->render(scene.get(), cam, 40.0, &img, nullptr, st).isOk());
    EXPECT_EQ(img.at(48, 0), skyColor(std::asin(cam.rayDirection(48.5, 0.5).z)));
    // A small object wholly beyond the near plane is culled, not just clipped.
    SceneMesh far;
    far.origin = kWorld + glm::dvec3(0, 200, 0);
    addQuad(far, {-5, 0, 0}, {5, 0, 0}, {5, 0, 10}, {-5, 0, 10}, {0, 255, 0, 255});
    auto farScene = sceneOf({far});
    ASSERT_TRUE(r.value()->render(farScene.get(), cam, 40.0, &img, nullptr, st).isOk());
    EXPECT_EQ(st.triangles, 0u);
    ASSERT_TRUE(r.value()->render(farScene.get(), cam, 0.0, &img, nullptr, st).isOk());
    EXPECT_EQ(st.triangles, 2u);
}

TEST(Offscreen, BadSizesAndMismatchedCameras) {
    EXPECT_FALSE(OffscreenRenderer::create(0, 0).isOk());
    REQUIRE_DISPLAY();
    auto r = OffscreenRenderer::create(32, 24);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    Image img;
    FrameStats st;
    osg::ref_ptr<osg::Group> empty = new osg::Group;
    EXPECT_FALSE(r.value()->render(empty.get(), testCamera(64, 48), 0.0, &img, nullptr, st).isOk());
}
namespace {
// A tile (double MatrixTransform) holding one coloured box, as a city file's tiles are.
osg::ref_ptr<osg::Node> boxTile(const glm::dvec3& origin, glm::vec3 lo, glm::vec3 hi, glm::u8vec4 colour) {
    SceneMesh m;
    m.origin = origin;
    addBox(m, lo, hi, colour);
    osg::ref_ptr<osg::Group> g = sceneOf({m});
    return g->getChild(0);
}

struct ImpostorFrame {
    std::string note;
    uint64_t triangles = 0, fullTriangles = 0;
    double psnrVsFull = 0;
};

// osgimpostor at `first` (sprites made there), then at `cam`, against full at `cam`.
ImpostorFrame renderOsgImpostor(osg::Group* scene, OffscreenRenderer& renderer, const Camera& first,
                                const Camera& cam) {
    ModeContext ctx;
    ctx.scene = scene;
    ctx.renderer = &renderer;
    ctx.options.nearDistance = 100;
    auto imp = createRenderMode("osgimpostor", ctx), full = createRenderMode("full", ctx);
    EXPECT_TRUE(imp.isOk() && full.isOk());
    if (!imp.isOk() || !full.isOk()) return {};
    Image a, b;
    FrameStats sa, sb;
    EXPECT_TRUE(imp.value()->renderFrame(first, a, sa).isOk());
    sa = FrameStats();
    EXPECT_TRUE(imp.value()->renderFrame(cam, a, sa).isOk());
    EXPECT_TRUE(full.value()->renderFrame(cam, b, sb).isOk());
    return {sa.notes.empty() ? "" : sa.notes.back(), sa.triangles, sb.triangles, lumaPsnr(a, b)};
}

}  // namespace

// Why osgimpostor scored 99 dB on small cities: osgSim::Impostor draws the
// real geometry while the eye is within nearD + r (or sqrt(2) r) of a tile's
// centre; when every tile is that close no sprite is ever drawn and the
// image is exactly `full`'s. A tile beyond the threshold is drawn as a sprite.
TEST(OsgImpostor, SpritesOnlyBeyondTheThreshold) {
    REQUIRE_DISPLAY();
    auto r = OffscreenRenderer::create(160, 120);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    Camera first = testCamera(160, 120), cam = first;
    cam.eye.x += 6.0;  // the sprite made at `first` is reused (its pixel error stays small)
    osg::ref_ptr<osg::Group> scene = new osg::Group;
    scene->getOrCreateStateSet()->setMode(GL_LIGHTING, osg::StateAttribute::OFF);
    scene->addChild(boxTile(kWorld + glm::dvec3(0, 60, 0), {-10, -5, 0}, {10, 5, 12}, {200, 80, 60, 255}));
    const ImpostorFrame within = renderOsgImpostor(scene.get(), *r.value(), first, cam);
    EXPECT_EQ(within.note, "impostors: 0 sprites, 1 geometry");
    EXPECT_EQ(within.triangles, within.fullTriangles);
    EXPECT_EQ(within.psnrVsFull, kPsnrCapDb) << "within the threshold osgimpostor is full";
    // A tall block 700 m ahead, right of the near one: beyond 100 m + its radius.
    scene->addChild(boxTile(kWorld + glm::dvec3(250, 700, 0), {-40, -20, 0}, {40, 20, 120}, {60, 90, 200, 255}));
    const ImpostorFrame beyond = renderOsgImpostor(scene.get(), *r.value(), first, cam);
    EXPECT_EQ(beyond.note, "impostors: 1 sprites, 1 geometry");
    EXPECT_EQ(beyond.triangles, within.triangles + 2) << "the far tile is one sprite quad, not its 10 triangles";
    EXPECT_EQ(beyond.fullTriangles, within.fullTriangles + 10);
    EXPECT_LT(beyond.psnrVsFull, kPsnrCapDb) << "the sprite made from the first viewpoint is not the geometry";
    EXPECT_GT(beyond.psnrVsFull, 20.0) << "the sprite shows the far tile";
    std::printf("osgimpostor with one sprite vs full: %.2f dB\n", beyond.psnrVsFull);
}

// The viewer derives the camera of its modes' frame hook from OSG's matrices.
TEST(ViewCamera, PoseFromOsgMatricesRoundTrips) {
    Camera c = testCamera(320, 240);
    c.eye = kWorld + glm::dvec3(12.5, -40.25, 31.0);
    c.heading = 2.1;
    c.pitch = -0.3;
    c.roll = 0.05;
    for (double zFar : {0.0, 1.0e5}) {
        Camera back;
        double zf = -1;
        ASSERT_TRUE(cameraFromOsg(osg::Matrixd(glm::value_ptr(c.view())),
                                  osg::Matrixd(glm::value_ptr(c.projection(zFar))), c.width, c.height, back, zf))
            << zFar;
        EXPECT_NEAR(glm::length(back.eye - c.eye), 0.0, 1e-6) << zFar;
        EXPECT_NEAR(back.heading, c.heading, 1e-9) << zFar;
        EXPECT_NEAR(back.pitch, c.pitch, 1e-9) << zFar;
        EXPECT_NEAR(back.roll, c.roll, 1e-9) << zFar;
        EXPECT_NEAR(back.fovY, c.fovY, 1e-9) << zFar;
        EXPECT_NEAR(zf, zFar, 1e-3 * zFar) << zFar;
    }
}

// The tiny city with its ray scene and a 160x120 renderer, as a ModeContext.
struct TinyModes {
    SceneModel city = tinyCity();
    std::unique_ptr<RayScene> rays;
    std::unique_ptr<OffscreenRenderer> renderer;
    ModeContext ctx;
    std::string error;
    TinyModes() {
        auto rs = RayScene::build(city);
        auto r = OffscreenRenderer::create(160, 120);
        if (!rs.isOk() || !r.isOk()) {
            error = (rs.isOk() ? r.status() : rs.status()).message();
            return;
        }
        rays = std::move(rs.value());
        renderer = std::move(r.value());
        ctx.city = &city;
        ctx.scene = sceneRoot(city);
        ctx.renderer = renderer.get();
        ctx.rays = rays.get();
    }
    bool ready() const { return error.empty(); }
};

// Ray casting and rasterising the same prelit scene agree: on a still frame
// luma PSNR >= 30 dB (differences only along edges, where pixel centres fall
// on different sides of a triangle edge).
TEST(Bench, RaycastAgreesWithFull) {
    REQUIRE_DISPLAY();
    TinyModes t;
    ASSERT_TRUE(t.ready()) << t.error;
    ModeContext& ctx = t.ctx;
    auto full = createRenderMode("full", ctx), ray = createRenderMode("raycast", ctx);
    ASSERT_TRUE(full.isOk());
    ASSERT_TRUE(ray.isOk()) << ray.status().message();
    Camera cam = testCamera(160, 120);
    cam.eye = kWorld + glm::dvec3(-10, -40, 1.7);
    cam.heading = 0.15;
    Image a, b;
    FrameStats sa, sb;
    ASSERT_TRUE(full.value()->renderFrame(cam, a, sa).isOk());
    ASSERT_TRUE(ray.value()->renderFrame(cam, b, sb).isOk());
    double psnr = lumaPsnr(a, b);
    EXPECT_GE(psnr, 30.0) << "raycast vs full";
    std::printf("raycast vs full on a still frame: %.2f dB, %.4f of pixels differ by > 8\n", psnr,
                fractionDiffering(a, b, 8));
    EXPECT_GT(sb.pixels.rayHit, 0u);
    EXPECT_GT(sb.pixels.rayMiss, 0u);
    EXPECT_EQ(sb.pixels.rayHit + sb.pixels.rayMiss, uint64_t(160 * 120));
    EXPECT_EQ(sb.raysCast, uint64_t(160 * 120));
}

// A near field with nothing in it needs no GL pass: the hybrid then skips the
// draw and the read-back and casts every pixel, as `raycast` does (the split's
// "0 m: ray casting" candidate). The tiny city is one chunk (its layout is not
// a tiled city file: bounds from OSG); from 2 km away it is beyond the 1 m
// near distance, and the hybrid's picture must be raycast's, with every pixel
// written although the GL pass (which would clear them) is gone.
TEST(Hybrid, AnEmptyNearFieldSkipsTheGlPassAndCastsEveryPixel) {
    REQUIRE_DISPLAY();
    TinyModes t;
    ASSERT_TRUE(t.ready()) << t.error;
    ModeContext& ctx = t.ctx;
    ctx.options.nearDistance = 1.0;
    ctx.options.cache = false;
    auto hyb = createRenderMode("hybrid", ctx), ray = createRenderMode("raycast", ctx);
    ASSERT_TRUE(hyb.isOk()) << hyb.status().message();
    ASSERT_TRUE(ray.isOk()) << ray.status().message();
    Camera cam = testCamera(160, 120);
    cam.eye = kWorld + glm::dvec3(0, -2000, 300);
    cam.pitch = -0.15;
    Image h(160, 120), c;
    for (size_t i = 0; i < h.rgba.size(); ++i) h.rgba[i] = uint8_t(i % 4 == 3 ? 255 : 7);  // stale content
    FrameStats sh, sc;
    ASSERT_TRUE(hyb.value()->renderFrame(cam, h, sh).isOk());
    ASSERT_TRUE(ray.value()->renderFrame(cam, c, sc).isOk());
    EXPECT_NE(std::find(sh.notes.begin(), sh.notes.end(), "near field empty: no GL pass"), sh.notes.end());
    EXPECT_EQ(sh.stages.ms(Stage::Near), 0.0);
    EXPECT_EQ(sh.pixels.covered, 0u);
    EXPECT_GT(sh.pixels.rayHit, 0u);
    EXPECT_EQ(fractionDiffering(h, c, 0), 0.0) << "hybrid without a near field vs raycast";
    // A near field that holds something (the eye inside the chunk's bounds) is drawn as before.
    cam.eye = kWorld + glm::dvec3(0, 0, 1.7);
    FrameStats sn;
    ASSERT_TRUE(hyb.value()->renderFrame(cam, h, sn).isOk());
    EXPECT_EQ(std::find(sn.notes.begin(), sn.notes.end(), "near field empty: no GL pass"), sn.notes.end());
    EXPECT_GT(sn.stages.ms(Stage::Near), 0.0);
}

namespace {
// True when a far-field stage (anything the hybrid adds to a plain GL or ray-cast frame) ran.
bool anyFarFieldStage(const FrameStats& s) {
    for (Stage st : {Stage::Opacity, Stage::Seam, Stage::Horizon, Stage::Cache, Stage::Composite})
        if (s.stages.ran(st)) return true;
    return false;
}
// Exactly equal images (sizes and every byte).
bool sameBytes(const Image& a, const Image& b) {
    return a.width == b.width && a.height == b.height && a.rgba == b.rgba;
}
}  // namespace

// The split's ends are the modes they stand for: at 0 m the hybrid's frame is
// the `raycast` frame (no GL pass, no read-back, no far-field stage) and at
// "everything" the `full` frame (no read-back, no far-field stage), byte for
// byte, in clear air and in haze (raycast hazes by the ray's depth, full in
// the rasteriser). Checked independently: ray casting vs rasterising the same
// frame agree to >= 30 dB (both ends are pictures of the city, not copies of
// each other), and the two end frames differ from the middle choice's
// classification (the hybrid at 20 m draws and casts).
TEST(Hybrid, EndPointsAreTheFramesOfTheirModes) {
    REQUIRE_DISPLAY();
    for (const bool haze : {false, true}) {
        TinyModes t;
        ASSERT_TRUE(t.ready()) << t.error;
        ModeContext& ctx = t.ctx;
        ctx.options.effects.haze = haze;
        ctx.options.effects.visibility = 120.0;
        auto full = createRenderMode("full", ctx), ray = createRenderMode("raycast", ctx);
        ASSERT_TRUE(full.isOk() && ray.isOk());
        Camera cam = testCamera(160, 120);
        cam.eye = kWorld + glm::dvec3(-10, -40, 1.7);
        cam.heading = 0.15;
        Image fa, ra;
        FrameStats fs, rs;
        ASSERT_TRUE(full.value()->renderFrame(cam, fa, fs).isOk());
        ASSERT_TRUE(ray.value()->renderFrame(cam, ra, rs).isOk());
        EXPECT_GE(lumaPsnr(fa, ra), 30.0) << "haze " << haze;

        // 0 m: ray casting.
        ctx.options.nearDistance = 0.0;
        auto h0 = createRenderMode("hybrid", ctx);
        ASSERT_TRUE(h0.isOk()) << h0.status().message();
        Image a(160, 120);
        for (size_t i = 0; i < a.rgba.size(); ++i) a.rgba[i] = 7;  // stale content
        FrameStats s0;
        ASSERT_TRUE(h0.value()->renderFrame(cam, a, s0).isOk());
        EXPECT_TRUE(sameBytes(a, ra)) << "hybrid at 0 m vs raycast, haze " << haze << ": "
                                      << fractionDiffering(a, ra, 0) << " of pixels differ";
        EXPECT_FALSE(s0.stages.ran(Stage::Near));
        EXPECT_FALSE(s0.stages.ran(Stage::Readback));
        EXPECT_FALSE(anyFarFieldStage(s0));
        EXPECT_EQ(s0.pixels.covered, 0u);
        EXPECT_EQ(s0.raysCast, rs.raysCast);
        EXPECT_EQ(s0.pixels.rayHit, rs.pixels.rayHit);
        EXPECT_EQ(s0.effects.ran(EffectId::Haze), haze);
        EXPECT_EQ(rs.effects.ran(EffectId::Haze), haze);

        // Everything near: the full frame.
        ctx.options.nearDistance = std::numeric_limits<double>::infinity();
        auto hInf = createRenderMode("hybrid", ctx);
        ASSERT_TRUE(hInf.isOk()) << hInf.status().message();
        Image b;
        FrameStats si;
        ASSERT_TRUE(hInf.value()->renderFrame(cam, b, si).isOk());
        EXPECT_TRUE(sameBytes(b, fa)) << "hybrid with everything near vs full, haze " << haze << ": "
                                      << fractionDiffering(b, fa, 0) << " of pixels differ";
        EXPECT_FALSE(anyFarFieldStage(si));
        EXPECT_FALSE(si.stages.ran(Stage::Rays));
        EXPECT_EQ(si.raysCast, 0u);
        EXPECT_EQ(si.triangles, fs.triangles);
        // The picture stays the same after another mode drew in between (the end frame restores
        // the renderer's effects, and the hybrid's haze of covered pixels is its own).
        ASSERT_TRUE(ray.value()->renderFrame(cam, ra, rs).isOk());
        ASSERT_TRUE(hInf.value()->renderFrame(cam, b, si).isOk());
        EXPECT_TRUE(sameBytes(b, fa)) << "haze " << haze;

        // A middle distance runs the far field (so the checks above can fail).
        ctx.options.nearDistance = 20.0;
        auto hMid = createRenderMode("hybrid", ctx);
        ASSERT_TRUE(hMid.isOk());
        Image m;
        FrameStats sm;
        ASSERT_TRUE(hMid.value()->renderFrame(cam, m, sm).isOk());
        EXPECT_TRUE(anyFarFieldStage(sm));
        EXPECT_TRUE(sm.stages.ran(Stage::Near));
    }
}

// `hybrid-fixed` is the hybrid at the fixed near distance even when --near is auto: the
// split's middle choice, for side-by-side runs.
TEST(Hybrid, FixedModeKeepsTheDefaultNearDistanceUnderAuto) {
    REQUIRE_DISPLAY();
    TinyModes t;
    ASSERT_TRUE(t.ready()) << t.error;
    t.ctx.options.nearDistance = -1.0;  // auto
    auto fixed = createRenderMode("hybrid-fixed", t.ctx);
    ASSERT_TRUE(fixed.isOk()) << fixed.status().message();
    EXPECT_EQ(fixed.value()->name(), "hybrid-fixed");
    Camera cam = testCamera(160, 120);
    Image img;
    FrameStats s;
    ASSERT_TRUE(fixed.value()->renderFrame(cam, img, s).isOk());
    for (const std::string& n : s.notes) EXPECT_EQ(n.rfind("near auto", 0), std::string::npos) << n;
    ASSERT_NE(fixed.value()->lastRaster(), nullptr);
    EXPECT_EQ(fixed.value()->lastRaster()->nearDistance, kDefaultNearDistance);
}
