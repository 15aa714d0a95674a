// Bounding boxes (runtime/engine/boxes.h) against independent computations:
// on a generated city (written and loaded as a scene file) every 3D box holds
// every vertex of its instance and is no larger than a brute-force yaw sweep
// finds; on ray-cast instance images the 2D visible boxes equal the mask
// extents counted here, the projected extents contain them, and the
// unoccluded pixel counts agree with rays cast at the instance alone; a box
// partly behind the camera is clipped at the near plane, not inverted; the
// vehicle frame, the JSON, the KITTI label lines and the KITTI calibration
// agree with hand computations.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "citygen/generate.h"
#include "citygen/labels.h"
#include "foundation/atomic_file.h"
#include "foundation/units.h"
#include "runtime/engine/boxes.h"
#include "runtime/engine/ground_truth.h"
#include "runtime/engine/image.h"
#include "runtime/engine/lidar.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/scene/city_file.h"
#include "tests/common/temp_dir.h"
#include "tests/runtime/engine/boxes_city.h"
#include "tests/runtime/engine/fixtures.h"

using namespace vista;

namespace {

// A small generated city with every object kind it can have (night: street lights; parked cars).
using TestCity = test::BoxesCity;

const TestCity& testCity() {
    static TestCity* city = [] {
        CityParams p;
        p.seed = 7;
        p.size_m = 400.0;
        p.tile_size_m = 100.0;
        p.origin_x = 2000.0;
        p.origin_y = -1000.0;
        p.parked_car_share = 0.5;
        p.effects.enable(EffectId::Night);
        return test::makeBoxesCity(p, "vista_boxes");
    }();
    return *city;
}

// Every world point of each object instance, gathered here: triangles by their first vertex's id, trees
// through their instance transform.
std::map<uint32_t, std::vector<glm::dvec3>> pointsById(const SceneModel& city) {
    std::map<uint32_t, std::vector<glm::dvec3>> out;
    for (const SceneMesh& m : city.meshes) {
        if (m.ids.size() != m.positions.size()) continue;
        for (size_t k = 0; k + 2 < m.indices.size(); k += 3) {
            const uint32_t id = m.ids[m.indices[k]];
            if (!isObjectKind(instanceKind(id))) continue;
            for (int j = 0; j < 3; ++j) out[id].push_back(m.origin + glm::dvec3(m.positions[m.indices[k + size_t(j)]]));
        }
    }
    for (const SceneInstance& in : city.instances)
        for (const glm::vec3& p : city.prototypes[in.prototype].positions)
            out[in.id].push_back(glm::dvec3(in.transform * glm::dvec4(glm::dvec3(p), 1.0)));
    return out;
}

// The smallest footprint area over yaws sampled every `stepDeg` degrees.
double bruteMinArea(const std::vector<glm::dvec3>& pts, double stepDeg) {
    double best = 1e300;
    for (double a = 0; a < 90.0; a += stepDeg) {
        const double c = std::cos(degToRad(a)), s = std::sin(degToRad(a));
        double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
        for (const glm::dvec3& p : pts) {
            const double u = c * p.x + s * p.y, v = -s * p.x + c * p.y;
            x0 = std::min(x0, u), x1 = std::max(x1, u), y0 = std::min(y0, v), y1 = std::max(y1, v);
        }
        best = std::min(best, (x1 - x0) * (y1 - y0));
    }
    return best;
}

// A camera on street edge e (at `at` of its length), 1.6 m above the ground, looking along it.
Camera streetCamera(const TestCity& c, size_t e, double at, int w, int h) {
    const StreetGraph& g = c.model.streets;
    const glm::dvec2 a = g.nodes[g.edges[e].a], b = g.nodes[g.edges[e].b];
    const glm::dvec2 xy = a + at * (b - a) + glm::dvec2(c.model.params.origin_x, c.model.params.origin_y);
    const glm::dvec3 top(xy, 300.0);
    const RayHit down = c.rays->intersect(glm::vec3(top - c.rays->frameOrigin()), glm::vec3(0, 0, -1));
    const double ground = down.hit ? 300.0 - double(down.t) : 0.0;
    const glm::dvec2 d = b - a;
    return test::testCamera(glm::dvec3(xy, ground + 1.6), std::atan2(d.x, d.y), 0.0, w, h, degToRad(60.0));
}

LabelImage castAll(const SceneModel& city, const RayScene& rays, const Camera& cam) {
    LabelImage img;
    img.resize(cam.width, cam.height);
    std::vector<uint32_t> all(size_t(cam.width) * size_t(cam.height));
    for (size_t i = 0; i < all.size(); ++i) all[i] = uint32_t(i);
    castLabels(city, rays, cam, all, img);
    return img;
}

// Pixels whose centre ray hits the instance's triangles alone (back faces culled, from the near plane).
uint32_t raysAtInstanceAlone(const Camera& cam, const std::vector<glm::dvec3>& tris) {
    TriangleSoup soup;
    for (const glm::dvec3& p : tris) {
        soup.indices.push_back(uint32_t(soup.positions.size()));
        soup.positions.push_back(glm::vec3(p - cam.eye));
        soup.colors.push_back({255, 255, 255, 255});
    }
    SoupSceneOptions o;
    o.cullBackFaces = true;
    auto scene = RayScene::build(soup, o);
    VISTA_CHECK(scene.isOk());
    uint32_t n = 0;
    for (int y = 0; y < cam.height; ++y)
        for (int x = 0; x < cam.width; ++x) {
            const glm::dvec3 d = cam.rayDirection(x + 0.5, y + 0.5);
            const float tnear = float(cam.zNear / glm::dot(d, cam.forward()));
            n += (*scene)->intersect(glm::vec3(0.0f), glm::vec3(d), tnear).hit ? 1u : 0u;
        }
    return n;
}

}  // namespace

TEST(Boxes, FitUprightBoxRecoversARotatedRectangleAndBeatsEverySampledYaw) {
    const double yaw = 0.4, L = 6.0, W = 2.0;
    const glm::dvec2 ax(std::cos(yaw), std::sin(yaw)), aw(-std::sin(yaw), std::cos(yaw));
    std::vector<glm::dvec3> pts;
    for (int i = 0; i <= 10; ++i)
        for (int j = 0; j <= 4; ++j)
            for (double z : {1.0, 3.5}) {
                const glm::dvec2 p = glm::dvec2(100.0, -50.0) + (L * i / 10 - L / 2) * ax + (W * j / 4 - W / 2) * aw;
                pts.push_back(glm::dvec3(p, z));
            }
    const OrientedBox b = fitUprightBox(pts);
    EXPECT_NEAR(b.yaw, yaw, 1e-9);
    EXPECT_NEAR(b.size.x, L, 1e-9);
    EXPECT_NEAR(b.size.y, W, 1e-9);
    EXPECT_NEAR(b.size.z, 2.5, 1e-12);
    EXPECT_NEAR(b.center.x, 100.0, 1e-9);
    EXPECT_NEAR(b.center.y, -50.0, 1e-9);
    EXPECT_NEAR(b.center.z, 2.25, 1e-12);
    // Random clouds: the box holds them and no sampled yaw gives a smaller rectangle.
    std::mt19937 rng(3);
    std::normal_distribution<double> n(0.0, 5.0);
    for (int t = 0; t < 20; ++t) {
        std::vector<glm::dvec3> cloud;
        for (int i = 0; i < 40; ++i) cloud.push_back({n(rng), 0.3 * n(rng), n(rng)});
        const OrientedBox c = fitUprightBox(cloud);
        for (const glm::dvec3& p : cloud) EXPECT_TRUE(c.contains(p, 1e-9));
        EXPECT_LE(c.size.x * c.size.y, bruteMinArea(cloud, 0.05) + 1e-9);
        EXPECT_GE(c.size.x, c.size.y);
        EXPECT_GT(c.yaw, -kHalfPi);
        EXPECT_LE(c.yaw, kHalfPi);
    }
}

TEST(Boxes, CityBoxesHoldEveryVertexAndAreMinimalAgainstAYawSweep) {
    const TestCity& c = testCity();
    const auto points = pointsById(c.model);
    ASSERT_EQ(points.size(), c.boxes.boxes.size());
    std::set<InstanceKind> kinds;
    size_t swept = 0;
    for (const auto& [id, pts] : points) {
        const InstanceBox* b = c.boxes.find(id);
        ASSERT_NE(b, nullptr) << id;
        kinds.insert(instanceKind(id));
        for (const glm::dvec3& p : pts) ASSERT_TRUE(b->box.contains(p, 1e-3)) << instanceKindName(instanceKind(id));
        double zLo = 1e300, zHi = -1e300;
        for (const glm::dvec3& p : pts) zLo = std::min(zLo, p.z), zHi = std::max(zHi, p.z);
        EXPECT_NEAR(b->box.size.z, zHi - zLo, 1e-6);
        // Minimal: never above a sampled yaw, and within the sampling's error of the best sample.
        if (swept++ % 3 != 0) continue;
        const double brute = bruteMinArea(pts, 0.05), area = b->box.size.x * b->box.size.y;
        EXPECT_LE(area, brute * (1 + 1e-9) + 1e-9) << id;
        EXPECT_GE(area, brute * 0.98 - 1e-6) << id;
    }
    // Every vertex carrying an object id lies in that id's box too.
    for (const SceneMesh& m : c.model.meshes)
        for (size_t v = 0; v < m.ids.size(); ++v)
            if (const InstanceBox* b = c.boxes.find(m.ids[v])) {
                ASSERT_TRUE(b->box.contains(m.origin + glm::dvec3(m.positions[v]), 1e-3));
            }
    for (InstanceKind k : {InstanceKind::Building, InstanceKind::Tree, InstanceKind::StreetLight, InstanceKind::Car})
        EXPECT_TRUE(kinds.count(k)) << instanceKindName(k);
    for (InstanceKind k : {InstanceKind::Road, InstanceKind::Junction, InstanceKind::Sidewalk, InstanceKind::Park})
        EXPECT_FALSE(kinds.count(k)) << instanceKindName(k);
}

TEST(Boxes, VisibleBoxesEqualTheInstanceMaskAndTheProjectedExtentsContainThem) {
    const TestCity& c = testCity();
    const int W = 240, H = 160;
    size_t compared = 0, aloneChecked = 0;
    for (size_t e = 0; e < c.model.streets.edges.size() && compared < 60; e += 5) {
        const Camera cam = streetCamera(c, e, 0.3, W, H);
        ASSERT_TRUE(c.rays->placeFrameNear(cam.eye).isOk());
        const LabelImage img = castAll(c.model, *c.rays, cam);
        // The mask extents, counted here.
        struct Ext {
            int u0 = 1 << 30, v0 = 1 << 30, u1 = -1, v1 = -1;
            uint32_t n = 0;
        };
        std::map<uint32_t, Ext> ext;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                const uint32_t id = img.ids[size_t(y) * W + size_t(x)];
                if (!c.boxes.find(id)) continue;
                Ext& m = ext[id];
                m.u0 = std::min(m.u0, x), m.v0 = std::min(m.v0, y), m.u1 = std::max(m.u1, x), m.v1 = std::max(m.v1, y);
                ++m.n;
            }
        const std::vector<FrameBox> fb = frameBoxes(c.model, c.boxes, cam, img.ids);
        ASSERT_EQ(fb.size(), ext.size());
        for (const FrameBox& f : fb) {
            const Ext& m = ext.at(f.id);
            EXPECT_EQ(f.visibleU0, m.u0);
            EXPECT_EQ(f.visibleV0, m.v0);
            EXPECT_EQ(f.visibleU1, m.u1);
            EXPECT_EQ(f.visibleV1, m.v1);
            EXPECT_EQ(f.pixels, m.n);
            // Visible pixel centres lie within the projected geometry and the projected 3D box.
            for (const PixelBox& p : {f.full, f.boxExtent}) {
                ASSERT_TRUE(p.valid());
                EXPECT_LE(p.u0, m.u0 + 1e-6);
                EXPECT_LE(p.v0, m.v0 + 1e-6);
                EXPECT_GE(p.u1, m.u1 - 1e-6);
                EXPECT_GE(p.v1, m.v1 - 1e-6);
            }
            EXPECT_LE(f.boxExtent.u0, f.full.u0 + 1e-6);
            EXPECT_GE(f.boxExtent.u1, f.full.u1 - 1e-6);
            EXPECT_GE(f.visibleFraction, 0.0);
            EXPECT_LE(f.visibleFraction, 1.0);
            EXPECT_GE(f.truncated, 0.0);
            EXPECT_LE(f.truncated, 1.0);
            // The mask of the instance alone covers (almost) every visible pixel.
            EXPECT_GE(f.unoccludedPixels + 2 + f.pixels / 50, f.pixels) << instanceKindName(instanceKind(f.id));
            ++compared;
            if (aloneChecked < 12 && f.pixels > 200) {
                const uint32_t alone = raysAtInstanceAlone(cam, instancePoints(c.model, c.boxes, *c.boxes.find(f.id)));
                EXPECT_NEAR(double(f.unoccludedPixels), double(alone), 3.0 + 0.02 * alone)
                    << instanceKindName(instanceKind(f.id));
                ++aloneChecked;
            }
        }
    }
    EXPECT_GT(compared, 20u);
    EXPECT_GT(aloneChecked, 4u);
}

TEST(Boxes, AnObjectPartlyBehindTheCameraIsClippedNotInverted) {
    // A car-sized box to the right of the camera, from 5 m behind to 5 m ahead.
    SceneModel city;
    SceneMesh m;
    m.material = Material::Car;
    test::addBox(m, {1.0f, -5.0f, 0.0f}, {3.0f, 5.0f, 1.5f}, {200, 30, 30, 255});
    const uint32_t id = makeInstanceId(InstanceKind::Car, 0);
    m.ids.assign(m.positions.size(), id);
    city.meshes.push_back(m);
    city.triangles = m.indices.size() / 3;
    auto rays = RayScene::build(city);
    ASSERT_TRUE(rays.isOk());
    const Camera cam = test::testCamera({0.0, 0.0, 1.0}, 0.0, 0.0, 200, 150, degToRad(60.0));
    const CityBoxes boxes = buildCityBoxes(city);
    ASSERT_EQ(boxes.boxes.size(), 1u);
    const LabelImage img = castAll(city, **rays, cam);
    const std::vector<FrameBox> fb = frameBoxes(city, boxes, cam, img.ids);
    ASSERT_EQ(fb.size(), 1u);
    const FrameBox& f = fb[0];
    const PinholeIntrinsics k = pinholeIntrinsics(cam);
    // Hand computation: the far left edge is the box's near-left vertical edge 5 m ahead (x = 1);
    // the near-plane section runs off the right, top and bottom of the image.
    const PixelBox expected{k.fx * 1.0 / 5.0 + k.cx, -0.5, cam.width - 0.5, cam.height - 0.5};
    for (const PixelBox& p : {f.full, f.boxExtent}) {
        ASSERT_TRUE(p.valid());
        EXPECT_NEAR(p.u0, expected.u0, 1e-6);
        EXPECT_NEAR(p.v0, expected.v0, 1e-9);
        EXPECT_NEAR(p.u1, expected.u1, 1e-9);
        EXPECT_NEAR(p.v1, expected.v1, 1e-9);
    }
    EXPECT_GE(double(f.visibleU0), expected.u0);
    EXPECT_GT(f.truncated, 0.9);                // most of the near-clipped extent lies outside
    EXPECT_NEAR(f.visibleFraction, 1.0, 0.02);  // nothing in front of it
    // Unclipped at the near plane, the corners behind the camera would project to the left half.
    const PixelBox raw = projectedBox(cam, boxes.boxes[0].box);
    EXPECT_GT(raw.u0, k.cx);
    EXPECT_GT(raw.u1, 1e3);
    // Wholly behind the camera: no extent at all.
    OrientedBox behind = boxes.boxes[0].box;
    behind.center.y = -20.0;
    EXPECT_FALSE(projectedBox(cam, behind).valid());
}

TEST(Boxes, TreesComeFromTheirInstanceAndImpostorsOnlyFillIn) {
    // A 2 m cube prototype; tree 0 as a full instance at x = 10 and as an impostor at x = 50 (a coarse
    // level of the same tree), tree 1 only as an impostor at x = -20, scaled by 2.
    SceneModel city;
    SceneMesh proto;
    test::addBox(proto, {-1.0f, -1.0f, 0.0f}, {1.0f, 1.0f, 2.0f}, {40, 120, 40, 255});
    city.prototypes.push_back(proto);
    auto at = [](double x, double scale) {
        return glm::scale(glm::translate(glm::dmat4(1.0), glm::dvec3(x, 0.0, 0.0)), glm::dvec3(scale));
    };
    const uint32_t t0 = makeInstanceId(InstanceKind::Tree, 0), t1 = makeInstanceId(InstanceKind::Tree, 1);
    city.instances.push_back({0, at(10.0, 1.0), t0});
    city.impostors.push_back({0, at(50.0, 1.0), t0});
    city.impostors.push_back({0, at(-20.0, 2.0), t1});
    const CityBoxes boxes = buildCityBoxes(city);
    ASSERT_EQ(boxes.boxes.size(), 2u);
    const InstanceBox* a = boxes.find(t0);
    const InstanceBox* b = boxes.find(t1);
    ASSERT_TRUE(a && b);
    EXPECT_NEAR(a->box.center.x, 10.0, 1e-9);
    EXPECT_NEAR(a->box.size.x, 2.0, 1e-9);
    EXPECT_NEAR(a->box.size.z, 2.0, 1e-9);
    EXPECT_TRUE(a->impostors.empty());
    EXPECT_NEAR(b->box.center.x, -20.0, 1e-9);
    EXPECT_NEAR(b->box.size.y, 4.0, 1e-9);
    EXPECT_NEAR(b->box.center.z, 2.0, 1e-9);
    EXPECT_EQ(boxes.find(makeInstanceId(InstanceKind::Tree, 2)), nullptr);
}

TEST(Boxes, VehicleFrameKittiLabelsAndCalibrationMatchHandComputations) {
    OrientedBox b;
    b.center = {110.0, 205.0, 1.0};
    b.size = {4.0, 2.0, 1.5};
    b.yaw = 0.0;  // length along east
    LidarPose pose;
    pose.position = {100.0, 200.0, 1.0};
    pose.heading = kHalfPi;  // facing east
    const OrientedBox v = boxInVehicleFrame(b, pose);
    EXPECT_NEAR(v.center.x, 10.0, 1e-9);  // 10 m ahead
    EXPECT_NEAR(v.center.y, 5.0, 1e-9);   // 5 m to the left (north)
    EXPECT_NEAR(v.center.z, 0.0, 1e-9);
    EXPECT_NEAR(v.yaw, 0.0, 1e-9);
    pose.heading = 0.0;  // facing north: the length axis points to the right
    EXPECT_NEAR(std::abs(boxInVehicleFrame(b, pose).yaw), kHalfPi, 1e-9);

    Camera cam = test::testCamera({100.0, 200.0, 1.5}, kHalfPi, 0.0, 320, 240, degToRad(60.0));
    FrameBox f;
    f.id = makeInstanceId(InstanceKind::Car, 3);
    f.box = b;
    f.visibleU0 = 10, f.visibleV0 = 20, f.visibleU1 = 30, f.visibleV1 = 40;
    f.pixels = 300;
    f.visibleFraction = 0.5;
    const std::string line = kittiLabels({f}, cam);
    std::istringstream in(line);
    std::string type;
    double tr, alpha, l, t, r, bo, h, w, len, x, y, z, ry;
    int occ;
    in >> type >> tr >> occ >> alpha >> l >> t >> r >> bo >> h >> w >> len >> x >> y >> z >> ry;
    ASSERT_FALSE(in.fail()) << line;
    EXPECT_EQ(type, "Car");
    EXPECT_EQ(occ, 1);
    EXPECT_DOUBLE_EQ(l, 10.0);
    EXPECT_DOUBLE_EQ(bo, 40.0);
    EXPECT_DOUBLE_EQ(h, 1.5);
    EXPECT_DOUBLE_EQ(w, 2.0);
    EXPECT_DOUBLE_EQ(len, 4.0);
    // Camera facing east: the bottom centre is 5 m left (x = -5), 1.25 m down, 10 m ahead;
    // a length axis along the optical axis is rotation_y = -pi/2 (KITTI).
    EXPECT_NEAR(x, -5.0, 0.01);
    EXPECT_NEAR(y, 1.25, 0.01);
    EXPECT_NEAR(z, 10.0, 0.01);
    EXPECT_NEAR(ry, -kHalfPi, 0.01);
    EXPECT_NEAR(alpha, -kHalfPi - std::atan2(-5.0, 10.0), 0.01);
    // JSON: the same numbers, world positions minus the offset.
    const nlohmann::json j = nlohmann::json::parse(frameBoxesJson({f}, cam, {100.0, 0.0, 0.0}));
    EXPECT_EQ(j["format"], "vista.boxes");
    ASSERT_EQ(j["boxes"].size(), 1u);
    const nlohmann::json& jb = j["boxes"][0];
    EXPECT_EQ(jb["kind"], "car");
    EXPECT_EQ(jb["index"], 3);
    EXPECT_EQ(jb["visible"], nlohmann::json({10, 20, 30, 40}));
    EXPECT_DOUBLE_EQ(jb["box"]["center"][0].get<double>(), 10.0);
    EXPECT_DOUBLE_EQ(jb["box"]["center"][1].get<double>(), 205.0);
    EXPECT_NEAR(jb["camera"]["rotation_y"].get<double>(), -kHalfPi, 1e-3);
    EXPECT_TRUE(jb["full"].is_null());
    // Calibration: a LiDAR point through Tr_velo_to_cam and P2 lands where the camera projects it.
    LidarPose lidar;
    lidar.position = {101.0, 199.0, 2.0};
    lidar.heading = kHalfPi + 0.1;
    lidar.pitch = 0.02;
    std::istringstream calib(kittiCalib(cam, lidar));
    std::map<std::string, std::vector<double>> rows;
    for (std::string name; calib >> name;) {
        std::string rest;
        std::getline(calib, rest);
        std::istringstream vals(rest);
        for (double d; vals >> d;) rows[name].push_back(d);
    }
    EXPECT_EQ(rows.size(), 7u);  // P0..P3, R0_rect, Tr_velo_to_cam, Tr_imu_to_velo
    const std::vector<double>& T = rows["Tr_velo_to_cam:"];
    const std::vector<double>& P = rows["P2:"];
    ASSERT_EQ(T.size(), 12u);
    ASSERT_EQ(P.size(), 12u);
    const glm::dvec3 q(12.0, -3.0, 0.5);  // sensor frame: ahead, right, up
    Camera lc;
    lc.heading = lidar.heading, lc.pitch = lidar.pitch;
    const glm::dvec3 world = lidar.position + q.x * lc.forward() - q.y * lc.right() + q.z * lc.up();
    double pc[3];
    for (int i = 0; i < 3; ++i)
        pc[i] = T[size_t(i) * 4] * q.x + T[size_t(i) * 4 + 1] * q.y + T[size_t(i) * 4 + 2] * q.z + T[size_t(i) * 4 + 3];
    const glm::dvec3 expectCam = cameraPoint(cam, world);
    EXPECT_NEAR(pc[0], expectCam.x, 1e-9);
    EXPECT_NEAR(pc[1], expectCam.y, 1e-9);
    EXPECT_NEAR(pc[2], expectCam.z, 1e-9);
    const double u = (P[0] * pc[0] + P[2] * pc[2]) / pc[2], vpx = (P[5] * pc[1] + P[6] * pc[2]) / pc[2];
    const PinholeIntrinsics k = pinholeIntrinsics(cam);
    EXPECT_NEAR(u, k.fx * expectCam.x / expectCam.z + k.cx, 1e-6);
    EXPECT_NEAR(vpx, k.fy * expectCam.y / expectCam.z + k.cy, 1e-6);
}

// Writes one frame for docs/tools/show_frame.py (rgb.png, boxes.json, label.txt, lidar.bin,
// calib.txt) into $VISTA_BOXES_DUMP_DIR when it is set; otherwise checks the writers' output only.
TEST(Boxes, OneFrameOfFilesForTheReader) {
    const TestCity& c = testCity();
    const Camera cam = streetCamera(c, 2, 0.3, 480, 320);
    ASSERT_TRUE(c.rays->placeFrameNear(cam.eye).isOk());
    const LabelImage img = castAll(c.model, *c.rays, cam);
    const std::vector<FrameBox> fb = frameBoxes(c.model, c.boxes, cam, img.ids);
    ASSERT_FALSE(fb.empty());
    const glm::dvec3 offset(c.model.params.origin_x, c.model.params.origin_y, 0.0);
    const std::string json = frameBoxesJson(fb, cam, offset), kitti = kittiLabels(fb, cam);
    EXPECT_EQ(nlohmann::json::parse(json)["boxes"].size(), fb.size());
    EXPECT_EQ(size_t(std::count(kitti.begin(), kitti.end(), '\n')), fb.size());
    const char* dir = std::getenv("VISTA_BOXES_DUMP_DIR");
    if (!dir) return;
    const std::string d(dir);
    Image rgb(cam.width, cam.height);
    const glm::vec3 org(cam.eye - c.rays->frameOrigin());
    for (int y = 0; y < cam.height; ++y)
        for (int x = 0; x < cam.width; ++x) {
            const RayHit h = c.rays->intersect(org, glm::vec3(cam.rayDirection(x + 0.5, y + 0.5)), float(cam.zNear));
            rgb.set(x, y, h.hit ? h.color : glm::u8vec4(150, 190, 230, 255));
        }
    ASSERT_TRUE(writePngRgb(rgb, d + "/rgb.png").isOk());
    ASSERT_TRUE(writeFileAtomic(d + "/boxes.json", json).isOk());
    ASSERT_TRUE(writeFileAtomic(d + "/label.txt", kitti).isOk());
    LidarSpec spec;
    spec.elevationDeg = evenBeamTable(32, -25.0, 10.0);
    spec.columns = 1024;
    LidarPose pose;
    pose.position = cam.eye + glm::dvec3(0.0, 0.0, 0.3);
    pose.heading = cam.heading;
    const LidarSweep s = castLidarSweep(
        c.model, *c.rays, spec, [&](double) { return pose; }, 0.0);
    std::string bin;
    for (const LidarPoint& p : s.points) {
        const float v[4] = {p.sensor.x, p.sensor.y, p.sensor.z, p.intensity};
        bin.append(reinterpret_cast<const char*>(v), sizeof v);
    }
    ASSERT_TRUE(writeFileAtomic(d + "/lidar.bin", bin).isOk());
    ASSERT_TRUE(writeFileAtomic(d + "/calib.txt", kittiCalib(cam, pose)).isOk());
}
