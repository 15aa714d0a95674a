// RayScene regions: instanced region scenes against the flat scene, regions
// added and removed at run time, and the same street geometry traced at the
// frame origin and 32 km from it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include "runtime/engine/frame_raycast.h"
#include "runtime/engine/ray_scene.h"
#include "tests/runtime/engine/fixtures.h"

using namespace vista;
using namespace vista::test;

namespace {

// A city of n x n tiles of `tileM` metres around the frame origin
// (params.origin), its geometry shifted by `shift` (world metres): per tile a
// ground quad and a few boxes (tile-local float positions, the tile origin in
// double) and trees (instances of two prototypes). The same seed gives the
// same tile-local geometry for any shift.
SceneModel tiledCity(uint32_t seed, int n, double tileM, const glm::dvec3& shift = glm::dvec3(0.0)) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> pos(float(0.05 * tileM), float(0.8 * tileM)), size(3.0f, 20.0f),
        height(3.0f, 50.0f), yaw(0.0f, 6.2831853f), scale(0.7f, 1.4f);
    std::uniform_int_distribution<int> col(30, 220);
    SceneModel city;
    city.params.origin_x = 0.0;
    city.params.origin_y = 0.0;
    city.params.size_m = n * tileM;
    for (int p = 0; p < 2; ++p) {
        SceneMesh proto;
        addBox(proto, {-0.3f, -0.3f, 0.0f}, {0.3f, 0.3f, 3.0f}, {90, 60, 30, 255});
        addBox(proto, {-2.0f - p, -2.0f - p, 3.0f}, {2.0f + p, 2.0f + p, 7.0f + p},
               {40, uint8_t(120 + 40 * p), 40, 255});
        city.prototypes.push_back(proto);
    }
    for (int ty = 0; ty < n; ++ty)
        for (int tx = 0; tx < n; ++tx) {
            SceneTile tile;
            tile.child = uint32_t(city.tiles.size());
            tile.origin = shift + glm::dvec3((tx - n / 2) * tileM, (ty - n / 2) * tileM, 0.0);
            SceneMesh ground, boxes;
            ground.origin = boxes.origin = tile.origin;
            addGround(ground, glm::vec2(0.0f), glm::vec2(float(tileM)), 0.0f,
                      {uint8_t(80 + 10 * ((tx + ty) % 3)), 90, 95, 255});
            for (int b = 0; b < 4; ++b) {
                const glm::vec3 lo(pos(rng), pos(rng), 0.0f);
                const glm::vec3 hi = lo + glm::vec3(size(rng), size(rng), height(rng));
                addBox(boxes, lo, hi, glm::u8vec4(uint8_t(col(rng)), uint8_t(col(rng)), uint8_t(col(rng)), 255));
            }
            for (SceneMesh* m : {&ground, &boxes}) {
                tile.meshes.push_back(uint32_t(city.meshes.size()));
                city.meshes.push_back(*m);
                expandBounds(*m, tile.lo, tile.hi);
            }
            for (int t = 0; t < 3; ++t) {
                SceneInstance in;
                in.prototype = uint32_t(t % 2);
                const glm::dvec3 at = tile.origin + glm::dvec3(pos(rng), pos(rng), 0.0);
                in.transform = glm::translate(glm::dmat4(1.0), at) *
                               glm::rotate(glm::dmat4(1.0), double(yaw(rng)), glm::dvec3(0, 0, 1)) *
                               glm::scale(glm::dmat4(1.0), glm::dvec3(scale(rng)));
                tile.instances.push_back(uint32_t(city.instances.size()));
                city.instances.push_back(in);
                expandBounds(city, in, tile.lo, tile.hi);
            }
            city.tiles.push_back(tile);
        }
    return city;
}

// Rays from eye-height points spread over the city, in random directions
// (mostly near the horizon, some down), scene-local.
struct Rays {
    std::vector<glm::vec3> org, dir;
};
Rays randomRays(uint32_t seed, int n, double extent, const glm::dvec3& shift, const RayScene& rs) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> p(-extent / 2, extent / 2), z(1.5, 30.0);
    std::uniform_real_distribution<float> az(-3.14159f, 3.14159f), el(-0.5f, 0.15f);
    Rays r;
    for (int i = 0; i < n; ++i) {
        const glm::dvec3 eye = shift + glm::dvec3(p(rng), p(rng), z(rng));
        r.org.emplace_back(eye - rs.frameOrigin());
        const float a = az(rng), e = el(rng);
        r.dir.push_back({std::sin(a) * std::cos(e), std::cos(a) * std::cos(e), std::sin(e)});
    }
    return r;
}

std::vector<RayHit> castAll(const RayScene& rs, const Rays& r) {
    std::vector<RayHit> h(r.org.size());
    rs.intersectMany(r.org.data(), r.dir.data(), int(r.org.size()), h.data());
    return h;
}

// Smallest barycentric coordinate of a hit: near 0 on a triangle's edge.
float edgeDistance(const RayHit& h) { return std::min({h.u, h.v, 1.0f - h.u - h.v}); }

}  // namespace

TEST(RayRegions, InstancedRegionsHitWhatTheFlatSceneHits) {
    const SceneModel city = tiledCity(7, 6, 250.0);
    RaySceneOptions flatOpt;
    flatOpt.regionSizeM = 0;
    RaySceneOptions regOpt;
    regOpt.regionSizeM = 500;  // tiles from -750 to +750 m: 4 x 4 regions
    auto flat = RayScene::build(city, flatOpt);
    auto reg = RayScene::build(city, regOpt);
    ASSERT_TRUE(flat.isOk()) << flat.status().message();
    ASSERT_TRUE(reg.isOk()) << reg.status().message();
    EXPECT_EQ((*reg)->regionCount(), 16);
    EXPECT_EQ((*flat)->regionCount(), 0);
    EXPECT_EQ((*reg)->triangleCount(), (*flat)->triangleCount());
    const Rays r = randomRays(3, 4000, 1500.0, glm::dvec3(0.0), **flat);
    const std::vector<RayHit> a = castAll(**flat, r), b = castAll(**reg, r);
    int hits = 0, trees = 0, grazing = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        if (a[i].hit != b[i].hit) {
            // Only a ray through a triangle's edge may find it in one layout and not the other.
            const RayHit& h = a[i].hit ? a[i] : b[i];
            EXPECT_LT(edgeDistance(h), 1e-3f) << "ray " << i;
            ++grazing;
            continue;
        }
        if (!a[i].hit) continue;
        ++hits;
        const HitSource sa = (*flat)->source(a[i]), sb = (*reg)->source(b[i]);
        // Hit distance within 1e-5 relative (float rounding of the two layouts' vertices).
        EXPECT_NEAR(a[i].t, b[i].t, 1e-5f * a[i].t + 1e-4f) << "ray " << i;
        if (std::fabs(a[i].t - b[i].t) < 1e-3f && edgeDistance(a[i]) > 1e-3f) {
            EXPECT_EQ(sa.mesh, sb.mesh) << "ray " << i;
            EXPECT_EQ(sa.instance, sb.instance) << "ray " << i;
            EXPECT_EQ(a[i].primId, b[i].primId) << "ray " << i;
            EXPECT_NEAR(a[i].color.x, b[i].color.x, 1) << "ray " << i;
            EXPECT_NEAR(a[i].color.y, b[i].color.y, 1) << "ray " << i;
            EXPECT_NEAR(a[i].color.z, b[i].color.z, 1) << "ray " << i;
            EXPECT_NEAR(glm::dot(a[i].normal, b[i].normal), 1.0f, 1e-4f) << "ray " << i;
        }
        EXPECT_EQ(sa.region, -1);
        EXPECT_GE(sb.region, 0);
        trees += sb.instance >= 0 ? 1 : 0;
    }
    EXPECT_GT(hits, 2000);
    EXPECT_GT(trees, 20);
    EXPECT_LE(grazing, 4);
}

TEST(RayRegions, AddingThenRemovingARegionGivesTheHitsOfNeverAdding) {
    const SceneModel city = tiledCity(11, 4, 250.0);
    auto rs = RayScene::empty(glm::dvec3(city.params.origin_x, city.params.origin_y, 0.0));
    ASSERT_TRUE(rs.isOk()) << rs.status().message();
    RayScene& s = **rs;
    // Regions: the tile rows (4 tiles each); row 2 is the one added and removed.
    std::vector<int> ids;
    for (int row : {0, 1, 3}) {
        auto id =
            s.addRegion(city, {uint32_t(4 * row), uint32_t(4 * row + 1), uint32_t(4 * row + 2), uint32_t(4 * row + 3)});
        ASSERT_TRUE(id.isOk()) << id.status().message();
        ids.push_back(*id);
    }
    ASSERT_TRUE(s.commit().isOk());
    EXPECT_EQ(s.regionCount(), 3);
    const size_t tris = s.triangleCount();
    const Rays r = randomRays(5, 3000, 1000.0, glm::dvec3(0.0), s);
    const std::vector<RayHit> never = castAll(s, r);

    auto added = s.addRegion(city, {8, 9, 10, 11});
    ASSERT_TRUE(added.isOk()) << added.status().message();
    ASSERT_TRUE(s.commit().isOk());
    EXPECT_EQ(s.regionCount(), 4);
    EXPECT_GT(s.triangleCount(), tris);
    const std::vector<RayHit> with = castAll(s, r);
    int changed = 0, inAdded = 0;
    for (size_t i = 0; i < with.size(); ++i) {
        changed += with[i].hit != never[i].hit || with[i].t != never[i].t ? 1 : 0;
        const HitSource src = s.source(with[i]);
        if (src.region == *added) {
            ++inAdded;
            // Its meshes and trees are those of tiles 8..11.
            if (src.mesh >= 0) { EXPECT_GE(src.mesh, 2 * 8) << "ray " << i; }
            if (src.instance >= 0) { EXPECT_GE(src.instance, 3 * 8) << "ray " << i; }
        }
    }
    EXPECT_GT(changed, 100);  // the region is really traced
    EXPECT_GT(inAdded, 100);

    ASSERT_TRUE(s.removeRegion(*added).isOk());
    ASSERT_TRUE(s.commit().isOk());
    EXPECT_EQ(s.regionCount(), 3);
    EXPECT_EQ(s.triangleCount(), tris);
    EXPECT_FALSE(s.removeRegion(*added).isOk());  // gone already
    const std::vector<RayHit> after = castAll(s, r);
    for (size_t i = 0; i < after.size(); ++i) {
        ASSERT_EQ(after[i].hit, never[i].hit) << "ray " << i;
        if (!after[i].hit) continue;
        EXPECT_EQ(after[i].t, never[i].t) << "ray " << i;
        EXPECT_EQ(after[i].color, never[i].color) << "ray " << i;
        EXPECT_EQ(after[i].primId, never[i].primId) << "ray " << i;
        const HitSource x = s.source(after[i]), y = s.source(never[i]);
        EXPECT_EQ(x.mesh, y.mesh) << "ray " << i;
        EXPECT_EQ(x.instance, y.instance) << "ray " << i;
        EXPECT_EQ(x.region, y.region) << "ray " << i;
    }
}

TEST(RayRegions, BadRegionRequestsAreRefused) {
    const SceneModel city = tiledCity(2, 2, 100.0);
    auto rs = RayScene::empty(glm::dvec3(0.0));
    ASSERT_TRUE(rs.isOk());
    auto bad = (*rs)->addRegion(city, {4});
    ASSERT_FALSE(bad.isOk());
    EXPECT_NE(bad.status().message().find("tile 4 out of range"), std::string::npos) << bad.status().message();
    EXPECT_FALSE((*rs)->removeRegion(0).isOk());
    EXPECT_EQ((*rs)->regionCount(), 0);
    RaySceneOptions flatOpt;
    flatOpt.regionSizeM = 0;
    auto flat = RayScene::build(city, flatOpt);
    ASSERT_TRUE(flat.isOk());
    EXPECT_FALSE((*flat)->addRegion(city, {0}).isOk());
}

// The same street geometry placed at the frame origin and 32 km from it in
// each diagonal direction (a corner of a 64 km paged city, whose frame origin
// is the city centre) gives the same raycast image, camera at the same place
// relative to the geometry, when the frame follows the camera
// (placeFrameNear, as vista bench and render do): regions keep vertices
// region-local and their translations exact, and the ray origins are small.
// (The flat layout, float vertices and ray origins around the centre, gives
// 24 to 30 channels that differ by more than 1 level here.)
TEST(RayRegions, SameImageAtTheCentreAndThirtyTwoKilometresAway) {
    const int W = 480, H = 360;
    auto render = [&](const glm::dvec3& shift, double regionSizeM, Image& out) {
        const SceneModel city = tiledCity(9, 4, 250.0, shift);
        RaySceneOptions o;
        o.regionSizeM = regionSizeM;
        auto rs = RayScene::build(city, o);
        ASSERT_TRUE(rs.isOk()) << rs.status().message();
        RayCounts counts;
        for (int k = 0; k < 3; ++k) {
            const Camera c = testCamera(shift + glm::dvec3(-310.3 + 97.1 * k, -140.7 + 45.3 * k, k == 1 ? 40.0 : 1.7),
                                        0.7 + 0.9 * k, k == 1 ? -0.25 : 0.02, W, H, 1.0);
            ASSERT_TRUE((*rs)->placeFrameNear(c.eye).isOk());
            Image img;
            castFrame(**rs, c, img, counts, 1);
            out.width = W;
            out.height = H * (k + 1);
            out.rgba.insert(out.rgba.end(), img.rgba.begin(), img.rgba.end());
        }
    };
    Image centre;
    render(glm::dvec3(0.0), 2000.0, centre);
    for (const glm::dvec3 shift : {glm::dvec3(32000, 32000, 0), glm::dvec3(-32000, 32000, 0),
                                   glm::dvec3(32000, -32000, 0), glm::dvec3(-32000, -32000, 0)}) {
        Image far;
        render(shift, 2000.0, far);
        ASSERT_EQ(far.rgba.size(), centre.rgba.size());
        int worst = 0;
        size_t differ = 0;
        for (size_t i = 0; i < far.rgba.size(); ++i) {
            const int d = std::abs(int(far.rgba[i]) - int(centre.rgba[i]));
            worst = std::max(worst, d);
            differ += d > 1 ? 1 : 0;
        }
        EXPECT_LE(worst, 1) << "shift " << shift.x << ", " << shift.y << ": " << differ << " channels differ by more";
    }
}
