// Ray sets (runtime/engine/ray_set.h): the file round trip and its refusal of
// truncated, corrupt and inconsistent files; FarField::lastTraced() is
// exactly what the frame's ray stage cast, and the rays a set describes
// (primaryRays, coherentRuns) reproduce the stage's pixels; `vista bench
// --dump-rays` writes the sets of the hybrid frames it rendered.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "foundation/hash.h"
#include "runtime/engine/far_field.h"
#include "runtime/engine/far_field_rays.h"
#include "runtime/engine/horizon.h"
#include "runtime/engine/image.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/engine/ray_set.h"
#include "runtime/scene/city_file.h"
#include "tests/common/run_vista.h"
#include "tests/common/temp_dir.h"
#include "tests/runtime/engine/fixtures.h"

using namespace vista;
using namespace vista::test;

namespace {

RaySet sampleSet() {
    RaySet s;
    s.frame = 17;
    s.camera = testCamera({1.0e6 + 0.25, -3.5, 1.7}, 0.3, -0.05, 64, 48, 0.9, 0.01);
    s.camera.zNear = 0.25;
    s.hazeFar = 1234.5;
    s.tnear = 87.25;
    for (uint32_t i = 3; i < 64 * 48; i += 7) s.pixels.push_back(i);
    return s;
}

void expectSame(const RaySet& a, const RaySet& b) {
    EXPECT_EQ(a.frame, b.frame);
    EXPECT_EQ(a.camera.eye, b.camera.eye);
    EXPECT_EQ(a.camera.heading, b.camera.heading);
    EXPECT_EQ(a.camera.pitch, b.camera.pitch);
    EXPECT_EQ(a.camera.roll, b.camera.roll);
    EXPECT_EQ(a.camera.fovY, b.camera.fovY);
    EXPECT_EQ(a.camera.zNear, b.camera.zNear);
    EXPECT_EQ(a.camera.width, b.camera.width);
    EXPECT_EQ(a.camera.height, b.camera.height);
    EXPECT_EQ(a.hazeFar, b.hazeFar);
    EXPECT_EQ(a.tnear, b.tnear);
    EXPECT_EQ(a.pixels, b.pixels);
}

// The bytes with the trailing hash recomputed (to reach the checks behind it).
std::string rehash(std::string b) {
    const size_t end = b.size() - 8;
    const uint64_t h = hashBytes64(b.data(), end);
    storeLE64(reinterpret_cast<unsigned char*>(&b[end]), h);
    return b;
}
void putU32(std::string& b, size_t at, uint32_t v) { std::memcpy(&b[at], &v, 4); }  // little-endian host

// Byte offsets of the layout (ray_set.h).
constexpr size_t kWidthAt = 16, kCountAt = 8 + 16 + 10 * 8, kPixelsAt = kCountAt + 8;

void expectRefused(const std::string& bytes, const std::string& words, const std::string& label) {
    auto r = decodeRaySet(bytes, "set.rays");
    ASSERT_FALSE(r.isOk()) << label;
    EXPECT_NE(r.status().message().find("set.rays"), std::string::npos) << r.status().message();
    EXPECT_NE(r.status().message().find(words), std::string::npos) << label << ": " << r.status().message();
}

}  // namespace

TEST(RaySet, RoundTripsThroughBytesAndFiles) {
    const RaySet s = sampleSet();
    const std::string bytes = encodeRaySet(s);
    EXPECT_EQ(bytes.size(), kPixelsAt + 4 * s.pixels.size() + 8);
    auto d = decodeRaySet(bytes, "mem");
    ASSERT_TRUE(d.isOk()) << d.status().message();
    expectSame(s, *d);
    EXPECT_EQ(encodeRaySet(*d), bytes);

    TempDir dir("vista_rayset");
    const std::string path = dir.file("f.rays");
    ASSERT_TRUE(writeRaySet(path, s).isOk());
    auto f = readRaySet(path);
    ASSERT_TRUE(f.isOk()) << f.status().message();
    expectSame(s, *f);
    RaySet empty = s;  // a frame that traced nothing is a valid set
    empty.pixels.clear();
    ASSERT_TRUE(writeRaySet(path, empty).isOk());
    auto e = readRaySet(path);
    ASSERT_TRUE(e.isOk()) << e.status().message();
    EXPECT_TRUE(e->pixels.empty());
    auto missing = readRaySet(dir.file("missing.rays"));
    ASSERT_FALSE(missing.isOk());
    EXPECT_NE(missing.status().message().find("missing.rays"), std::string::npos) << missing.status().message();
}

TEST(RaySet, RefusesTruncatedCorruptAndInconsistentFiles) {
    const std::string good = encodeRaySet(sampleSet());
    // Every truncation.
    for (size_t n = 0; n < good.size(); ++n) {
        auto r = decodeRaySet(good.substr(0, n), "set.rays");
        ASSERT_FALSE(r.isOk()) << "accepted " << n << " of " << good.size() << " bytes";
    }
    expectRefused(good.substr(0, 20), "truncated", "header cut");
    expectRefused(good.substr(0, good.size() - 12), "truncated", "pixels cut");
    // Every single flipped byte.
    for (size_t i = 0; i < good.size(); ++i) {
        std::string b = good;
        b[i] = char(b[i] ^ 0x10);
        ASSERT_FALSE(decodeRaySet(b, "set.rays").isOk()) << "accepted a flipped byte at " << i;
    }
    std::string b = good;
    b[kPixelsAt + 5] = char(b[kPixelsAt + 5] ^ 1);
    expectRefused(b, "checksum", "pixel byte flipped");
    expectRefused("NOTRAYS!" + good.substr(8), "magic", "magic");
    expectRefused(good + "xy", "trailing", "trailing bytes");
    // Fields out of range, with a valid hash: the message names field and range.
    b = good;
    putU32(b, kWidthAt, 0);
    expectRefused(rehash(b), "width = 0 out of range 1 .. 8192", "width 0");
    b = good;
    putU32(b, kWidthAt + 4, 9000);
    expectRefused(rehash(b), "height = 9000", "height");
    b = good;
    putU32(b, 8, 1);
    expectRefused(rehash(b), "version = 1", "version");
    b = good;
    putU32(b, kPixelsAt + 4, 1);  // pixel 1 = 1 < pixel 0 = 3
    expectRefused(rehash(b), "not above", "descending");
    b = good;
    putU32(b, kPixelsAt, 64 * 48);
    expectRefused(rehash(b), "out of range 0 .. 3071", "pixel beyond the image");
    b = good;
    putU32(b, kCountAt, 64 * 48 + 1);
    expectRefused(rehash(b), "count = 3073", "count beyond the image");
    b = good;
    putU32(b, kCountAt, 1000);
    expectRefused(rehash(b), "truncated", "count beyond the bytes");
    b = good;
    const double nan = std::nan("");
    std::memcpy(&b[kWidthAt + 8 + 6 * 8], &nan, 8);  // fovY
    expectRefused(rehash(b), "fovY", "fovY NaN");
}

// A covered left third: even rows close (no seam ray), odd rows at 500 m eye
// depth (beyond the near distance: seam rays, some hit the city in front).
std::vector<float> coveredLeftThird(const Camera& c) {
    std::vector<float> depth(size_t(c.width) * size_t(c.height), 1.0f);
    for (int y = 0; y < c.height; ++y)
        for (int x = 0; x < c.width / 3; ++x)
            depth[size_t(y) * size_t(c.width) + size_t(x)] = float(1.0 - c.zNear / (y % 2 ? 500.0 : 5.0));
    return depth;
}

TEST(RaySet, LastTracedIsWhatTheRayStageCastAndReproducesItsPixels) {
    const SceneModel city = randomCity(5, 80);
    auto rs = RayScene::build(city);
    ASSERT_TRUE(rs.isOk()) << rs.status().message();
    const HeightGrid grid = HeightGrid::build(city, (*rs)->frameOrigin(), 64);
    FarFieldOptions o;
    o.nearDistance = 60.0;
    FarField ff(**rs, &grid, o);
    const Camera c = testCamera({-150.0, -20.0, 1.7}, 1.2, 0.02, 96, 64, 0.9);
    const std::vector<float> depth = coveredLeftThird(c);
    Image out;
    FrameStats stats;
    ff.render(c, depth.data(), out, stats);
    const std::vector<uint32_t>& traced = ff.lastTraced();
    // Exactly the uncovered pixels that became rayHit or rayMiss, ascending.
    std::vector<uint32_t> expect;
    uint64_t seamHits = 0;
    for (uint32_t i = 0; i < depth.size(); ++i) {
        const uint8_t k = ff.classification()[i];
        if (depth[i] >= 1.0f && (k == kFarRayHit || k == kFarRayMiss)) expect.push_back(i);
        if (depth[i] < 1.0f && k == kFarRayHit) ++seamHits;
    }
    EXPECT_EQ(traced, expect);
    EXPECT_GT(traced.size(), 100u);
    EXPECT_GT(seamHits, 0u) << "the frame has seam rays (not in the list)";
    EXPECT_EQ(stats.pixels.rayHit + stats.pixels.rayMiss, traced.size() + seamHits);
    EXPECT_GT(stats.raysCast, traced.size() + seamHits) << "seam rays that missed count only in raysCast";

    // The set's rays, cast alone, give the frame's colours at those pixels:
    // castPrimaryRays and primaryRays + coherentRuns + intersectMany alike.
    Image again(c.width, c.height);
    RayCounts counts;
    RayShading start;
    start.tnear = ff.lastRayStart();
    EXPECT_GT(start.tnear, 0.0f) << "a near field given as a distance: rays start there";
    castPrimaryRays(**rs, c, traced.data(), traced.size(), again, counts, 1, nullptr, start);
    EXPECT_EQ(counts.rays, traced.size());
    const PrimaryRays rays = primaryRays(c, (*rs)->frameOrigin(), traced.data(), traced.size(), 0.0, ff.lastRayStart());
    const std::vector<size_t> runs = coherentRuns(traced.data(), traced.size(), c.width);
    ASSERT_EQ(runs.back(), traced.size());
    std::vector<RayHit> hits(traced.size());
    const std::vector<glm::vec3> orgs(traced.size(), rays.org);
    for (size_t r = 0; r + 1 < runs.size(); ++r)
        (*rs)->intersectMany(orgs.data() + runs[r], rays.dirs.data() + runs[r], int(runs[r + 1] - runs[r]),
                             hits.data() + runs[r], 1e30f, rays.tfars.data() + runs[r], rays.tnear);
    for (size_t k = 0; k < traced.size(); ++k) {
        const int x = int(traced[k] % uint32_t(c.width)), y = int(traced[k] / uint32_t(c.width));
        ASSERT_EQ(again.at(x, y), out.at(x, y)) << "pixel " << traced[k];
        ASSERT_EQ(hits[k].hit, ff.classification()[traced[k]] == kFarRayHit) << "pixel " << traced[k];
        if (hits[k].hit) { ASSERT_EQ(hits[k].color, out.at(x, y)) << "pixel " << traced[k]; }
    }

    // A frame whose ray stage does not run leaves an empty list.
    const std::vector<float> all(depth.size(), 0.5f);
    FrameStats s2;
    ff.render(c, all.data(), out, s2);
    EXPECT_TRUE(ff.lastTraced().empty());
}

// Haze: the set's far limits are the stage's (a ray stops where its eye-plane
// depth reaches hazeFar), so hits beyond the visibility do not happen.
TEST(RaySet, PrimaryRaysCarryTheHazeLimit) {
    const Camera c = testCamera({0.0, 0.0, 1.7}, 0.4, 0.0, 32, 24, 0.9);
    std::vector<uint32_t> px;
    for (uint32_t i = 0; i < 32 * 24; i += 5) px.push_back(i);
    const PrimaryRays none = primaryRays(c, glm::dvec3(0.0), px.data(), px.size(), 0.0);
    const PrimaryRays hz = primaryRays(c, glm::dvec3(0.0), px.data(), px.size(), 300.0);
    ASSERT_EQ(hz.dirs.size(), px.size());
    EXPECT_EQ(hz.dirs, none.dirs);
    const glm::dvec3 f = c.forward();
    for (size_t k = 0; k < px.size(); ++k) {
        EXPECT_EQ(none.tfars[k], 1e30f);
        const double z = double(hz.tfars[k]) * glm::dot(glm::dvec3(hz.dirs[k]), f);
        // At or beyond the haze depth (no hit short of it is cut), by no more than hazeTfar's margin.
        EXPECT_GE(z, 300.0) << k;
        EXPECT_LE(z, 300.0 * (1.0 + 5e-6)) << k;
        EXPECT_NEAR(glm::length(hz.dirs[k]), 1.0f, 1e-6f);
    }
}

// `vista bench --dump-rays`: one set per dumped hybrid frame, each the list
// that frame traced (its pixels re-cast give the saved frame's colours).
TEST(RaySet, BenchDumpsTheHybridFramesRays) {
    const char* d = std::getenv("DISPLAY");
    if (!d || !*d) GTEST_SKIP() << "no X display: run the rendering tests under xvfb-run -a";
    TempDir dir("vista_dump_rays");
    const std::string city = dir.file("tiny.osgb");
    CliRun r = runVista("gen --size 300 --seed 3 -q -o " + city);
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string common = city + " --seed 4 --duration 10 --frames 3 --size 160x120 -q --near 10 --modes hybrid";
    r = runVista("bench " + common + " --save-frames --dump-rays " + dir.file("rays") + " --dump-rays-every 2 --out " +
                 dir.file("b"));
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(listTree(dir.file("rays")), (std::set<std::string>{"hybrid_f0000.rays", "hybrid_f0002.rays"}));
    auto loaded = loadCityFile(city);
    ASSERT_TRUE(loaded.isOk()) << loaded.status().message();
    auto rs = RayScene::build(*loaded);
    ASSERT_TRUE(rs.isOk()) << rs.status().message();
    // frames.csv: px_ray_hit (column 15, from 0) and px_ray_miss (16) per frame.
    std::ifstream csv(dir.file("b/frames.csv"));
    std::string line;
    std::getline(csv, line);
    std::vector<std::pair<uint64_t, uint64_t>> px;
    while (std::getline(csv, line)) {
        std::vector<std::string> col;
        std::stringstream ss(line);
        for (std::string c; std::getline(ss, c, ',');) col.push_back(c);
        ASSERT_GE(col.size(), 17u) << line;
        if (col[3] == "hybrid") px.push_back({std::stoull(col[15]), std::stoull(col[16])});
    }
    ASSERT_EQ(px.size(), 3u);
    for (int f : {0, 2}) {
        char name[64];
        std::snprintf(name, sizeof name, "rays/hybrid_f%04d.rays", f);
        auto set = readRaySet(dir.file(name));
        ASSERT_TRUE(set.isOk()) << set.status().message();
        EXPECT_EQ(set->frame, uint32_t(f));
        EXPECT_EQ(set->camera.width, 160);
        EXPECT_EQ(set->hazeFar, 0.0);
        const auto [hit, miss] = px[size_t(f)];
        EXPECT_GT(set->pixels.size(), 0u) << "near 10 m: far pixels are traced";
        EXPECT_GE(set->pixels.size(), miss) << "every ray-stage miss is in the list";
        EXPECT_LE(set->pixels.size(), hit + miss) << "seam hits are the only rayHit pixels not in it";
        std::snprintf(name, sizeof name, "b/frames/f%04d_hybrid.png", f);
        auto png = readPng(dir.file(name));
        ASSERT_TRUE(png.isOk()) << png.status().message();
        EXPECT_NEAR(set->tnear, 10.0, 0.05) << "--near 10: the far rays start at the near distance";
        Image again(160, 120);
        RayCounts counts;
        RayShading start;
        start.tnear = float(set->tnear);
        castPrimaryRays(**rs, set->camera, set->pixels.data(), set->pixels.size(), again, counts, 1, nullptr, start);
        size_t differ = 0;
        for (uint32_t i : set->pixels)
            differ += again.at(int(i % 160), int(i / 160)) != png->at(int(i % 160), int(i / 160)) ? 1 : 0;
        EXPECT_EQ(differ, 0u) << "frame " << f << ": the set's rays give the frame's far pixels";
    }
    // No mode with a far-field ray stage: refused, naming the option.
    r = runVista("bench " + city + " --seed 4 --frames 1 --size 160x120 -q --modes near --dump-rays " + dir.file("r2") +
                 " --out " + dir.file("b2"));
    EXPECT_NE(r.code, 0);
    EXPECT_NE(r.err.find("--dump-rays"), std::string::npos) << r.err;
    r = runVista("bench " + common + " --dump-rays " + dir.file("r3") + " --dump-rays-every 0 --out " + dir.file("b3"));
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("option --dump-rays-every = '0' is out of range [1, 1000000]"), std::string::npos) << r.err;
}
