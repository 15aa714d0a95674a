// `vista render --rig` through the CLI on a small generated city: every
// sensor writes its files at its own rate in the KITTI-style layout
// (image_NN/, velodyne/, labels/, calib.txt, times.txt) with rig.json and
// summary.json (per-sensor costs, LiDAR misses counted, rig frames per
// second); a fisheye depth pixel equals an independent ray's distance; bad
// rig files and flags that do not apply exit with code 2 naming the field,
// with nothing written. (The resume after kill -9: test_ground_truth.cpp,
// RigResumesAfterKillByteIdentical.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

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
        const std::string flo = test::readBytes(out + "/flow_00/" + name + ".flo");
        EXPECT_EQ(flo.size(), 12u + 64u * 48u * 8u);
        EXPECT_EQ(flo.substr(0, 4), "PIEH");
    }
    for (const char* f : {"calib.txt", "times.txt", "classes.json", "rig.json", "summary.json"})
        EXPECT_TRUE(fs::exists(out + "/" + f)) << f;
    const std::string calib = test::readBytes(out + "/calib.txt");
    EXPECT_EQ(calib.rfind("P0: ", 0), 0u) << calib;
    EXPECT_NE(calib.find("Tr_velo_to_cam: "), std::string::npos);
    EXPECT_EQ(calib.find("P1:"), std::string::npos) << "no P line for a fisheye";
    const auto summary = nlohmann::json::parse(test::readBytes(out + "/summary.json"));
    EXPECT_EQ(summary["sensors"]["front"]["firings"].get<int>(), 3);
    EXPECT_EQ(summary["sensors"]["left"]["firings"].get<int>(), 7);
    const auto& top = summary["sensors"]["top"];
    EXPECT_EQ(top["points"].get<uint64_t>() + top["misses"].get<uint64_t>(), 3u * 16u * 360u);
    EXPECT_GT(top["misses"].get<uint64_t>(), 0u) << "upward beams see sky: misses counted, not written";
    EXPECT_GT(summary["rig_frames_per_second"].get<double>(), 0.0);
    const auto manifest = nlohmann::json::parse(test::readBytes(out + "/rig.json"));
    ASSERT_EQ(manifest["frames"].size(), 7u);
    EXPECT_TRUE(manifest["frames"][3]["sensors"].contains("top"));
    EXPECT_FALSE(manifest["frames"][4]["sensors"].contains("top"));

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
}

}  // namespace
}  // namespace vista
