// The rig file and sensor poses (rig.h, rig_dataset.h): the example rig of
// data/rigs parses; bad rig files are refused naming the field and its range;
// mount rotations follow the documented yaw / pitch / roll; the vehicle pose
// is interpolated between path samples; LiDAR heading / pitch / roll give the
// same axes back; sensors fire at their rates; the KITTI calibration maps a
// LiDAR point to the pixel its pose gives; the file encoders' layouts.
#include <gtest/gtest.h>

#include <map>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>

#include "citygen/labels.h"
#include "foundation/input_file.h"
#include "foundation/units.h"
#include "runtime/engine/rig.h"
#include "runtime/engine/rig_camera.h"
#include "runtime/engine/rig_dataset.h"

using namespace vista;

namespace {

std::string camera(const std::string& extra = "", const std::string& intrinsics = "") {
    return R"({"name": "c", "type": "pinhole", "channels": ["rgb"], "intrinsics": {"width": 64, "height": 48,
              "fx": 50, "fy": 50, "cx": 31.5, "cy": 23.5)" +
           intrinsics + "}" + extra + "}";
}

std::string rigOf(const std::string& sensors) { return R"({"sensors": [)" + sensors + "]}"; }

double near(const glm::dvec3& a, const glm::dvec3& b) { return glm::length(a - b); }

}  // namespace

TEST(Rig, ExampleRigParses) {
    auto rig = loadRigFile(std::string(VISTA_SOURCE_DIR) + "/data/rigs/car_4cam_lidar64.json");
    ASSERT_TRUE(rig.isOk()) << rig.status().message();
    ASSERT_EQ(rig->cameras.size(), 4u);
    ASSERT_EQ(rig->lidars.size(), 1u);
    EXPECT_EQ(rig->cameras[2].model.kind, CameraModel::Kind::Fisheye);
    EXPECT_EQ(rig->cameras[0].channels,
              unsigned(kRigRgb | kRigDepth | kRigSemantic | kRigInstance | kRigFlow | kRigBoxes));
    EXPECT_EQ(rig->lidars[0].spec.elevationDeg.size(), 64u);
    EXPECT_EQ(rig->lidars[0].spec.columns, 2048);
    EXPECT_TRUE(validateLidarSpec(rig->lidars[0].spec).isOk());
    // The canonical form reads back to itself.
    auto again = parseRigJson(rigToJson(*rig), "canonical");
    ASSERT_TRUE(again.isOk()) << again.status().message();
    EXPECT_EQ(rigToJson(*again), rigToJson(*rig));
}

TEST(Rig, BadRigFilesNameTheFieldAndRange) {
    const std::pair<std::string, std::string> cases[] = {
        {"[]", "a rig file is a JSON object"},
        {R"({"sensors": []})", "sensors must be a list of 1 .. 64 sensors"},
        {R"({"sensors": [], "extra": 1})", "unknown field 'extra'"},
        {rigOf(camera("", ", \"max_fov_deg\": 100")), "sensors[0].intrinsics has an unknown field 'max_fov_deg'"},
        {rigOf(R"({"name": "c", "type": "radar"})"), "sensors[0].type = \"radar\" (allowed: \"pinhole\""},
        {rigOf(R"({"type": "lidar"})"), "sensors[0].name is missing"},
        {rigOf(camera() + "," + camera()), "sensors[1].name = \"c\" is used by two sensors"},
        {rigOf(R"({"name": "c", "type": "pinhole", "channels": ["rgb"], "intrinsics": {"width": 0, "height": 48,
              "fx": 50, "fy": 50, "cx": 1, "cy": 1}})"),
         "sensors[0].intrinsics.width = 0 is out of range 1 .. 8192"},
        {rigOf(R"({"name": "c", "type": "pinhole", "channels": ["rgb"], "intrinsics": {"width": 64, "height": 48,
              "fx": -5, "fy": 50, "cx": 1, "cy": 1}})"),
         "sensors[0].intrinsics.fx = -5 is out of range (0, 1000000] (pixels)"},
        {rigOf(R"({"name": "c", "type": "fisheye", "channels": ["rgb"], "intrinsics": {"width": 64, "height": 48,
              "fx": 50, "fy": 50, "cx": 1, "cy": 1, "max_fov_deg": 400}})"),
         "sensors[0].intrinsics.max_fov_deg = 400 is out of range (0, 360] (degrees)"},
        {rigOf(camera(", \"pose\": {\"pitch_deg\": 91}")), "sensors[0].pose.pitch_deg = 91 is out of range [-90, 90]"},
        {rigOf(camera(", \"rate_hz\": 0")), "sensors[0].rate_hz = 0 is out of range (0, 1000]"},
        {rigOf(R"({"name": "c", "type": "pinhole", "channels": ["rgb", "lidar"], "intrinsics": {"width": 64,
              "height": 48, "fx": 50, "fy": 50, "cx": 1, "cy": 1}})"),
         "sensors[0].channels[1] = \"lidar\" is not a channel"},
        {rigOf(R"({"name": "l", "type": "lidar", "beams": {"count": 300, "min_deg": -10, "max_deg": 10}})"),
         "sensors[0].beams.count = 300 is out of range 1 .. 256"},
        {rigOf(R"({"name": "l", "type": "lidar", "beams": [0, 95]})"),
         "sensors[0].beams[1] = 95 is out of range [-90, 90]"},
        {rigOf(R"({"name": "l", "type": "lidar", "beams": [0], "columns": 2.5})"),
         "sensors[0].columns must be a whole number in 1 .. 65536"},
        {rigOf(R"({"name": "l", "type": "lidar", "beams": [0], "rotation_hz": 200})"),
         "sensors[0].rotation_hz = 200 is out of range (0, 100]"},
        {rigOf(R"({"name": "l", "type": "lidar", "beams": [0], "min_range_m": 5, "max_range_m": 2})"),
         "sensors[0].max_range_m = 2 is out of range (5, 10000]"},
        {rigOf(R"({"name": "l", "type": "lidar", "beams": {"count": 256, "min_deg": 0, "max_deg": 1},
              "columns": 65536})"),
         "rays per sweep"},
        {R"({"sensors": [{"name": "a", "name": "b"}]})", "key 'name' appears twice"},
    };
    for (const auto& [text, want] : cases) {
        auto r = parseRigJson(text, "rig.json");
        ASSERT_FALSE(r.isOk()) << text;
        EXPECT_NE(r.status().message().find(want), std::string::npos) << r.status().message() << "\nwant: " << want;
        EXPECT_EQ(r.status().message().rfind("rig.json", 0), 0u) << r.status().message();
    }
    auto missing = loadRigFile("/nonexistent/rig.json");
    ASSERT_FALSE(missing.isOk());
    EXPECT_NE(missing.status().message().find("rig file"), std::string::npos);
}

// A focal length passes (0, 1e6] yet may still be meaningless: fx = 1e-300
// sends every pixel's ray 90 degrees off the axis. The lower bound follows
// from the field of view: a pinhole spans at most 179 degrees (89.5 either side
// of the principal point), a fisheye's edge lies at most 180 degrees off the axis.
TEST(Rig, FocalLengthsHaveAFieldOfViewLowerBound) {
    auto pinhole = [](const std::string& fx, const std::string& fy, const std::string& cx) {
        return rigOf(R"({"name": "c", "type": "pinhole", "channels": ["depth"], "intrinsics": {"width": 64,
              "height": 48, "fx": )" +
                     fx + ", \"fy\": " + fy + ", \"cx\": " + cx + R"(, "cy": 23.5}})");
    };
    // Independent: the farther image edge from cx (pixel centres at integers) over tan(89.5 degrees).
    const double tan895 = std::tan(89.5 * kPi / 180.0);
    const double minCentred = 32.0 / tan895, minOffCentre = (64 - 0.5) / tan895;  // cx = 31.5, cx = 0
    for (const auto& [text, field] : {std::pair{pinhole("1e-300", "50", "31.5"), "fx = 1e-300"},
                                      std::pair{pinhole("50", "1e-300", "31.5"), "fy = 1e-300"},
                                      std::pair{pinhole("0.27", "50", "31.5"), "fx = 0.27"}}) {
        auto r = parseRigJson(text, "rig.json");
        ASSERT_FALSE(r.isOk()) << text;
        const std::string& m = r.status().message();
        EXPECT_NE(m.find(std::string("sensors[0].intrinsics.") + field + " is out of range"), std::string::npos) << m;
        EXPECT_NE(m.find("179 degrees"), std::string::npos) << m;
    }
    char ok[32], low[32];
    std::snprintf(ok, sizeof ok, "%.6f", minCentred * 1.0001);
    std::snprintf(low, sizeof low, "%.6f", minCentred * 0.9999);
    EXPECT_TRUE(parseRigJson(pinhole(ok, "50", "31.5"), "rig.json").isOk()) << ok;
    EXPECT_FALSE(parseRigJson(pinhole(low, "50", "31.5"), "rig.json").isOk()) << low;
    // The bound moves with the principal point: the farther edge decides.
    std::snprintf(ok, sizeof ok, "%.6f", minOffCentre * 1.0001);
    std::snprintf(low, sizeof low, "%.6f", minOffCentre * 0.9999);
    EXPECT_TRUE(parseRigJson(pinhole(ok, "50", "0"), "rig.json").isOk()) << ok;
    EXPECT_FALSE(parseRigJson(pinhole(low, "50", "0"), "rig.json").isOk()) << low;
    // Fisheye: theta = extent / f <= pi.
    auto fisheye = [](double f) {
        char b[64];
        std::snprintf(b, sizeof b, "%.6f", f);
        return rigOf(R"({"name": "f", "type": "fisheye", "channels": ["rgb"], "intrinsics": {"width": 64,
              "height": 48, "fx": )" +
                     std::string(b) + R"(, "fy": 20, "cx": 31.5, "cy": 23.5, "max_fov_deg": 190}})");
    };
    EXPECT_TRUE(parseRigJson(fisheye(32.0 / kPi * 1.0001), "rig.json").isOk());
    auto f = parseRigJson(fisheye(32.0 / kPi * 0.9999), "rig.json");
    ASSERT_FALSE(f.isOk());
    EXPECT_NE(f.status().message().find("360 degrees"), std::string::npos) << f.status().message();
    // An accepted pinhole's corner ray stays in front of the camera.
    auto edge = parseRigJson(pinhole("0.3", "0.3", "31.5"), "rig.json");
    ASSERT_TRUE(edge.isOk()) << edge.status().message();
    glm::dvec3 dir;
    ASSERT_TRUE(edge->cameras[0].model.pixelRay(-0.5, -0.5, dir));
    EXPECT_GT(dir.z, 0.0);
    EXPECT_TRUE(std::isfinite(dir.x) && std::isfinite(dir.y));
}

TEST(Rig, MountRotationFollowsYawPitchRoll) {
    SensorMount m;
    m.yawDeg = 90;  // x turns to the left (vehicle y)
    EXPECT_LT(near(mountRotation(m)[0], {0, 1, 0}), 1e-12);
    m = {};
    m.pitchDeg = 30;  // nose up
    EXPECT_LT(near(mountRotation(m)[0], {std::cos(kPi / 6), 0, std::sin(kPi / 6)}), 1e-12);
    m = {};
    m.rollDeg = 90;  // left side up: y turns to z
    EXPECT_LT(near(mountRotation(m)[1], {0, 0, 1}), 1e-12);
    m.yawDeg = 33, m.pitchDeg = -12, m.rollDeg = 7;
    const glm::dmat3 r = mountRotation(m);
    EXPECT_NEAR(glm::determinant(r), 1.0, 1e-12);
    // The LiDAR angles of any pose give the same axes back (lidarToWorld).
    RigPose v;
    v.position = {10, 20, 3};
    PathSample s;
    s.heading = 2.9, s.pitch = 0.05;
    v = vehiclePose(s);
    const RigPose sp = sensorPose(v, m);
    const glm::dmat3 back = lidarToWorld(lidarPoseOf(sp));
    for (int c = 0; c < 3; ++c) EXPECT_LT(near(back[c], sp.rotation[c]), 1e-12) << c;
}

TEST(Rig, VehiclePoseIsInterpolatedAndClamped) {
    Path path;
    PathSample a, b;
    a.t = 1.0, a.position = {0, 0, 1}, a.heading = kPi - 0.1;
    b.t = 2.0, b.position = {10, 0, 1}, b.heading = -kPi + 0.1;  // across the +-pi seam
    path.samples = {a, b};
    const RigPose mid = vehiclePoseAt(path, 1.25);
    EXPECT_LT(near(mid.position, {2.5, 0, 1}), 1e-12);
    const RigPose want = vehiclePose({0, {}, kPi - 0.05, 0});
    EXPECT_LT(near(mid.rotation[0], want.rotation[0]), 1e-12) << "heading along the shorter arc";
    EXPECT_LT(near(vehiclePoseAt(path, -5).position, a.position), 1e-12);
    EXPECT_LT(near(vehiclePoseAt(path, 9).position, b.position), 1e-12);
    // Sensor position: mount offset turned by the vehicle's heading.
    SensorMount m;
    m.position = {1, 0.5, 0.3};
    const RigPose v = vehiclePose({0, {100, 200, 1}, 0.0, 0.0});  // facing north: x = +y world, y = -x world
    EXPECT_LT(near(sensorPose(v, m).position, {99.5, 201, 1.3}), 1e-12);
}

TEST(Rig, SensorsFireAtTheirRates) {
    std::vector<double> t;
    for (int i = 0; i < 10; ++i) t.push_back(5.0 + i / 30.0);
    const std::vector<uint8_t> every = firingFrames(0, t), tenHz = firingFrames(10, t), fast = firingFrames(100, t);
    EXPECT_EQ(every, std::vector<uint8_t>(10, 1));
    EXPECT_EQ(fast, std::vector<uint8_t>(10, 1));
    EXPECT_EQ(tenHz, (std::vector<uint8_t>{1, 0, 0, 1, 0, 0, 1, 0, 0, 1}));
    EXPECT_EQ(firingFrames(7, t), (std::vector<uint8_t>{1, 0, 0, 0, 0, 1, 0, 0, 0, 0}));
    // Flow looks ahead to the next firing, after the last one to a period later.
    EXPECT_EQ(nextFiringTime(10, tenHz, t, 0, 99), t[3]);
    EXPECT_EQ(nextFiringTime(10, tenHz, t, 4, 99), t[6]);
    EXPECT_NEAR(nextFiringTime(10, tenHz, t, 9, 99), t[9] + 0.1, 1e-12);
    EXPECT_EQ(nextFiringTime(0, every, t, 9, 99), 99.0) << "every frame: the next path sample";
}

TEST(Rig, KittiCalibMapsLidarPointsToThePixelsOfThePoses) {
    auto rig = loadRigFile(std::string(VISTA_SOURCE_DIR) + "/data/rigs/car_4cam_lidar64.json");
    ASSERT_TRUE(rig.isOk());
    const std::string calib = kittiCalib(*rig);
    std::istringstream in(calib);
    std::string line;
    std::map<std::string, std::vector<double>> m;
    while (std::getline(in, line)) {
        std::istringstream l(line);
        std::string key;
        l >> key;
        double v;
        while (l >> v) m[key].push_back(v);
    }
    ASSERT_EQ(m.size(), 7u) << calib;  // P0 .. P3, R0_rect, Tr_velo_to_cam, Tr_imu_to_velo
    for (const char* k : {"P0:", "P1:", "P2:", "P3:", "Tr_velo_to_cam:", "Tr_imu_to_velo:"})
        ASSERT_EQ(m[k].size(), 12u) << k << calib;
    ASSERT_EQ(m["R0_rect:"].size(), 9u) << calib;
    // A point in the LiDAR frame -> reference camera -> rectified -> P1 pixel equals its pixel through the poses.
    const RigPose vehicle = vehiclePose({0, {0, 0, 0}, 0.0, 0.0});
    const RigPose lidar = sensorPose(vehicle, rig->lidars[0].mount);
    const RigPose cam1 = sensorPose(vehicle, rig->cameras[1].mount);
    const glm::dvec3 pl(-12.0, 1.5, -0.7);  // behind the car, seen by the rear camera
    const glm::dvec3 world = lidar.position + lidar.rotation * pl;
    glm::dvec2 want;
    ASSERT_TRUE(projectWorld(rig->cameras[1].model, cam1, world, want));
    const auto& T = m["Tr_velo_to_cam:"];
    const auto& R0 = m["R0_rect:"];
    const auto& P = m["P1:"];
    double c[3], r[3];
    for (int i = 0; i < 3; ++i) c[i] = T[i * 4] * pl.x + T[i * 4 + 1] * pl.y + T[i * 4 + 2] * pl.z + T[i * 4 + 3];
    for (int i = 0; i < 3; ++i) r[i] = R0[i * 3] * c[0] + R0[i * 3 + 1] * c[1] + R0[i * 3 + 2] * c[2];
    double q[3];
    for (int i = 0; i < 3; ++i) q[i] = P[i * 4] * r[0] + P[i * 4 + 1] * r[1] + P[i * 4 + 2] * r[2] + P[i * 4 + 3];
    EXPECT_NEAR(q[0] / q[2], want.x, 1e-6);
    EXPECT_NEAR(q[1] / q[2], want.y, 1e-6);
}

TEST(Rig, KittiRectifiedFrameIsTheFirstCameraLevelled) {
    // Camera 0 pitched and rolled: R0_rect turns its frame into one whose y is the vehicle's down
    // and whose z is camera 0's heading in the vehicle's ground plane.
    auto rig = parseRigJson(R"({"sensors": [
      {"name": "c", "type": "pinhole", "pose": {"x": 1, "yaw_deg": 30, "pitch_deg": -10, "roll_deg": 5},
       "intrinsics": {"width": 64, "height": 48, "fx": 50, "fy": 50, "cx": 31.5, "cy": 23.5}, "channels": ["rgb"]}]})",
                            "rig.json");
    ASSERT_TRUE(rig.isOk()) << rig.status().message();
    const std::string calib = kittiCalib(*rig);
    std::istringstream in(calib);
    std::map<std::string, std::vector<double>> m;
    for (std::string line; std::getline(in, line);) {
        std::istringstream l(line);
        std::string key;
        l >> key;
        for (double v; l >> v;) m[key].push_back(v);
    }
    ASSERT_EQ(m["R0_rect:"].size(), 9u) << calib;
    // Without a LiDAR, Tr_velo_to_cam maps the vehicle frame: its rotation then R0_rect.
    const auto& T = m["Tr_velo_to_cam:"];
    const auto& R0 = m["R0_rect:"];
    auto rectOf = [&](const glm::dvec3& v) {
        double c[3], r[3];
        for (int i = 0; i < 3; ++i) c[i] = T[i * 4] * v.x + T[i * 4 + 1] * v.y + T[i * 4 + 2] * v.z;
        for (int i = 0; i < 3; ++i) r[i] = R0[i * 3] * c[0] + R0[i * 3 + 1] * c[1] + R0[i * 3 + 2] * c[2];
        return glm::dvec3(r[0], r[1], r[2]);
    };
    const glm::dvec3 down = rectOf({0, 0, -1}), ahead = rectOf({std::cos(kPi / 6), std::sin(kPi / 6), 0});
    EXPECT_NEAR(down.x, 0.0, 1e-9);
    EXPECT_NEAR(down.y, 1.0, 1e-9);
    EXPECT_NEAR(down.z, 0.0, 1e-9);
    EXPECT_NEAR(ahead.z, 1.0, 1e-9);
    EXPECT_NEAR(m["P1:"][0], 0.0, 0.0) << "no camera 1: zeros";
}

TEST(Rig, FileLayouts) {
    const float flow[4] = {1.5f, -2.0f, 0.25f, kUnknownFlow};
    const std::string flo = floBytes(flow, 2, 1);
    ASSERT_EQ(flo.size(), 12u + 16u);
    EXPECT_EQ(flo.substr(0, 4), "PIEH");
    int32_t w = 0, h = 0;
    std::memcpy(&w, flo.data() + 4, 4);
    std::memcpy(&h, flo.data() + 8, 4);
    EXPECT_EQ(w, 2);
    EXPECT_EQ(h, 1);
    LidarSweep s;
    LidarPoint p;
    p.sensor = {1, 2, 3};
    p.intensity = 0.5f;
    p.semantic = 14;
    p.instance = (10u << 28) | 7u;
    s.points = {p, p};
    p.time = 0.025f;
    s.points = {p, p};
    const std::string bin = velodyneBytes(s), label = vistaLabelBytes(s), inst = lidarInstanceBytes(s);
    const std::string sk = semanticKittiLabelBytes(s), times = lidarTimeBytes(s);
    ASSERT_EQ(bin.size(), 32u);
    float xyzi[4];
    std::memcpy(xyzi, bin.data() + 16, 16);
    EXPECT_EQ(xyzi[2], 3.0f);
    EXPECT_EQ(xyzi[3], 0.5f);
    uint32_t l = 0, i = 0;
    std::memcpy(&l, label.data(), 4);
    std::memcpy(&i, inst.data() + 4, 4);
    EXPECT_EQ(l, 14u);
    EXPECT_EQ(i, p.instance);
    // SemanticKITTI: car = 10 in the lower 16 bits; the instance ((11 * 7 + 10) mod 65535) + 1 above.
    ASSERT_EQ(sk.size(), 8u);
    std::memcpy(&l, sk.data() + 4, 4);
    EXPECT_EQ(l & 0xFFFFu, 10u);
    EXPECT_EQ(l >> 16, 88u);
    float t = 0;
    ASSERT_EQ(times.size(), 8u);
    std::memcpy(&t, times.data() + 4, 4);
    EXPECT_EQ(t, 0.025f);
    // A road point: class 40, no instance.
    EXPECT_EQ(semanticKittiClass(uint8_t(SemanticClass::Road)), 40u);
    EXPECT_EQ(semanticKittiInstance((3u << 28) | 5u), 0u);
    EXPECT_EQ(semanticKittiClass(200), 0u);
    EXPECT_NE(semanticKittiYaml().find("  10: \"car\""), std::string::npos);
}

// The moving agents' classes in SemanticKITTI's ids (semantic-kitti.yaml of
// the SemanticKITTI API): vans are cars there, a bicycle with its rider a
// bicyclist; every class has a name in the mapping file and agents an instance.
TEST(Rig, AgentClassesMapToSemanticKitti) {
    const std::map<SemanticClass, std::pair<unsigned, std::string>> want = {
        {SemanticClass::Car, {10, "car"}},
        {SemanticClass::Van, {10, "car"}},
        {SemanticClass::Bus, {13, "bus"}},
        {SemanticClass::Truck, {18, "truck"}},
        {SemanticClass::Vehicle, {20, "other-vehicle"}},
        {SemanticClass::Bicycle, {31, "bicyclist"}},
        {SemanticClass::Pedestrian, {30, "person"}}};
    const std::string yaml = semanticKittiYaml();
    for (const auto& [cls, sk] : want) {
        EXPECT_EQ(semanticKittiClass(uint8_t(cls)), sk.first) << semanticClassName(cls);
        EXPECT_NE(yaml.find("  " + std::to_string(sk.first) + ": \"" + sk.second + "\""), std::string::npos)
            << sk.second;
    }
    for (int c = 0; c < kSemanticClassCount; ++c) {
        const unsigned id = semanticKittiClass(uint8_t(c));
        EXPECT_NE(yaml.find("\n  " + std::to_string(id) + ": \""), std::string::npos) << "class " << c;
        EXPECT_STRNE(semanticClassName(SemanticClass(c)), "unknown");
    }
    EXPECT_NE(semanticKittiInstance(makeInstanceId(InstanceKind::Vehicle, 4)), 0u);
    EXPECT_NE(semanticKittiInstance(makeInstanceId(InstanceKind::Pedestrian, 4)), 0u);
    EXPECT_NE(semanticKittiInstance(makeInstanceId(InstanceKind::Vehicle, 4)),
              semanticKittiInstance(makeInstanceId(InstanceKind::Pedestrian, 4)));
}
