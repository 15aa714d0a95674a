// RayScene moving objects (placeMovers): instances of prototype meshes placed
// per frame in the movers' scene, hit with their labels, moved and hidden,
// seen with the city as one scene (against a brute force), the top level
// left alone.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <embree3/rtcore.h>
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

namespace {

// A world triangle of the brute force: corners in double, what it belongs to.
struct WorldTri {
    glm::dvec3 a, b, c;
    int mesh = -1, mover = -1;
};

// Nearest front-facing hit (counter-clockwise seen from the ray's origin side,
// as the scene's back-face culling keeps) of a ray in (tnear, tfar), by
// Moeller-Trumbore in double over every triangle. `second`: the nearest hit
// of another object (to skip rays whose answer a rounding could change);
// `edge`: the smallest barycentric coordinate of the nearest hit.
struct Brute {
    bool hit = false;
    double t = 0, second = 1e300, edge = 1;
    int mesh = -1, mover = -1;
};
Brute bruteForce(const std::vector<WorldTri>& tris, const glm::dvec3& o, const glm::dvec3& d, double tnear,
                 double tfar) {
    Brute best;
    best.t = tfar;
    for (const WorldTri& tr : tris) {
        const glm::dvec3 e1 = tr.b - tr.a, e2 = tr.c - tr.a;
        if (glm::dot(glm::cross(e1, e2), d) >= 0) continue;  // back face (or edge-on)
        const glm::dvec3 p = glm::cross(d, e2);
        const double det = glm::dot(e1, p);
        if (std::abs(det) < 1e-14) continue;
        const glm::dvec3 s = o - tr.a;
        const double u = glm::dot(s, p) / det;
        const glm::dvec3 q = glm::cross(s, e1);
        const double v = glm::dot(d, q) / det;
        const double t = glm::dot(e2, q) / det;
        if (u < 0 || v < 0 || u + v > 1 || !(t > tnear) || !(t < tfar)) continue;
        const bool same = best.hit && best.mesh == tr.mesh && best.mover == tr.mover;
        if (!best.hit || t < best.t) {
            if (best.hit && !same) best.second = std::min(best.second, best.t);
            best.hit = true;
            best.t = t;
            best.edge = std::min({u, v, 1 - u - v});
            best.mesh = tr.mesh;
            best.mover = tr.mover;
        } else if (!(best.mesh == tr.mesh && best.mover == tr.mover)) {
            best.second = std::min(best.second, t);
        }
    }
    return best;
}

void addWorld(std::vector<WorldTri>& out, const SceneMesh& m, const glm::dmat4& xf, int mesh, int mover) {
    for (size_t i = 0; i + 2 < m.indices.size(); i += 3) {
        WorldTri t;
        glm::dvec3* c[3] = {&t.a, &t.b, &t.c};
        for (int k = 0; k < 3; ++k)
            *c[k] = glm::dvec3(xf * glm::dvec4(glm::dvec3(m.positions[m.indices[i + size_t(k)]]) + m.origin, 1.0));
        t.mesh = mesh;
        t.mover = mover;
        out.push_back(t);
    }
}

}  // namespace

// The movers' scene beside the top level answers every query as one scene
// holding both would: nearest hits, their objects, occlusion and layers,
// against a brute force over the world triangles of the city's boxes and of
// the placed objects (several prototypes, turned, some inside buildings).
TEST(RayMovers, QueriesSeeTheCityAndTheMoversAsOneScene) {
    const SceneModel city = randomCity(7, 40, 300.0, 5000.0, -3000.0);
    auto rs = RayScene::build(city);
    ASSERT_TRUE(rs.isOk()) << rs.status().message();
    RayScene& s = **rs;
    EXPECT_EQ(s.embreeMoverScene(), nullptr);
    std::vector<SceneMesh> protos(3);
    addBox(protos[0], {-2, -1, 0}, {2, 1, 1.5}, {10, 20, 200, 255});
    addBox(protos[1], {-0.3f, -0.3f, 0}, {0.3f, 0.3f, 1.8f}, {200, 20, 10, 255});
    addBox(protos[2], {-6, -1.25f, 0}, {6, 1.25f, 3}, {20, 200, 10, 255});
    addBox(protos[2], {-5, -1, 3}, {5, 1, 3.5f}, {220, 220, 10, 255});  // a roof box on top
    ASSERT_TRUE(s.setMoverPrototypes(protos));
    ASSERT_NE(s.embreeMoverScene(), nullptr);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> pos(-140.0, 140.0), yaw(0.0, 2.0 * M_PI), unit(0.0, 1.0);
    std::vector<MoverPlacement> movers;
    for (int i = 0; i < 150; ++i) {
        MoverPlacement p;
        p.prototype = uint32_t(i % 3);
        p.transform = glm::rotate(glm::translate(glm::dmat4(1.0), glm::dvec3(5000.0 + pos(rng), -3000.0 + pos(rng),
                                                                             unit(rng) < 0.2 ? 10.0 * unit(rng) : 0.0)),
                                  yaw(rng), glm::dvec3(0, 0, 1));
        p.id = 1000u + uint32_t(i);
        p.cls = uint8_t(i % 2 ? 15 : 16);
        movers.push_back(p);
    }
    ASSERT_TRUE(s.placeMovers(movers));
    std::vector<WorldTri> tris;
    for (size_t mi = 0; mi < city.meshes.size(); ++mi) addWorld(tris, city.meshes[mi], glm::dmat4(1.0), int(mi), -1);
    for (size_t i = 0; i < movers.size(); ++i)
        addWorld(tris, protos[movers[i].prototype], movers[i].transform, -1, int(i));

    const glm::dvec3 frame = s.frameOrigin();
    const int n = 4000;
    std::vector<glm::vec3> orgs, dirs;
    std::vector<float> tfars;
    for (int i = 0; i < n; ++i) {
        // Eye-height and roof-height origins, mostly near-horizontal rays (the far field's), some down.
        const glm::dvec3 o(5000.0 + pos(rng), -3000.0 + pos(rng),
                           unit(rng) < 0.7 ? 1.0 + 2.0 * unit(rng) : 40.0 * unit(rng));
        const double h = yaw(rng), p = unit(rng) < 0.7 ? -0.1 * unit(rng) : -1.5 * unit(rng);
        orgs.push_back(glm::vec3(o - frame));
        dirs.push_back(glm::normalize(
            glm::vec3(float(std::cos(h) * std::cos(p)), float(std::sin(h) * std::cos(p)), float(std::sin(p)))));
        tfars.push_back(float(300.0 * unit(rng)));
    }
    std::vector<RayHit> many(n);
    s.intersectMany(orgs.data(), dirs.data(), n, many.data());
    std::vector<uint8_t> occ(n);
    s.occludedMany(orgs.data(), dirs.data(), n, tfars.data(), occ.data());
    constexpr int kLayers = 3;
    std::vector<float> tnears(n, 0.0f), inf(n, 1e30f);
    std::vector<RayHit> layers(size_t(n) * kLayers);
    std::vector<int> counts(n);
    s.allHitsMany(orgs.data(), dirs.data(), n, tnears.data(), inf.data(), kLayers, 0.01f, layers.data(), counts.data());
    int checked = 0, moverHits = 0, moverOcclusions = 0;
    for (int i = 0; i < n; ++i) {
        const glm::dvec3 o = glm::dvec3(orgs[i]) + frame, d(dirs[i]);
        const Brute b = bruteForce(tris, o, d, 0.0, 1e30);
        // Skip rays a rounding could turn: grazing an edge, or two objects within a millimetre.
        if (b.hit && (b.edge < 1e-4 || b.second - b.t < 1e-3)) continue;
        ++checked;
        const RayHit h = s.intersect(orgs[i], dirs[i]);
        ASSERT_EQ(h.hit, b.hit) << "ray " << i;
        EXPECT_EQ(many[size_t(i)].hit, b.hit) << "ray " << i;
        if (b.hit) {
            EXPECT_NEAR(h.t, b.t, 1e-3 + 1e-5 * b.t) << "ray " << i;
            const HitSource src = s.source(h);
            EXPECT_EQ(src.mover, b.mover) << "ray " << i;
            EXPECT_EQ(src.mesh, b.mesh) << "ray " << i;
            if (b.mover >= 0) {
                ++moverHits;
                EXPECT_EQ(src.moverId, movers[size_t(b.mover)].id);
                EXPECT_EQ(src.moverClass, movers[size_t(b.mover)].cls);
                EXPECT_NE(h.instId & 0x80000000u, 0u);
            }
            // The packet path: the same surface.
            EXPECT_EQ(many[size_t(i)].geomId, h.geomId) << "ray " << i;
            EXPECT_EQ(many[size_t(i)].instId, h.instId) << "ray " << i;
            EXPECT_EQ(many[size_t(i)].primId, h.primId) << "ray " << i;
            EXPECT_NEAR(many[size_t(i)].t, h.t, 1e-4f * std::max(1.0f, h.t));
            EXPECT_EQ(many[size_t(i)].color, h.color);
            // The first layer of allHitsMany is that hit.
            ASSERT_GE(counts[size_t(i)], 1) << "ray " << i;
            EXPECT_EQ(layers[size_t(i) * kLayers].instId, h.instId);
            EXPECT_NEAR(layers[size_t(i) * kLayers].t, h.t, 1e-4f * std::max(1.0f, h.t));
        } else {
            EXPECT_EQ(counts[size_t(i)], 0);
        }
        // Occlusion within (0, tfar): a hit of either scene nearer than tfar.
        if (b.hit && std::abs(b.t - double(tfars[size_t(i)])) < 1e-3) continue;
        const bool blocked = b.hit && b.t < double(tfars[size_t(i)]);
        EXPECT_EQ(s.occluded(orgs[i], dirs[i], 0.0f, tfars[size_t(i)]), blocked) << "ray " << i;
        EXPECT_EQ(occ[size_t(i)] != 0, blocked) << "ray " << i;
        moverOcclusions += blocked && b.mover >= 0 ? 1 : 0;
    }
    EXPECT_GT(checked, n * 95 / 100);
    EXPECT_GT(moverHits, 100);  // the rays do meet the movers
    EXPECT_GT(moverOcclusions, 30);
    // Hidden again: the same rays see the city alone.
    ASSERT_TRUE(s.placeMovers({}));
    std::vector<WorldTri> cityTris(tris.begin(), tris.begin() + std::ptrdiff_t(city.triangles));
    for (int i = 0; i < n; i += 7) {
        const Brute b = bruteForce(cityTris, glm::dvec3(orgs[i]) + frame, glm::dvec3(dirs[i]), 0.0, 1e30);
        if (b.hit && (b.edge < 1e-4 || b.second - b.t < 1e-3)) continue;
        const RayHit h = s.intersect(orgs[i], dirs[i]);
        ASSERT_EQ(h.hit, b.hit) << "ray " << i;
        if (b.hit) { EXPECT_EQ(s.source(h).mover, -1); }
    }
}

// Placing objects leaves the top level as it is (its bounds do not grow to an
// object placed far outside the city); a scene without prototypes has no
// movers' scene, and placing nothing in it makes none.
TEST(RayMovers, TheTopLevelIsNotRebuiltForMovers) {
    auto rs = RayScene::build(ground());
    ASSERT_TRUE(rs.isOk()) << rs.status().message();
    RayScene& s = **rs;
    ASSERT_TRUE(s.placeMovers({}));
    EXPECT_EQ(s.embreeMoverScene(), nullptr);
    EXPECT_EQ(s.moverCount(), 0u);
    EXPECT_TRUE(s.moverSpheres().empty());
    RTCBounds before;
    rtcGetSceneBounds(s.embreeScene(), &before);
    ASSERT_TRUE(s.setMoverPrototypes({carBox()}));
    ASSERT_TRUE(s.placeMovers({{0, placed(5000, 0, 0.0), 1u, 15}}));
    RTCBounds after;
    rtcGetSceneBounds(s.embreeScene(), &after);
    EXPECT_EQ(after.upper_x, before.upper_x);
    EXPECT_LT(after.upper_x, 1000.0f);
    RTCBounds movers;
    rtcGetSceneBounds(s.embreeMoverScene(), &movers);
    EXPECT_GT(movers.upper_x, 4000.0f);
    // The object is still hit, through the movers' scene.
    const glm::vec3 org(glm::dvec3(5000, 0, 50) - s.frameOrigin());
    EXPECT_NEAR(s.intersect(org, {0, 0, -1}).t, 48.5f, 1e-3f);
}

// Still objects (placeMovers' `still` list): hit with their labels beside the
// moving ones, re-placed only where a slot's entry changed (each change
// advances stillSerial() and that slot's version), hidden by a shorter list.
TEST(RayMovers, StillSlotsChangeOnlyWhereTheirEntryChanged) {
    auto rs = RayScene::build(ground());
    ASSERT_TRUE(rs.isOk()) << rs.status().message();
    RayScene& s = **rs;
    const glm::vec3 down(0, 0, -1);
    SceneMesh tall;
    addBox(tall, {-1, -1, 0}, {1, 1, 4}, {200, 20, 20, 255});
    ASSERT_TRUE(s.setMoverPrototypes({carBox(), tall}));
    auto slot = [](uint32_t proto, double x, uint32_t id) {
        StillPlacement p;
        p.object = {proto, placed(x, 0, 0.0), id, 9};
        return p;
    };
    std::vector<StillPlacement> still = {slot(1, -30, 0xC0000001u), slot(1, -60, 0xC0000002u)};
    const uint64_t commits = s.moverCommits();
    ASSERT_TRUE(s.placeMovers({{0, placed(30, 0, 0.0), 5u, 15}}, &still));
    EXPECT_EQ(s.moverCommits(), commits + 1);
    EXPECT_EQ(s.moverSpheres().size(), 1u);  // the moving one only
    ASSERT_EQ(s.stillObjects().size(), 2u);
    const uint64_t v0 = s.stillSerial();
    EXPECT_GT(v0, 0u);
    for (const StillState& st : s.stillObjects()) {
        EXPECT_TRUE(st.shown);
        EXPECT_EQ(st.version, v0);
    }
    EXPECT_NEAR(s.stillObjects()[1].sphere.x, -60.0, 1e-9);
    RayHit h = s.intersect({-60, 0, 50}, down);
    ASSERT_TRUE(h.hit);
    EXPECT_NEAR(h.t, 46.0f, 1e-3f);  // the tall box's roof at 4 m
    HitSource src = s.source(h);
    EXPECT_EQ(src.still, 1);
    EXPECT_EQ(src.mover, -1);
    EXPECT_EQ(src.moverId, 0xC0000002u);
    EXPECT_EQ(src.moverClass, 9);
    EXPECT_EQ(s.source(s.intersect({30, 0, 50}, down)).mover, 0);
    // The moving one moves, the still ones are passed unchanged: no still change.
    ASSERT_TRUE(s.placeMovers({{0, placed(35, 0, 0.0), 5u, 15}}, &still));
    EXPECT_EQ(s.stillSerial(), v0);
    ASSERT_TRUE(s.placeMovers({{0, placed(40, 0, 0.0), 5u, 15}}));  // still list not passed: as they are
    EXPECT_EQ(s.stillSerial(), v0);
    EXPECT_EQ(s.source(s.intersect({-30, 0, 50}, down)).still, 0);
    // Slot 0 shows another prototype: only its version advances.
    still[0].object.prototype = 0;
    ASSERT_TRUE(s.placeMovers({}, &still));
    const uint64_t v1 = s.stillSerial();
    EXPECT_GT(v1, v0);
    EXPECT_EQ(s.stillObjects()[0].version, v1);
    EXPECT_EQ(s.stillObjects()[1].version, v0);
    EXPECT_NEAR(s.intersect({-30, 0, 50}, down).t, 48.5f, 1e-3f);  // the car box's roof
    EXPECT_EQ(s.moverCount(), 0u);
    // A shorter list hides slot 1; the slot keeps its last sphere, not shown.
    still.resize(1);
    ASSERT_TRUE(s.placeMovers({}, &still));
    EXPECT_GT(s.stillSerial(), v1);
    EXPECT_FALSE(s.stillObjects()[1].shown);
    EXPECT_EQ(s.stillObjects()[0].version, v1);
    EXPECT_NEAR(s.stillObjects()[1].sphere.x, -60.0, 1e-9);
    EXPECT_NEAR(s.intersect({-60, 0, 50}, down).t, 60.0f, 1e-3f);  // the ground again
    // A still slot of an unknown prototype is an error; nothing changes.
    const uint64_t v2 = s.stillSerial();
    std::vector<StillPlacement> bad = {slot(7, -30, 1u)};
    EXPECT_FALSE(s.placeMovers({}, &bad));
    EXPECT_EQ(s.stillSerial(), v2);
    // A new prototype set hides every slot (a change of the shown one).
    ASSERT_TRUE(s.setMoverPrototypes({carBox()}));
    EXPECT_GT(s.stillSerial(), v2);
    EXPECT_FALSE(s.stillObjects()[0].shown);
    EXPECT_NEAR(s.intersect({-30, 0, 50}, down).t, 60.0f, 1e-3f);
}
