// Rig cameras (camera_model.h, rig_camera.h): pinhole and fisheye pixels map
// to their rays and back within 1e-3 px; a fisheye's depth equals the
// distance of an independent Embree ray within 1 cm and a pinhole's its
// z-depth; forward flow equals the flow of independent rays (the pixel's ray
// cast, its hit projected with the next pose by formulas written here)
// within 0.05 px; channels nobody asked for are not computed; a shared ray
// table (camera_ray_table.h) gives the same bytes as pixelRay per pixel.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "runtime/engine/ray_scene.h"
#include "runtime/engine/rig_camera.h"
#include "tests/runtime/engine/fixtures.h"

using namespace vista;

namespace {

CameraModel fisheye(double maxFovDeg = 200.0) {
    CameraModel m;
    m.kind = CameraModel::Kind::Fisheye;
    m.width = 160;
    m.height = 120;
    m.fx = 40.0;
    m.fy = 42.0;
    m.cx = 79.5;
    m.cy = 60.25;
    m.maxFovDeg = maxFovDeg;
    return m;
}

CameraModel pinhole() {
    CameraModel m;
    m.width = 160;
    m.height = 120;
    m.fx = 100.0;
    m.fy = 110.0;
    m.cx = 81.0;
    m.cy = 58.5;
    return m;
}

// An upright pose at `p` with heading h (clockwise from north), written out
// here: x forward = (sin h, cos h, 0), y left = (-cos h, sin h, 0), z up.
RigPose uprightPose(const glm::dvec3& p, double h) {
    RigPose r;
    r.position = p;
    r.rotation[0] = {std::sin(h), std::cos(h), 0.0};
    r.rotation[1] = {-std::cos(h), std::sin(h), 0.0};
    r.rotation[2] = {0.0, 0.0, 1.0};
    return r;
}

// The equidistant ray of pixel (u, v) in the OpenCV camera frame, written out
// here: theta = |((u - cx) / fx, (v - cy) / fy)|.
glm::dvec3 fisheyeRay(const CameraModel& m, double u, double v) {
    const double x = (u - m.cx) / m.fx, y = (v - m.cy) / m.fy, th = std::hypot(x, y);
    if (th == 0) return {0, 0, 1};
    return {std::sin(th) * x / th, std::sin(th) * y / th, std::cos(th)};
}

// OpenCV camera frame -> world for an upright pose.
glm::dvec3 toWorld(const RigPose& p, const glm::dvec3& c) {
    return p.rotation[0] * c.z - p.rotation[1] * c.x - p.rotation[2] * c.y;
}

// Pixel of world point w seen from pose p, written out here.
bool pixelOf(const CameraModel& m, const RigPose& p, const glm::dvec3& w, glm::dvec2& uv) {
    const glm::dvec3 d = w - p.position;
    const glm::dvec3 c(-glm::dot(d, p.rotation[1]), -glm::dot(d, p.rotation[2]), glm::dot(d, p.rotation[0]));
    if (!m.fisheye()) {
        if (c.z <= 0) return false;
        uv = {m.cx + m.fx * c.x / c.z, m.cy + m.fy * c.y / c.z};
        return true;
    }
    const double rho = std::hypot(c.x, c.y), th = std::atan2(rho, c.z);
    if (rho == 0) return false;
    uv = {m.cx + m.fx * th * c.x / rho, m.cy + m.fy * th * c.y / rho};
    return true;
}

}  // namespace

TEST(CameraModel, FisheyePixelsMapToRaysAndBack) {
    const CameraModel m = fisheye(360.0);
    int checked = 0;
    double worst = 0;
    for (double v = -0.5; v <= m.height; v += 1.37)
        for (double u = -0.5; u <= m.width; u += 1.29) {
            glm::dvec3 d;
            if (!m.pixelRay(u, v, d)) continue;
            EXPECT_NEAR(glm::length(d), 1.0, 1e-12);
            const glm::dvec3 ref = fisheyeRay(m, u, v);
            EXPECT_NEAR(glm::length(d - ref), 0.0, 1e-12);
            glm::dvec2 uv;
            if (std::acos(std::clamp(d.z, -1.0, 1.0)) > 3.1415) continue;  // at theta = pi the azimuth is lost
            ASSERT_TRUE(m.project(d * 7.5, uv));
            worst = std::max(worst, glm::length(uv - glm::dvec2(u, v)));
            ++checked;
        }
    EXPECT_GT(checked, 10000);
    EXPECT_LT(worst, 1e-3) << "pixel -> ray -> pixel";
    // Beyond the image circle a pixel sees nothing.
    const CameraModel narrow = fisheye(120.0);
    glm::dvec3 d;
    EXPECT_TRUE(narrow.pixelRay(narrow.cx + narrow.fx * 1.04, narrow.cy, d));   // theta 59.6 deg
    EXPECT_FALSE(narrow.pixelRay(narrow.cx + narrow.fx * 1.06, narrow.cy, d));  // theta 60.7 deg
}

TEST(CameraModel, PinholePixelsMapToRaysAndBack) {
    const CameraModel m = pinhole();
    double worst = 0;
    for (double v = -0.5; v <= m.height; v += 3.1)
        for (double u = -0.5; u <= m.width; u += 2.9) {
            glm::dvec3 d;
            ASSERT_TRUE(m.pixelRay(u, v, d));
            glm::dvec2 uv;
            ASSERT_TRUE(m.project(d * 3.0, uv));
            worst = std::max(worst, glm::length(uv - glm::dvec2(u, v)));
        }
    EXPECT_LT(worst, 1e-6);
    glm::dvec2 uv;
    EXPECT_FALSE(m.project({0.0, 0.0, -1.0}, uv)) << "behind a pinhole camera";
}

TEST(RigCamera, FisheyeDepthIsTheDistanceOfAnIndependentRay) {
    const SceneModel city = test::randomCity(5, 80, 300.0);
    auto rays = RayScene::build(city);
    ASSERT_TRUE(rays.isOk()) << rays.status().message();
    CameraShot shot;
    shot.model = fisheye(190.0);
    shot.pose = uprightPose({3.0, -7.0, 1.6}, 0.4);
    shot.channels = kRigDepth | kRigSemantic;
    CameraImages im;
    castRigCamera(city, **rays, shot, im, 2);
    EXPECT_TRUE(im.rgb.rgba.empty() && im.ids.empty() && im.flow.empty()) << "only the channels asked";
    ASSERT_EQ(im.depth.size(), size_t(160 * 120));
    const glm::vec3 org(shot.pose.position - (*rays)->frameOrigin());
    int hits = 0, outside = 0;
    for (int v = 0; v < 120; ++v)
        for (int u = 0; u < 160; ++u) {
            const size_t p = size_t(v) * 160 + size_t(u);
            const glm::dvec3 c = fisheyeRay(shot.model, u, v);
            if (std::acos(c.z) > 95.0 * M_PI / 180.0) {
                ++outside;
                EXPECT_TRUE(std::isnan(im.depth[p])) << u << "," << v;
                EXPECT_EQ(im.classes[p], 255);
                continue;
            }
            const RayHit h = (*rays)->intersect(org, glm::vec3(toWorld(shot.pose, c)));
            if (!h.hit) {
                EXPECT_TRUE(std::isinf(im.depth[p])) << u << "," << v;
                continue;
            }
            ++hits;
            EXPECT_NEAR(im.depth[p], h.t, 0.01) << u << "," << v;
        }
    EXPECT_GT(hits, 3000);
    EXPECT_GT(outside, 100);
}

TEST(RigCamera, PinholeDepthIsZDepth) {
    const SceneModel city = test::randomCity(6, 60, 300.0);
    auto rays = RayScene::build(city);
    ASSERT_TRUE(rays.isOk());
    CameraShot shot;
    shot.model = pinhole();
    shot.pose = uprightPose({-4.0, 2.0, 1.7}, -1.1);
    shot.channels = kRigDepth;
    CameraImages im;
    castRigCamera(city, **rays, shot, im, 2);
    const glm::vec3 org(shot.pose.position - (*rays)->frameOrigin());
    int hits = 0;
    for (int v = 0; v < 120; v += 2)
        for (int u = 0; u < 160; u += 2) {
            glm::dvec3 c((u - 81.0) / 100.0, (v - 58.5) / 110.0, 1.0);
            c = glm::normalize(c);
            const RayHit h = (*rays)->intersect(org, glm::vec3(toWorld(shot.pose, c)));
            const float d = im.depth[size_t(v) * 160 + size_t(u)];
            if (!h.hit) {
                EXPECT_TRUE(std::isinf(d));
                continue;
            }
            ++hits;
            EXPECT_NEAR(d, h.t * c.z, 0.01);
        }
    EXPECT_GT(hits, 1000);
}

// Flow of every pixel against its independent ray: hit projected with the
// next pose (sky: the direction), within 0.05 px.
void expectFlowMatchesRays(const CameraModel& model) {
    const SceneModel city = test::randomCity(9, 40, 300.0);
    auto rays = RayScene::build(city);
    ASSERT_TRUE(rays.isOk());
    CameraShot shot;
    shot.model = model;
    shot.pose = uprightPose({0.5, 1.0, 1.5}, 0.3);
    shot.next = uprightPose(shot.pose.position + 1.2 * shot.pose.rotation[0] + glm::dvec3(0.1, 0.0, 0.02), 0.35);
    shot.channels = kRigFlow;
    CameraImages im;
    castRigCamera(city, **rays, shot, im, 2);
    ASSERT_EQ(im.flow.size(), size_t(2 * 160 * 120));
    const glm::vec3 org(shot.pose.position - (*rays)->frameOrigin());
    int surface = 0, sky = 0;
    double worst = 0;
    for (int v = 0; v < 120; ++v)
        for (int u = 0; u < 160; ++u) {
            const size_t p = size_t(v) * 160 + size_t(u);
            glm::dvec3 c;
            if (!model.pixelRay(u, v, c)) {
                EXPECT_EQ(im.flow[2 * p], kUnknownFlow);
                continue;
            }
            const glm::dvec3 d = toWorld(shot.pose, c);
            const RayHit h = (*rays)->intersect(org, glm::vec3(d));
            glm::dvec2 uv;
            const bool ok = h.hit ? pixelOf(model, shot.next, shot.pose.position + double(h.t) * d, uv)
                                  : pixelOf(model, shot.next, shot.next.position + d, uv);
            if (!ok) continue;
            (h.hit ? surface : sky) += 1;
            const glm::dvec2 flow(im.flow[2 * p], im.flow[2 * p + 1]);
            const double e = glm::length(flow - (uv - glm::dvec2(u, v)));
            worst = std::max(worst, e);
            EXPECT_LT(e, 0.05) << u << "," << v << (h.hit ? " surface" : " sky");
        }
    EXPECT_GT(surface, 2000);
    EXPECT_GT(sky, 100);
    EXPECT_LT(worst, 0.05);
}

TEST(RigCamera, PinholeFlowMatchesIndependentRays) { expectFlowMatchesRays(pinhole()); }
TEST(RigCamera, FisheyeFlowMatchesIndependentRays) { expectFlowMatchesRays(fisheye(190.0)); }

// A shared CameraRayTable gives the bytes of pixelRay per pixel, in every
// channel, for both models; a table of another model is not used.
TEST(RigCamera, RayTableGivesTheBytesOfPixelRayPerPixel) {
    const SceneModel city = test::randomCity(11, 60, 300.0);
    auto rays = RayScene::build(city);
    ASSERT_TRUE(rays.isOk());
    for (const CameraModel& model : {pinhole(), fisheye(190.0)}) {
        CameraShot shot;
        shot.model = model;
        shot.pose = uprightPose({1.5, -2.0, 1.6}, 0.7);
        shot.next = uprightPose(shot.pose.position + 0.8 * shot.pose.rotation[0], 0.72);
        shot.channels = kRigRgb | kRigDepth | kRigSemantic | kRigInstance | kRigFlow;
        CameraImages slow, fast, other;
        castRigCamera(city, **rays, shot, slow, 2);
        const CameraRayTable table(model, 2);
        ASSERT_TRUE(table.matches(model));
        shot.rays = &table;
        castRigCamera(city, **rays, shot, fast, 2);
        EXPECT_EQ(fast.rgb.rgba, slow.rgb.rgba);
        EXPECT_EQ(0, std::memcmp(fast.depth.data(), slow.depth.data(), slow.depth.size() * sizeof(float)));
        EXPECT_EQ(fast.classes, slow.classes);
        EXPECT_EQ(fast.ids, slow.ids);
        EXPECT_EQ(0, std::memcmp(fast.flow.data(), slow.flow.data(), slow.flow.size() * sizeof(float)));
        // A table of another model (fx differs) is ignored: the same bytes again.
        CameraModel wider = model;
        wider.fx *= 0.9;
        const CameraRayTable stale(wider, 2);
        EXPECT_FALSE(stale.matches(model));
        shot.rays = &stale;
        castRigCamera(city, **rays, shot, other, 2);
        EXPECT_EQ(other.ids, slow.ids);
        EXPECT_EQ(other.rgb.rgba, slow.rgb.rgba);
    }
}
