// Boxes of rig cameras in the frames a dataset reader uses (rig_boxes.h): a box in the vehicle frame
// is the world box through the inverse of the pose's 4x4 matrix, in the file too; sightings merge
// cameras and LiDARs; KITTI label lines read back with the devkit's corners hold the world box (equal
// to it for a level vehicle) and carry the instance id; moving objects are boxed from their mesh and
// tracked.
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

TEST(RigBoxes, VehicleFrameBoxesAreTheWorldBoxesThroughThePose) {
    PathSample s;
    s.position = {-2950.0, 1520.0, 31.5};
    s.heading = 1.1;
    s.pitch = 0.04;
    const RigPose vehicle = vehiclePose(s);
    OrientedBox b;
    b.center = {-2940.0, 1531.0, 31.0};
    b.size = {4.4, 1.8, 1.5};
    b.yaw = -0.7;
    // The pose's 4x4 matrix (columns: the body axes, then the position), inverted by glm.
    glm::dmat4 T(1.0);
    for (int i = 0; i < 3; ++i) T[i] = glm::dvec4(vehicle.rotation[i], 0.0);
    T[3] = glm::dvec4(vehicle.position, 1.0);
    const glm::dmat4 inv = glm::inverse(T);
    const glm::dvec3 c = glm::dvec3(inv * glm::dvec4(b.center, 1.0));
    const glm::dvec3 tip = glm::dvec3(inv * glm::dvec4(b.center + b.lengthAxis(), 1.0)) - c;
    double yaw = std::atan2(tip.y, tip.x);
    if (yaw > kHalfPi) yaw -= kPi;
    if (yaw <= -kHalfPi) yaw += kPi;
    const OrientedBox v = boxInPoseFrame(b, vehicle);
    EXPECT_NEAR(v.center.x, c.x, 1e-9);
    EXPECT_NEAR(v.center.y, c.y, 1e-9);
    EXPECT_NEAR(v.center.z, c.z, 1e-9);
    EXPECT_NEAR(v.yaw, yaw, 1e-9);
    EXPECT_EQ(v.size, b.size);
    // Heading 1.1 rad east of north, the box 10 m east and 11 m north: ahead and to the left.
    EXPECT_GT(v.center.x, 10.0);
    EXPECT_GT(v.center.y, 0.0);

    // The file: world minus the offset, vehicle frame as above, vehicle_to_world its inverse.
    CityBoxes boxes;
    InstanceBox ib;
    ib.id = makeInstanceId(InstanceKind::Car, 7);
    ib.box = b;
    boxes.boxes.push_back(ib);
    FrameSightings seen;
    addCameraSightings(seen, "front", {FrameBox{ib.id, b}});
    LidarSweep sweep;
    for (uint32_t id : {ib.id, ib.id, 0u, makeInstanceId(InstanceKind::Road, 1), ib.id}) {
        LidarPoint p;
        p.instance = id;
        sweep.points.push_back(p);
    }
    addLidarSightings(seen, "top", sweep, boxes);
    ASSERT_EQ(seen.size(), 1u) << "a road has no box";
    const glm::dvec3 offset(-3000.0, 1500.0, 0.0);
    const auto j = nlohmann::json::parse(frameBoxes3dJson(boxes, seen, vehicle, offset, "000004", 0.4));
    EXPECT_EQ(j["format"], "vista.boxes_3d");
    EXPECT_EQ(j["frame"], "000004");
    ASSERT_EQ(j["boxes"].size(), 1u);
    const auto& jb = j["boxes"][0];
    EXPECT_EQ(jb["kind"], "car");
    EXPECT_EQ(jb["index"], 7);
    EXPECT_EQ(jb["seen_by"], nlohmann::json({"front", "top"}));
    EXPECT_EQ(jb["lidar_points"], 3);
    const auto& M = j["vehicle_to_world"];
    glm::dmat4 F(1.0);  // from the file's rows
    for (int r = 0; r < 4; ++r)
        for (int k = 0; k < 4; ++k) F[k][r] = M[r][k].get<double>();
    glm::dvec3 w;
    for (int i = 0; i < 3; ++i) w[i] = jb["world"]["center"][size_t(i)].get<double>();
    EXPECT_NEAR(w.x, 60.0, 1e-9);
    const glm::dvec3 fromFile = glm::dvec3(glm::inverse(F) * glm::dvec4(w, 1.0));
    for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(jb["vehicle"]["center"][size_t(i)].get<double>(), c[i], 1e-3);
        EXPECT_NEAR(fromFile[i], c[i], 2e-3);
    }
    EXPECT_NEAR(jb["vehicle"]["yaw"].get<double>(), yaw, 1e-3);
}

// KITTI label lines of a rig (kittiRigLabels) read back the KITTI devkit's way: corners of length
// along x turned by rotation_y about y, height up (-y), width along z, from the bottom centre.
TEST(RigBoxes, KittiLabelsAreUprightInTheRectifiedFrameAndHoldTheWorldBox) {
    OrientedBox b;
    b.center = {12.0, 31.0, 0.9};
    b.size = {4.4, 1.8, 1.5};
    b.yaw = -0.7;
    FrameBox f;
    f.id = makeInstanceId(InstanceKind::Car, 7);
    f.box = b;
    f.visibleFraction = 0.5;
    for (double pitch : {0.0, 0.06}) {
        PathSample s;
        s.position = {2.0, 3.0, 1.2};
        s.heading = 1.1;
        s.pitch = pitch;
        SensorMount rect;
        rect.position = {0.3, 0.1, 0.4};
        rect.yawDeg = 20;
        const RigPose pose = sensorPose(vehiclePose(s), rect);
        const std::string text = kittiRigLabels({f}, pose);
        std::istringstream in(text);
        std::string type;
        double trunc, alpha, bb[4], h, w, l, x, y, z, ry;
        int occluded;
        uint32_t id = 0;
        in >> type >> trunc >> occluded >> alpha >> bb[0] >> bb[1] >> bb[2] >> bb[3] >> h >> w >> l >> x >> y >> z >>
            ry >> id;
        ASSERT_FALSE(in.fail()) << text;
        EXPECT_EQ(type, "Car");
        EXPECT_EQ(occluded, 1);
        EXPECT_EQ(id, f.id) << "the 16th column is the instance id";
        // The world box's corners in the rectified frame (OpenCV axes of the pose: -y, -z, x).
        const glm::dmat3 axes(-pose.rotation[1], -pose.rotation[2], pose.rotation[0]);
        const double c = std::cos(ry), sn = std::sin(ry);
        double worst = 0, nearest = 0;
        for (const glm::dvec3& corner : b.corners()) {
            const glm::dvec3 p = glm::transpose(axes) * (corner - pose.position) - glm::dvec3(x, y, z);
            // Into the label box's frame: R_y^T p.
            const glm::dvec3 q(c * p.x - sn * p.z, p.y, sn * p.x + c * p.z);
            worst = std::max({worst, std::abs(q.x) - l / 2, q.y, -h - q.y, std::abs(q.z) - w / 2});
            // Distance to the nearest label corner (the devkit's corners, in the same box frame).
            double best = 1e9;
            for (double sx : {-0.5, 0.5})
                for (double sy : {0.0, -1.0})
                    for (double sz : {-0.5, 0.5})
                        best = std::min(best, glm::length(q - glm::dvec3(sx * l, sy * h, sz * w)));
            nearest = std::max(nearest, best);
        }
        EXPECT_LE(worst, 2e-3) << "every world corner inside the label box, pitch " << pitch;
        if (pitch == 0.0) {
            EXPECT_NEAR(h, 1.5, 1e-3);
            EXPECT_NEAR(w, 1.8, 1e-3);
            EXPECT_NEAR(l, 4.4, 1e-3);
            EXPECT_LE(nearest, 3e-3) << "a level vehicle: the label box is the world box";
        } else {
            EXPECT_GT(h * w * l, 1.5 * 1.8 * 4.4) << "a pitched vehicle: a box around the tilted one";
            EXPECT_LT(h * w * l, 1.3 * 1.5 * 1.8 * 4.4);
        }
    }
}

// A moving object's box: found by id where the city has none, its class and
// velocity carried, its unoccluded pixels those of its own mesh (through its
// transform), its KITTI type that of its class; KITTI tracking lines keep the
// agents only, with the agent's number as track id and a truncation level.
TEST(RigBoxes, MovingObjectsAreBoxedFromTheirMeshAndTracked) {
    // A 2 m cube (12 outward triangles) in model frame, placed 10 m ahead of a camera looking along +x.
    Mesh cube;
    for (int i = 0; i < 8; ++i) cube.positions.push_back({i & 1 ? 1.f : -1.f, i & 2 ? 1.f : -1.f, i & 4 ? 2.f : 0.f});
    const uint32_t faces[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                   {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    for (const auto& f : faces) cube.indices.insert(cube.indices.end(), {f[0], f[1], f[2]});
    MovingObject m;
    m.id = makeInstanceId(InstanceKind::Vehicle, 42);
    m.semantic = uint8_t(SemanticClass::Bicycle);
    m.mesh = &cube;
    m.toWorld = glm::translate(glm::dmat4(1.0), glm::dvec3(10.0, 0.0, 0.0));
    m.box.center = {10.0, 0.0, 1.0};
    m.box.size = {2.0, 2.0, 2.0};
    m.velocity = {3.0, -1.0, 0.0};
    CameraModel model;
    model.width = 64, model.height = 48, model.fx = model.fy = 40, model.cx = 31.5, model.cy = 23.5;
    RigPose pose;
    pose.position = {0.0, 0.0, 1.0};
    const BoxCamera cam = rigBoxCamera(model, pose);
    // The instance image: the cube's left half visible (an occluder covers the rest).
    std::vector<uint32_t> ids(size_t(model.width * model.height), 0u);
    int full = 0;
    for (int v = 0; v < model.height; ++v)
        for (int u = 0; u < model.width; ++u) {
            const bool on =
                std::abs(u - model.cx) <= 0.9 / 9.0 * model.fx && std::abs(v - model.cy) <= 0.9 / 9.0 * model.fy;
            full += on;
            if (on && u < model.cx) ids[size_t(v * model.width + u)] = m.id;
        }
    SceneModel city;
    CityBoxes none;
    const std::vector<FrameBox> fb = frameBoxes(city, none, {m}, cam, ids);
    ASSERT_EQ(fb.size(), 1u);
    EXPECT_EQ(fb[0].id, m.id);
    EXPECT_EQ(fb[0].semantic, m.semantic);
    EXPECT_EQ(fb[0].velocity, m.velocity);
    EXPECT_EQ(fb[0].box.center, m.box.center);
    // The front face (x = 9 m, 2 m square) covers about (2 / 9 * 40)^2 pixels.
    EXPECT_NEAR(double(fb[0].unoccludedPixels), std::pow(2.0 / 9.0 * 40.0, 2.0), 40.0);
    EXPECT_NEAR(fb[0].visibleFraction, 0.5, 0.1);
    EXPECT_STREQ(kittiType(fb[0]), "Cyclist");
    EXPECT_TRUE(frameBoxes(city, none, cam, ids).empty()) << "without the moving objects: no box";
    // The KITTI object line, then the tracking line of it.
    const std::string objects = kittiRigLabels(fb, pose);
    const std::string parked = "Car 0.00 0 0.10 1.00 2.00 3.00 4.00 1.50 1.80 4.40 1.000 2.000 3.000 0.100 " +
                               std::to_string(makeInstanceId(InstanceKind::Car, 3)) + "\n";
    const std::string truncated = "Pedestrian 0.60 2 0.10 1.00 2.00 3.00 4.00 1.70 0.60 0.60 1.000 2.000 3.000 0.100 " +
                                  std::to_string(makeInstanceId(InstanceKind::Pedestrian, 7)) + "\n";
    const std::string tracking = kittiTrackingLines({{5, objects + parked}, {9, truncated + "bad line\n"}});
    std::istringstream in(tracking);
    std::vector<std::vector<std::string>> rows;
    for (std::string line; std::getline(in, line);) {
        std::istringstream cols(line);
        rows.emplace_back();
        for (std::string w; cols >> w;) rows.back().push_back(w);
    }
    ASSERT_EQ(rows.size(), 2u) << tracking;
    ASSERT_EQ(rows[0].size(), 17u);
    EXPECT_EQ(rows[0][0], "5");
    EXPECT_EQ(rows[0][1], "42");
    EXPECT_EQ(rows[0][2], "Cyclist");
    EXPECT_EQ(rows[0][3], "0");
    std::istringstream obj(objects);
    std::vector<std::string> o;
    for (std::string w; obj >> w;) o.push_back(w);
    ASSERT_EQ(o.size(), 16u);
    for (size_t i = 2; i < 15; ++i) EXPECT_EQ(rows[0][i + 2], o[i]) << "column " << i;
    EXPECT_EQ(rows[1][0], "9");
    EXPECT_EQ(rows[1][1], "7");
    EXPECT_EQ(rows[1][3], "2") << "a share of 0.6 is truncation level 2";
}
