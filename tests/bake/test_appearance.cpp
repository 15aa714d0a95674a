// Bake: Monte Carlo appearance of the sampled points.
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

// ---------------------------------------------------------------- appearance
TEST(Appearance, ConstantColourSceneIsExactAndCompressesToOneColour) {
    TriangleSoup soup = testFarField(true);
    auto scene = RayScene::build(soup);
    ASSERT_TRUE(scene.isOk());
    const Box3 cell{{-100, -5, 1.2}, {0, 5, 2.0}};
    Box3 far{glm::dvec3(1e300), glm::dvec3(-1e300)};
    for (auto& p : soup.positions) {
        far.lo = glm::min(far.lo, glm::dvec3(p));
        far.hi = glm::max(far.hi, glm::dvec3(p));
    }
    auto s = setupSampling(cell, far);
    ASSERT_TRUE(s.isOk());
    // Points on the facade's front, away from its edges (no sky in the pixel filter).
    std::vector<glm::vec3> pts;
    for (int i = 0; i < 20; ++i)
        for (int j = 0; j < 6; ++j) pts.emplace_back(160.0f, -20.0f + 2.0f * i, 4.0f + 2.5f * j);
    AppearanceParams ap;
    AppearanceStats st;
    PointImpostorData d;
    computeAppearance(**scene, *s, pts, ap, 1, 42, d, st);
    ASSERT_EQ(d.positions.size(), pts.size());
    EXPECT_EQ(st.dropped, 0u);
    EXPECT_EQ(st.textured, 0u);
    EXPECT_TRUE(d.texels.empty());
    for (size_t k = 0; k < d.colors.size(); ++k) {
        EXPECT_EQ(d.block[k], -1);
        EXPECT_EQ(d.colors[k], constantColor({})) << k;
    }
}

TEST(Appearance, InvisiblePointsDroppedAndVisibleOnesKept) {
    TriangleSoup soup = testFarField(false);
    auto scene = RayScene::build(soup);
    const Box3 cell{{-100, -5, 1.2}, {0, 5, 2.0}};
    Box3 far{{150, -40, -1}, {210, 40, 24}};
    auto s = setupSampling(cell, far);
    ASSERT_TRUE(s.isOk());
    // A point on the roof edge of a strip (sky behind at the top), one on a
    // colour boundary, one hidden behind the facade (back face of the ground).
    std::vector<glm::vec3> pts = {{160, 0.5f, 23.95f}, {160, 0.0f, 12.0f}, {200, 0, 0}};
    AppearanceParams ap;
    AppearanceStats st;
    PointImpostorData d;
    std::vector<uint32_t> kept;
    computeAppearance(**scene, *s, pts, ap, 1, 7, d, st, &kept);
    EXPECT_EQ(st.dropped, 1u);
    ASSERT_EQ(kept.size(), 2u);
    EXPECT_EQ(kept[0], 0u);
    EXPECT_EQ(kept[1], 1u);
    EXPECT_EQ(d.texels.size(), st.textured * 16);
}

// View dependence vs Monte Carlo noise. A wall 300 m away is dark for y < 0
// and bright for y > 0; a 10 cm post 200 m away stands in front of y = 0.
//  - Points on the post: their pixel filter sees mostly the wall beside the
//    post, which is bright from viewpoints with y < 0 and dark from y > 0
//    (parallax): the colour depends on the viewpoint, so they must be textured,
//    with the texel luma falling from the y < 0 side to the y > 0 side.
//  - Points on the wall's colour boundary, above the post: a 50/50 mix from
//    every viewpoint; the per-sample spread is large but the same everywhere,
//    so the F test makes them single-coloured (the old spread-only rule, level
//    0, textures them).
struct ParallaxScene {
    TriangleSoup soup;
    Box3 cell{{-100, -5, 1.2}, {0, 5, 2.0}};
    Box3 far{{199, -20, -0.5}, {302, 20, 12.5}};
    ParallaxScene() {
        addBox(soup, {300, -20, 0}, {301, 0, 12}, [](glm::vec3) { return glm::u8vec4(20, 20, 20, 255); });
        addBox(soup, {300, 0, 0}, {301, 20, 12}, [](glm::vec3) { return glm::u8vec4(235, 235, 235, 255); });
        addBox(soup, {200, -0.05f, 0}, {200.1f, 0.05f, 6}, [](glm::vec3) { return glm::u8vec4(128, 128, 128, 255); });
    }
};

TEST(Appearance, ViewDependentPointsTexturedNoiseOnlyPointsOneColour) {
    ParallaxScene ps;
    auto scene = RayScene::build(ps.soup);
    ASSERT_TRUE(scene.isOk());
    auto s = setupSampling(ps.cell, ps.far);
    ASSERT_TRUE(s.isOk());
    std::vector<glm::vec3> pts;
    for (int k = 0; k < 5; ++k) pts.emplace_back(200.0f, 0.0f, 1.0f + float(k));          // post
    for (int k = 0; k < 10; ++k) pts.emplace_back(300.0f, 0.0f, 7.0f + 0.4f * float(k));  // boundary
    AppearanceParams ap;
    ASSERT_GT(ap.significance, 0.0);
    AppearanceStats st;
    PointImpostorData d;
    std::vector<uint32_t> kept;
    computeAppearance(**scene, *s, pts, ap, 1, 9, d, st, &kept);
    ASSERT_EQ(kept.size(), pts.size());
    const int nt = ap.texelsX * ap.texelsY;
    auto texelY = [&](int t) {  // frame y of the texel centre on the sampling plane
        const glm::dvec2 size = s->rectHi - s->rectLo;
        const glm::dvec2 q = s->rectLo + glm::dvec2((t % ap.texelsX + 0.5) * size.x / ap.texelsX,
                                                    (t / ap.texelsX + 0.5) * size.y / ap.texelsY);
        return s->toFrame(q).y;
    };
    auto luma = [](glm::u8vec4 c) { return (0.299 * c.x + 0.587 * c.y + 0.114 * c.z) / 255.0; };
    for (int k = 0; k < 5; ++k) {
        ASSERT_GE(d.block[size_t(k)], 0) << "post point " << k << " not textured";
        double left = 0, right = 0;
        int nl = 0, nr = 0;
        for (int t = 0; t < nt; ++t) {
            const double l = luma(d.texels[size_t(d.block[size_t(k)]) * size_t(nt) + size_t(t)]);
            if (texelY(t) < -2) {
                left += l;
                ++nl;
            }
            if (texelY(t) > 2) {
                right += l;
                ++nr;
            }
        }
        ASSERT_GT(nl, 0);
        ASSERT_GT(nr, 0);
        EXPECT_GT(left / nl - right / nr, 0.3) << "post point " << k;  // wall beside the post: bright vs dark
    }
    int boundarySingle = 0;
    for (int k = 5; k < 15; ++k) {
        if (d.block[size_t(k)] >= 0) continue;
        ++boundarySingle;
        EXPECT_NEAR(luma(d.colors[size_t(k)]), (20 + 235) / 2 / 255.0, 0.15) << "boundary point " << k;
    }
    EXPECT_GE(boundarySingle, 8);  // expected false-positive rate of the test: 1 %
    EXPECT_GE(st.noiseOnly, size_t(boundarySingle));

    // Level 0 (spread-only rule): the same boundary points are textured.
    ap.significance = 0;
    AppearanceStats st0;
    PointImpostorData d0;
    computeAppearance(**scene, *s, pts, ap, 1, 9, d0, st0);
    int boundaryTextured = 0;
    for (int k = 5; k < 15; ++k) boundaryTextured += d0.block[size_t(k)] >= 0 ? 1 : 0;
    EXPECT_GE(boundaryTextured, 8);
    EXPECT_EQ(st0.noiseOnly, 0u);
}

}  // namespace
}  // namespace vista
