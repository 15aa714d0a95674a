// The ray scene of a paged city: the coarse levels' trees (impostors for the
// rasteriser) are traced as their prototype meshes, so the far field shows
// trees beyond the full-detail radius.
#include <gtest/gtest.h>

#include <cmath>

#include "runtime/engine/ray_scene.h"
#include "runtime/scene/paged_load.h"
#include "tests/common/small_paged_city.h"

TEST(RayPaged, CoarseRegionsTraceTheirTrees) {
    // The shared 1.5 km city in 500 m regions (3 x 3), read in place.
    auto m = vista::readPagedManifest(vista::test::smallPagedCity().dir);
    ASSERT_TRUE(m.isOk()) << m.status().message();
    const glm::dvec2 centre(m->params.origin_x, m->params.origin_y);
    const std::vector<int> full = vista::selectPagedRegions(*m, {centre}, 0.0);
    ASSERT_FALSE(full.empty());
    const std::vector<int> coarse = vista::selectCoarseRegions(*m, {centre}, 5000.0, full);
    ASSERT_FALSE(coarse.empty());
    auto city = vista::loadPagedCity(*m, full, 0.0, nullptr, coarse);
    ASSERT_TRUE(city.isOk()) << city.status().message();
    ASSERT_FALSE(city->impostors.empty()) << "the coarse levels carry tree impostors";
    auto rs = vista::RayScene::build(*city);
    ASSERT_TRUE(rs.isOk()) << rs.status().message();
    // Rays fanned out at tree height from the centre, slightly downwards, over the coarse city.
    int treeHits = 0, impostorHits = 0;
    for (int i = 0; i < 3600; ++i) {
        const double a = 2.0 * M_PI * i / 3600.0;
        for (double z : {4.0, 6.0}) {
            const glm::vec3 org(0.0f, 0.0f, float(z));
            const glm::vec3 dir = glm::normalize(glm::vec3(float(std::sin(a)), float(std::cos(a)), -0.004f));
            const vista::RayHit h = (*rs)->intersect(org, dir, 260.0f);  // beyond region 0's part around the centre
            const vista::HitSource s = (*rs)->source(h);
            if (s.impostor >= 0) {
                ++impostorHits;
                EXPECT_LT(size_t(s.impostor), city->impostors.size());
                EXPECT_EQ(s.mesh, -1);
                EXPECT_EQ(s.instance, -1);
            }
            treeHits += s.instance >= 0 ? 1 : 0;
        }
    }
    EXPECT_GT(impostorHits, 10) << "tree instances hit: " << treeHits;
}
