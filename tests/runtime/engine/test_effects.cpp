// Effects without GL in the engine: haze maths and the reflection stage.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "citygen/effects.h"
#include "citygen/lighting.h"
#include "citygen/mesh_builder.h"
#include "citygen/params.h"
#include "bake/gen/baked_lighting.h"
#include "runtime/engine/far_field_rays.h"
#include "runtime/engine/frame_raycast.h"
#include "runtime/engine/frame_effects.h"
#include "runtime/engine/haze_kernels.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/engine/reflections.h"

namespace vista {
namespace {
// ---- haze ----------------------------------------------------------------------

TEST(Haze, KoschmiederContrastAtTheVisibilityAndStableFrom20mTo1e6m) {
    for (double v : {20.0, 150.0, 1500.0, 1e4, 1e6}) {
        FrameEffects fx;
        fx.haze = true;
        fx.visibility = v;
        // Independent: 2 % contrast at the visibility distance (Koschmieder, ln 50 = 3.912).
        EXPECT_NEAR(fx.transmittance(v), 0.02, 1e-4) << v;
        EXPECT_FLOAT_EQ(fx.transmittance(0), 1.0f);
        EXPECT_DOUBLE_EQ(fx.hazeFar(), v);
        const glm::u8vec4 c(10, 200, 30, 128), h = fx.hazeColor();
        EXPECT_EQ(fx.applyHaze(c, 0.0), c);
        const glm::u8vec4 far = fx.applyHaze(c, 1e9);
        for (int k = 0; k < 3; ++k) EXPECT_EQ(far[k], h[k]) << v;
        EXPECT_EQ(far.w, 128) << "glass marks survive haze";
        int last = -1;
        for (double z = 0; z <= 2 * v; z += v / 16) {  // monotone towards the haze colour
            const int d = std::abs(int(fx.applyHaze(c, z).y) - int(h.y));
            if (last >= 0) { EXPECT_LE(d, last) << v << " " << z; }
            last = d;
        }
        for (double z : {-1.0, std::numeric_limits<double>::infinity(), 1e300})
            EXPECT_TRUE(std::isfinite(fx.transmittance(z))) << z;
    }
}

// The haze kernels: the baseline's bytes agree with FrameEffects::applyHaze
// (exp evaluated by the library) within one level, and the AVX2 build of the
// same kernels gives exactly the baseline's bytes, so a frame does not depend
// on the machine that drew it. The covered rows: exactly the pixels of window
// depth < 1 change.
TEST(HazeKernels, BaselineMatchesApplyHazeAndAvx2MatchesTheBaselineByteForByte) {
    FrameEffects fx;
    fx.haze = true;
    fx.visibility = 600.0;
    HazeParams h;
    h.beta = float(fx.extinction());
    for (int k = 0; k < 3; ++k) h.colour[k] = float(fx.hazeColor()[k]);
    // Rows of 97 pixels: not a multiple of any vector width, so the loops' tails run too.
    const size_t width = 97, rows = 43, n = width * rows;
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> z(0.0f, 3000.0f);
    std::uniform_int_distribution<uint32_t> word;
    std::vector<float> depth(n);
    std::vector<uint32_t> pixels(n);
    for (size_t i = 0; i < n; ++i) {
        depth[i] = i % 7 == 0 ? std::numeric_limits<float>::infinity() : z(rng);
        pixels[i] = word(rng);
    }
    // Window depths of an infinite far plane (a = zNear, b = 1): eye depth zNear / (1 - d). Uncovered
    // (window depth 1): every third pixel of rows 0 .. 9, all of rows 10 .. 14; rows 15 .. are covered
    // but for the infinite depths (sky).
    const float zNear = 0.3f;
    std::vector<float> window(n);
    for (size_t i = 0; i < n; ++i) {
        const size_t y = i / width;
        const bool open = std::isinf(depth[i]) || (y < 10 && i % 3 == 0) || (y >= 10 && y < 15);
        window[i] = open ? 1.0f : 1.0f - zNear / std::max(depth[i], zNear);
    }
    auto run = [&](const HazeKernels& k, std::vector<uint32_t>& byDepth, std::vector<uint32_t>& covered) {
        byDepth = pixels;
        k.depth(reinterpret_cast<PixelWord*>(byDepth.data()), depth.data(), n, hazeTable(h.beta), h);
        covered = pixels;
        hazeCoveredRows(k, reinterpret_cast<PixelWord*>(covered.data()), window.data(), width, 0, rows, 1.0f / zNear,
                        1.0f, hazeTable(h.beta), h);
    };
    std::vector<uint32_t> base, baseCovered;
    run(hazeKernelsBaseline(), base, baseCovered);
    size_t changedOrChecked = 0;
    for (size_t i = 0; i < n; ++i) {
        glm::u8vec4 src, got;
        std::memcpy(&src, &pixels[i], 4);
        std::memcpy(&got, &base[i], 4);
        const glm::u8vec4 want = std::isinf(depth[i]) ? src : fx.applyHaze(src, depth[i]);
        for (int c = 0; c < 4; ++c)
            ASSERT_LE(std::abs(int(got[c]) - int(want[c])), c == 3 || std::isinf(depth[i]) ? 0 : 1) << i << " " << c;
        if (!(window[i] < 1.0f)) {
            EXPECT_EQ(baseCovered[i], pixels[i]) << "uncovered pixel " << i << " changed";
        } else {
            std::memcpy(&got, &baseCovered[i], 4);
            for (int c = 0; c < 4; ++c) ASSERT_LE(std::abs(int(got[c]) - int(want[c])), c == 3 ? 0 : 1) << i;
            ++changedOrChecked;
        }
    }
    EXPECT_GT(changedOrChecked, n / 2);
    const HazeKernels* avx2 = hazeKernelsAvx2();
    if (!avx2) GTEST_SKIP() << "this build or CPU has no AVX2 kernels; the baseline was checked";
    std::vector<uint32_t> wide, wideCovered;
    run(*avx2, wide, wideCovered);
    EXPECT_EQ(wide, base);
    EXPECT_EQ(wideCovered, baseCovered);
}

// The haze table (HazeTableView) against FrameEffects::applyHaze (exp by the
// library, in double) over the whole range of the effect: visibilities of
// 20 m to 1,000 km, eye depths from the near plane to 10^7 m (log-spaced),
// colours at both ends of the range; the covered pixels by window depth for
// finite and infinite far planes, the traced pixels by eye depth (and depth
// 0): every channel within one level, alpha kept, on both builds of the kernels.
TEST(HazeKernels, HazedPixelsStayWithinALevelFrom20mTo1000kmOfVisibility) {
    const glm::u8vec4 colours[] = {{0, 0, 0, 255}, {255, 255, 255, 0}, {10, 200, 30, 77}, {128, 64, 250, 129}};
    const float zNear = 0.25f;
    std::vector<const HazeKernels*> builds = {&hazeKernelsBaseline()};
    if (hazeKernelsAvx2()) builds.push_back(hazeKernelsAvx2());
    size_t checked = 0;
    for (double visibility : {20.0, 150.0, 600.0, 3000.0, 5e4, 1e6}) {
        FrameEffects fx;
        fx.haze = true;
        fx.visibility = visibility;
        HazeParams h;
        h.beta = float(fx.extinction());
        for (int k = 0; k < 3; ++k) h.colour[k] = float(fx.hazeColor()[k]);
        const HazeTableView table = hazeTable(h.beta);
        for (double zFar : {0.0, 50.0, 600.0, 5000.0}) {
            // The renderer's window depth d = b - a / z (infinite far plane: a = zNear, b = 1).
            const double a = zFar > 0 ? zNear * zFar / (zFar - zNear) : zNear,
                         b = zFar > 0 ? zFar / (zFar - zNear) : 1.0;
            std::vector<float> window;
            std::vector<uint32_t> pixels;
            for (double z = zNear; z < 1e7; z *= 1.013) {
                const float d = float(b - a / z);
                if (!(d < 1.0f)) break;  // beyond the far plane or past float's resolution: not covered
                for (const glm::u8vec4& c : colours) {
                    window.push_back(d);
                    uint32_t w;
                    std::memcpy(&w, &c, 4);
                    pixels.push_back(w);
                }
            }
            ASSERT_GT(window.size(), 100u) << visibility << " " << zFar;
            for (const HazeKernels* k : builds) {
                std::vector<uint32_t> out = pixels;
                hazeCoveredRows(*k, reinterpret_cast<PixelWord*>(out.data()), window.data(), window.size(), 0, 1,
                                float(1.0 / a), float(b), table, h);
                for (size_t i = 0; i < out.size(); ++i) {
                    glm::u8vec4 src, got;
                    std::memcpy(&src, &pixels[i], 4);
                    std::memcpy(&got, &out[i], 4);
                    const double z = a / (b - double(window[i]));  // the eye depth this window depth stands for
                    const glm::u8vec4 want = fx.applyHaze(src, z);
                    for (int c = 0; c < 3; ++c)
                        ASSERT_LE(std::abs(int(got[c]) - int(want[c])), 1)
                            << "visibility " << visibility << " zFar " << zFar << " z " << z << " channel " << c;
                    ASSERT_EQ(got[3], src[3]);
                    ++checked;
                }
            }
        }
        std::vector<float> eye = {0.0f};
        for (double z = zNear; z < 1e7; z *= 1.013) eye.push_back(float(z));
        std::vector<float> depth;
        std::vector<uint32_t> pixels;
        for (float z : eye)
            for (const glm::u8vec4& c : colours) {
                depth.push_back(z);
                uint32_t w;
                std::memcpy(&w, &c, 4);
                pixels.push_back(w);
            }
        for (const HazeKernels* k : builds) {
            std::vector<uint32_t> out = pixels;
            k->depth(reinterpret_cast<PixelWord*>(out.data()), depth.data(), depth.size(), table, h);
            for (size_t i = 0; i < out.size(); ++i) {
                glm::u8vec4 src, got;
                std::memcpy(&src, &pixels[i], 4);
                std::memcpy(&got, &out[i], 4);
                const glm::u8vec4 want = fx.applyHaze(src, double(depth[i]));
                for (int c = 0; c < 3; ++c)
                    ASSERT_LE(std::abs(int(got[c]) - int(want[c])), 1)
                        << "visibility " << visibility << " eye depth " << depth[i] << " channel " << c;
                ASSERT_EQ(got[3], src[3]);
                ++checked;
            }
        }
    }
    EXPECT_GT(checked, 20000u);
}

// A hand-built scene: a wall of glass (alpha kGlassAlpha) facing -y at y = 20
// and a red wall behind the camera at y = -30 (so the glass reflects red).
SceneModel glassScene() {
    SceneModel m;
    SceneMesh glass, red;
    auto quad = [](SceneMesh& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, glm::u8vec4 col) {
        const uint32_t base = uint32_t(s.positions.size());
        for (auto p : {a, b, c, d}) {
            s.positions.push_back(p);
            s.colors.push_back(col);
        }
        for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) s.indices.push_back(base + i);
    };
    // Counter-clockwise seen from -y (the camera side).
    quad(glass, {-50, 20, -10}, {50, 20, -10}, {50, 20, 40}, {-50, 20, 40}, {40, 60, 90, kGlassAlpha});
    quad(red, {50, -30, -10}, {-50, -30, -10}, {-50, -30, 40}, {50, -30, 40}, {230, 10, 10, 255});
    m.meshes = {glass, red};
    m.triangles = 4;
    return m;
}

Camera lookNorth(int w = 64, int h = 48) {
    Camera c;
    c.eye = {0, 0, 2};
    c.heading = 0;
    c.width = w;
    c.height = h;
    c.fovY = 0.8;
    return c;
}

TEST(Reflections, GlassReflectsTheCityAndNoGlassCastsNoRay) {
    auto rays = RayScene::build(glassScene());
    ASSERT_TRUE(rays) << rays.status().message();
    const Camera cam = lookNorth();
    FrameEffects fx;
    fx.glass = fx.glassMarked = true;
    fx.reflectance = 0.5;
    fx.rayBudget = 100000;
    Image img(cam.width, cam.height);
    RayCounts counts;
    castFrame(**rays, cam, img, counts, 1);
    const glm::u8vec4 before = img.at(cam.width / 2, cam.height / 2);
    ASSERT_EQ(before.w, kGlassAlpha) << "the ray caster keeps the glass mark";
    FrameStats st;
    reflectionStage(rays->get(), cam, fx, img, st);
    const glm::u8vec4 after = img.at(cam.width / 2, cam.height / 2);
    EXPECT_GT(int(after.x), int(before.x) + 40) << "red reflected into the glass";
    EXPECT_EQ(after.w, 255);
    EXPECT_TRUE(st.stages.ran(Stage::Reflect));
    EXPECT_TRUE(st.effects.ran(EffectId::Glass));
    EXPECT_GT(st.reflectionRays, 0u);
    EXPECT_FALSE(hasGlassPixels(img));
    // Independent Fresnel check at normal incidence-ish (centre pixel, cos ~ 1):
    // after = before (1 - F) + red F with F ~ F0 = 0.5.
    const double F = (double(after.x) - before.x) / (230.0 - before.x);
    EXPECT_NEAR(F, 0.5, 0.06);

    // Looking away from the glass: nothing marked, no stage, no ray.
    Camera away = cam;
    away.heading = 3.14159;
    Image img2(cam.width, cam.height);
    castFrame(**rays, away, img2, counts, 1);
    FrameStats st2;
    reflectionStage(rays->get(), away, fx, img2, st2);
    EXPECT_FALSE(st2.stages.ran(Stage::Reflect));
    EXPECT_EQ(st2.reflectionRays, 0u);
    EXPECT_EQ(st2.raysCast, 0u);
}

TEST(Reflections, BudgetBoundsTheRaysAndZeroBudgetOnlyClearsMarks) {
    auto rays = RayScene::build(glassScene());
    ASSERT_TRUE(rays);
    const Camera cam = lookNorth(320, 240);
    Image base(cam.width, cam.height);
    RayCounts counts;
    castFrame(**rays, cam, base, counts, 1);
    for (int64_t budget : {int64_t(0), int64_t(50), int64_t(1000), int64_t(1) << 40}) {
        FrameEffects fx;
        fx.glass = fx.glassMarked = true;
        fx.rayBudget = budget;
        Image img = base;
        FrameStats st;
        reflectionStage(rays->get(), cam, fx, img, st);
        EXPECT_FALSE(hasGlassPixels(img)) << budget;
        // Two rays (find the pane, reflect) per sampled block, at most `budget` blocks
        // (the stride stops at 64 pixels: at most ceil(320/64) * ceil(240/64) blocks).
        EXPECT_LE(st.reflectionRays,
                  uint64_t(2 * std::max<int64_t>(budget == 0 ? 0 : 20, std::min<int64_t>(budget, 320 * 240))))
            << budget;
        if (budget == 0) EXPECT_EQ(st.reflectionRays, 0u);
        else EXPECT_GT(st.reflectionRays, 0u);
    }
}

TEST(Reflections, GrazingAndParallelRaysStayFinite) {
    auto rays = RayScene::build(glassScene());
    ASSERT_TRUE(rays);
    FrameEffects fx;
    fx.glass = fx.glassMarked = true;
    fx.rayBudget = 1 << 20;
    fx.haze = true;
    fx.visibility = 20;                                           // the shortest haze too
    for (double heading : {1.55, 1.5707963, 1.58, -1.5707963}) {  // along the pane (x axis)
        for (double z : {20.0 - 1e-4, 20.0 - 0.01}) {             // eye on / next to the glass plane's side
            Camera c = lookNorth(96, 64);
            c.eye = {0, z, 2};
            c.heading = heading;
            Image img(c.width, c.height);
            RayCounts counts;
            castFrame(**rays, c, img, counts, 1);
            FrameStats st;
            reflectionStage(rays->get(), c, fx, img, st);
            EXPECT_FALSE(hasGlassPixels(img));
            for (size_t i = 3; i < img.rgba.size(); i += 4) ASSERT_EQ(img.rgba[i], 255);
        }
    }
}

}  // namespace
}  // namespace vista
