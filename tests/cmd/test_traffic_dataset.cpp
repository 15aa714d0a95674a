// The moving agents in a rig dataset (`vista render --rig --traffic`): a
// small city run through SUMO once, an ego path riding one of its cars, a rig
// of two pinhole cameras with depth, instance, flow and boxes. Checked
// against the traffic's floating-car data, computed here independently of
// the writer: the flow of every agent pixel is the agent's own rigid motion
// between the two shots (from its FCD poses) seen by the moving camera,
// within 0.05 px; the boxes carry the agent's class and a velocity that
// agrees with SUMO's speed and heading; the KITTI tracking files name each
// agent by one track id whose tracks.json entry is its SUMO id, and a
// resumed run writes them byte for byte as an uninterrupted one; every LiDAR
// point on an agent lies on that agent's box where the agent is at the
// point's firing time (a slow 2 Hz LiDAR: agents move far during a sweep);
// the traffic-light labels resume byte for byte, and a resume with other
// lamps (signals.xml) is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "citygen/labels.h"
#include "citygen/lighting.h"
#include "runtime/engine/rig.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/paths.h"
#include "runtime/traffic/agent_models.h"
#include "runtime/traffic/traffic_tracks.h"
#include "tests/common/busy_ride.h"
#include "tests/common/npy.h"
#include "tests/common/run_vista.h"
#include "tests/common/sumo_city.h"
#include "tests/common/temp_dir.h"

namespace fs = std::filesystem;
using namespace vista;
using test::loadNpy;
using test::readBytes;
using test::runVista;
using test::TempDir;

namespace {

constexpr int kW = 200, kH = 120;
constexpr double kFx = 110, kFy = 110, kCx = 99.5, kCy = 59.5;
constexpr int kFrames = 20;

const char* const kRig = R"({"sensors": [
  {"name": "front", "type": "pinhole", "rate_hz": 10, "pose": {"x": 0.5, "z": 0.3},
   "intrinsics": {"width": 200, "height": 120, "fx": 110, "fy": 110, "cx": 99.5, "cy": 59.5},
   "channels": ["depth", "instance", "flow", "boxes"]},
  {"name": "rear", "type": "pinhole", "rate_hz": 10, "pose": {"x": -0.5, "z": 0.3, "yaw_deg": 180},
   "intrinsics": {"width": 200, "height": 120, "fx": 110, "fy": 110, "cx": 99.5, "cy": 59.5},
   "channels": ["depth", "instance", "flow", "boxes"]},
  {"name": "lidar", "type": "lidar", "pose": {"z": 0.6}, "beams": {"count": 16, "min_deg": -15, "max_deg": 5},
   "columns": 1440, "max_range_m": 60, "rotation_hz": 2}]})";

// The city, its traffic, a path riding one of its cars and the rig run, made once for the file.
struct Fixture {
    std::string city, traffic, path, rig, out;
    bool ok = false;
};
const Fixture& fixture() {
    static TempDir dir("vista_traffic_dataset");  // lives for the whole run, removed at exit
    static Fixture f;
    if (f.city.empty()) {
        f.city = dir.file("city.osgb");
        f.traffic = dir.file("traffic");
        f.path = dir.file("ego.csv");
        f.out = dir.file("rig");
        f.rig = dir.file("rig.json");
        std::ofstream(f.rig) << kRig;
        auto r = test::genTrafficCity(f.city);
        EXPECT_EQ(r.code, 0) << r.err;
        r = runVista("traffic " + f.city + " --vehicles 300 --pedestrians 30 --duration 120 --seed 4 -q -o " +
                     f.traffic);
        EXPECT_EQ(r.code, 0) << r.err;
        const std::string ride = test::busiestRide(f.traffic, 10.0);
        EXPECT_FALSE(ride.empty()) << "no car of the traffic rides for 10 s";
        r = runVista("path " + f.city + " --traffic " + f.traffic + " --ego " + ride + " --duration 10 --dt 0.1 -o " +
                     f.path);
        EXPECT_EQ(r.code, 0) << r.err;
        r = runVista("render " + f.city + " --path " + f.path + " --rig " + f.rig + " --traffic " + f.traffic +
                     " --frames " + std::to_string(kFrames) + " --sampling consecutive -q --out " + f.out);
        EXPECT_EQ(r.code, 0) << r.err;
        f.ok = r.code == 0;
    }
    return f;
}

// A Middlebury .flo file: its (du, dv) pairs.
std::vector<float> loadFlo(const std::string& path) {
    const std::string b = readBytes(path);
    if (b.size() < 12) return {};
    std::vector<float> v((b.size() - 12) / 4);
    std::memcpy(v.data(), b.data() + 12, v.size() * 4);
    return v;
}

glm::dmat4 matrixOf(const nlohmann::json& rows) {
    glm::dmat4 m(1.0);
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) m[c][r] = rows[r][c].get<double>();
    return m;
}

class TrafficDataset : public ::testing::Test {
protected:
    void SetUp() override {
        VISTA_SKIP_WITHOUT_SUMO();
        if (!fixture().ok) GTEST_FAIL() << "the traffic dataset fixture could not be made";
    }
};

}  // namespace

// Flow at an agent pixel: the surface point (depth image, camera pose of
// rig.json) moved rigidly with its agent from its FCD pose at the shot's time
// to its pose at the next shot's (SUMO's reference point and heading; the
// city is flat), projected by the next camera, minus the pixel.
TEST_F(TrafficDataset, FlowOnAgentsIsTheAgentsOwnMotion) {
    const auto& f = fixture();
    auto tracks = loadTrafficTracks(f.traffic);
    ASSERT_TRUE(tracks) << tracks.status().message();
    const auto rig = nlohmann::json::parse(readBytes(f.out + "/rig.json"));
    const glm::dvec3 offset(rig["world_offset"][0], rig["world_offset"][1], rig["world_offset"][2]);
    const auto& frames = rig["frames"];
    ASSERT_EQ(frames.size(), size_t(kFrames));
    size_t checked = 0, moving = 0, unknown = 0;
    double worst = 0;
    for (int k = 0; k < 2; ++k) {
        const std::string cam = k == 0 ? "front" : "rear", nn = k == 0 ? "00" : "01";
        for (int fr = 0; fr + 1 < kFrames; ++fr) {
            char name[16];
            std::snprintf(name, sizeof name, "%06d", fr);
            const glm::dmat4 c0 = matrixOf(frames[fr]["sensors"][cam]["camera_to_world"]);
            const glm::dmat4 w1 = glm::inverse(matrixOf(frames[fr + 1]["sensors"][cam]["camera_to_world"]));
            const double t0 = frames[fr]["t_s"], t1 = frames[fr + 1]["t_s"];
            const auto ids = loadNpy<uint32_t>(f.out + "/instance_" + nn + "/" + name + ".npy");
            const auto depth = loadNpy<float>(f.out + "/depth_" + nn + "/" + name + ".npy");
            const auto flow = loadFlo(f.out + "/flow_" + nn + "/" + name + ".flo");
            ASSERT_EQ(ids.size(), size_t(kW * kH));
            ASSERT_EQ(depth.size(), ids.size());
            ASSERT_EQ(flow.size(), 2 * ids.size());
            for (int v = 0; v < kH; ++v)
                for (int u = 0; u < kW; ++u) {
                    const size_t i = size_t(v) * kW + size_t(u);
                    const InstanceKind kind = instanceKind(ids[i]);
                    if (kind != InstanceKind::Vehicle && kind != InstanceKind::Pedestrian) continue;
                    const uint32_t agent = instanceIndex(ids[i]);
                    AgentPose a0, a1;
                    ASSERT_TRUE(tracks->poseAt(agent, t0, &a0)) << "agent " << agent << " drawn at " << t0;
                    if (!tracks->poseAt(agent, t1, &a1)) {
                        EXPECT_GT(std::abs(flow[2 * i]), 1e9f) << "agent " << agent << " is gone at " << t1;
                        ++unknown;
                        continue;
                    }
                    const double z = depth[i];
                    const glm::dvec3 p0 = glm::dvec3(c0 * glm::dvec4(z * (u - kCx) / kFx, z * (v - kCy) / kFy, z, 1.0));
                    // The agent's rigid motion: its reference point and heading at both times.
                    const double dh = double(a1.heading) - double(a0.heading), c = std::cos(dh), s = std::sin(dh);
                    const glm::dvec2 r0 = glm::dvec2(p0) + glm::dvec2(offset) - glm::dvec2(a0.x, a0.y);
                    const glm::dvec2 q = glm::dvec2(a1.x, a1.y) + glm::dvec2(c * r0.x - s * r0.y, s * r0.x + c * r0.y) -
                                         glm::dvec2(offset);
                    const glm::dvec3 p1c = glm::dvec3(w1 * glm::dvec4(q, p0.z, 1.0));
                    ASSERT_GT(p1c.z, 0.0);
                    const double du = kFx * p1c.x / p1c.z + kCx - u, dv = kFy * p1c.y / p1c.z + kCy - v;
                    const double err = std::hypot(du - flow[2 * i], dv - flow[2 * i + 1]);
                    worst = std::max(worst, err);
                    ++checked;
                    if (glm::length(glm::dvec2(a1.x - a0.x, a1.y - a0.y)) > 0.05) ++moving;
                }
        }
    }
    EXPECT_GT(moving, 200u) << "agent pixels on agents that moved between the shots";
    EXPECT_LE(worst, 0.05) << "over " << checked << " agent pixels (" << unknown << " of agents gone)";
}

// boxes_3d: every agent box has its class, and a vehicle driving straight
// (its FCD heading the same at both ends of the sample interval around the
// frame's time, the frame 0.05 s or more inside it) the velocity of its FCD
// positions over that interval (a straight vehicle's box centre moves as its
// front bumper), within the files' 1 mm rounding; SUMO's own speed agrees
// within 0.5 m/s.
TEST_F(TrafficDataset, AgentBoxesCarryClassAndVelocity) {
    const auto& f = fixture();
    auto tracks = loadTrafficTracks(f.traffic);
    ASSERT_TRUE(tracks) << tracks.status().message();
    const std::map<AgentType, std::string> kClass = {
        {AgentType::Car, "car"},     {AgentType::Van, "van"},         {AgentType::Bus, "bus"},
        {AgentType::Truck, "truck"}, {AgentType::Bicycle, "bicycle"}, {AgentType::Pedestrian, "pedestrian"}};
    size_t straight = 0, agents = 0;
    for (int fr = 0; fr < kFrames; ++fr) {
        char name[16];
        std::snprintf(name, sizeof name, "%06d", fr);
        const auto doc = nlohmann::json::parse(readBytes(f.out + "/boxes_3d/" + name + ".json"));
        const double t = doc["t_s"];
        for (const auto& b : doc["boxes"]) {
            const std::string kind = b["kind"];
            if (kind != "vehicle" && kind != "pedestrian") {
                EXPECT_EQ(b["world"]["velocity"], nlohmann::json({0.0, 0.0, 0.0}));
                continue;
            }
            ++agents;
            const uint32_t agent = b["index"];
            ASSERT_LT(agent, tracks->agentTypes.size());
            EXPECT_EQ(b["class"], kClass.at(tracks->agentTypes[agent]));
            if (kind != "vehicle") continue;
            // The sample interval holding t and the poses at its ends.
            const size_t k = tracks->frameAt(t);
            if (k + 1 >= tracks->frames()) continue;
            AgentPose a, e;
            if (!tracks->poseAt(agent, tracks->times[k], &a) || !tracks->poseAt(agent, tracks->times[k + 1], &e))
                continue;
            const double t0 = tracks->times[k], t1 = tracks->times[k + 1];
            if (e.heading != a.heading || t - t0 < 0.05 || t1 - t < 0.05) continue;
            ++straight;
            const glm::dvec2 vel(b["world"]["velocity"][0].get<double>(), b["world"]["velocity"][1].get<double>());
            const glm::dvec2 want = glm::dvec2(e.x - a.x, e.y - a.y) / (t1 - t0);
            EXPECT_LE(glm::length(vel - want), 0.002) << "agent " << agent << " at " << t;
            EXPECT_NEAR(glm::length(vel), e.speed, 0.5) << "agent " << agent << " at " << t;
        }
    }
    EXPECT_GT(agents, 0u);
    EXPECT_GT(straight, 0u) << "vehicles driving straight";
}

// A run killed after 7 frames and resumed writes the tracking files of the
// uninterrupted run byte for byte (they are rebuilt from every frame's labels).
TEST_F(TrafficDataset, ResumedRunWritesTheSameTrackingFiles) {
    const auto& f = fixture();
    TempDir tmp("vista_traffic_dataset_resume");
    const std::string out = tmp.file("rig");
    const std::string args = "render " + f.city + " --path " + f.path + " --rig " + f.rig + " --traffic " + f.traffic +
                             " --frames " + std::to_string(kFrames) + " --sampling consecutive -q --out " + out;
    auto r = runVista(args, "VISTA_RENDER_KILL_AFTER_FRAMES=7");
    ASSERT_NE(r.code, 0) << "the run kills itself after 7 frames";
    ASSERT_FALSE(fs::exists(out));
    r = runVista(args);
    ASSERT_EQ(r.code, 0) << r.err;
    for (const std::string rel : {"tracking/label_00/0000.txt", "tracking/label_01/0000.txt", "tracking/tracks.json"})
        EXPECT_EQ(readBytes(out + "/" + rel), readBytes(f.out + "/" + rel)) << rel;
    EXPECT_FALSE(readBytes(out + "/tracking/label_00/0000.txt").empty());
    // The traffic-light labels of every frame and camera, too.
    for (const std::string nn : {"00", "01"})
        for (int fr = 0; fr < kFrames; ++fr) {
            char name[40];
            std::snprintf(name, sizeof name, "traffic_lights_%s/%06d.txt", nn.c_str(), fr);
            ASSERT_TRUE(fs::exists(out + "/" + name)) << name;
            EXPECT_EQ(readBytes(out + "/" + name), readBytes(f.out + "/" + name)) << name;
        }
}

// The lamps decide the traffic-light labels: a run resumed with a traffic
// directory whose signals.xml changed is refused, naming traffic_hash.
TEST_F(TrafficDataset, AResumeWithOtherLampsIsRefused) {
    const auto& f = fixture();
    TempDir tmp("vista_traffic_dataset_lamps");
    const std::string traffic = tmp.file("traffic"), out = tmp.file("rig");
    fs::copy(f.traffic, traffic, fs::copy_options::recursive);
    const std::string args = "render " + f.city + " --path " + f.path + " --rig " + f.rig + " --traffic " + traffic +
                             " --frames " + std::to_string(kFrames) + " --sampling consecutive -q --out " + out;
    auto r = runVista(args, "VISTA_RENDER_KILL_AFTER_FRAMES=3");
    ASSERT_NE(r.code, 0) << "the run kills itself after 3 frames";
    // One link of the first recorded state switched between green and red.
    std::string signals = readBytes(traffic + "/signals.xml");
    const size_t at = signals.find("state=\"");
    ASSERT_NE(at, std::string::npos);
    char& letter = signals[at + 7];
    letter = letter == 'G' ? 'r' : 'G';
    std::ofstream(traffic + "/signals.xml", std::ios::binary | std::ios::trunc) << signals;
    r = runVista(args);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("traffic_hash"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
}

// tracking/label_NN/0000.txt: KITTI tracking lines (17 columns, integer
// truncation level); every agent line of label_NN/ is there with the agent's
// number as track id, and tracks.json names its SUMO id and class.
TEST_F(TrafficDataset, TrackingFilesNameEveryAgentByItsSumoId) {
    const auto& f = fixture();
    auto tracks = loadTrafficTracks(f.traffic);
    ASSERT_TRUE(tracks) << tracks.status().message();
    const auto tj = nlohmann::json::parse(readBytes(f.out + "/tracking/tracks.json"));
    EXPECT_EQ(tj["format"], "vista.tracks");
    ASSERT_EQ(tj["tracks"].size(), tracks->agentIds.size());
    for (size_t a = 0; a < tracks->agentIds.size(); ++a) {
        EXPECT_EQ(tj["tracks"][a]["track_id"], a);
        EXPECT_EQ(tj["tracks"][a]["sumo_id"], tracks->agentIds[a]);
    }
    for (const std::string nn : {"00", "01"}) {
        std::set<std::string> want, got;
        for (int fr = 0; fr < kFrames; ++fr) {
            char name[16];
            std::snprintf(name, sizeof name, "%06d", fr);
            std::istringstream in(readBytes(f.out + "/label_" + nn + "/" + name + ".txt"));
            for (std::string line; std::getline(in, line);) {
                std::istringstream cols(line);
                std::vector<std::string> c;
                for (std::string w; cols >> w;) c.push_back(w);
                ASSERT_EQ(c.size(), 16u) << line;
                const uint32_t id = uint32_t(std::stoul(c[15]));
                const InstanceKind kind = instanceKind(id);
                if (kind != InstanceKind::Vehicle && kind != InstanceKind::Pedestrian) continue;
                // Frame, track, type, the truncation level, then the columns from occluded on.
                const double share = std::stod(c[1]);
                std::string w = std::to_string(fr) + " " + std::to_string(instanceIndex(id)) + " " + c[0] + " " +
                                (share < 0.01  ? "0"
                                 : share < 0.5 ? "1"
                                               : "2");
                for (size_t i = 2; i < 15; ++i) w += " " + c[i];
                want.insert(w);
            }
        }
        std::istringstream in(readBytes(f.out + "/tracking/label_" + nn + "/0000.txt"));
        for (std::string line; std::getline(in, line);) got.insert(line);
        EXPECT_EQ(got, want) << "camera " << nn;
        EXPECT_FALSE(want.empty()) << "camera " << nn << " labels no agent";
    }
}

// LiDAR points on agents: back in the world through the sensor's pose at each
// point's firing time (the path's pose, the mount z = 0.6 m), they lie on the
// model box of their agent placed from its FCD pose at that same time (SUMO's
// front bumper half a model length ahead of the box centre) within 5 cm.
TEST_F(TrafficDataset, LidarSeesEachAgentWhereItIsWhenTheColumnFires) {
    const auto& f = fixture();
    auto tracks = loadTrafficTracks(f.traffic);
    ASSERT_TRUE(tracks) << tracks.status().message();
    auto city = loadCityFile(f.city);
    ASSERT_TRUE(city) << city.status().message();
    auto path = loadPathCsv(f.path);
    ASSERT_TRUE(path) << path.status().message();
    const AgentModels models = agentModels(Lighting(city->params));
    const auto rig = nlohmann::json::parse(readBytes(f.out + "/rig.json"));
    SensorMount mount;
    mount.position = {0.0, 0.0, 0.6};
    size_t points = 0, off = 0, moved = 0;
    double worst = 0;
    for (const auto& fr : rig["frames"]) {
        const std::string name = fr["name"];
        const double t0 = fr["t_s"];
        const std::string xyz = readBytes(f.out + "/velodyne/" + name + ".bin"),
                          ids = readBytes(f.out + "/lidar_instance/" + name + ".bin"),
                          times = readBytes(f.out + "/velodyne_time/" + name + ".bin");
        const size_t n = ids.size() / 4;
        ASSERT_EQ(xyz.size(), 16 * n);
        ASSERT_EQ(times.size(), 4 * n);
        for (size_t i = 0; i < n; ++i) {
            uint32_t id;
            float p[3], dt;
            std::memcpy(&id, ids.data() + 4 * i, 4);
            const InstanceKind kind = instanceKind(id);
            if (kind != InstanceKind::Vehicle && kind != InstanceKind::Pedestrian) continue;
            std::memcpy(p, xyz.data() + 16 * i, 12);
            std::memcpy(&dt, times.data() + 4 * i, 4);
            const RigPose s = sensorPose(vehiclePoseAt(*path, t0 + dt), mount);
            const glm::dvec3 w = s.position + s.rotation * glm::dvec3(p[0], p[1], p[2]);
            const uint32_t agent = instanceIndex(id);
            ASSERT_LT(agent, tracks->agentTypes.size());
            const AgentType type = tracks->agentTypes[agent];
            const AgentModel& m = models.models[agentPrototype(models, type, agent)];
            AgentPose start, at;
            if (tracks->poseAt(agent, t0, &start) && tracks->poseAt(agent, t0 + dt, &at) &&
                std::hypot(at.x - start.x, at.y - start.y) > 0.1)
                ++moved;
            // The distance outside the agent's box at time t (0 inside).
            auto outside = [&](double t) {
                AgentPose a;
                if (!tracks->poseAt(agent, t, &a)) return 1e9;
                const glm::dvec2 dir(std::cos(a.heading), std::sin(a.heading)), left(-dir.y, dir.x);
                glm::dvec2 c(a.x, a.y);
                if (type != AgentType::Pedestrian) c -= 0.5 * m.length * dir;
                const glm::dvec2 d = glm::dvec2(w) - c;
                return std::max(
                    {std::abs(glm::dot(d, dir)) - 0.5 * m.length, std::abs(glm::dot(d, left)) - 0.5 * m.width, 0.0});
            };
            const double e = outside(t0 + dt);
            worst = std::max(worst, e);
            ++points;
            off += e > 0.05;
        }
    }
    EXPECT_GT(points, 50u);
    EXPECT_EQ(off, 0u) << "of " << points << " agent points off their agent's box at their firing time (worst " << worst
                       << " m)";
    EXPECT_GT(moved, 25u) << "points on agents that moved over 10 cm since the sweep's start";
}
