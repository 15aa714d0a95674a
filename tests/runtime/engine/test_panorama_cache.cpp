// Panoramic image cache and far-field pipeline tests: rotation-invariant
// indexing, azimuth wrap, the reprojection-error bound and the budget,
// graceful degradation, convergence of a still viewer to the exact ray-cast
// image, and a moving viewer staying close to the uncached image.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include "runtime/engine/far_field.h"
#include "runtime/engine/horizon.h"
#include "runtime/engine/metrics.h"
#include "runtime/engine/panorama_cache.h"
#include "runtime/engine/ray_scene.h"
#include "tests/runtime/engine/fixtures.h"

using namespace vista;
using namespace vista::test;

namespace {

Camera cam(const glm::dvec3& eye, double heading, double pitch = 0.0, int w = 96, int h = 64) {
    return testCamera(eye, heading, pitch, w, h, 0.8);
}

// Reference: every pixel cast individually, sky on a miss (as FarField shades).
Image exactImage(const RayScene& rs, const Camera& c, const FarField& ff, const Image& farImage) {
    Image out(c.width, c.height);
    glm::vec3 org(c.eye - rs.frameOrigin());
    for (int y = 0; y < c.height; ++y)
        for (int x = 0; x < c.width; ++x) {
            RayHit h = rs.intersect(org, glm::vec3(c.rayDirection(x + 0.5, y + 0.5)));
            if (h.hit) out.set(x, y, glm::u8vec4(h.color.x, h.color.y, h.color.z, 255));
            else out.set(x, y, farImage.at(x, y));  // sky pixels: compared separately below
        }
    (void)ff;
    return out;
}

int countDiff(const Image& a, const Image& b) {
    int n = 0;
    for (size_t i = 0; i < a.rgba.size(); i += 4)
        if (std::abs(int(a.rgba[i]) - int(b.rgba[i])) > 1 || std::abs(int(a.rgba[i + 1]) - int(b.rgba[i + 1])) > 1 ||
            std::abs(int(a.rgba[i + 2]) - int(b.rgba[i + 2])) > 1)
            ++n;
    return n;
}

}  // namespace

TEST(Panorama, IndexIsInvariantUnderViewRotation) {
    PanoramaCache pc = PanoramaCache::forCamera(cam(glm::dvec3(0), 0.0, 0.0, 640, 480));
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> a(-M_PI, M_PI);
    // The same world direction seen from differently rotated cameras maps to
    // the same cell; the cell depends only on the world direction.
    for (int i = 0; i < 200; ++i) {
        Camera c1 = cam(glm::dvec3(0), a(rng), 0.1 * a(rng) / M_PI, 640, 480);
        glm::dvec3 d = c1.rayDirection(100.5 + i, 200.5);
        int64_t i1 = pc.index(d);
        // A second camera rotated by some angle sees d through another pixel.
        Camera c2 = c1;
        c2.heading += a(rng);
        // Find d's pixel in c2 is not needed: index is a function of d alone.
        EXPECT_EQ(pc.index(d), i1);
        // Rotating d about the vertical axis by a whole number of cells moves the column only.
        double step = 2 * M_PI / pc.width() * 7;
        glm::dvec3 r(d.x * std::cos(-step) - d.y * std::sin(-step), d.x * std::sin(-step) + d.y * std::cos(-step), d.z);
        glm::dvec2 m1 = pc.mapCoord(d), m2 = pc.mapCoord(r);
        EXPECT_NEAR(std::fmod(m2.x - m1.x + pc.width(), double(pc.width())), 7.0, 1e-6);
        EXPECT_NEAR(m2.y, m1.y, 1e-9);
    }
    // Pixels of one frame: distinct pixels rarely share a cell (oversampled map).
    Camera c = cam(glm::dvec3(0), 0.7, 0.0, 640, 480);
    std::vector<int64_t> idx;
    for (int y = 0; y < 480; ++y)
        for (int x = 0; x < 640; ++x) idx.push_back(pc.index(c.rayDirection(x + 0.5, y + 0.5)));
    std::sort(idx.begin(), idx.end());
    EXPECT_EQ(std::adjacent_find(idx.begin(), idx.end()), idx.end());
}

TEST(Panorama, AzimuthWrapsAtZeroAndTwoPi) {
    PanoramaCache pc(1000, 100, 1.0);
    // Directions just either side of north (+y): first and last column.
    double e = 1e-9;
    glm::dvec3 right(std::sin(e), std::cos(e), 0), left(std::sin(-e), std::cos(-e), 0), north(0, 1, 0);
    EXPECT_EQ(pc.index(north) % 1000, 0);
    EXPECT_EQ(pc.index(right) % 1000, 0);
    EXPECT_EQ(pc.index(left) % 1000, 999);
    EXPECT_EQ(pc.index(right) / 1000, pc.index(left) / 1000);
    // Exactly 2 pi after rounding stays in range.
    glm::dvec3 almost(-1e-17, 1, 0);
    int64_t i = pc.index(almost);
    EXPECT_GE(i % 1000, 0);
    EXPECT_LT(i, 1000 * 100);
    // Too steep / degenerate directions are not cacheable.
    EXPECT_EQ(pc.index(glm::dvec3(0, 0, 1)), -1);
    EXPECT_EQ(pc.index(glm::dvec3(0, 0.1, 0.9)), -1);
    EXPECT_EQ(pc.index(glm::dvec3(NAN, 1, 0)), -1);
}

// clear() forgets every stored cell and record (what a walkthrough's restart asks).
TEST(Panorama, ClearForgetsEveryCell) {
    PanoramaCache pc(1000, 100, 1.0);
    pc.beginFrame(cam(glm::dvec3(0, 0, 2), 0.3));
    std::vector<int64_t> cells;
    std::vector<glm::u8vec2> subs;
    std::vector<glm::u8vec4> colors;
    std::vector<float> nears;
    for (int64_t c = 0; c < 1000 * 100; c += 997) {
        cells.push_back(c);
        subs.push_back(glm::u8vec2(10, 200));
        colors.push_back(glm::u8vec4(1, 2, 3, 255));
        nears.push_back(50.0f);
    }
    pc.store(cells, subs, colors, nears);
    ASSERT_EQ(pc.record(cells[3]), pc.currentRecord());
    ASSERT_GT(pc.recordCount(), 1u);
    pc.clear();
    EXPECT_EQ(pc.recordCount(), 1u);
    EXPECT_EQ(pc.currentRecord(), 0u);
    for (int64_t c = 0; c < 1000 * 100; ++c) {
        ASSERT_EQ(pc.record(c), 0u) << c;
        ASSERT_EQ(pc.color(c).w, 0) << c;
        ASSERT_TRUE(std::isinf(pc.nearDistance(c))) << c;
    }
}

// A part of the scene arrived or left: every cell whose stored ray, from its
// own record's eye, passes through the box (checked by a slab test on the ray
// itself) counts as never traced; a record farther than the reach is
// forgotten whole; most cells elsewhere are kept.
TEST(Panorama, InvalidateBoxForgetsEveryCellWhoseRayCrossesTheBox) {
    PanoramaCache pc(720, 200, 1.0);
    const glm::dvec3 lo(40, 60, 0), hi(80, 120, 30);
    auto crosses = [&](const glm::dvec3& o, const glm::dvec3& d) {
        double t0 = 0, t1 = 1e30;
        for (int k = 0; k < 3; ++k) {
            if (std::abs(d[k]) < 1e-15) {
                if (o[k] < lo[k] || o[k] > hi[k]) return false;
                continue;
            }
            double a = (lo[k] - o[k]) / d[k], b = (hi[k] - o[k]) / d[k];
            if (a > b) std::swap(a, b);
            t0 = std::max(t0, a);
            t1 = std::min(t1, b);
        }
        return t0 <= t1;
    };
    struct Sample {
        glm::dvec3 eye, dir;
        int64_t cell;
        glm::u8vec2 sub;
        bool far;
    };
    std::vector<Sample> samples;
    std::map<int64_t, size_t> lastWriter;
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> az(0.0, 2.0 * M_PI), v(-0.9, 0.9);
    // The far record first, the current one (the origin) last.
    const glm::dvec3 eyes[4] = {{100, 0, 2}, {1.0, 0.2, 2}, {0.5, 0, 2}, {0, 0, 2}};
    for (int r = 0; r < 4; ++r) {
        pc.beginFrame(cam(eyes[r], 0.1 * r));
        std::vector<int64_t> cells;
        std::vector<glm::u8vec2> subs;
        std::vector<glm::u8vec4> colors;
        std::vector<float> nears;
        std::map<int64_t, int> inFrame;
        for (int k = 0; k < 4000; ++k) {
            const double a = az(rng);
            const glm::dvec3 d = glm::normalize(glm::dvec3(std::sin(a), std::cos(a), v(rng)));
            glm::u8vec2 sub;
            const int64_t c = pc.index(d, &sub);
            if (c < 0 || inFrame[c]++ > 0) continue;  // one ray per cell and frame
            cells.push_back(c);
            subs.push_back(sub);
            colors.push_back(glm::u8vec4(9, 9, 9, 255));
            nears.push_back(200.0f);
            lastWriter[c] = samples.size();
            samples.push_back({eyes[r], d, c, sub, r == 0});
        }
        pc.store(cells, subs, colors, nears);
    }
    CachePolicy p;
    p.lowerDepth = 1e9;  // errors stay finite for every record kept
    p.radPerPixel = 1e-3;
    const uint64_t zeroed = pc.invalidateBox(lo, hi, /*reach=*/10.0);
    EXPECT_GT(zeroed, 0u);
    size_t crossing = 0, kept = 0, near = 0;
    for (const auto& [cell, i] : lastWriter) {
        const Sample& s = samples[i];
        const double e = pc.error(cell, s.sub, p);
        if (s.far) {
            EXPECT_TRUE(std::isinf(e)) << "a record beyond the reach is forgotten whole";
            continue;
        }
        ++near;
        if (crosses(s.eye, s.dir)) {
            ++crossing;
            EXPECT_TRUE(std::isinf(e)) << "cell " << cell << " shows the box from " << s.eye.x;
        } else if (!std::isinf(e)) {
            ++kept;
        }
    }
    EXPECT_GT(crossing, 20u) << "the test has rays through the box";
    EXPECT_GT(kept, near * 3 / 4) << "cells away from the box are kept";
    // Nothing traced yet: nothing to forget.
    PanoramaCache fresh(720, 200, 1.0);
    EXPECT_EQ(fresh.invalidateBox(lo, hi, 10.0), 0u);
}

TEST(Panorama, ErrorBoundAndBudgetRetraceTheWorstCells) {
    PanoramaCache pc(100, 10, 1.0);
    auto at = [](double x, double heading = 0.0) { return cam(glm::dvec3(x, 0, 1.7), heading); };
    // Cells 0..29 traced at x = 0 with surfaces 1000 m away, 30..59 at x = 0 with
    // surfaces 50 m away, 60..89 at x = 9 (near 1000 m); 90..99 never traced.
    auto storeRange = [&](int a, int b, float near) {
        std::vector<int64_t> cells;
        std::vector<glm::u8vec4> cols;
        std::vector<float> nears;
        for (int i = a; i < b; ++i) {
            cells.push_back(i);
            cols.push_back(glm::u8vec4(uint8_t(i), 0, 0, 255));
            nears.push_back(near);
        }
        pc.store(cells, std::vector<glm::u8vec2>(cells.size(), glm::u8vec2(128)), cols, nears);
    };
    pc.beginFrame(at(0));
    storeRange(0, 30, 1000.0f);
    storeRange(30, 60, 50.0f);
    pc.beginFrame(at(9));
    storeRange(60, 90, 1000.0f);
    pc.beginFrame(at(10));
    CachePolicy p;
    p.radPerPixel = 1e-3;
    p.windowPx = 8;
    p.lowerDepth = 40.0;
    p.maxErrorPx = 0.5;
    // Independent computation of the bound: eye moved b since tracing; own term b / near,
    // outside-the-window term b / lowerDepth - 8 px.
    const glm::u8vec2 mid(128, 128);
    auto expected = [&](double b, double near) { return std::max(b / near, b / 40.0 - 8e-3) / 1e-3; };
    EXPECT_NEAR(pc.error(5, mid, p), expected(10, 1000), 1e-9);  // 242 px: the window term dominates
    EXPECT_NEAR(pc.error(45, mid, p), expected(10, 50), 1e-9);   // 242 px as well
    EXPECT_NEAR(pc.error(70, mid, p), expected(1, 1000), 1e-9);  // max(1, 17) px
    EXPECT_TRUE(std::isinf(pc.error(95, mid, p)));
    // Far lower bound (nothing nearer than 2 km): the own term decides.
    p.lowerDepth = 2000.0;
    EXPECT_NEAR(pc.error(45, mid, p), 10.0 / 50.0 / 1e-3, 1e-9);   // 200 px
    EXPECT_NEAR(pc.error(5, mid, p), 10.0 / 1000.0 / 1e-3, 1e-9);  // 10 px
    EXPECT_NEAR(pc.error(70, mid, p), 1.0 / 1000.0 / 1e-3, 1e-9);  // 1 px
    std::vector<CacheCandidate> cand;
    for (int i = 0; i < 100; ++i) cand.push_back({i, uint32_t(i)});
    cand.push_back({-1, 100u});  // not cacheable: always traced
    std::vector<uint8_t> tr;
    auto marked = [&](int a, int b) {
        int n = 0;
        for (int i = a; i < b; ++i) n += tr[size_t(i)];
        return n;
    };
    // Bound 5 px: all but the 1-px cells (60..89) are re-traced.
    p.maxErrorPx = 5.0;
    EXPECT_EQ(pc.selectForTracing(cand, p, tr), 71);
    EXPECT_EQ(marked(0, 60), 60);
    EXPECT_EQ(marked(60, 90), 0);
    EXPECT_EQ(marked(90, 100), 10);
    EXPECT_EQ(tr[100], 1);
    // Budget 41: the uncacheable one, never traced (10), then the 200-px cells (30).
    p.budget = 41;
    EXPECT_EQ(pc.selectForTracing(cand, p, tr), 41);
    EXPECT_EQ(marked(90, 100), 10);
    EXPECT_EQ(marked(30, 60), 30);
    EXPECT_EQ(marked(0, 30), 0);
    // Budget 0: only what cannot be cached (graceful degradation).
    p.budget = 0;
    EXPECT_EQ(pc.selectForTracing(cand, p, tr), 1);
    // Bound 0, no cap: everything that is not exact.
    p.budget = -1;
    p.maxErrorPx = 0.0;
    EXPECT_EQ(pc.selectForTracing(cand, p, tr), 101);
    // The same eye, another heading: error 0, reused under any bound > 0, re-traced under bound 0.
    pc.beginFrame(at(10, 0.3));
    storeRange(0, 10, 1000.0f);
    storeRange(400, 410, 1000.0f);  // row 4: v = 1 - 4.5 * 0.2 = 0.1
    pc.beginFrame(at(10, 0.6));
    EXPECT_EQ(pc.error(3, mid, p), 0.0);
    // ... unless the pixel's ray falls elsewhere in the cell: half a column at elevation
    // atan(0.1) is pi / 100 radians of azimuth, times cos(elevation).
    const double halfColumn = M_PI / 100.0 / std::sqrt(1.0 + 0.1 * 0.1) / 1e-3;
    EXPECT_NEAR(pc.error(403, glm::u8vec2(0, 128), p), halfColumn, 1e-9);
    EXPECT_EQ(pc.error(403, mid, p), 0.0);
    // This very camera: exact.
    storeRange(10, 20, 1000.0f);
    EXPECT_EQ(pc.error(15, mid, p), -1.0);
    // Stored colours and distances come back.
    EXPECT_EQ(pc.color(42).x, 42);
    EXPECT_EQ(pc.nearDistance(42), 50.0f);
}

TEST(Panorama, StillViewerConvergesToTheExactImage) {
    SceneModel city = randomCity(4, 70, 400.0, 1.0e6, 0.0);  // 1,000 km from the origin
    auto rs = RayScene::build(city);
    ASSERT_TRUE(rs.isOk());
    HeightGrid grid = HeightGrid::build(city, rs.value()->frameOrigin(), 64);
    FarFieldOptions o;
    o.nearDistance = 0;
    o.pixelBudget = 700;
    o.cacheErrorPx = 0;  // reuse only what this very camera traced: converges to exact
    FarField ff(*rs.value(), &grid, o);
    // Walk a few frames, then stop.
    Image img;
    for (int f = 0; f < 4; ++f) {
        FrameStats st;
        ff.render(cam(glm::dvec3(1.0e6 + 2.0 * f, -180, 1.7), 0.2 + 0.05 * f), nullptr, img, st);
        EXPECT_LE(st.pixels.rayHit + st.pixels.rayMiss, 700u);
    }
    Camera still = cam(glm::dvec3(1.0e6 + 8.0, -180, 1.7), 0.4);
    const uint64_t N = uint64_t(still.width) * still.height;
    int frames = 0;
    uint64_t traced = 1;
    while (traced > 0 && frames < 100) {
        FrameStats st;
        ff.render(still, nullptr, img, st);
        EXPECT_EQ(st.pixels.covered + st.pixels.horizonCulled + st.pixels.cache + st.pixels.rayHit + st.pixels.rayMiss,
                  N);
        traced = st.pixels.rayHit + st.pixels.rayMiss;
        EXPECT_LE(traced, 700u);
        ++frames;
    }
    EXPECT_GT(frames, 2);    // the budget forced progressive refinement
    EXPECT_LT(frames, 100);  // ... and it finished
    Image ref = exactImage(*rs.value(), still, ff, img);
    EXPECT_EQ(countDiff(img, ref), 0);
    // Sky pixels equal an unlimited-budget frame (no cache) of the same camera.
    FarFieldOptions u = o;
    u.pixelBudget = -1;
    FarField direct(*rs.value(), &grid, u);
    Image img2;
    FrameStats st2;
    direct.render(still, nullptr, img2, st2);
    EXPECT_EQ(countDiff(img, img2), 0);
    EXPECT_EQ(st2.pixels.cache, 0u);
    EXPECT_GT(st2.pixels.rayHit, st2.pixels.rayMiss);  // the far field was traced: mostly buildings, not sky
    EXPECT_EQ(st2.raysCast, st2.pixels.rayHit + st2.pixels.rayMiss);
}

TEST(FarField, PixelClassesPartitionTheImageAndStagesRunOnlyWhenNeeded) {
    SceneModel city = randomCity(6, 50);
    auto rs = RayScene::build(city);
    ASSERT_TRUE(rs.isOk());
    HeightGrid grid = HeightGrid::build(city, glm::dvec3(0), 64);
    FarFieldOptions o;
    o.nearDistance = 0;
    FarField ff(*rs.value(), &grid, o);
    Camera c = cam(glm::dvec3(0, -190, 1.7), 0.0);
    const size_t N = size_t(c.width) * size_t(c.height);
    // Half the image covered by a fake near field (bottom half).
    std::vector<float> depth(N, 1.0f);
    for (size_t i = N / 2; i < N; ++i) depth[i] = 0.5f;
    Image img(c.width, c.height);
    FrameStats st;
    ff.render(c, depth.data(), img, st);
    EXPECT_EQ(st.pixels.covered, N - N / 2);
    EXPECT_EQ(st.pixels.covered + st.pixels.horizonCulled + st.pixels.cache + st.pixels.rayHit + st.pixels.rayMiss, N);
    EXPECT_GT(st.pixels.horizonCulled, 0u);
    EXPECT_TRUE(st.stages.ran(Stage::Horizon));
    EXPECT_TRUE(st.stages.ran(Stage::Rays));
    // Fully covered: only the opacity stage runs.
    std::vector<float> full(N, 0.2f);
    FrameStats s2;
    ff.render(c, full.data(), img, s2);
    EXPECT_EQ(s2.pixels.covered, N);
    EXPECT_EQ(s2.stages.count(), 1u);
    // Rolled camera: horizon off, says so, still a complete classification.
    Camera r = c;
    r.roll = 0.2;
    FrameStats s3;
    ff.render(r, nullptr, img, s3);
    EXPECT_FALSE(s3.stages.ran(Stage::Horizon));
    ASSERT_FALSE(s3.notes.empty());
    EXPECT_EQ(s3.pixels.horizonCulled, 0u);
    EXPECT_EQ(s3.pixels.rayHit + s3.pixels.rayMiss + s3.pixels.cache, N);  // same eye: some reused from the cache
    // Near distance beyond the whole city: no far geometry -> no ray stage.
    FarFieldOptions far = o;
    far.nearDistance = 5000;
    ff.setOptions(far);
    FrameStats s4;
    ff.render(c, depth.data(), img, s4);
    EXPECT_FALSE(s4.stages.ran(Stage::Rays));
    EXPECT_EQ(s4.pixels.rayHit + s4.pixels.rayMiss, 0u);
    EXPECT_EQ(s4.pixels.covered + s4.pixels.horizonCulled, N);
}

TEST(FarField, HardCasesStayFinite) {
    SceneModel city = randomCity(8, 40);
    auto rs = RayScene::build(city);
    ASSERT_TRUE(rs.isOk());
    HeightGrid grid = HeightGrid::build(city, glm::dvec3(0), 32);
    FarFieldOptions o;
    o.pixelBudget = 5000;
    FarField ff(*rs.value(), &grid, o);
    const double s = grid.cellSize();
    std::vector<Camera> cams = {
        cam(glm::dvec3(grid.gridMin().x + 10 * s, grid.gridMin().y + 7 * s, 1.7), 0.0),  // on grid lines, axis rays
        cam(glm::dvec3(0, 0, 1.7), 0.5 * M_PI),
        cam(glm::dvec3(0, 0, 1.7), 0.0, 0.5 * M_PI),    // straight up
        cam(glm::dvec3(0, 0, 30.0), 0.0, -0.5 * M_PI),  // straight down
        cam(glm::dvec3(0, -100, 1.7), 0.0, 0.0, 1, 1),
    };
    for (const Camera& c : cams) {
        Image img;
        FrameStats st;
        ff.render(c, nullptr, img, st);
        const uint64_t N = uint64_t(c.width) * c.height;
        EXPECT_EQ(st.pixels.covered + st.pixels.horizonCulled + st.pixels.cache + st.pixels.rayHit + st.pixels.rayMiss,
                  N);
        for (size_t i = 3; i < img.rgba.size(); i += 4) ASSERT_EQ(img.rgba[i], 255);  // every pixel written
    }
    // Empty city: nothing to trace, all sky.
    SceneModel empty;
    auto er = RayScene::build(empty);
    ASSERT_TRUE(er.isOk());
    HeightGrid eg = HeightGrid::build(empty, glm::dvec3(0), 16);
    FarField ef(*er.value(), &eg, o);
    Image img;
    FrameStats st;
    ef.render(cam(glm::dvec3(0, 0, 1.7), 0.0), nullptr, img, st);
    EXPECT_EQ(st.pixels.rayHit + st.pixels.rayMiss, 0u);
    EXPECT_EQ(st.pixels.horizonCulled, uint64_t(96 * 64));
}

TEST(FarField, LargeViewport) {
    SceneModel city = randomCity(10, 30);
    auto rs = RayScene::build(city);
    ASSERT_TRUE(rs.isOk());
    HeightGrid grid = HeightGrid::build(city, glm::dvec3(0), 64);
    FarFieldOptions o;
    o.pixelBudget = 20000;
    FarField ff(*rs.value(), &grid, o);
    Camera c = cam(glm::dvec3(0, -190, 1.7), 0.0, 0.0, 4096, 2160);
    std::vector<float> depth(size_t(4096) * 2160, 1.0f);
    for (size_t i = depth.size() / 3; i < depth.size(); ++i) depth[i] = 0.5f;  // cover most
    Image img;
    FrameStats st;
    ff.render(c, depth.data(), img, st);
    EXPECT_EQ(img.width, 4096);
    EXPECT_EQ(st.pixels.covered + st.pixels.horizonCulled + st.pixels.cache + st.pixels.rayHit + st.pixels.rayMiss,
              uint64_t(4096) * 2160);
    EXPECT_LE(st.pixels.rayHit + st.pixels.rayMiss, 20000u);
}

// A viewer moving 0.2 m a frame through a ring of buildings 300 .. 1500 m
// away (nothing within the 100 m near distance): with the quality-bounded
// cache every frame stays close to the uncached frame of the same camera,
// while far fewer rays are cast; a looser bound reuses more and costs PSNR;
// bound 0 gives the uncached image exactly.
TEST(Panorama, MovingViewerStaysCloseToTheUncachedImage) {
    std::mt19937 rng(21);
    std::uniform_real_distribution<double> ang(0, 2 * M_PI), rad(300, 1500), size(10, 60), height(10, 120);
    std::uniform_int_distribution<int> col(30, 220);
    SceneModel city;
    city.params.size_m = 3200;
    SceneMesh m;
    for (int i = 0; i < 300; ++i) {
        const double a = ang(rng), r = rad(rng), s = size(rng);
        const glm::vec3 lo(float(r * std::sin(a)), float(r * std::cos(a)), 0.0f);
        addBox(m, lo, lo + glm::vec3(float(s), float(s), float(height(rng))),
               glm::u8vec4(uint8_t(col(rng)), uint8_t(col(rng)), uint8_t(col(rng)), 255));
    }
    city.meshes.push_back(m);
    city.triangles = m.indices.size() / 3;
    auto rs = RayScene::build(city);
    ASSERT_TRUE(rs.isOk());
    HeightGrid grid = HeightGrid::build(city, rs.value()->frameOrigin(), 128);
    FarFieldOptions plain;
    plain.nearDistance = 100;
    plain.cache = false;
    plain.horizonAdaptive = false;  // the cache's policy is measured here, not the horizon's timed pause
    auto run = [&](double bound, double& psnrMin, double& psnrMean, uint64_t& rays, uint64_t& raysPlain) {
        FarFieldOptions o = plain;
        o.cache = true;
        o.cacheErrorPx = bound;
        o.cacheAdaptive = false;  // the policy itself, never paused on timings
        FarField cached(*rs.value(), &grid, o), direct(*rs.value(), &grid, plain);
        psnrMin = 1e9;
        psnrMean = 0;
        rays = raysPlain = 0;
        const int frames = 40;
        for (int f = 0; f < frames; ++f) {
            Camera c = cam(glm::dvec3(0.2 * f, -0.1 * f, 1.7), 0.3 + 0.01 * f, 0.0, 192, 128);
            Image a, b;
            FrameStats sa, sb;
            cached.render(c, nullptr, a, sa);
            direct.render(c, nullptr, b, sb);
            const uint64_t N = uint64_t(c.width) * c.height;
            EXPECT_EQ(
                sa.pixels.covered + sa.pixels.horizonCulled + sa.pixels.cache + sa.pixels.rayHit + sa.pixels.rayMiss,
                N);
            const double p = std::min(99.0, lumaPsnr(a, b));
            psnrMin = std::min(psnrMin, p);
            psnrMean += p / frames;
            rays += sa.raysCast;
            raysPlain += sb.raysCast;
        }
    };
    double tightMin, tightMean, looseMin, looseMean, exactMin, exactMean;
    uint64_t tightRays, looseRays, plainRays, exactRays;
    // Bound 0: nothing but this very camera's pixels is reused: the uncached image, bit for bit.
    run(0.0, exactMin, exactMean, exactRays, plainRays);
    EXPECT_EQ(exactMin, 99.0);
    EXPECT_EQ(exactRays, plainRays);
    run(0.5, tightMin, tightMean, tightRays, plainRays);
    run(4.0, looseMin, looseMean, looseRays, plainRays);
    EXPECT_GE(tightMin, 33.0) << "mean " << tightMean;
    EXPECT_GE(tightMean, 40.0);
    EXPECT_LT(double(tightRays), 0.7 * double(plainRays));
    // A looser bound: fewer rays, lower quality.
    EXPECT_LT(looseRays, tightRays);
    EXPECT_LT(looseMean, tightMean);
}

// The duty cycle (FarFieldOptions::cacheAdaptive): a moving camera whose
// cache reuses nothing (bound 0: only this very camera's pixels) is judged
// on its second cache frame, pauses for kCachePauseFrames moving frames
// (no cache stage, a note), then looks up again, and pauses twice as long
// after each further verdict in a row; a still camera, a pixel budget and
// cacheAdaptive = false never pause.
TEST(FarField, CachePausesWhileItsReuseDoesNotPayAndResumes) {
    SceneModel city = randomCity(8, 60);
    auto rs = RayScene::build(city);
    ASSERT_TRUE(rs.isOk());
    HeightGrid grid = HeightGrid::build(city, glm::dvec3(0), 64);
    auto paused = [](const FrameStats& st) {
        for (const std::string& n : st.notes)
            if (n.find("cache paused") != std::string::npos) return true;
        return false;
    };
    auto runFrames = [&](FarFieldOptions o, bool move, int frames) {
        FarField ff(*rs.value(), &grid, o);
        std::vector<int> pattern;  // 1 = the cache stage ran, 0 = paused
        for (int f = 0; f < frames; ++f) {
            Camera c = cam(glm::dvec3(move ? 3.0 * (f % 50) : 0.0, -190, 1.7), 0.1);  // back and forth within the city
            Image img;
            FrameStats st;
            ff.render(c, nullptr, img, st);
            EXPECT_EQ(st.stages.ran(Stage::Cache), !paused(st)) << "frame " << f;
            if (paused(st)) { EXPECT_EQ(st.pixels.cache, 0u) << "frame " << f; }
            pattern.push_back(st.stages.ran(Stage::Cache) ? 1 : 0);
        }
        return pattern;
    };
    FarFieldOptions o;
    o.nearDistance = 0;
    o.cacheErrorPx = 0;  // reuse exactly nothing while moving: the verdict does not depend on timings
    // Frames 0 and 1 look up, frame 1 finds no reuse, 2 .. 9 pause, 10 and 11 look up and judge
    // again, then 16 pause, then 32, then 64, and 64 again (the longest pause).
    std::vector<int> expect = {1, 1};
    for (int len : {kCachePauseFrames, 2 * kCachePauseFrames, 4 * kCachePauseFrames, kCacheMaxPauseFrames,
                    kCacheMaxPauseFrames}) {
        for (int k = 0; k < len; ++k) expect.push_back(0);
        expect.insert(expect.end(), {1, 1});
    }
    EXPECT_EQ(runFrames(o, true, int(expect.size())), expect);
    // Still camera: every frame runs the cache stage.
    EXPECT_EQ(runFrames(o, false, 6), std::vector<int>(6, 1));
    // Always look up.
    FarFieldOptions always = o;
    always.cacheAdaptive = false;
    EXPECT_EQ(runFrames(always, true, 12), std::vector<int>(12, 1));
    // Under a pixel budget the cache is what spreads the rays: never paused.
    FarFieldOptions budget = o;
    budget.pixelBudget = 1000000;
    EXPECT_EQ(runFrames(budget, true, 12), std::vector<int>(12, 1));
}
