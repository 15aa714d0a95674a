// Far-field frame tests: the staged FarField against a straightforward
// per-pixel reference (Camera::rayDirection + RayScene::intersect, depth
// unprojected with the camera's own matrices), truthful ray counts (seam
// rays that miss), stages run only when called for, and the primary-ray
// caster shared with the `raycast` mode (per-pixel rays, the raycast mode's
// row batches, pixel lists, thread counts).
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
#include "runtime/engine/far_field_stages.h"
#include "runtime/engine/frame_raycast.h"
#include "runtime/engine/horizon.h"
#include "runtime/engine/metrics.h"
#include "runtime/engine/ray_scene.h"
#include "tests/runtime/engine/fixtures.h"
#include "tests/runtime/engine/far_field_fixtures.h"

using namespace vista;
using namespace vista::test;
namespace {
// A fake near field: window depth (projection with far plane zFar, <= 0 =
// infinite) of every pixel whose first hit lies within `cut` metres; the
// surface is pushed back by 5 % in every third column, so seam rays of those
// pixels hit the surface in front while the others miss. Colours of covered
// pixels are a marker the far field must leave alone.
std::vector<float> fakeNearField(const RayScene& rs, const Camera& c, double cut, double zFar, Image& img) {
    img = Image(c.width, c.height);
    std::vector<float> depth(size_t(c.width) * size_t(c.height), 1.0f);
    const glm::dmat4 pv = c.projection(zFar) * c.view();
    const glm::vec3 org(c.eye - rs.frameOrigin());
    for (int y = 0; y < c.height; ++y)
        for (int x = 0; x < c.width; ++x) {
            const glm::dvec3 d = c.rayDirection(x + 0.5, y + 0.5);
            const RayHit h = rs.intersect(org, glm::vec3(d));
            if (!h.hit || h.t > cut) continue;
            const glm::dvec4 clip = pv * glm::dvec4(c.eye + d * (double(h.t) * (x % 3 == 0 ? 1.05 : 1.0)), 1.0);
            depth[size_t(y) * size_t(c.width) + size_t(x)] = float(std::min(0.5 * (clip.z / clip.w) + 0.5, 0.9999999));
            img.set(x, y, glm::u8vec4(1, 2, 3, 255));
        }
    return depth;
}

// The straightforward far field: covered pixels keep their colour unless
// their seam ray (depth unprojected to a distance beyond the near distance,
// cast up to just before it) hits; every other pixel gets its own ray's hit
// colour or the sky.
struct Reference {
    Image image;
    std::vector<uint8_t> hit;      // per pixel: 1 = shows a ray's hit (uncovered or seam)
    std::vector<uint8_t> covered;  // per pixel: covered and kept
    uint64_t seamRays = 0, seamHits = 0;
};

Reference reference(const RayScene& rs, const Camera& c, const float* depth, const Image& start,
                    const FarFieldOptions& o) {
    Reference r;
    r.image = start;
    const size_t N = size_t(c.width) * size_t(c.height);
    r.hit.assign(N, 0);
    r.covered.assign(N, 0);
    const glm::dmat4 inv = glm::inverse(c.projection(o.depthZFar));
    const glm::vec3 org(c.eye - rs.frameOrigin());
    // A near field given as a distance holds every surface nearer than it
    // (FarFieldOptions::nearIsDistance), so rays start just short of it.
    const float tnear = o.nearIsDistance && o.nearDistance > 0 ? float(o.nearDistance * 0.999) : 0.0f;
    for (int y = 0; y < c.height; ++y)
        for (int x = 0; x < c.width; ++x) {
            const size_t i = size_t(y) * size_t(c.width) + size_t(x);
            const glm::dvec3 d = c.rayDirection(x + 0.5, y + 0.5);
            if (depth && depth[i] < 1.0f) {
                r.covered[i] = 1;
                const glm::dvec4 ndc(2.0 * (x + 0.5) / c.width - 1.0, 1.0 - 2.0 * (y + 0.5) / c.height,
                                     2.0 * depth[i] - 1.0, 1.0);
                const glm::dvec4 e = inv * ndc;
                const double dist = glm::length(glm::dvec3(e) / e.w);
                if (!o.verifySeam || o.nearDistance <= 0 || dist <= o.nearDistance) continue;
                ++r.seamRays;
                const RayHit h = rs.intersect(org, glm::vec3(d), tnear, float(dist * (1.0 - 1e-3)));
                if (h.hit) {
                    ++r.seamHits;
                    r.covered[i] = 0;
                    r.hit[i] = 1;
                    r.image.set(x, y, opaque(h));
                }
                continue;
            }
            const RayHit h = rs.intersect(org, glm::vec3(d), tnear);
            r.hit[i] = h.hit ? 1 : 0;
            r.image.set(x, y, h.hit ? opaque(h) : skyOf(d));
        }
    return r;
}

}  // namespace

// Tolerance: a packet and a single ray may in principle disagree on a hit
// that grazes a triangle edge, so up to 0.1 % of the pixels may differ from
// the reference; every other pixel equals it within 1 per channel and has the
// matching class. (Measured here: no pixel differs.)
TEST(FarFieldFrame, MatchesAPerPixelReferenceWithTruthfulCounts) {
    uint64_t seamHitsTotal = 0, seamMissesTotal = 0, horizonTotal = 0, hitsTotal = 0, badTotal = 0;
    for (uint32_t seed : {3u, 6u}) {
        const double ox = seed == 6 ? 1.0e6 : 0.0;  // also 1,000 km from the origin
        const TestCity t = testCity(seed, 70, ox);
        ASSERT_TRUE(t.rays);
        const glm::dvec3 o = t.rays->frameOrigin();
        struct Case {
            Camera camera;
            double nearD, zFar;
            bool nearField;
        };
        const std::vector<Case> cases = {
            {cam(o + glm::dvec3(0, -150, 1.7), 0.2), 30, 60, true},                    // street, finite far plane
            {cam(o + glm::dvec3(20, -170, 25), 0.4, -0.2), 35, 0, true},               // elevated, infinite far plane
            {cam(o + glm::dvec3(0, -190, 1.7), 0.1, 0.0, 120, 80, 0.2), 0, 0, false},  // rolled: no horizon
            {cam(o + glm::dvec3(-30, -120, 3.0), -0.3, 0.05), 25, 45, true},
        };
        for (size_t ci = 0; ci < cases.size(); ++ci) {
            const Case& k = cases[ci];
            const Camera& c = k.camera;
            const size_t N = size_t(c.width) * size_t(c.height);
            Image start;
            std::vector<float> depth = fakeNearField(*t.rays, c, k.nearD * 1.4, k.zFar, start);
            const float* dp = k.nearField ? depth.data() : nullptr;
            if (!k.nearField) start = Image(c.width, c.height);
            FarFieldOptions opt;
            opt.nearDistance = k.nearD;
            opt.depthZFar = k.zFar;
            opt.pixelBudget = -1;
            const Reference ref = reference(*t.rays, c, dp, start, opt);
            Image first;
            for (int threads : {2, 1}) {
                opt.threads = threads;
                FarField ff(*t.rays, &t.grid, opt);
                Image img = start;
                FrameStats st;
                ff.render(c, dp, img, st);
                const std::string where = "seed " + std::to_string(seed) + " case " + std::to_string(ci);
                const auto& cls = ff.classification();
                ASSERT_EQ(cls.size(), N);
                size_t bad = 0;
                PixelCounts counted;
                for (size_t i = 0; i < N; ++i) {
                    const uint8_t k2 = cls[i];
                    counted.covered += k2 == kFarCovered;
                    counted.horizonCulled += k2 == kFarHorizon;
                    counted.cache += k2 == kFarCache;
                    counted.rayHit += k2 == kFarRayHit;
                    counted.rayMiss += k2 == kFarRayMiss;
                    const bool classOk = ref.covered[i] ? k2 == kFarCovered
                                         : ref.hit[i]   ? k2 == kFarRayHit
                                                        : (k2 == kFarRayMiss || k2 == kFarHorizon);
                    if (!classOk || channelDiff(img, ref.image, i) > 1) ++bad;
                }
                EXPECT_LE(bad, N / 1000) << where;
                badTotal += bad;
                // Counts: the classification's, and every ray (seam rays hit or miss).
                EXPECT_EQ(st.pixels.covered, counted.covered) << where;
                EXPECT_EQ(st.pixels.horizonCulled, counted.horizonCulled) << where;
                EXPECT_EQ(st.pixels.cache, 0u) << where;
                EXPECT_EQ(st.pixels.rayHit, counted.rayHit) << where;
                EXPECT_EQ(st.pixels.rayMiss, counted.rayMiss) << where;
                const uint64_t traced = st.pixels.rayHit - ref.seamHits + st.pixels.rayMiss;
                EXPECT_EQ(st.raysCast, ref.seamRays + traced) << where;
                EXPECT_EQ(st.stages.ran(Stage::Seam), dp != nullptr) << where;
                EXPECT_EQ(st.stages.ran(Stage::Horizon), c.roll == 0.0) << where;
                EXPECT_TRUE(st.stages.ran(Stage::Rays) && st.stages.ran(Stage::Composite)) << where;
                // Determinism: bit-identical whatever the thread count.
                if (threads == 2) first = img;
                else EXPECT_TRUE(img.rgba == first.rgba) << where;
                if (threads == 1) {
                    seamHitsTotal += ref.seamHits;
                    seamMissesTotal += ref.seamRays - ref.seamHits;
                    horizonTotal += st.pixels.horizonCulled;
                    hitsTotal += st.pixels.rayHit;
                }
            }
        }
    }
    std::printf("reference: %llu pixels differ; seam rays hit %llu, missed %llu; horizon %llu; ray hits %llu\n",
                (unsigned long long)badTotal, (unsigned long long)seamHitsTotal, (unsigned long long)seamMissesTotal,
                (unsigned long long)horizonTotal, (unsigned long long)hitsTotal);
    // The scenes exercise what they claim: seam rays that hit and that miss,
    // horizon culling and traced far geometry.
    EXPECT_GT(seamHitsTotal, 0u);
    EXPECT_GT(seamMissesTotal, 0u);
    EXPECT_GT(horizonTotal, 0u);
    EXPECT_GT(hitsTotal, 0u);
}

TEST(FarFieldFrame, SeamRaysThatMissAreCountedAsRaysAndStayCovered) {
    const TestCity t = testCity(5, 60);
    ASSERT_TRUE(t.rays);
    Camera c = cam(glm::dvec3(0, -150, 1.7), 0.3);
    const size_t N = size_t(c.width) * size_t(c.height);
    // The near field's true depth (no push-back): nothing lies in front of any
    // drawn surface, so every seam ray misses.
    std::vector<float> depth(N, 1.0f);
    const glm::dmat4 pv = c.projection(80.0) * c.view();
    const glm::vec3 org(c.eye - t.rays->frameOrigin());
    uint64_t beyond = 0, coveredPixels = 0;
    const double nearD = 20.0;
    for (int y = 0; y < c.height; ++y)
        for (int x = 0; x < c.width; ++x) {
            const glm::dvec3 d = c.rayDirection(x + 0.5, y + 0.5);
            const RayHit h = t.rays->intersect(org, glm::vec3(d));
            if (!h.hit || h.t > 70.0f) continue;
            const glm::dvec4 clip = pv * glm::dvec4(c.eye + d * double(h.t), 1.0);
            depth[size_t(y) * size_t(c.width) + size_t(x)] = float(0.5 * (clip.z / clip.w) + 0.5);
            ++coveredPixels;
            beyond += h.t > nearD * 1.01 ? 1 : 0;
        }
    ASSERT_GT(beyond, 100u);
    FarFieldOptions o;
    o.nearDistance = nearD;
    o.depthZFar = 80.0;
    FarField ff(*t.rays, &t.grid, o);
    Image img(c.width, c.height);
    FrameStats st;
    ff.render(c, depth.data(), img, st);
    EXPECT_TRUE(st.stages.ran(Stage::Seam));
    EXPECT_EQ(st.pixels.covered, coveredPixels);  // missed seam rays leave pixels covered
    EXPECT_GT(st.raysCast, st.pixels.rayHit + st.pixels.rayMiss);
    EXPECT_GE(st.raysCast - (st.pixels.rayHit + st.pixels.rayMiss), beyond);
    EXPECT_EQ(st.pixels.total(), N);
    // Without the seam check the same frame casts exactly its traced pixels.
    o.verifySeam = false;
    ff.setOptions(o);
    FrameStats s2;
    ff.render(c, depth.data(), img, s2);
    EXPECT_FALSE(s2.stages.ran(Stage::Seam));
    EXPECT_EQ(s2.raysCast, s2.pixels.rayHit + s2.pixels.rayMiss);
    EXPECT_EQ(s2.pixels.covered, coveredPixels);
}

TEST(FarFieldFrame, StagesRunOnlyWhenCalledFor) {
    const TestCity t = testCity(7, 50);
    ASSERT_TRUE(t.rays);
    Camera c = cam(glm::dvec3(0, -190, 1.7), 0.0);
    const size_t N = size_t(c.width) * size_t(c.height);
    FarFieldOptions o;
    o.nearDistance = 0;
    FarField ff(*t.rays, &t.grid, o);
    Image img;
    // Cache on, no cap: the first frame traces every far pixel (nothing cached yet).
    FrameStats a;
    ff.render(c, nullptr, img, a);
    EXPECT_TRUE(a.stages.ran(Stage::Cache));
    EXPECT_EQ(a.pixels.cache, 0u);
    EXPECT_TRUE(a.stages.ran(Stage::Opacity));
    EXPECT_FALSE(a.stages.ran(Stage::Seam));  // nothing covered
    EXPECT_EQ(a.raysCast, a.pixels.rayHit + a.pixels.rayMiss);
    EXPECT_EQ(a.pixels.horizonCulled + a.pixels.rayHit + a.pixels.rayMiss, N);
    // The same camera again: every far pixel is exact in the cache, no ray.
    const Image first = img;
    FrameStats a2;
    ff.render(c, nullptr, img, a2);
    EXPECT_EQ(a2.raysCast, 0u);
    EXPECT_EQ(a2.pixels.cache, a.pixels.rayHit + a.pixels.rayMiss);
    EXPECT_EQ(img.rgba, first.rgba);
    // A budget caps the rays of a moved camera.
    o.pixelBudget = 500;
    ff.setOptions(o);
    FrameStats b;
    Camera moved = c;
    moved.eye.x += 5.0;
    ff.render(moved, nullptr, img, b);
    EXPECT_TRUE(b.stages.ran(Stage::Cache));
    EXPECT_LE(b.raysCast, 500u);
    EXPECT_GT(b.pixels.cache, 0u);
    // A frame-time target below what the frame costs: the budget falls to its floor (1 % of the pixels, >= 64).
    o.pixelBudget = -1;
    o.frameMsTarget = 1e-6;
    ff.setOptions(o);
    FrameStats tight;
    moved.eye.x += 5.0;
    ff.render(moved, nullptr, img, tight);
    const uint64_t floor = std::max<uint64_t>(64, N / 100);
    EXPECT_TRUE(has(tight, "cache budget " + std::to_string(floor) + " rays"));
    EXPECT_LE(tight.raysCast, floor);
    o.frameMsTarget = 0;
    // Cache off: no cache stage, every far pixel traced.
    o.cache = false;
    ff.setOptions(o);
    FrameStats d;
    ff.render(c, nullptr, img, d);
    EXPECT_FALSE(d.stages.ran(Stage::Cache));
    EXPECT_EQ(d.pixels.cache, 0u);
    EXPECT_EQ(d.raysCast, d.pixels.rayHit + d.pixels.rayMiss);
    // Horizon switched off by option: no stage, nothing culled.
    o.horizon = false;
    ff.setOptions(o);
    FrameStats e;
    ff.render(c, nullptr, img, e);
    EXPECT_FALSE(e.stages.ran(Stage::Horizon));
    EXPECT_EQ(e.pixels.horizonCulled, 0u);
    EXPECT_EQ(e.raysCast, N);
    // Fully covered, seam check off: opacity only, no ray at all.
    std::vector<float> full(N, 0.3f);
    o.verifySeam = false;
    o.nearDistance = 10;
    ff.setOptions(o);
    FrameStats g;
    ff.render(c, full.data(), img, g);
    EXPECT_EQ(g.stages.count(), 1u);
    EXPECT_TRUE(g.stages.ran(Stage::Opacity));
    EXPECT_EQ(g.raysCast, 0u);
    // No far geometry: sky without rays, composite only after opacity.
    o.nearDistance = 5000;
    ff.setOptions(o);
    FrameStats h;
    ff.render(c, nullptr, img, h);
    EXPECT_EQ(h.raysCast, 0u);
    EXPECT_EQ(h.pixels.horizonCulled, N);
    EXPECT_TRUE(has(h, "no far geometry"));
    EXPECT_TRUE(h.stages.ran(Stage::Composite));
    EXPECT_FALSE(h.stages.ran(Stage::Horizon) || h.stages.ran(Stage::Rays) || h.stages.ran(Stage::Cache));
}

namespace {
// The hybrid's far field under haze of `visibility` metres: it hazes the covered pixels of a depth
// buffer projected with far plane zFar (0 = infinite).
FarFieldOptions coveredHazeOptions(double nearDistance, double zFar, double visibility) {
    FarFieldOptions o;
    o.nearDistance = nearDistance;
    o.depthZFar = zFar;
    o.hazeCovered = true;
    o.effects.haze = true;
    o.effects.visibility = visibility;
    return o;
}
}  // namespace

// hazeCovered: covered pixels arrive unhazed and leave hazed for the eye depth
// their window depth encodes (finite and infinite far plane), within one 8-bit
// level of FrameEffects::applyHaze (exp evaluated directly); uncovered pixels
// and alpha are not touched by that pass; without haze nothing changes.
TEST(FarFieldFrame, HazeOfCoveredPixelsMatchesTheFormulaAtTheirDepth) {
    const TestCity t = testCity(3, 20);
    ASSERT_TRUE(t.rays);
    Camera c = cam(glm::dvec3(0, -150, 1.7), 0.3, 0.0, 64, 48);
    c.zNear = 0.5;
    const size_t N = size_t(c.width) * size_t(c.height);
    for (double zFar : {400.0, 0.0}) {
        std::vector<float> depth(N, 1.0f);
        std::vector<double> eyeZ(N, 0.0);
        std::mt19937 rng(7);
        std::uniform_real_distribution<double> z(0.6, 390.0);  // also beyond the visibility (300 m)
        Image in(c.width, c.height);
        for (size_t i = 0; i < N; ++i) {
            if (i % 7 == 3) continue;  // some pixels uncovered
            eyeZ[i] = z(rng);
            // Window depth of eye depth z (OpenGL perspective, [0, 1]).
            const double d = zFar > 0 ? (zFar / (zFar - c.zNear)) * (1.0 - c.zNear / eyeZ[i]) : 1.0 - c.zNear / eyeZ[i];
            depth[i] = float(d);
            in.rgba[i * 4 + 0] = uint8_t(rng() % 256);
            in.rgba[i * 4 + 1] = uint8_t(rng() % 256);
            in.rgba[i * 4 + 2] = uint8_t(rng() % 256);
            in.rgba[i * 4 + 3] = i % 5 == 0 ? 128 : 255;
        }
        FarFieldOptions o = coveredHazeOptions(400.0, zFar, 300.0);
        o.verifySeam = false;
        FarField ff(*t.rays, &t.grid, o);
        Image out = in;
        FrameStats st;
        ff.render(c, depth.data(), out, st);
        EXPECT_TRUE(st.effects.ran(EffectId::Haze));
        int worst = 0;
        for (size_t i = 0; i < N; ++i) {
            if (ff.classification()[i] != kFarCovered) continue;
            const glm::u8vec4 src(in.rgba[i * 4], in.rgba[i * 4 + 1], in.rgba[i * 4 + 2], in.rgba[i * 4 + 3]);
            const glm::u8vec4 want = o.effects.applyHaze(src, eyeZ[i]);
            for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(int(out.rgba[i * 4 + k]) - int(want[k])));
            EXPECT_EQ(out.rgba[i * 4 + 3], src[3]) << "alpha (glass marks) must pass through";
        }
        EXPECT_LE(worst, 1) << "zFar " << zFar;
        // Without haze the covered pixels are left as they were.
        o.effects.haze = false;
        ff.setOptions(o);
        Image plain = in;
        FrameStats s2;
        ff.render(c, depth.data(), plain, s2);
        for (size_t i = 0; i < N; ++i)
            if (ff.classification()[i] == kFarCovered) {
                ASSERT_EQ(std::memcmp(&plain.rgba[i * 4], &in.rgba[i * 4], 4), 0);
            }
    }
}

// Under haze the seam's hits show their own ray's colour hazed once at the
// hit's eye depth, while the covered pixels around them are hazed by the
// covered pass running beside the seam (task and calling-thread paths): no
// seam hit keeps the near field's colour or is hazed twice.
TEST(FarFieldFrame, HazedSeamHitsShowTheirRayHazedOnce) {
    const TestCity t = testCity(3, 60);
    ASSERT_TRUE(t.rays);
    const Camera c = cam(glm::dvec3(0, -150, 1.7), 0.3);
    const double nearD = 30.0, zFar = 80.0;
    for (int threads : {0, 1}) {
        Image in;
        const std::vector<float> depth = fakeNearField(*t.rays, c, 70.0, zFar, in);
        FarFieldOptions o = coveredHazeOptions(nearD, zFar, 150.0);
        o.threads = threads;
        FarField ff(*t.rays, &t.grid, o);
        Image out = in;
        FrameStats st;
        ff.render(c, depth.data(), out, st);
        const glm::vec3 org(c.eye - t.rays->frameOrigin());
        const glm::dvec3 fwd = c.forward();
        uint64_t seamHits = 0, covered = 0;
        for (int y = 0; y < c.height; ++y)
            for (int x = 0; x < c.width; ++x) {
                const size_t i = size_t(y) * size_t(c.width) + size_t(x);
                if (!(depth[i] < 1.0f)) continue;
                const glm::u8vec4 got = out.at(x, y);
                glm::u8vec4 want;
                if (ff.classification()[i] == kFarRayHit) {
                    const glm::dvec3 d = c.rayDirection(x + 0.5, y + 0.5);
                    const RayHit h = t.rays->intersect(org, glm::vec3(d));
                    ASSERT_TRUE(h.hit);
                    want = o.effects.applyHaze(h.color, double(h.t) * glm::dot(d, fwd));
                    ++seamHits;
                } else {
                    ASSERT_EQ(ff.classification()[i], kFarCovered);
                    want = o.effects.applyHaze(in.at(x, y), eyeDepthOfWindowDepth(double(depth[i]), c.zNear, zFar));
                    ++covered;
                }
                for (int k = 0; k < 3; ++k)
                    ASSERT_LE(std::abs(int(got[k]) - int(want[k])), 1)
                        << "threads " << threads << " pixel " << x << "," << y << " channel " << k;
            }
        EXPECT_GT(seamHits, 20u) << threads;
        EXPECT_GT(covered, 100u) << threads;
    }
}

// The horizon pauses while it does not pay: here the near field covers every
// pixel above the horizon, so the horizon culls nothing and saves no ray;
// after kHorizonStrikes judged frames in a row say so, the next
// kHorizonPauseFrames moving frames run without it. The picture is the same
// as with the horizon always traced (the pixels it would cull are covered),
// and the pause ends after kHorizonPauseFrames frames.
TEST(FarFieldFrame, HorizonPausesWhileItSavesNoRays) {
    const TestCity t = testCity(9, 60);
    ASSERT_TRUE(t.rays);
    Camera c = cam(glm::dvec3(0, -190, 1.7), 0.2);
    const size_t N = size_t(c.width) * size_t(c.height);
    std::vector<float> depth(N, 1.0f);
    for (size_t i = 0; i < N / 2; ++i) depth[i] = 0.5f;  // the top half covered: all the sky
    FarFieldOptions o;
    o.nearDistance = 0;
    o.cache = false;
    FarFieldOptions always = o;
    always.horizonAdaptive = false;
    FarField adaptive(*t.rays, &t.grid, o), traced(*t.rays, &t.grid, always);
    int paused = 0, firstPaused = -1;
    for (int f = 0; f < 1 + kHorizonStrikes + kHorizonPauseFrames + 1; ++f) {
        c.eye.x += 3.0;  // moving
        Image a, b;
        FrameStats sa, sb;
        adaptive.render(c, depth.data(), a, sa);
        traced.render(c, depth.data(), b, sb);
        EXPECT_EQ(sb.pixels.horizonCulled, 0u);
        EXPECT_FALSE(has(sb, "horizon paused"));
        EXPECT_EQ(a.rgba, b.rgba) << "frame " << f;
        EXPECT_EQ(sa.raysCast, sb.raysCast) << "frame " << f;
        if (has(sa, "horizon paused")) {
            if (firstPaused < 0) firstPaused = f;
            ++paused;
            EXPECT_FALSE(sa.stages.ran(Stage::Horizon));
        } else {
            EXPECT_TRUE(sa.stages.ran(Stage::Horizon)) << "frame " << f;
        }
    }
    // Frame 0 measures no ray cost yet; frames 1 .. kHorizonStrikes are judged, then the pause.
    EXPECT_EQ(firstPaused, 1 + kHorizonStrikes);
    EXPECT_EQ(paused, kHorizonPauseFrames);
}
