// `vista render --rig` through the CLI on a small generated city: every
// sensor writes its files at its own rate in the KITTI-style layout
// (image_NN/, velodyne/, labels/, calib.txt, times.txt) with rig.json and
// summary.json (per-sensor costs and their stages, sensors fired per frame,
// LiDAR misses counted, rig frames per
// second); a fisheye depth pixel equals an independent ray's distance; bad
// rig files and flags that do not apply exit with code 2 naming the field,
// with nothing written; the boxes channel writes per firing the 2D boxes
// (equal to the instance image's extents), KITTI label lines for pinhole
// cameras, and per frame the 3D boxes in the world and vehicle frames (the
// world boxes through the inverse of rig.json's vehicle_to_world). (The
// resume after kill -9: test_ground_truth.cpp, RigResumesAfterKillByteIdentical.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <algorithm>
#include <array>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "runtime/engine/ray_scene.h"
#include "runtime/engine/rig.h"
#include "runtime/scene/city_file.h"
#include "tests/common/run_vista.h"
#include "tests/common/temp_dir.h"

namespace vista {
namespace {

namespace fs = std::filesystem;
using test::runVista;
using test::TempDir;

const char* const kRig = R"({"sensors": [
  {"name": "front", "type": "pinhole", "rate_hz": 10, "pose": {"x": 0.3, "z": 0.4},
   "intrinsics": {"width": 64, "height": 48, "fx": 50, "fy": 50, "cx": 31.5, "cy": 23.5},
   "channels": ["rgb", "depth", "semantic", "instance", "flow"]},
  {"name": "left", "type": "fisheye", "pose": {"yaw_deg": 90, "pitch_deg": -10},
   "intrinsics": {"width": 48, "height": 40, "fx": 14, "fy": 14, "cx": 23.5, "cy": 19.5, "max_fov_deg": 190},
   "channels": ["depth"]},
  {"name": "top", "type": "lidar", "pose": {"z": 0.5}, "beams": {"count": 16, "min_deg": -15, "max_deg": 15},
   "columns": 360, "max_range_m": 60}
]})";

class RigRender : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        dir = new TempDir("vista_rig");
        city = dir->file("city.osgb");
        pathCsv = dir->file("path.csv");
        rig = dir->file("rig.json");
        std::ofstream(rig) << kRig;
        ASSERT_EQ(runVista("gen --size 400 --seed 11 -q -o " + city).code, 0);
        ASSERT_EQ(runVista("path " + city + " --seed 2 --duration 3 -o " + pathCsv).code, 0);
    }
    static void TearDownTestSuite() {
        delete dir;
        dir = nullptr;
    }
    static TempDir* dir;
    static std::string city, pathCsv, rig;
};
TempDir* RigRender::dir = nullptr;
std::string RigRender::city, RigRender::pathCsv, RigRender::rig;

TEST_F(RigRender, SensorsWriteAtTheirRatesInTheKittiLayout) {
    const std::string out = dir->file("run");
    const auto r = runVista("render " + city + " --path " + pathCsv +
                            " --frames 7 --sampling consecutive -q --stats --rig " + rig + " --out " + out);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("rig frames per second"), std::string::npos) << "--stats on stderr: " << r.err;
    // Path samples 1/30 s apart: the 10 Hz sensors fire at frames 0, 3, 6; the fisheye at every frame.
    for (int f = 0; f < 7; ++f) {
        char name[16];
        std::snprintf(name, sizeof name, "%06d", f);
        const bool tenHz = f % 3 == 0;
        EXPECT_EQ(fs::exists(out + "/image_00/" + name + ".png"), tenHz) << name;
        EXPECT_EQ(fs::exists(out + "/flow_00/" + name + ".flo"), tenHz) << name;
        EXPECT_EQ(fs::exists(out + "/velodyne/" + name + ".bin"), tenHz) << name;
        EXPECT_TRUE(fs::exists(out + "/depth_01/" + name + ".npy")) << name;
        EXPECT_FALSE(fs::exists(out + "/image_01")) << "channels nobody asked for are not written";
        if (!tenHz) continue;
        const std::string bin = test::readBytes(out + "/velodyne/" + name + ".bin");
        const std::string label = test::readBytes(out + "/labels/" + name + ".label");
        EXPECT_GT(bin.size(), 0u);
        EXPECT_EQ(bin.size() % 16, 0u);
        EXPECT_EQ(label.size() * 4, bin.size()) << "one label per point";
        EXPECT_EQ(test::readBytes(out + "/lidar_instance/" + name + ".bin").size(), label.size());
        EXPECT_EQ(test::readBytes(out + "/labels_vista/" + name + ".label").size(), label.size());
        EXPECT_EQ(test::readBytes(out + "/velodyne_time/" + name + ".bin").size(), label.size()) << "a time per point";
        const std::string flo = test::readBytes(out + "/flow_00/" + name + ".flo");
        EXPECT_EQ(flo.size(), 12u + 64u * 48u * 8u);
        EXPECT_EQ(flo.substr(0, 4), "PIEH");
    }
    for (const char* f : {"calib.txt", "times.txt", "classes.json", "semantic-kitti.yaml", "rig.json", "summary.json"})
        EXPECT_TRUE(fs::exists(out + "/" + f)) << f;
    const std::string calib = test::readBytes(out + "/calib.txt");
    // KITTI's seven lines in mmdetection3d's order; the fisheye's P1 is its pinhole equivalent, P2 and P3
    // (no such cameras) are zeros.
    std::vector<std::string> keys;
    std::istringstream lines(calib);
    for (std::string l; std::getline(lines, l);) keys.push_back(l.substr(0, l.find(':')));
    EXPECT_EQ(keys, (std::vector<std::string>{"P0", "P1", "P2", "P3", "R0_rect", "Tr_velo_to_cam", "Tr_imu_to_velo"}))
        << calib;
    EXPECT_NE(calib.find("P2: 0.000000000000e+00 0.000000000000e+00"), std::string::npos) << calib;
    const auto summary = nlohmann::json::parse(test::readBytes(out + "/summary.json"));
    EXPECT_EQ(summary["sensors"]["front"]["firings"].get<int>(), 3);
    EXPECT_EQ(summary["sensors"]["left"]["firings"].get<int>(), 7);
    const auto& top = summary["sensors"]["top"];
    EXPECT_EQ(top["points"].get<uint64_t>() + top["misses"].get<uint64_t>(), 3u * 16u * 360u);
    EXPECT_GT(top["misses"].get<uint64_t>(), 0u) << "upward beams see sky: misses counted, not written";
    EXPECT_GT(summary["rig_frames_per_second"].get<double>(), 0.0);
    // The frames' files are written by the file writers: a frame's end waits for them, and says how long.
    ASSERT_TRUE(summary.contains("io_wait_median_ms") && summary["io_wait_median_ms"].is_number()) << summary.dump();
    EXPECT_GE(summary["io_wait_median_ms"].get<double>(), 0.0);
    const auto manifest = nlohmann::json::parse(test::readBytes(out + "/rig.json"));
    ASSERT_EQ(manifest["frames"].size(), 7u);
    EXPECT_TRUE(manifest["frames"][3]["sensors"].contains("top"));
    EXPECT_FALSE(manifest["frames"][4]["sensors"].contains("top"));
    // Sensors fired per frame: the mean count of rig.json's per-frame sensors; every sensor has the
    // median of each stage (cast, write, boxes), none above the sensor's total time over its firings.
    double fired = 0;
    for (const auto& fr : manifest["frames"]) fired += double(fr["sensors"].size());
    EXPECT_NEAR(summary["sensors_fired_per_frame"].get<double>(), fired / 7.0, 1e-9);
    for (const char* sensor : {"front", "left", "top"}) {
        const auto& st = summary["sensors"][sensor]["stage_median_ms"];
        for (const char* stage : {"cast", "write", "boxes"}) {
            ASSERT_TRUE(st.contains(stage) && st[stage].is_number()) << sensor << " " << stage;
            EXPECT_GE(st[stage].get<double>(), 0.0);
            const auto& sum = summary["sensors"][sensor];
            EXPECT_LE(st[stage].get<double>(), sum["mean_ms"].get<double>() * sum["firings"].get<double>() + 1e-9);
        }
        EXPECT_GT(st["cast"].get<double>(), 0.0) << sensor;
    }

    // A fisheye depth pixel is the distance of an independent ray through it.
    auto model = loadCityFile(city);
    ASSERT_TRUE(bool(model));
    auto rays = RayScene::build(*model);
    ASSERT_TRUE(bool(rays));
    const auto& T = manifest["frames"][2]["sensors"]["left"]["camera_to_world"];
    const glm::dvec3 offset(manifest["world_offset"][0].get<double>(), manifest["world_offset"][1].get<double>(), 0);
    const glm::dvec3 eye = offset + glm::dvec3(T[0][3].get<double>(), T[1][3].get<double>(), T[2][3].get<double>());
    const std::string npy = test::readBytes(out + "/depth_01/000002.npy");
    const size_t header = 10 + (uint8_t(npy[8]) | size_t(uint8_t(npy[9])) << 8);
    ASSERT_EQ(npy.size(), header + 48u * 40u * 4u);
    int checked = 0;
    for (int v = 0; v < 40; v += 3)
        for (int u = 0; u < 48; u += 3) {
            const double x = (u - 23.5) / 14.0, y = (v - 19.5) / 14.0, th = std::hypot(x, y);
            if (th > 95.0 * M_PI / 180.0 || th == 0) continue;
            const glm::dvec3 c(std::sin(th) * x / th, std::sin(th) * y / th, std::cos(th));
            glm::dvec3 d;
            for (int i = 0; i < 3; ++i)
                d[i] = T[i][0].get<double>() * c.x + T[i][1].get<double>() * c.y + T[i][2].get<double>() * c.z;
            const RayHit h = (*rays)->intersect(glm::vec3(eye - (*rays)->frameOrigin()), glm::vec3(d));
            float depth;
            std::memcpy(&depth, npy.data() + header + (size_t(v) * 48 + size_t(u)) * 4, 4);
            if (!h.hit) {
                EXPECT_TRUE(std::isinf(depth)) << u << "," << v;
                continue;
            }
            ++checked;
            EXPECT_NEAR(depth, h.t, 0.01) << u << "," << v;
        }
    EXPECT_GT(checked, 50);
}

// uint32 (height, width) from a .npy file's bytes.
std::vector<uint32_t> npyU32(const std::string& npy, size_t count) {
    const size_t header = 10 + (uint8_t(npy[8]) | size_t(uint8_t(npy[9])) << 8);
    std::vector<uint32_t> v(count);
    if (npy.size() == header + count * 4) std::memcpy(v.data(), npy.data() + header, count * 4);
    return v;
}

TEST_F(RigRender, BoxesChannelWritesTwoDBoxesKittiLabelsAndVehicleFrameBoxes) {
    const std::string boxRig = dir->file("boxes_rig.json");
    std::ofstream(boxRig) << R"({"sensors": [
  {"name": "front", "type": "pinhole", "rate_hz": 15, "pose": {"x": 0.3, "z": 0.4},
   "intrinsics": {"width": 96, "height": 64, "fx": 70, "fy": 55, "cx": 40.25, "cy": 35.5},
   "channels": ["instance", "boxes"]},
  {"name": "left", "type": "fisheye", "pose": {"yaw_deg": 90, "pitch_deg": -10},
   "intrinsics": {"width": 48, "height": 40, "fx": 14, "fy": 14, "cx": 23.5, "cy": 19.5, "max_fov_deg": 190},
   "channels": ["boxes"]},
  {"name": "top", "type": "lidar", "pose": {"z": 0.5}, "beams": {"count": 16, "min_deg": -15, "max_deg": 15},
   "columns": 360, "max_range_m": 60}
]})";
    const std::string out = dir->file("boxes_run");
    const auto r = runVista("render " + city + " --path " + pathCsv + " --frames 4 --sampling consecutive -q --rig " +
                            boxRig + " --out " + out);
    ASSERT_EQ(r.code, 0) << r.err;
    const auto manifest = nlohmann::json::parse(test::readBytes(out + "/rig.json"));
    EXPECT_EQ(manifest["boxes_3d"], "boxes_3d");
    // Samples 1/30 s apart: the pinhole (15 Hz) fires at frames 0 and 2, the LiDAR (10 Hz) at 0 and 3, the fisheye at
    // every frame.
    for (int f = 0; f < 4; ++f) {
        char name[16];
        std::snprintf(name, sizeof name, "%06d", f);
        EXPECT_EQ(fs::exists(out + "/boxes_00/" + name + ".json"), f % 2 == 0) << name;
        EXPECT_EQ(fs::exists(out + "/label_00/" + name + ".txt"), f % 2 == 0) << name;
        EXPECT_TRUE(fs::exists(out + "/boxes_01/" + name + ".json")) << name;
        EXPECT_TRUE(fs::exists(out + "/boxes_3d/" + name + ".json")) << name;
    }
    EXPECT_FALSE(fs::exists(out + "/label_01")) << "no KITTI lines for a fisheye";
    EXPECT_FALSE(fs::exists(out + "/instance_01")) << "the instance image of boxes is not written unless asked";

    // The 2D boxes: the extents of the instance image, counted here; one KITTI line per box.
    const auto b2 = nlohmann::json::parse(test::readBytes(out + "/boxes_00/000000.json"));
    EXPECT_EQ(b2["camera_name"], "front");
    EXPECT_EQ(b2["model"], "pinhole");
    EXPECT_DOUBLE_EQ(b2["fy"].get<double>(), 55.0);
    EXPECT_DOUBLE_EQ(b2["cx"].get<double>(), 40.25);
    const std::vector<uint32_t> ids = npyU32(test::readBytes(out + "/instance_00/000000.npy"), 96 * 64);
    std::map<uint32_t, std::array<int, 5>> ext;  // u0, v0, u1, v1, pixels
    for (int v = 0; v < 64; ++v)
        for (int u = 0; u < 96; ++u) {
            const uint32_t id = ids[size_t(v) * 96 + size_t(u)];
            const uint32_t kind = id >> 28;
            if (!(kind == 1 || kind == 2 || (kind >= 7 && kind <= 10))) continue;  // object kinds
            auto it = ext.emplace(id, std::array<int, 5>{u, v, u, v, 0}).first;
            auto& e = it->second;
            e[0] = std::min(e[0], u), e[1] = std::min(e[1], v), e[2] = std::max(e[2], u), e[3] = std::max(e[3], v);
            ++e[4];
        }
    ASSERT_EQ(b2["boxes"].size(), ext.size());
    ASSERT_GT(ext.size(), 0u);
    std::set<uint32_t> frontIds;
    for (const auto& b : b2["boxes"]) {
        const auto& e = ext.at(b["id"].get<uint32_t>());
        EXPECT_EQ(b["visible"], nlohmann::json({e[0], e[1], e[2], e[3]}));
        EXPECT_EQ(b["pixels"].get<int>(), e[4]);
        frontIds.insert(b["id"].get<uint32_t>());
    }
    const std::string labels = test::readBytes(out + "/label_00/000000.txt");
    EXPECT_EQ(size_t(std::count(labels.begin(), labels.end(), '\n')), ext.size());
    const auto fish = nlohmann::json::parse(test::readBytes(out + "/boxes_01/000000.json"));
    EXPECT_EQ(fish["model"], "fisheye");
    EXPECT_EQ(fish["camera_name"], "left");

    // The 3D boxes of frame 0: every instance the front camera boxed, seen_by naming it; the vehicle
    // frame is the world box through the inverse of rig.json's vehicle_to_world.
    const auto b3 = nlohmann::json::parse(test::readBytes(out + "/boxes_3d/000000.json"));
    EXPECT_EQ(b3["format"], "vista.boxes_3d");
    const auto& M = manifest["frames"][0]["vehicle_to_world"];
    EXPECT_EQ(b3["vehicle_to_world"], M);
    glm::dmat3 R;
    glm::dvec3 t;
    for (int i = 0; i < 3; ++i) {
        for (int k = 0; k < 3; ++k) R[k][i] = M[i][k].get<double>();
        t[i] = M[i][3].get<double>();
    }
    size_t fromFront = 0, fromLidar = 0;
    for (const auto& b : b3["boxes"]) {
        const std::vector<std::string> by = b["seen_by"];
        const bool front = std::find(by.begin(), by.end(), "front") != by.end();
        EXPECT_EQ(front, frontIds.count(b["id"].get<uint32_t>()) == 1);
        fromFront += front ? 1 : 0;
        fromLidar += b["lidar_points"].get<uint64_t>() > 0 ? 1 : 0;
        glm::dvec3 w, v;
        for (int i = 0; i < 3; ++i) {
            w[i] = b["world"]["center"][size_t(i)].get<double>();
            v[i] = b["vehicle"]["center"][size_t(i)].get<double>();
        }
        const glm::dvec3 expect = glm::transpose(R) * (w - t);
        for (int i = 0; i < 3; ++i) EXPECT_NEAR(v[i], expect[i], 2e-3);
        const double yaw = b["world"]["yaw"].get<double>();
        const glm::dvec3 axis = glm::transpose(R) * glm::dvec3(std::cos(yaw), std::sin(yaw), 0.0);
        const double vy = b["vehicle"]["yaw"].get<double>();
        EXPECT_NEAR(std::sin(2 * vy), std::sin(2 * std::atan2(axis.y, axis.x)), 3e-3) << "yaw modulo a half turn";
        EXPECT_EQ(b["vehicle"]["size"], b["world"]["size"]);
    }
    EXPECT_EQ(fromFront, frontIds.size());
    EXPECT_GT(fromLidar, 0u);
    const auto b3odd = nlohmann::json::parse(test::readBytes(out + "/boxes_3d/000001.json"));
    for (const auto& b : b3odd["boxes"]) EXPECT_EQ(b["seen_by"], nlohmann::json({"left"})) << "the fisheye alone fired";
}

TEST_F(RigRender, BadRigsExitTwoNamingTheFieldAndWriteNothing) {
    const std::string bad = dir->file("bad.json");
    std::string text = kRig;
    text.replace(text.find("\"columns\": 360"), 14, "\"columns\": 0");
    std::ofstream(bad) << text;
    const std::string out = dir->file("bad_out");
    auto r = runVista("render " + city + " --path " + pathCsv + " --frames 2 -q --rig " + bad + " --out " + out);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("sensors[2].columns = 0 is out of range 1 .. 65536"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
    EXPECT_FALSE(fs::exists(out + ".partial"));
    r = runVista("render " + city + " --path " + pathCsv + " --frames 2 -q --size 64x48 --rig " + rig + " --out " +
                 out);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--size does not apply with --rig"), std::string::npos) << r.err;
    r = runVista("render " + city + " --path " + pathCsv + " --frames 2 -q --rig " + dir->file("none.json") +
                 " --out " + out);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--rig: rig file"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
    EXPECT_FALSE(fs::exists(out + ".partial"));
    for (const auto& [channels, message] :
         {std::pair<std::string, std::string>{R"(["boxes", "boxes"])",
                                              "sensors[1].channels[1] = \"boxes\" is given twice"},
          {R"(["box"])",
           "sensors[1].channels[0] = \"box\" is not a channel (rgb, depth, semantic, instance, flow, boxes)"}}) {
        text = kRig;
        text.replace(text.find(R"(["depth"])"), 9, channels);
        std::ofstream(bad) << text;
        r = runVista("render " + city + " --path " + pathCsv + " --frames 2 -q --rig " + bad + " --out " + out);
        EXPECT_EQ(r.code, 2);
        EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(out));
        EXPECT_FALSE(fs::exists(out + ".partial"));
    }
}

}  // namespace
}  // namespace vista
