// Boxes of rig cameras (rig_boxes.h, boxes.h BoxCamera) against independent
// computations on a generated city with parked cars: for a pinhole with an
// off-centre principal point and fx != fy the visible boxes equal the
// instance mask's extents counted here, the full extents hold every visible
// pixel centre, and an instance wholly in front of the camera has the
// extent of its vertices projected here within 0.5 px; for a fisheye the
// visible boxes equal the mask's extents, the full extents hold every
// visible pixel centre and every vertex inside the image circle projected
// here, and the unoccluded pixel counts agree with rays cast here at the
// instance alone, and the fast fisheye masks count exactly the pixels of
// every pixel ray tested against every front triangle, also for large
// cuboids around the camera (whole tiles, skipped runs of edge samples),
// whose extents equal every edge sample taken the plain way; visible
// extents of a tall image counted in bands equal those counted here
// (test_rig_boxes_frames.cpp: the boxes in the vehicle and KITTI frames).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "citygen/generate.h"
#include "citygen/labels.h"
#include "foundation/units.h"
#include "runtime/engine/boxes.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/engine/rig_boxes.h"
#include "runtime/engine/rig_camera.h"
#include "runtime/scene/city_file.h"
#include "tests/common/temp_dir.h"
#include "tests/runtime/engine/boxes_city.h"

using namespace vista;

namespace {

using TestCity = test::BoxesCity;

const TestCity& testCity() {
    static TestCity* city = [] {
        CityParams p;
        p.seed = 5;
        p.size_m = 400.0;
        p.tile_size_m = 100.0;
        p.origin_x = -3000.0;
        p.origin_y = 1500.0;
        p.parked_car_share = 0.6;
        return test::makeBoxesCity(p, "vista_rig_boxes");
    }();
    return *city;
}

// A vehicle on street edge e (at `at` of its length), 1.2 m above the ground, driving along it;
// the camera mounted 0.4 m up, turned `yawDeg` to the left and pitched down 3 degrees.
RigPose cameraPose(const TestCity& c, size_t e, double at, double yawDeg) {
    const StreetGraph& g = c.model.streets;
    const glm::dvec2 a = g.nodes[g.edges[e].a], b = g.nodes[g.edges[e].b];
    const glm::dvec2 xy = a + at * (b - a) + glm::dvec2(c.model.params.origin_x, c.model.params.origin_y);
    const glm::dvec3 top(xy, 300.0);
    const RayHit down = c.rays->intersect(glm::vec3(top - c.rays->frameOrigin()), glm::vec3(0, 0, -1));
    PathSample s;
    s.position = glm::dvec3(xy, (down.hit ? 300.0 - double(down.t) : 0.0) + 1.2);
    const glm::dvec2 d = b - a;
    s.heading = std::atan2(d.x, d.y);
    SensorMount m;
    m.position = {0.2, 0.0, 0.4};
    m.yawDeg = yawDeg;
    m.pitchDeg = -3.0;
    return sensorPose(vehiclePose(s), m);
}

// The OpenCV camera coordinates of a world point, written out here: x = -left, y = -up, z = forward.
glm::dvec3 cvPoint(const RigPose& p, const glm::dvec3& w) {
    const glm::dvec3 d = w - p.position;
    return {-glm::dot(d, p.rotation[1]), -glm::dot(d, p.rotation[2]), glm::dot(d, p.rotation[0])};
}

struct Mask {
    int u0 = 1 << 30, v0 = 1 << 30, u1 = -1, v1 = -1;
    uint32_t n = 0;
    std::vector<glm::ivec2> pixels;
};

std::map<uint32_t, Mask> masks(const CityBoxes& boxes, const std::vector<uint32_t>& ids, int W, int H) {
    std::map<uint32_t, Mask> out;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const uint32_t id = ids[size_t(y) * size_t(W) + size_t(x)];
            if (!boxes.find(id)) continue;
            Mask& m = out[id];
            m.u0 = std::min(m.u0, x), m.v0 = std::min(m.v0, y), m.u1 = std::max(m.u1, x), m.v1 = std::max(m.v1, y);
            ++m.n;
            m.pixels.push_back({x, y});
        }
    return out;
}

CameraImages castBoxes(const TestCity& c, const CameraModel& model, const RigPose& pose) {
    CameraShot shot;
    shot.model = model;
    shot.pose = pose;
    shot.channels = kRigBoxes;
    CameraImages im;
    VISTA_CHECK(c.rays->placeFrameNear(pose.position).isOk());
    castRigCamera(c.model, *c.rays, shot, im);
    return im;
}

void expectVisibleEqualsMask(const FrameBox& f, const Mask& m) {
    EXPECT_EQ(f.visibleU0, m.u0);
    EXPECT_EQ(f.visibleV0, m.v0);
    EXPECT_EQ(f.visibleU1, m.u1);
    EXPECT_EQ(f.visibleV1, m.v1);
    EXPECT_EQ(f.pixels, m.n);
}

void expectHolds(const PixelBox& b, double u, double v, double tol, uint32_t id) {
    ASSERT_TRUE(b.valid()) << id;
    EXPECT_LE(b.u0, u + tol) << instanceKindName(instanceKind(id));
    EXPECT_GE(b.u1, u - tol) << instanceKindName(instanceKind(id));
    EXPECT_LE(b.v0, v + tol) << instanceKindName(instanceKind(id));
    EXPECT_GE(b.v1, v - tol) << instanceKindName(instanceKind(id));
}

// Fisheye pixels whose ray, written out here, hits the instance's triangles alone (back faces culled).
uint32_t fisheyeRaysAtInstanceAlone(const CameraModel& m, const RigPose& pose, const std::vector<glm::dvec3>& tris) {
    TriangleSoup soup;
    for (const glm::dvec3& p : tris) {
        soup.indices.push_back(uint32_t(soup.positions.size()));
        soup.positions.push_back(glm::vec3(p - pose.position));
        soup.colors.push_back({255, 255, 255, 255});
    }
    SoupSceneOptions o;
    o.cullBackFaces = true;
    auto scene = RayScene::build(soup, o);
    VISTA_CHECK(scene.isOk());
    const double thetaMax = 0.5 * degToRad(m.maxFovDeg);
    uint32_t n = 0;
    for (int v = 0; v < m.height; ++v)
        for (int u = 0; u < m.width; ++u) {
            const double x = (u - m.cx) / m.fx, y = (v - m.cy) / m.fy, th = std::hypot(x, y);
            if (th > thetaMax) continue;
            const double s = th > 0 ? std::sin(th) / th : 1.0;
            // OpenCV (x right, y down, z forward) = (-left, -up, forward).
            const glm::dvec3 d = -x * s * pose.rotation[1] - y * s * pose.rotation[2] + std::cos(th) * pose.rotation[0];
            n += (*scene)->intersect(glm::vec3(0.0f), glm::vec3(d)).hit ? 1u : 0u;
        }
    return n;
}

// The fisheye extent of triangles (world points, 3 per triangle) the plain
// way boxes.h states: every edge sampled at ceil(angle * max(fx, fy))
// even steps, each sample inside the image circle's cone projected, the
// cone crossings found by bisection (40 halvings), and the circle's four
// extreme points whose ray passes through the triangle; no shortcut.
PixelBox fisheyeExtentEverySample(const CameraModel& m, const BoxCamera& cam, const std::vector<glm::dvec3>& tris) {
    const double thetaMax = std::min(kPi, 0.5 * m.maxFovDeg * kPi / 180.0);
    PixelBox out;
    auto add = [&](double u, double v) {
        if (!out.valid()) out = {u, v, u, v};
        out.u0 = std::min(out.u0, u), out.v0 = std::min(out.v0, v);
        out.u1 = std::max(out.u1, u), out.v1 = std::max(out.v1, v);
    };
    auto inCone = [&](const glm::dvec3& p) {
        const double rho = std::hypot(p.x, p.y);
        return (rho > 0.0 || p.z > 0.0) && std::atan2(rho, p.z) <= thetaMax;
    };
    auto addPoint = [&](const glm::dvec3& p) {
        const double rho = std::hypot(p.x, p.y), theta = std::atan2(rho, p.z);
        if (rho == 0.0) add(m.cx, m.cy);
        else add(m.cx + m.fx * theta * p.x / rho, m.cy + m.fy * theta * p.y / rho);
    };
    const glm::dmat3 toCam = glm::transpose(cam.axes);
    for (size_t t = 0; t + 2 < tris.size(); t += 3) {
        const glm::dvec3 p[3] = {toCam * (tris[t] - cam.eye), toCam * (tris[t + 1] - cam.eye),
                                 toCam * (tris[t + 2] - cam.eye)};
        for (int i = 0; i < 3; ++i) {
            const glm::dvec3 &a = p[i], &b = p[(i + 1) % 3];
            const double la = glm::length(a), lb = glm::length(b);
            const double angle = la > 0 && lb > 0 ? std::acos(std::clamp(glm::dot(a, b) / (la * lb), -1.0, 1.0)) : kPi;
            const int n = int(std::clamp(std::ceil(angle * std::max(m.fx, m.fy)), 1.0, 4096.0));
            glm::dvec3 prev = a;
            bool prevIn = inCone(a);
            if (prevIn) addPoint(a);
            for (int k = 1; k <= n; ++k) {
                const glm::dvec3 q = a + (double(k) / n) * (b - a);
                const bool in = inCone(q);
                if (in) addPoint(q);
                if (in != prevIn) {
                    glm::dvec3 lo = prev, hi = q;  // lo on prev's side
                    for (int h = 0; h < 40; ++h) {
                        const glm::dvec3 mid = 0.5 * (lo + hi);
                        (inCone(mid) == prevIn ? lo : hi) = mid;
                    }
                    glm::dvec2 uv(m.cx, m.cy);
                    m.project(prevIn ? lo : hi, uv);
                    add(uv.x, uv.y);
                }
                prev = q, prevIn = in;
            }
        }
        const glm::dvec3 n0 = glm::cross(p[1], p[2]), n1 = glm::cross(p[2], p[0]), n2 = glm::cross(p[0], p[1]);
        const double det = glm::dot(p[0], n0);
        const double st = std::sin(thetaMax), ct = std::cos(thetaMax);
        const double r[4][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
        for (const auto& q : r) {
            const glm::dvec3 d(st * q[0], st * q[1], ct);
            const double x = glm::dot(d, n0), y = glm::dot(d, n1), z = glm::dot(d, n2);
            if (det != 0.0 && (det > 0 ? x >= 0 && y >= 0 && z >= 0 : x <= 0 && y <= 0 && z <= 0))
                add(m.cx + m.fx * thetaMax * q[0], m.cy + m.fy * thetaMax * q[1]);
        }
    }
    return out;
}

}  // namespace

TEST(RigBoxes, PinholeWithOffCentreIntrinsicsMatchesTheMaskAndProjectedVertices) {
    const TestCity& c = testCity();
    CameraModel model;
    model.width = 200, model.height = 150;
    model.fx = 170.0, model.fy = 130.0, model.cx = 83.25, model.cy = 88.75;
    size_t compared = 0, projected = 0, cars = 0;
    for (size_t e = 0; e < c.model.streets.edges.size() && compared < 80; e += 4) {
        const RigPose pose = cameraPose(c, e, 0.35, e % 8 == 0 ? 20.0 : -15.0);
        const CameraImages im = castBoxes(c, model, pose);
        ASSERT_EQ(im.ids.size(), size_t(model.width) * size_t(model.height)) << "boxes compute the instance image";
        EXPECT_TRUE(im.depth.empty() && im.classes.empty() && im.rgb.width == 0);
        const auto mask = masks(c.boxes, im.ids, model.width, model.height);
        const std::vector<FrameBox> fb = frameBoxes(c.model, c.boxes, rigBoxCamera(model, pose), im.ids);
        ASSERT_EQ(fb.size(), mask.size());
        for (const FrameBox& f : fb) {
            const Mask& m = mask.at(f.id);
            expectVisibleEqualsMask(f, m);
            for (const glm::ivec2& px : m.pixels) expectHolds(f.full, px.x, px.y, 1e-6, f.id);
            EXPECT_GE(f.unoccludedPixels + 2 + f.pixels / 50, f.pixels) << instanceKindName(instanceKind(f.id));
            ++compared;
            // Wholly in front of the camera: the extent of its vertices projected here, clipped to the image.
            const std::vector<glm::dvec3> pts = instancePoints(c.model, c.boxes, *c.boxes.find(f.id));
            double u0 = 1e300, v0 = 1e300, u1 = -1e300, v1 = -1e300;
            bool front = true;
            for (const glm::dvec3& w : pts) {
                const glm::dvec3 q = cvPoint(pose, w);
                if (q.z < 0.05) front = false;
                const double u = model.cx + model.fx * q.x / q.z, v = model.cy + model.fy * q.y / q.z;
                u0 = std::min(u0, u), u1 = std::max(u1, u), v0 = std::min(v0, v), v1 = std::max(v1, v);
            }
            if (!front) continue;
            u0 = std::max(u0, -0.5), v0 = std::max(v0, -0.5);
            u1 = std::min(u1, model.width - 0.5), v1 = std::min(v1, model.height - 0.5);
            EXPECT_NEAR(f.full.u0, u0, 0.5) << f.id;
            EXPECT_NEAR(f.full.v0, v0, 0.5) << f.id;
            EXPECT_NEAR(f.full.u1, u1, 0.5) << f.id;
            EXPECT_NEAR(f.full.v1, v1, 0.5) << f.id;
            ++projected;
            cars += instanceKind(f.id) == InstanceKind::Car ? 1 : 0;
        }
    }
    EXPECT_GT(compared, 30u);
    EXPECT_GT(projected, 10u);
    EXPECT_GT(cars, 2u);
}

TEST(RigBoxes, FisheyeBoxesHoldTheVisiblePixelsAndTheVerticesInsideTheImageCircle) {
    const TestCity& c = testCity();
    CameraModel model;
    model.kind = CameraModel::Kind::Fisheye;
    model.width = 160, model.height = 120;
    model.fx = 38.0, model.fy = 42.0, model.cx = 78.5, model.cy = 61.0;
    model.maxFovDeg = 190.0;
    const double thetaMax = degToRad(95.0);
    size_t compared = 0, vertices = 0, aloneChecked = 0;
    for (size_t e = 1; e < c.model.streets.edges.size() && compared < 60; e += 6) {
        const RigPose pose = cameraPose(c, e, 0.5, 90.0);
        const CameraImages im = castBoxes(c, model, pose);
        const auto mask = masks(c.boxes, im.ids, model.width, model.height);
        const std::vector<FrameBox> fb = frameBoxes(c.model, c.boxes, rigBoxCamera(model, pose), im.ids);
        ASSERT_EQ(fb.size(), mask.size());
        for (const FrameBox& f : fb) {
            const Mask& m = mask.at(f.id);
            expectVisibleEqualsMask(f, m);
            for (const glm::ivec2& px : m.pixels) expectHolds(f.full, px.x, px.y, 0.1, f.id);
            EXPECT_GE(f.unoccludedPixels + 2 + f.pixels / 50, f.pixels) << instanceKindName(instanceKind(f.id));
            EXPECT_GE(f.visibleFraction, 0.0);
            EXPECT_LE(f.visibleFraction, 1.0);
            ++compared;
            const std::vector<glm::dvec3> pts = instancePoints(c.model, c.boxes, *c.boxes.find(f.id));
            if (aloneChecked < 10 && f.pixels > 100) {
                const uint32_t alone = fisheyeRaysAtInstanceAlone(model, pose, pts);
                EXPECT_NEAR(double(f.unoccludedPixels), double(alone), 3.0 + 0.02 * alone)
                    << instanceKindName(instanceKind(f.id));
                ++aloneChecked;
            }
            for (const glm::dvec3& w : pts) {
                const glm::dvec3 q = cvPoint(pose, w);
                const double rho = std::hypot(q.x, q.y), th = std::atan2(rho, q.z);
                if (rho == 0 || th > thetaMax) continue;
                const double u = model.cx + model.fx * th * q.x / rho, v = model.cy + model.fy * th * q.y / rho;
                if (u < -0.5 || v < -0.5 || u > model.width - 0.5 || v > model.height - 0.5) continue;
                expectHolds(f.full, u, v, 1e-6, f.id);
                expectHolds(f.boxExtent, u, v, 0.01, f.id);  // sampled curved edges err inside
                ++vertices;
            }
        }
    }
    EXPECT_GT(compared, 30u);
    EXPECT_GT(vertices, 1000u);
    EXPECT_GT(aloneChecked, 4u);
}

// The fisheye masks' pixel count, written out here the slow way: every pixel
// inside the image circle (pixelRay) against every front-facing triangle of
// the instance (camera coordinates; a ray from the origin passes through a
// triangle when the three triple products have the sign of its determinant).
uint32_t fisheyeMaskEveryPixel(const CameraModel& m, const BoxCamera& cam, const std::vector<glm::dvec3>& tris) {
    const size_t W = size_t(m.width), H = size_t(m.height);
    std::vector<glm::dvec3> ray(W * H);
    std::vector<uint8_t> inside(W * H), covered(W * H, 0);
    for (size_t v = 0; v < H; ++v)
        for (size_t u = 0; u < W; ++u) inside[v * W + u] = m.pixelRay(double(u), double(v), ray[v * W + u]) ? 1 : 0;
    for (size_t t = 0; t + 2 < tris.size(); t += 3) {
        const glm::dvec3 p0 = cam.toCamera(tris[t]), p1 = cam.toCamera(tris[t + 1]), p2 = cam.toCamera(tris[t + 2]);
        if (!(glm::dot(glm::cross(p1 - p0, p2 - p0), p0) < 0)) continue;  // back face
        const glm::dvec3 n0 = glm::cross(p1, p2), n1 = glm::cross(p2, p0), n2 = glm::cross(p0, p1);
        const double det = glm::dot(p0, n0);
        if (det == 0.0) continue;
        for (size_t q = 0; q < W * H; ++q) {
            if (!inside[q] || covered[q]) continue;
            const double a = glm::dot(ray[q], n0), b = glm::dot(ray[q], n1), c = glm::dot(ray[q], n2);
            if (det > 0 ? a >= 0 && b >= 0 && c >= 0 : a <= 0 && b <= 0 && c <= 0) covered[q] = 1;
        }
    }
    uint32_t n = 0;
    for (uint8_t c : covered) n += c;
    return n;
}

// The fast fisheye masks (a shared ray table, triangles bounded before their
// edges are sampled) count the pixels of the slow way exactly, and a run with
// or without a shared table gives the same boxes.
TEST(RigBoxes, FisheyeMasksCountThePixelsOfEveryPixelTestedAgainstEveryTriangle) {
    const TestCity& c = testCity();
    CameraModel model;
    model.kind = CameraModel::Kind::Fisheye;
    model.width = 96, model.height = 72;
    model.fx = 23.0, model.fy = 25.0, model.cx = 47.5, model.cy = 36.0;
    model.maxFovDeg = 190.0;
    const CameraRayTable table(model);
    size_t compared = 0, nonEmpty = 0;
    for (size_t e = 3; e < c.model.streets.edges.size() && compared < 30; e += 9) {
        const RigPose pose = cameraPose(c, e, 0.5, e % 2 ? 90.0 : -90.0);
        const CameraImages im = castBoxes(c, model, pose);
        const BoxCamera cam = rigBoxCamera(model, pose);
        const std::vector<FrameBox> own = frameBoxes(c.model, c.boxes, cam, im.ids);
        FrameBoxOptions o;
        o.rays = &table;
        const std::vector<FrameBox> shared = frameBoxes(c.model, c.boxes, cam, im.ids, o);
        ASSERT_EQ(own.size(), shared.size());
        for (size_t i = 0; i < own.size(); ++i) {
            const FrameBox &a = own[i], &b = shared[i];
            EXPECT_EQ(a.id, b.id);
            EXPECT_EQ(a.unoccludedPixels, b.unoccludedPixels);
            EXPECT_EQ(a.full.u0, b.full.u0);
            EXPECT_EQ(a.full.v0, b.full.v0);
            EXPECT_EQ(a.full.u1, b.full.u1);
            EXPECT_EQ(a.full.v1, b.full.v1);
            EXPECT_EQ(a.boxExtent.u0, b.boxExtent.u0);
            EXPECT_EQ(a.boxExtent.v1, b.boxExtent.v1);
            if (compared >= 30) continue;
            const std::vector<glm::dvec3> pts = instancePoints(c.model, c.boxes, *c.boxes.find(a.id));
            EXPECT_EQ(a.unoccludedPixels, fisheyeMaskEveryPixel(model, cam, pts))
                << instanceKindName(instanceKind(a.id)) << " " << a.id;
            ++compared;
            nonEmpty += a.unoccludedPixels > 20 ? 1 : 0;
        }
    }
    EXPECT_GE(compared, 30u);
    EXPECT_GT(nonEmpty, 10u);
}

// A cuboid mesh (a moving object's, identity transform) whose corners and
// faces are those projectedBox samples: its `full` extent and its 3D box's
// extent, made with the fisheye shortcuts (whole tiles, skipped runs of edge
// samples), are the extent of every sample taken the plain way, exactly; and its
// unoccluded pixels are those of every pixel ray tested against every
// triangle. The boxes lie around the camera at 1 to 6 m, large in a
// 320x240 fisheye, the camera turned every way.
TEST(RigBoxes, FisheyeShortcutsGiveTheExtentAndPixelsOfTheUnshortenedWay) {
    CameraModel model;
    model.kind = CameraModel::Kind::Fisheye;
    model.width = 320, model.height = 240;
    model.fx = 75.0, model.fy = 78.0, model.cx = 159.5, model.cy = 118.0;
    model.maxFovDeg = 190.0;
    const CameraRayTable table(model);
    static const uint32_t kFaces[12][3] = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                                           {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
    const SceneModel city;
    const CityBoxes none;
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> turn(-kPi, kPi);
    std::uniform_int_distribution<int> halfMetres(-12, 12), sizeHalves(2, 14);
    size_t compared = 0, large = 0;
    for (int k = 0; k < 40; ++k) {
        OrientedBox box;  // corners at multiples of 0.25 m: exact as floats
        box.center = {0.5 * halfMetres(rng), 0.5 * halfMetres(rng), 0.5 * halfMetres(rng)};
        box.size = {0.5 * sizeHalves(rng), 0.5 * sizeHalves(rng), 0.5 * sizeHalves(rng)};
        if (box.contains(glm::dvec3(0.0), 0.3)) continue;  // the camera is not inside the box
        const std::array<glm::dvec3, 8> corners = box.corners();
        Mesh mesh;
        for (const glm::dvec3& c : corners) {
            mesh.positions.push_back(glm::vec3(c));
            ASSERT_EQ(glm::dvec3(mesh.positions.back()), c);
        }
        std::vector<glm::dvec3> tris;
        for (const auto& f : kFaces)
            for (uint32_t v : f) mesh.indices.push_back(v), tris.push_back(corners[v]);
        MovingObject mo;
        mo.id = 7;
        mo.box = box;
        mo.mesh = &mesh;
        BoxCamera cam;
        cam.model = model;
        cam.axes = glm::dmat3(glm::rotate(glm::dmat4(1.0), turn(rng), glm::dvec3(0, 0, 1)) *
                              glm::rotate(glm::dmat4(1.0), turn(rng), glm::dvec3(1, 0, 0)) *
                              glm::rotate(glm::dmat4(1.0), turn(rng), glm::dvec3(0, 1, 0)));
        std::vector<uint32_t> ids(size_t(model.width) * size_t(model.height), 0u);
        ids[size_t(model.width) * 120 + 160] = mo.id;  // one visible pixel: the box gets an entry
        FrameBoxOptions o;
        o.rays = &table;
        const std::vector<FrameBox> fb = frameBoxes(city, none, {mo}, cam, ids, o);
        ASSERT_EQ(fb.size(), 1u);
        const FrameBox& f = fb[0];
        const PixelBox want = clipToImage(fisheyeExtentEverySample(model, cam, tris), model.width, model.height);
        if (!want.valid()) {  // the box lies outside the image circle's cone
            EXPECT_FALSE(f.full.valid()) << k;
            EXPECT_EQ(f.unoccludedPixels, 0u) << k;
            continue;
        }
        for (const PixelBox& got : {f.full, f.boxExtent}) {
            EXPECT_EQ(got.u0, want.u0) << k;
            EXPECT_EQ(got.v0, want.v0) << k;
            EXPECT_EQ(got.u1, want.u1) << k;
            EXPECT_EQ(got.v1, want.v1) << k;
        }
        EXPECT_EQ(f.unoccludedPixels, fisheyeMaskEveryPixel(model, cam, tris)) << k;
        ++compared;
        large += f.unoccludedPixels > 5000 ? 1 : 0;
    }
    EXPECT_GE(compared, 25u);
    EXPECT_GE(large, 5u);
}

// The visible extents and pixel counts of an instance image made of bands
// of rows (every id in several bands) are those counted here, with any
// number of threads.
TEST(RigBoxes, VisibleExtentsOfATallImageAreThoseCountedHere) {
    CameraModel model;
    model.width = 50, model.height = 203;
    model.fx = model.fy = 60.0, model.cx = 24.5, model.cy = 101.0;
    std::mt19937 rng(3);
    std::uniform_int_distribution<uint32_t> pick(0, 9);
    std::vector<uint32_t> ids(size_t(model.width) * size_t(model.height));
    for (uint32_t& id : ids) id = pick(rng) < 3 ? 0u : 100u + pick(rng) % 7;
    std::vector<MovingObject> movers;
    for (uint32_t id = 100; id < 107; ++id) movers.push_back(MovingObject{id, 0, {}, {}, nullptr, glm::dmat4(1.0)});
    std::map<uint32_t, Mask> want;
    for (int y = 0; y < model.height; ++y)
        for (int x = 0; x < model.width; ++x) {
            const uint32_t id = ids[size_t(y) * size_t(model.width) + size_t(x)];
            if (id == 0) continue;
            Mask& m = want[id];
            m.u0 = std::min(m.u0, x), m.v0 = std::min(m.v0, y), m.u1 = std::max(m.u1, x), m.v1 = std::max(m.v1, y);
            ++m.n;
        }
    BoxCamera cam;
    cam.model = model;
    for (int threads : {1, 2, 0}) {
        FrameBoxOptions o;
        o.threads = threads;
        const std::vector<FrameBox> fb = frameBoxes(SceneModel{}, CityBoxes{}, movers, cam, ids, o);
        ASSERT_EQ(fb.size(), want.size());
        for (const FrameBox& f : fb) expectVisibleEqualsMask(f, want.at(f.id));
    }
}
