// Bake: view cells from street segments and the ray scene of a triangle soup.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>

#include <sys/stat.h>
#include <unistd.h>

#include <osg/UserDataContainer>
#include <osgDB/ReaderWriter>
#include <osgDB/Registry>
#include <tbb/global_control.h>

#include "citygen/generate.h"
#include "citygen/polygon.h"
#include "bake/appearance.h"
#include "bake/assembly.h"
#include "bake/bake_cell.h"
#include "bake/cell_result.h"
#include "bake/depth_mesh.h"
#include "bake/far_set.h"
#include "bake/impostor_frame.h"
#include "bake/driver.h"
#include "bake/ldi_sampling.h"
#include "bake/placement.h"
#include "bake/point_removal.h"
#include "bake/sampling_plane.h"
#include "bake/view_cells.h"
#include "foundation/hash.h"
#include "foundation/units.h"
#include "nodes/baked_file.h"
#include "foundation/rng.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_file.h"
#include "nodes/render/mode_impostor.h"
#include "nodes/render/mode_full.h"
#include "nodes/render/mode_lodmesh.h"
#include "runtime/engine/image.h"
#include "runtime/engine/metrics.h"
#include "nodes/render/offscreen.h"

#include "tests/common/temp_dir.h"
#include "tests/bake/bake_fixtures.h"

namespace vista {
namespace {
using test::readBytes;

// --------------------------------------------------------------- view cells
TEST(ViewCells, BoxesFromStreetSegments) {
    StreetGraph g;
    g.nodes = {{0, 0}, {100, 0}, {100, 0}, {100.3, 0}, {101, 0}, {100, 50}};
    g.edges = {{0, 1, RoadClass::Local, 10.0f, 2},  // normal
               {1, 2, RoadClass::Local, 8.0f, 2},   // zero length
               {1, 3, RoadClass::Local, 8.0f, 2},   // 0.3 m: below the minimum
               {1, 4, RoadClass::Local, 8.0f, 2},   // 1 m: very short but valid
               {1, 5, RoadClass::Local, 8.0f, 2}};
    std::vector<SkippedCell> skipped;
    ViewCellParams p;
    auto cells = makeViewCells(
        g, {1000.0, 2000.0}, [](const glm::dvec2& q) { return 0.01 * q.x; }, p, &skipped);
    ASSERT_EQ(cells.size(), 3u);
    ASSERT_EQ(skipped.size(), 2u);
    EXPECT_EQ(skipped[0].edge, 1u);
    EXPECT_EQ(skipped[1].edge, 2u);
    const ViewCell& c = cells[0];
    EXPECT_EQ(c.id, 0u);
    EXPECT_NEAR(c.box.center.x, 1050.0, 1e-9);
    EXPECT_NEAR(c.box.center.y, 2000.0, 1e-9);
    EXPECT_NEAR(c.box.halfLength, 50.0, 1e-9);
    EXPECT_NEAR(c.box.halfWidth, 5.0, 1e-9);
    // Eye heights 1.2..2 m above a ground rising from 0 to 1 m along the segment.
    EXPECT_NEAR(c.box.center.z - c.box.halfHeight, 0.0 + 1.2, 1e-9);
    EXPECT_NEAR(c.box.center.z + c.box.halfHeight, 1.0 + 2.0, 1e-9);
    EXPECT_EQ(cells[1].id, 3u);
    EXPECT_NEAR(cells[1].box.halfLength, 0.5, 1e-9);
    EXPECT_TRUE(c.box.contains({1010.0, 2004.0, 1.5}));
    EXPECT_FALSE(c.box.contains({1010.0, 2006.0, 1.5}));
    EXPECT_FALSE(c.box.contains({1010.0, 2000.0, 0.5}));
}

TEST(ViewCells, GridLookupMatchesBruteForce) {
    std::vector<ViewCellBox> boxes;
    Rng rng(3, 1, Stream::Bake);
    for (int i = 0; i < 200; ++i) {
        ViewCellBox b;
        b.center = {rng.uniform(-500, 500), rng.uniform(-500, 500), 1.6};
        const double a = rng.uniform(0, kTwoPi);
        b.axis = {std::cos(a), std::sin(a)};
        b.halfLength = rng.uniform(0.3, 80);
        b.halfWidth = rng.uniform(2, 12);
        b.halfHeight = 0.4;
        boxes.push_back(b);
    }
    boxes.push_back(ViewCellBox{});  // an absent cell (all zero) is never found
    ViewCellGrid grid;
    grid.build(boxes);
    int found = 0;
    for (int k = 0; k < 20000; ++k) {
        const glm::dvec3 p(rng.uniform(-600, 600), rng.uniform(-600, 600), rng.uniform(1.0, 2.2));
        int brute = -1;
        for (size_t i = 0; i < boxes.size(); ++i)
            if (boxes[i].halfHeight > 0 && boxes[i].contains(p)) {
                brute = int(i);
                break;
            }
        ASSERT_EQ(grid.find(p), brute) << p.x << "," << p.y << "," << p.z;
        found += brute >= 0;
    }
    EXPECT_GT(found, 100);
    EXPECT_EQ(grid.find({NAN, 0, 0}), -1);
}

// ------------------------------------------------------ ray scene of a soup
// What the bake relies on: every layer along a ray (front and back faces, no
// culling by default), interpolated colours without rounding, culling as an
// option, bad soups as errors.
TEST(RaySceneSoup, AllHitsUnroundedColoursAndCullingOption) {
    TriangleSoup soup;
    // First box: black at y = -1, white at y = 1 (linear across each face).
    addBox(soup, {10, -1, -1}, {12, 1, 1},
           [](glm::vec3 p) { return p.y < 0 ? glm::u8vec4(0, 0, 0, 255) : glm::u8vec4(255, 255, 255, 255); });
    addBox(soup, {20, -1, -1}, {21, 1, 1}, constantColor);
    auto scene = RayScene::build(soup);
    ASSERT_TRUE(scene.isOk()) << scene.status().message();
    EXPECT_EQ((*scene)->triangleCount(), 24u);
    RayHit hits[8];
    const int n = (*scene)->allHits({0, 0.3f, 0.2f}, {1, 0, 0}, 0.0f, 1e30f, 8, 0.01f, hits);
    ASSERT_EQ(n, 4);  // both boxes, entry and exit
    const float ts[] = {10, 12, 20, 21};
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(hits[k].t, ts[k], 1e-4f) << k;
    EXPECT_NEAR(hits[0].normal.x * hits[0].normal.x, 1.0f, 1e-6f);
    // At y = 0.3 the first box is 65 % white: hitColor interpolates without
    // rounding (0.65), RayHit::color is rounded to 8 bits (166 = 0.651).
    for (int k = 0; k < 2; ++k) {
        EXPECT_NEAR(glm::length((*scene)->hitColor(hits[k]) - glm::vec3(0.65f)), 0.0f, 1e-5f) << k;
        EXPECT_EQ(hits[k].color, glm::u8vec4(166, 166, 166, 255)) << k;
    }
    EXPECT_NEAR(glm::length((*scene)->hitColor(hits[2]) - glm::vec3(glm::u8vec3(100, 150, 200)) / 255.0f), 0.0f, 1e-6f);
    EXPECT_EQ((*scene)->allHits({0, 0.3f, 0.2f}, {1, 0, 0}, 0.0f, 15.0f, 8, 0.01f, hits), 2);  // tfar clips
    // The packet version (as the LDI rows use it) gives each ray the hits of
    // allHits: 19 rays fanning through both boxes (some miss, one with an
    // empty interval, one clipped), 3 layers at most.
    {
        std::vector<glm::vec3> org, dir;
        std::vector<float> tn, tf;
        for (int i = 0; i < 19; ++i) {
            org.push_back({0, 0.1f * i - 0.9f, 0.2f});
            dir.push_back(glm::normalize(glm::vec3(1, 0.0123f * (i - 9), 0.0037f * i)));  // no ray through an edge
            tn.push_back(i == 4 ? 30.0f : 0.5f * (i % 3));
            tf.push_back(i == 7 ? 11.0f : i == 4 ? 5.0f : 1e30f);
        }
        const int layers = 3;
        std::vector<RayHit> many(org.size() * layers);
        std::vector<int> counts(org.size(), -1);
        (*scene)->allHitsMany(org.data(), dir.data(), int(org.size()), tn.data(), tf.data(), layers, 0.01f, many.data(),
                              counts.data());
        int total = 0, missed = 0;
        for (size_t i = 0; i < org.size(); ++i) {
            RayHit one[3];
            const int n1 = (*scene)->allHits(org[i], dir[i], tn[i], tf[i], layers, 0.01f, one);
            ASSERT_EQ(counts[i], n1) << "ray " << i;
            for (int k = 0; k < n1; ++k) {
                EXPECT_NEAR(many[i * layers + size_t(k)].t, one[k].t, 1e-5f) << "ray " << i << " layer " << k;
                EXPECT_EQ(many[i * layers + size_t(k)].primId, one[k].primId) << "ray " << i << " layer " << k;
            }
            total += n1;
            missed += n1 == 0;
        }
        EXPECT_EQ(counts[4], 0) << "an empty interval has no hit";
        EXPECT_EQ(counts[7], 1) << "tfar clips after the entry face";
        EXPECT_GT(total, 19) << "rays cross several faces";
        EXPECT_GT(missed, 1) << "some rays pass beside the boxes";
    }

    EXPECT_TRUE((*scene)->occluded({0, 0.3f, 0.2f}, {1, 0, 0}, 0.0f, 10.5f));
    EXPECT_FALSE((*scene)->occluded({0, 0.3f, 0.2f}, {1, 0, 0}, 0.0f, 9.5f));
    // From inside the first box, looking out: the culled scene skips the exit (back) face.
    SoupSceneOptions cull;
    cull.cullBackFaces = true;
    cull.quality = RayBuildQuality::High;
    auto culled = RayScene::build(soup, cull);
    ASSERT_TRUE(culled.isOk());
    EXPECT_NEAR((*scene)->intersect({11, 0.3f, 0.2f}, {1, 0, 0}).t, 1.0f, 1e-4f);   // the exit face at x = 12
    EXPECT_NEAR((*culled)->intersect({11, 0.3f, 0.2f}, {1, 0, 0}).t, 9.0f, 1e-4f);  // the next box at x = 20
    // Bad soups are errors.
    TriangleSoup bad = soup;
    bad.indices.push_back(9999);
    bad.indices.push_back(0);
    bad.indices.push_back(1);
    EXPECT_FALSE(RayScene::build(bad).isOk());
    bad = soup;
    bad.colors.pop_back();
    EXPECT_FALSE(RayScene::build(bad).isOk());
    bad = soup;
    bad.positions[0].x = NAN;
    EXPECT_FALSE(RayScene::build(bad).isOk());
    auto empty = RayScene::build(TriangleSoup{});
    ASSERT_TRUE(empty.isOk());
    EXPECT_FALSE((*empty)->intersect({0, 0, 0}, {1, 0, 0}).hit);
}

}  // namespace
}  // namespace vista
