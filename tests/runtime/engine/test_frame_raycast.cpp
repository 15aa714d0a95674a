// Primary rays of a frame (runtime/engine/frame_raycast.h): the whole frame against per-pixel
// rays and row batches, pixel lists.
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
// ---- primary rays (shared with the raycast mode) ------------------------------

// What the raycast mode computes: every image row cast as one
// RayScene::intersectMany batch (packets of 8 from the row's first pixel),
// directions Camera::rayDirection(x + 0.5, y + 0.5), sky on a miss.
Image rowBatches(const RayScene& rays, const Camera& c, uint64_t& hits) {
    Image out(c.width, c.height);
    const size_t n = static_cast<size_t>(c.width);
    std::vector<glm::vec3> orgs(n, glm::vec3(c.eye - rays.frameOrigin())), dirs(n);
    std::vector<RayHit> res(n);
    hits = 0;
    for (int y = 0; y < c.height; ++y) {
        for (size_t x = 0; x < n; ++x) dirs[x] = glm::vec3(c.rayDirection(double(x) + 0.5, y + 0.5));
        rays.intersectMany(orgs.data(), dirs.data(), c.width, res.data());
        for (int x = 0; x < c.width; ++x) {
            const RayHit& h = res[size_t(x)];
            hits += h.hit ? 1 : 0;
            out.set(x, y, h.hit ? opaque(h) : skyOf(c.rayDirection(x + 0.5, y + 0.5)));
        }
    }
    return out;
}

}  // namespace

TEST(PrimaryRays, CastFrameEqualsPerPixelRaysAndRowBatches) {
    for (uint32_t seed : {2u, 9u}) {
        const double ox = seed == 9 ? 2.5e5 : 0.0;
        const TestCity t = testCity(seed, 80, ox);
        ASSERT_TRUE(t.rays);
        const glm::dvec3 o = t.rays->frameOrigin();
        for (const Camera& c : {cam(o + glm::dvec3(0, -180, 1.7), 0.3, 0.0, 133, 77),
                                cam(o + glm::dvec3(40, -120, 30), 1.0, -0.3, 64, 48, 0.15)}) {
            RayCounts counts;
            Image frame;
            castFrame(*t.rays, c, frame, counts, 2);
            const uint64_t N = uint64_t(c.width) * uint64_t(c.height);
            EXPECT_EQ(counts.rays, N);
            // Bit-identical to the raycast mode's row batches (same packets).
            uint64_t rowHits = 0;
            EXPECT_TRUE(frame.rgba == rowBatches(*t.rays, c, rowHits).rgba);
            EXPECT_EQ(counts.hits, rowHits);
            // Per pixel: Camera::rayDirection + RayScene::intersect.
            const glm::vec3 org(c.eye - o);
            uint64_t hits = 0;
            int differ = 0;
            for (int y = 0; y < c.height; ++y)
                for (int x = 0; x < c.width; ++x) {
                    const glm::dvec3 d = c.rayDirection(x + 0.5, y + 0.5);
                    const RayHit h = t.rays->intersect(org, glm::vec3(d));
                    hits += h.hit ? 1 : 0;
                    differ += frame.at(x, y) != (h.hit ? opaque(h) : skyOf(d)) ? 1 : 0;
                }
            EXPECT_EQ(differ, 0);
            EXPECT_EQ(counts.hits, hits);
            EXPECT_GT(hits, N / 4);
            EXPECT_LT(hits, N);  // some sky too
            // Thread count does not matter.
            for (int threads : {1, 0}) {
                RayCounts c2;
                Image f2;
                castFrame(*t.rays, c, f2, c2, threads);
                EXPECT_TRUE(f2.rgba == frame.rgba) << threads;
                EXPECT_EQ(c2.hits, counts.hits);
            }
        }
    }
}

TEST(PrimaryRays, PixelListWritesExactlyTheListedPixels) {
    const TestCity t = testCity(4, 70);
    ASSERT_TRUE(t.rays);
    const Camera c = cam(glm::dvec3(10, -170, 1.7), 0.2, 0.02, 97, 61);
    const uint32_t N = uint32_t(c.width * c.height);
    Image frame;
    RayCounts all;
    castFrame(*t.rays, c, frame, all, 2);
    std::mt19937 rng(17);
    std::vector<uint32_t> list;
    for (uint32_t i = 0; i < N; ++i)
        if (rng() % 3 == 0) list.push_back(i);
    std::vector<uint32_t> shuffled = list, sparse;  // sparse: rows with 1 or 2 pixels share packets
    std::shuffle(shuffled.begin(), shuffled.end(), rng);
    for (uint32_t i = 5; i < N; i += uint32_t(c.width) / 2 + 3) sparse.push_back(i);
    for (const auto* px : {&list, &shuffled, &sparse}) {
        Image out(c.width, c.height);
        std::fill(out.rgba.begin(), out.rgba.end(), uint8_t(7));
        std::vector<uint8_t> hit(px->size(), 2);
        RayCounts counts;
        counts.rays = 5;  // counts are added to
        castPrimaryRays(*t.rays, c, px->data(), px->size(), out, counts, 2, hit.data());
        EXPECT_EQ(counts.rays, 5 + px->size());
        std::vector<uint8_t> listed(N, 0);
        uint64_t hits = 0;
        for (size_t k = 0; k < px->size(); ++k) {
            const uint32_t i = (*px)[k];
            listed[i] = 1;
            const int x = int(i % uint32_t(c.width)), y = int(i / uint32_t(c.width));
            EXPECT_EQ(out.at(x, y), frame.at(x, y)) << i;
            ASSERT_LE(hit[k], 1);
            const bool sky = frame.at(x, y) == skyOf(c.rayDirection(x + 0.5, y + 0.5));
            if (!sky) {
                EXPECT_EQ(hit[k], 1) << i;  // a non-sky colour is a hit
            }
            hits += hit[k];
        }
        EXPECT_EQ(counts.hits, hits);
        EXPECT_GT(hits, 0u);
        for (uint32_t i = 0; i < N; ++i)
            if (!listed[i]) {
                ASSERT_EQ(out.at(int(i % uint32_t(c.width)), int(i / uint32_t(c.width))), glm::u8vec4(7)) << i;
            }
    }
    // An empty list casts nothing.
    Image out(c.width, c.height);
    RayCounts none;
    castPrimaryRays(*t.rays, c, nullptr, 0, out, none, 0);
    EXPECT_EQ(none.rays, 0u);
    EXPECT_EQ(none.hits, 0u);
}
