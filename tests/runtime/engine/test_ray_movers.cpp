// RayScene moving objects (placeMovers): instances of prototype meshes placed
// per frame in the top level, hit with their labels, moved and hidden.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "runtime/engine/ray_scene.h"
#include "tests/runtime/engine/fixtures.h"

using namespace vista;
using namespace vista::test;

namespace {

// A 4 x 2 x 1.5 m box standing on z = 0 around the prototype origin.
SceneMesh carBox() {
    SceneMesh m;
    addBox(m, {-2, -1, 0}, {2, 1, 1.5}, {10, 20, 200, 255});
    return m;
}

// A city scene: one ground box far below, so the scene has a region and a frame.
SceneModel ground() {
    SceneModel c;
    SceneMesh m;
    addBox(m, {-200, -200, -11}, {200, 200, -10}, {90, 90, 90, 255});
    c.meshes.push_back(m);
    return c;
}

glm::dmat4 placed(double x, double y, double yaw) {
    return glm::rotate(glm::translate(glm::dmat4(1.0), glm::dvec3(x, y, 0.0)), yaw, glm::dvec3(0, 0, 1));
}

}  // namespace

TEST(RayMovers, PlacedObjectsAreHitWithTheirLabelsMovedAndHidden) {
    auto rs = RayScene::build(ground());
    ASSERT_TRUE(rs.isOk()) << rs.status().message();
    RayScene& s = **rs;
    const glm::vec3 down(0, 0, -1);
    // Before any placement: the ray down at x = 30 reaches the ground.
    RayHit h = s.intersect({30, 0, 50}, down);
    ASSERT_TRUE(h.hit);
    EXPECT_NEAR(h.t, 60.0f, 1e-3f);
    EXPECT_EQ(s.source(h).mover, -1);
    ASSERT_TRUE(s.setMoverPrototypes({carBox()}));
    ASSERT_TRUE(s.placeMovers({{0, placed(30, 0, 0.0), 0xB0000007u, 15}}));
    EXPECT_EQ(s.moverCount(), 1u);
    h = s.intersect({30, 0, 50}, down);
    ASSERT_TRUE(h.hit);
    EXPECT_NEAR(h.t, 48.5f, 1e-3f);  // the roof at 1.5 m
    EXPECT_EQ(h.color, glm::u8vec4(10, 20, 200, 255));
    HitSource src = s.source(h);
    EXPECT_EQ(src.mover, 0);
    EXPECT_EQ(src.moverId, 0xB0000007u);
    EXPECT_EQ(src.moverClass, 15);
    EXPECT_EQ(src.mesh, -1);
    // Turned by 90 degrees: 1 m half-width along x now, so x = 31.5 misses, y = 1.5 hits.
    ASSERT_TRUE(s.placeMovers({{0, placed(30, 0, 0.5 * M_PI), 0xB0000007u, 15}}));
    EXPECT_NEAR(s.intersect({31.5f, 0, 50}, down).t, 60.0f, 1e-3f);
    EXPECT_NEAR(s.intersect({30, 1.5f, 50}, down).t, 48.5f, 1e-3f);
    // Moved away and a second object added: the old place shows the ground again.
    ASSERT_TRUE(s.placeMovers({{0, placed(-40, 5, 0.0), 1u, 16}, {0, placed(60, 0, 0.0), 2u, 15}}));
    EXPECT_NEAR(s.intersect({30, 0, 50}, down).t, 60.0f, 1e-3f);
    h = s.intersect({-40, 5, 50}, down);
    EXPECT_NEAR(h.t, 48.5f, 1e-3f);
    EXPECT_EQ(s.source(h).moverId, 1u);
    EXPECT_EQ(s.source(s.intersect({60, 0, 50}, down)).moverId, 2u);
    // Hidden: nothing of them is left.
    ASSERT_TRUE(s.placeMovers({}));
    EXPECT_EQ(s.moverCount(), 0u);
    for (float x : {-40.0f, 30.0f, 60.0f})
        EXPECT_NEAR(s.intersect({x, x == -40.0f ? 5.0f : 0.0f, 50}, down).t, 60.0f, 1e-3f);
    // Moving the frame origin keeps an object where it stands in the world.
    ASSERT_TRUE(s.placeMovers({{0, placed(30, 0, 0.0), 3u, 15}}));
    const glm::dvec3 before = s.frameOrigin();
    ASSERT_TRUE(s.setFrameOrigin(before + glm::dvec3(1000, 0, 0)));
    const glm::vec3 org(glm::dvec3(30, 0, 50) + before - s.frameOrigin());
    EXPECT_NEAR(s.intersect(org, down).t, 48.5f, 1e-3f);
    // An unknown prototype is an error that names it.
    const Status bad = s.placeMovers({{5, placed(0, 0, 0), 1u, 15}});
    EXPECT_FALSE(bad);
    EXPECT_NE(bad.message().find("prototype 5"), std::string::npos) << bad.message();
}
