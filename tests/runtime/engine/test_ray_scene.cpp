// RayScene (Embree) tests: hits, colours, packets, instances, precision far
// from the world origin, empty and malformed input.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include "runtime/engine/ray_scene.h"
#include "runtime/scene/scene_graph.h"
#include "tests/runtime/engine/fixtures.h"

using namespace vista;
using namespace vista::test;

namespace {

SceneModel oneBox(double ox = 0, double oy = 0) {
    SceneModel c;
    c.params.origin_x = ox;
    c.params.origin_y = oy;
    SceneMesh m;
    m.origin = glm::dvec3(ox, oy, 0);
    addBox(m, {-5, -10, 0}, {5, 10, 20}, {200, 100, 50, 255});
    c.meshes.push_back(m);
    return c;
}

}  // namespace

TEST(RayScene, HitsBoxFaceWithDistanceColourAndNormal) {
    auto rs = RayScene::build(oneBox());
    ASSERT_TRUE(rs.isOk()) << rs.status().message();
    EXPECT_EQ(rs.value()->triangleCount(), 12u);
    RayHit h = rs.value()->intersect({0, -50, 5}, {0, 1, 0});
    ASSERT_TRUE(h.hit);
    EXPECT_NEAR(h.t, 40.0f, 1e-4f);
    EXPECT_EQ(h.color, glm::u8vec4(200, 100, 50, 255));
    EXPECT_NEAR(h.normal.y, -1.0f, 1e-5f);
    // Pointing away: miss.
    EXPECT_FALSE(rs.value()->intersect({0, -50, 5}, {0, -1, 0}).hit);
    // tfar before the face: miss; occluded agrees.
    EXPECT_FALSE(rs.value()->intersect({0, -50, 5}, {0, 1, 0}, 0.0f, 39.0f).hit);
    EXPECT_FALSE(rs.value()->occluded({0, -50, 5}, {0, 1, 0}, 0.0f, 39.0f));
    EXPECT_TRUE(rs.value()->occluded({0, -50, 5}, {0, 1, 0}, 0.0f, 41.0f));
}

TEST(RayScene, InterpolatesVertexColoursLikeTheRasteriser) {
    SceneModel c;
    SceneMesh m;
    m.positions = {{0, 0, 0}, {10, 0, 0}, {0, 10, 0}};
    m.colors = {{255, 0, 0, 255}, {0, 255, 0, 255}, {0, 0, 255, 255}};
    m.indices = {0, 1, 2};
    c.meshes.push_back(m);
    auto rs = RayScene::build(c);
    ASSERT_TRUE(rs.isOk());
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.2f, 4.5f);
    for (int i = 0; i < 50; ++i) {
        float x = u(rng), y = u(rng);
        RayHit h = rs.value()->intersect({x, y, 10}, {0, 0, -1});
        ASSERT_TRUE(h.hit);
        // Independent barycentrics of (x, y) in the triangle.
        float b1 = x / 10, b2 = y / 10, b0 = 1 - b1 - b2;
        EXPECT_NEAR(h.color.x, 255 * b0, 0.51f + 255 * 1e-5f);
        EXPECT_NEAR(h.color.y, 255 * b1, 0.51f + 255 * 1e-5f);
        EXPECT_NEAR(h.color.z, 255 * b2, 0.51f + 255 * 1e-5f);
    }
}

TEST(RayScene, PacketsAgreeWithSingleRays) {
    SceneModel city = randomCity(3, 60);
    auto rs = RayScene::build(city);
    ASSERT_TRUE(rs.isOk()) << rs.status().message();
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> a(-3.14159f, 3.14159f), e(-0.6f, 0.3f);
    const int n = 203;  // not a multiple of 8
    std::vector<glm::vec3> org(n), dir(n);
    for (int i = 0; i < n; ++i) {
        org[i] = {0, 0, 1.7f};
        float az = a(rng), el = e(rng);
        dir[i] = {std::sin(az) * std::cos(el), std::cos(az) * std::cos(el), std::sin(el)};
    }
    std::vector<RayHit> many(n);
    rs.value()->intersectMany(org.data(), dir.data(), n, many.data());
    int hits = 0;
    for (int i = 0; i < n; ++i) {
        RayHit one = rs.value()->intersect(org[i], dir[i]);
        ASSERT_EQ(one.hit, many[i].hit) << i;
        if (one.hit) {
            ++hits;
            EXPECT_NEAR(one.t, many[i].t, 1e-3f * one.t);
            EXPECT_EQ(one.color, many[i].color);
        }
    }
    EXPECT_GT(hits, n / 4);
}

TEST(RayScene, InstancesUseWorldTransformAndNormals) {
    SceneModel c;
    SceneMesh proto;
    addBox(proto, {-1, -1, 0}, {1, 1, 4}, {10, 150, 20, 255});
    c.prototypes.push_back(proto);
    SceneInstance a;
    a.prototype = 0;
    a.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(0, 30, 0));
    SceneInstance b;
    b.prototype = 0;
    b.transform = glm::rotate(glm::translate(glm::dmat4(1.0), glm::dvec3(30, 0, 0)), 0.5 * M_PI, glm::dvec3(0, 0, 1)) *
                  glm::scale(glm::dmat4(1.0), glm::dvec3(2.0));
    c.instances = {a, b};
    auto rs = RayScene::build(c);
    ASSERT_TRUE(rs.isOk()) << rs.status().message();
    EXPECT_EQ(rs.value()->triangleCount(), 24u);
    RayHit h = rs.value()->intersect({0, 0, 2}, {0, 1, 0});
    ASSERT_TRUE(h.hit);
    EXPECT_NEAR(h.t, 29.0f, 1e-4f);
    EXPECT_NE(h.instId, 0xFFFFFFFFu);
    EXPECT_EQ(h.color, glm::u8vec4(10, 150, 20, 255));
    EXPECT_NEAR(h.normal.y, -1.0f, 1e-4f);
    RayHit g = rs.value()->intersect({0, 0, 2}, {1, 0, 0});  // scaled x2: face at x = 28
    ASSERT_TRUE(g.hit);
    EXPECT_NEAR(g.t, 28.0f, 1e-4f);
    EXPECT_NEAR(g.normal.x, -1.0f, 1e-4f);
    EXPECT_FALSE(rs.value()->intersect({0, 0, 9}, {1, 0, 0}).hit);  // above the scaled box (height 8)
}

TEST(RayScene, PreciseOneThousandKilometresFromOrigin) {
    const double ox = 1.0e6, oy = -1.0e6;
    auto rs = RayScene::build(oneBox(ox, oy));
    ASSERT_TRUE(rs.isOk());
    EXPECT_EQ(rs.value()->frameOrigin(), glm::dvec3(ox, oy, 0));
    // Camera at world (ox + 0.003, oy - 50.0, 5): scene-local org.
    glm::dvec3 eye(ox + 0.003, oy - 50.0, 5.0);
    glm::vec3 org(eye - rs.value()->frameOrigin());
    RayHit h = rs.value()->intersect(org, {0, 1, 0});
    ASSERT_TRUE(h.hit);
    EXPECT_NEAR(h.t, 40.0f, 1e-4f);
    // Grazing the box edge at x = 5 - 0.001: still a hit; just outside: miss.
    EXPECT_TRUE(rs.value()->intersect({4.999f, -50, 5}, {0, 1, 0}).hit);
    EXPECT_FALSE(rs.value()->intersect({5.001f, -50, 5}, {0, 1, 0}).hit);
}

TEST(RayScene, EmptyCityBuildsAndMisses) {
    SceneModel c;
    auto rs = RayScene::build(c);
    ASSERT_TRUE(rs.isOk()) << rs.status().message();
    EXPECT_EQ(rs.value()->triangleCount(), 0u);
    EXPECT_FALSE(rs.value()->intersect({0, 0, 0}, {0, 0, 1}).hit);
    glm::vec3 o(0), d(0, 1, 0);
    RayHit h;
    h.hit = true;
    rs.value()->intersectMany(&o, &d, 1, &h);
    EXPECT_FALSE(h.hit);
}

TEST(RayScene, RejectsMalformedMeshes) {
    SceneModel c = oneBox();
    c.meshes[0].indices.push_back(999);
    c.meshes[0].indices.push_back(0);
    c.meshes[0].indices.push_back(1);
    auto rs = RayScene::build(c);
    ASSERT_FALSE(rs.isOk());
    EXPECT_NE(rs.status().message().find("mesh 0"), std::string::npos);
    SceneModel d = oneBox();
    d.instances.push_back({3, glm::dmat4(1.0)});
    EXPECT_FALSE(RayScene::build(d).isOk());
}

TEST(RayScene, CullsBackFacesLikeTheRasteriser) {
    auto rs = RayScene::build(oneBox());
    ASSERT_TRUE(rs.isOk());
    // From inside the box every face is a back face: nothing is hit.
    EXPECT_FALSE(rs.value()->intersect({0, 0, 5}, {0, 1, 0}).hit);
    EXPECT_FALSE(rs.value()->intersect({0, 0, 5}, {0, 0, 1}).hit);
    EXPECT_FALSE(rs.value()->occluded({0, 0, 5}, {1, 0, 0}, 0.0f, 100.0f));
    // From outside, the far side's back face is skipped and the front face hit.
    RayHit h = rs.value()->intersect({0, 50, 5}, {0, -1, 0});
    ASSERT_TRUE(h.hit);
    EXPECT_NEAR(h.t, 40.0f, 1e-4f);
    EXPECT_NEAR(h.normal.y, 1.0f, 1e-5f);
}
