// Traffic drawn in the walkthrough commands (--traffic): a small city run
// through SUMO once, an ego path riding one of its cars, then `vista render`
// with the traffic: every pixel labelled vehicle or pedestrian lies on the
// model box of an agent present at that frame's time (back-projected from its
// depth), the hybrid's ray-cast far field shows agents beyond the split, rig
// cameras and LiDAR see them, a streamed paged city draws the same agent
// pixels as the city file, bench's ray-cast frames match full where agents
// are, frames without agents are the bytes of a run without --traffic,
// traffic-light heads show SUMO's lamp, and bad traffic directories are
// refused with exit 2 naming --traffic.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "citygen/labels.h"
#include "citygen/lighting.h"
#include "citygen/terrain.h"
#include "citygen/traffic_signals.h"
#include "nodes/render/signal_heads.h"
#include "runtime/engine/image.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/paths.h"
#include "runtime/traffic/agent_models.h"
#include "runtime/traffic/signal_states.h"
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

constexpr int kW = 320, kH = 200;

// The city, its traffic and a path riding one of its cars, made once for the file.
struct Fixture {
    std::string city, traffic, path, ego;  // ego: the SUMO id of the vehicle the path rides
    bool ok = false;
};
const Fixture& fixture() {
    static TempDir dir("vista_traffic_draw");  // lives for the whole run, removed at exit
    static Fixture f;
    if (f.city.empty()) {
        f.city = dir.file("city.osgb");
        f.traffic = dir.file("traffic");
        f.path = dir.file("ego.csv");
        auto r = test::genTrafficCity(f.city);
        EXPECT_EQ(r.code, 0) << r.err;
        r = runVista("traffic " + f.city + " --vehicles 60 --pedestrians 60 --duration 120 --seed 4 -q -o " +
                     f.traffic);
        EXPECT_EQ(r.code, 0) << r.err;
        const std::string ride = test::busiestRide(f.traffic, 40.0);
        EXPECT_FALSE(ride.empty()) << "no car of the traffic rides for 40 s";
        r = runVista("path " + f.city + " --traffic " + f.traffic + " --ego " + ride + " --duration 40 -o " + f.path);
        EXPECT_EQ(r.code, 0) << r.err;
        const size_t at = r.err.find("riding ");
        if (at != std::string::npos) f.ego = r.err.substr(at + 7, r.err.find(')', at) - at - 7);
        f.ok = fs::exists(f.path);
    }
    return f;
}

std::vector<uint8_t> loadSemantic(const std::string& path) {
    auto img = readPng(path);
    std::vector<uint8_t> out;
    if (!img) return out;
    for (size_t i = 0; i < img->rgba.size(); i += 4) out.push_back(img->rgba[i]);
    return out;
}

// What a render with labels says about its agents.
struct AgentPixels {
    size_t total = 0;       // pixels labelled vehicle or pedestrian
    size_t offBox = 0;      // of them: not on their agent's box at the frame's time
    size_t wrongClass = 0;  // of them: the semantic class disagrees with the id's kind
    size_t beyond = 0;      // of them: farther than `split` metres (eye depth)
    std::set<uint32_t> agents;
};

// The class of an agent's SUMO type (labels.h).
SemanticClass expectedClass(AgentType type) {
    static const std::map<AgentType, SemanticClass> kClass = {
        {AgentType::Car, SemanticClass::Car},         {AgentType::Van, SemanticClass::Van},
        {AgentType::Bus, SemanticClass::Bus},         {AgentType::Truck, SemanticClass::Truck},
        {AgentType::Bicycle, SemanticClass::Bicycle}, {AgentType::Pedestrian, SemanticClass::Pedestrian}};
    return kClass.at(type);
}

// Back-projects every agent pixel of every frame of `out` (cameras.json) and
// checks it against the agent boxes computed here from the FCD: SUMO's
// reference point (front bumper) half a model length ahead of the box centre.
AgentPixels checkAgentPixels(const std::string& out, const TrafficTracks& tracks, const CityParams& params,
                             double split) {
    const AgentModels models = agentModels(Lighting(params));
    const auto cams = nlohmann::json::parse(readBytes(out + "/cameras.json"));
    const double fx = cams["fx"], fy = cams["fy"], cx = cams["cx"], cy = cams["cy"];
    const glm::dvec3 offset(cams["world_offset"][0], cams["world_offset"][1], cams["world_offset"][2]);
    AgentPixels r;
    for (const auto& fr : cams["frames"]) {
        const std::string name = fr["name"];
        glm::dmat4 T(1.0);
        for (int row = 0; row < 4; ++row)
            for (int col = 0; col < 4; ++col) T[col][row] = fr["camera_from_world"][row][col].get<double>();
        const glm::dmat4 worldFromCamera = glm::inverse(T);
        const double t = fr["t_s"];
        const auto ids = loadNpy<uint32_t>(out + "/instance/" + name + ".npy");
        const auto depth = loadNpy<float>(out + "/depth/" + name + ".npy");
        const auto sem = loadSemantic(out + "/semantic/" + name + ".png");
        EXPECT_EQ(ids.size(), size_t(kW * kH));
        EXPECT_EQ(depth.size(), size_t(kW * kH));
        EXPECT_EQ(sem.size(), size_t(kW * kH));
        if (ids.size() != size_t(kW * kH) || depth.size() != ids.size() || sem.size() != ids.size()) continue;
        for (int v = 0; v < kH; ++v)
            for (int u = 0; u < kW; ++u) {
                const size_t i = size_t(v) * kW + size_t(u);
                const InstanceKind kind = instanceKind(ids[i]);
                if (kind != InstanceKind::Vehicle && kind != InstanceKind::Pedestrian) continue;
                ++r.total;
                const uint32_t agent = instanceIndex(ids[i]);
                r.agents.insert(agent);
                if (agent < tracks.agentTypes.size() && sem[i] != uint8_t(expectedClass(tracks.agentTypes[agent])))
                    ++r.wrongClass;
                const double z = depth[i];
                if (z > split) ++r.beyond;
                const glm::dvec3 p =
                    offset + glm::dvec3(worldFromCamera * glm::dvec4(z * (u - cx) / fx, z * (v - cy) / fy, z, 1.0));
                AgentPose pose;
                if (agent >= tracks.agentTypes.size() || !tracks.poseAt(agent, t, &pose)) {
                    ++r.offBox;
                    continue;
                }
                const AgentType type = tracks.agentTypes[agent];
                const AgentModel& m = models.models[agentPrototype(models, type, agent)];
                const glm::dvec2 dir(std::cos(pose.heading), std::sin(pose.heading)), left(-dir.y, dir.x);
                glm::dvec2 c(pose.x, pose.y);
                if (type != AgentType::Pedestrian) c -= 0.5 * m.length * dir;
                const glm::dvec2 d = glm::dvec2(p) - c;
                const double ground = terrainHeight(params, c - glm::dvec2(params.origin_x, params.origin_y));
                const double margin = 0.15 + 0.002 * z;  // depth and float rounding
                const bool on = std::abs(glm::dot(d, dir)) <= 0.5 * m.length + margin &&
                                std::abs(glm::dot(d, left)) <= 0.5 * m.width + margin && p.z >= ground - margin &&
                                p.z <= ground + m.height + margin;
                if (!on) ++r.offBox;
            }
    }
    return r;
}

class TrafficDraw : public ::testing::Test {
protected:
    void SetUp() override {
        VISTA_SKIP_WITHOUT_SUMO();
        if (!fixture().ok) GTEST_FAIL() << "the traffic fixture could not be made";
    }
    std::string render(const std::string& out, const std::string& extra) {
        const auto& f = fixture();
        const auto r = runVista("render " + f.city + " --path " + f.path + " --size " + std::to_string(kW) + "x" +
                                std::to_string(kH) + " --frames 16 -q --out " + out + " " + extra);
        EXPECT_EQ(r.code, 0) << r.err;
        return out;
    }
};

}  // namespace

TEST_F(TrafficDraw, RenderLabelsEveryAgentPixelOnItsAgentsBox) {
    TempDir tmp("vista_traffic_draw_full");
    const auto& f = fixture();
    const std::string out = render(tmp.file("full"), "--mode full --traffic " + f.traffic);
    auto tracks = loadTrafficTracks(f.traffic);
    ASSERT_TRUE(tracks) << tracks.status().message();
    auto city = loadCityFile(f.city);
    ASSERT_TRUE(city) << city.status().message();
    const AgentPixels r = checkAgentPixels(out, *tracks, city->params, 1e30);
    // The ego path passes other agents: enough pixels to mean something.
    EXPECT_GT(r.total, 500u);
    EXPECT_GE(r.agents.size(), 3u);
    EXPECT_EQ(r.wrongClass, 0u);
    // The vehicle the path rides is not seen by its own camera.
    const auto ego = std::find(tracks->agentIds.begin(), tracks->agentIds.end(), f.ego);
    ASSERT_NE(ego, tracks->agentIds.end()) << "'" << f.ego << "'";
    EXPECT_EQ(r.agents.count(uint32_t(ego - tracks->agentIds.begin())), 0u);
    // Pixels off their agent's box: only at silhouettes (depth mixing across an edge), at most 1 %.
    EXPECT_LE(double(r.offBox), 0.01 * double(r.total)) << r.offBox << " of " << r.total;
    // The classes file lists the moving agents' classes and kinds.
    const auto classes = nlohmann::json::parse(readBytes(out + "/classes.json"));
    EXPECT_EQ(classes["semantic_classes"][15]["name"], "vehicle");
    EXPECT_EQ(classes["semantic_classes"][16]["name"], "pedestrian");
}

TEST_F(TrafficDraw, HybridRayCastsAgentsBeyondTheSplit) {
    TempDir tmp("vista_traffic_draw_hybrid");
    const auto& f = fixture();
    constexpr double kNear = 15.0;
    const std::string out = render(tmp.file("hybrid"), "--mode hybrid --near 15 --traffic " + f.traffic);
    auto tracks = loadTrafficTracks(f.traffic);
    ASSERT_TRUE(tracks);
    auto city = loadCityFile(f.city);
    ASSERT_TRUE(city);
    const AgentPixels r = checkAgentPixels(out, *tracks, city->params, kNear + 5.0);
    // Agents far beyond the near distance come from the ray-cast far field (and its label rays).
    EXPECT_GT(r.beyond, 100u);
    EXPECT_EQ(r.wrongClass, 0u);
    EXPECT_LE(double(r.offBox), 0.01 * double(r.total)) << r.offBox << " of " << r.total;
    // The same frames in full: the agents' pixels agree (ray-cast and rasterised agents coincide).
    const std::string full = render(tmp.file("full"), "--mode full --traffic " + f.traffic);
    size_t both = 0, either = 0;
    for (int k = 0; k < 16; ++k) {
        char name[16];
        std::snprintf(name, sizeof name, "%06d", k);
        const auto a = loadNpy<uint32_t>(out + "/instance/" + name + ".npy");
        const auto b = loadNpy<uint32_t>(full + "/instance/" + name + ".npy");
        ASSERT_EQ(a.size(), b.size());
        for (size_t i = 0; i < a.size(); ++i) {
            const bool ma =
                instanceKind(a[i]) == InstanceKind::Vehicle || instanceKind(a[i]) == InstanceKind::Pedestrian;
            const bool mb =
                instanceKind(b[i]) == InstanceKind::Vehicle || instanceKind(b[i]) == InstanceKind::Pedestrian;
            either += (ma || mb) ? 1 : 0;
            both += (ma && mb && a[i] == b[i]) ? 1 : 0;
        }
    }
    ASSERT_GT(either, 0u);
    EXPECT_GE(double(both) / double(either), 0.9) << both << " of " << either;
}

TEST_F(TrafficDraw, RigCamerasAndLidarSeeTheAgents) {
    TempDir tmp("vista_traffic_draw_rig");
    const auto& f = fixture();
    const std::string out = tmp.file("rig");
    const auto r = runVista("render " + f.city + " --path " + f.path + " --frames 6 --sampling spread -q --rig " +
                            std::string(VISTA_SOURCE_DIR) + "/data/rigs/car_4cam_lidar64.json --traffic " + f.traffic +
                            " --out " + out);
    ASSERT_EQ(r.code, 0) << r.err;
    size_t cameraAgents = 0, lidarAgents = 0;
    for (const auto& e : fs::recursive_directory_iterator(out)) {
        const std::string p = e.path().string();
        const bool cam = p.find("/instance_0") != std::string::npos,
                   lidar = p.find("/lidar_instance/") != std::string::npos;
        if (!cam && !lidar) continue;
        const auto ids = cam ? loadNpy<uint32_t>(p) : std::vector<uint32_t>();
        std::vector<uint32_t> pts;
        if (lidar) {
            const std::string b = readBytes(p);
            pts.resize(b.size() / 4);
            std::memcpy(pts.data(), b.data(), pts.size() * 4);
        }
        for (uint32_t id : cam ? ids : pts) {
            const InstanceKind k = instanceKind(id);
            if (k == InstanceKind::Vehicle || k == InstanceKind::Pedestrian) ++(cam ? cameraAgents : lidarAgents);
        }
    }
    EXPECT_GT(cameraAgents, 20u);
    EXPECT_GT(lidarAgents, 10u);
}

TEST_F(TrafficDraw, AStreamedPagedCityDrawsTheSameAgents) {
    TempDir tmp("vista_traffic_draw_paged");
    const auto& f = fixture();
    // The same city as regions (same parameters): the traffic is city-wide, not per region.
    auto r = runVista("gen --size 700 --detail 0 --seed 5 --region-size 250 -q -o " + tmp.file("city.paged"));
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string common =
        " --path " + f.path + " --frames 8 --size 160x100 --mode full --channels rgb,semantic -q --out ";
    const std::string traffic = " --traffic " + f.traffic;
    r = runVista("render " + tmp.file("city.paged") + traffic + common + tmp.file("paged"));
    ASSERT_EQ(r.code, 0) << r.err;
    r = runVista("render " + f.city + traffic + common + tmp.file("file"));
    ASSERT_EQ(r.code, 0) << r.err;
    r = runVista("render " + f.city + common + tmp.file("still"));
    ASSERT_EQ(r.code, 0) << r.err;
    // A paged city has no instance channel; the agents' pixels are those whose class the traffic
    // changed (a moving car's class is `car`, as a parked one's), with the agents' classes.
    auto agentClass = [](uint8_t c) { return c == 14 || (c >= 16 && c <= 20); };
    size_t agents = 0, differ = 0;
    for (int k = 0; k < 8; ++k) {
        char name[32];
        std::snprintf(name, sizeof name, "semantic/%06d.png", k);
        const auto a = loadSemantic(tmp.file("paged") + "/" + name), b = loadSemantic(tmp.file("file") + "/" + name),
                   still = loadSemantic(tmp.file("still") + "/" + name);
        ASSERT_EQ(a.size(), b.size());
        ASSERT_EQ(a.size(), still.size());
        for (size_t i = 0; i < a.size(); ++i) {
            const bool ma = agentClass(a[i]) && a[i] != still[i], mb = agentClass(b[i]) && b[i] != still[i];
            agents += mb ? 1 : 0;
            differ += (ma != mb || (mb && a[i] != b[i])) ? 1 : 0;
        }
    }
    EXPECT_GT(agents, 50u);
    EXPECT_EQ(differ, 0u);
}

TEST_F(TrafficDraw, BenchDrawsTheAgentsAlikeInRasterAndRays) {
    TempDir tmp("vista_traffic_draw_bench");
    const auto& f = fixture();
    // raycast traces every agent, full rasterises them: against full, a raycast frame with an
    // agent missing would lose its pixels (a car is hundreds of pixels here).
    const auto r = runVista("bench " + f.city + " --path " + f.path + " --traffic " + f.traffic +
                            " --modes full,raycast,hybrid --frames 16 --sampling spread --size 320x200 -q --out " +
                            tmp.file("bench"));
    ASSERT_EQ(r.code, 0) << r.err;
    std::ifstream csv(tmp.file("bench/frames.csv"));
    std::string line;
    std::getline(csv, line);
    int frames = 0;
    while (std::getline(csv, line)) {
        std::vector<std::string> cols;
        size_t a = 0;
        for (size_t b; (b = line.find(',', a)) != std::string::npos; a = b + 1) cols.push_back(line.substr(a, b - a));
        if (cols.size() < 11 || cols[3] == "full") continue;
        ++frames;
        EXPECT_GE(std::stod(cols[10]), 40.0) << cols[3] << " frame " << cols[0];
    }
    EXPECT_EQ(frames, 32);
}

TEST_F(TrafficDraw, FramesWithoutAgentsAreTheBytesOfARunWithoutTraffic) {
    TempDir tmp("vista_traffic_draw_none");
    const auto& f = fixture();
    // The same path an hour after the traffic ends: no agent is present.
    std::ifstream in(f.path);
    std::ofstream shifted(tmp.file("late.csv"));
    std::string line;
    std::getline(in, line);
    shifted << line << "\n";
    while (std::getline(in, line)) {
        const size_t comma = line.find(',');
        shifted << std::to_string(std::stod(line.substr(0, comma)) + 3600.0) << line.substr(comma) << "\n";
    }
    shifted.close();
    for (const char* mode : {"full", "hybrid"}) {
        const std::string common = std::string("render ") + f.city + " --path " + tmp.file("late.csv") +
                                   " --size 160x100 --frames 4 -q --mode " + mode + " --out ";
        const std::string a = tmp.file(std::string(mode) + "_plain"), b = tmp.file(std::string(mode) + "_traffic");
        auto r = runVista(common + a);
        ASSERT_EQ(r.code, 0) << r.err;
        r = runVista(common + b + " --traffic " + f.traffic);
        ASSERT_EQ(r.code, 0) << r.err;
        for (const char* file : {"rgb/000000.png", "rgb/000003.png", "instance/000002.npy", "depth/000001.npy"})
            EXPECT_EQ(readBytes(a + "/" + file), readBytes(b + "/" + file)) << mode << " " << file;
    }
}

TEST_F(TrafficDraw, BadTrafficDirectoriesExitTwoNamingTheOption) {
    TempDir tmp("vista_traffic_draw_bad");
    const auto& f = fixture();
    fs::create_directories(tmp.file("empty"));
    fs::create_directories(tmp.file("cut"));
    fs::copy_file(f.traffic + "/traffic.json", tmp.file("cut/traffic.json"));
    const std::string fcd = readBytes(f.traffic + "/fcd.xml");
    std::ofstream(tmp.file("cut/fcd.xml")) << fcd.substr(0, fcd.size() / 2);
    // Whole tracks, signal states cut short.
    fs::create_directories(tmp.file("cutsignals"));
    for (const char* name : {"traffic.json", "fcd.xml", "city.net.xml"})
        fs::copy_file(f.traffic + "/" + name, tmp.file(std::string("cutsignals/") + name));
    const std::string signals = readBytes(f.traffic + "/signals.xml");
    std::ofstream(tmp.file("cutsignals/signals.xml")) << signals.substr(0, signals.size() / 2);
    for (const std::string& dir : {tmp.file("missing"), tmp.file("empty"), tmp.file("cut"), tmp.file("cutsignals")}) {
        const std::string out = tmp.file("out");
        const std::string cmds[] = {
            "render " + f.city + " --path " + f.path + " --frames 2 --size 64x48 --out " + out,
            "bench " + f.city + " --path " + f.path + " --frames 2 --size 64x48 --modes full --out " + out,
            "view " + f.city + " --path " + f.path + " --step --frames 2"};
        for (const std::string& cmd : cmds) {
            const auto r = runVista(cmd + " --traffic " + dir);
            EXPECT_EQ(r.code, 2) << cmd << ": " << r.err;
            EXPECT_NE(r.err.find("--traffic"), std::string::npos) << cmd << ": " << r.err;
            EXPECT_FALSE(fs::exists(out)) << cmd;
        }
    }
}

// Traffic-light heads (--traffic): a camera 2 m in front of a head of the
// city, at the height of its amber lamp, at a time SUMO has the head's links
// red and at one it has them green; in full (GL) and hybrid with the head
// beyond its near distance (rays) the pixel at each lamp's projected centre
// belongs to that head (instance id), and the lamp SignalStates gives is the
// bright one there, the others dark. Heads hidden behind a tree from that
// camera (the instance image says so) are skipped for the next one.
TEST_F(TrafficDraw, HeadsShowSumosLampInGlAndRays) {
    TempDir tmp("vista_traffic_draw_heads");
    const auto& f = fixture();
    auto city = loadCityFile(f.city);
    ASSERT_TRUE(city) << city.status().message();
    auto tracks = loadTrafficTracks(f.traffic);
    ASSERT_TRUE(tracks) << tracks.status().message();
    auto states = loadSignalStates(f.traffic);
    ASSERT_TRUE(states) << states.status().message();
    const std::vector<SignalHead> heads = signalHeads(city->streets, city->params);
    ASSERT_FALSE(heads.empty());
    const auto steady = [&](uint32_t s, double t, LampState l) {
        for (double dt : {-0.5, 0.0, 0.5})
            if (states->lampAt(s, t + dt) != l) return false;
        return true;
    };
    // Renders `head` at its red and green times in `mode`; counts the lamp
    // pixels that are not the head's (occluded) and checks the colours of the others.
    const auto check = [&](const SignalHead& head, double tRed, double tGreen, const std::string& mode,
                           const std::string& out, bool expectColours) -> size_t {
        const glm::dvec3 w(head.frame[2]), base(head.frame[3]);
        const glm::dvec3 centre(head.frame * glm::dvec4(lampOverlayCentre(), 1.0));
        const glm::dvec3 eye = glm::dvec3(base.x, base.y, centre.z) + 2.0 * w;
        const double headingDeg = std::atan2(-w.x, -w.y) * 180.0 / 3.14159265358979323846;
        {
            std::ofstream csv(out + ".csv");
            csv << "t_s,x_m,y_m,z_m,heading_deg,pitch_deg\n";
            for (double t : {std::min(tRed, tGreen), std::max(tRed, tGreen)})
                csv << t << "," << eye.x << "," << eye.y << "," << eye.z << "," << headingDeg << ",0\n";
        }
        const auto r = runVista("render " + f.city + " --path " + out + ".csv --size 160x100 --frames 2 -q --mode " +
                                mode + " --traffic " + f.traffic + " --out " + out);
        EXPECT_EQ(r.code, 0) << r.err;
        if (r.code != 0) return 1;
        const uint32_t id = makeInstanceId(InstanceKind::TrafficLight, head.signal);
        const auto cams = nlohmann::json::parse(readBytes(out + "/cameras.json"));
        const double fx = cams["fx"], fy = cams["fy"], cx = cams["cx"], cy = cams["cy"];
        const glm::dvec3 offset(cams["world_offset"][0], cams["world_offset"][1], cams["world_offset"][2]);
        size_t hidden = 0;
        for (const auto& fr : cams["frames"]) {
            const std::string name = fr["name"];
            glm::dmat4 T(1.0);
            for (int row = 0; row < 4; ++row)
                for (int col = 0; col < 4; ++col) T[col][row] = fr["camera_from_world"][row][col].get<double>();
            const double t = fr["t_s"];
            const LampState want = states->lampAt(head.signal, t);
            EXPECT_TRUE(want == LampState::Red || want == LampState::Green) << t;
            auto img = readPng(out + "/rgb/" + name + ".png");
            EXPECT_TRUE(img) << img.status().message();
            if (!img) return 1;
            const auto ids = loadNpy<uint32_t>(out + "/instance/" + name + ".npy");
            EXPECT_EQ(ids.size(), size_t(img->width) * size_t(img->height));
            if (ids.size() != size_t(img->width) * size_t(img->height)) return 1;
            for (int k = 0; k < 3; ++k) {  // red, amber, green from the top
                const glm::dvec3 lamp = centre + glm::dvec3(0, 0, (1 - k) * kTrafficLightHeight / 3.0);
                const glm::dvec3 p(T * glm::dvec4(lamp - offset, 1.0));
                EXPECT_GT(p.z, 0.5);
                const int u = int(std::lround(cx + fx * p.x / p.z)), v = int(std::lround(cy + fy * p.y / p.z));
                EXPECT_TRUE(u >= 0 && v >= 0 && u < img->width && v < img->height) << u << "," << v;
                if (!(u >= 0 && v >= 0 && u < img->width && v < img->height)) return 1;
                if (ids[size_t(v) * size_t(img->width) + size_t(u)] != id) {
                    ++hidden;
                    continue;
                }
                if (!expectColours) continue;
                const glm::u8vec4 px = img->at(u, v);
                const int c[3] = {px.x, px.y, px.z};
                const bool lit = (k == 0 && want == LampState::Red) || (k == 2 && want == LampState::Green);
                const int hi = std::max({c[0], c[1], c[2]});
                if (!lit) {
                    EXPECT_LT(hi, 110) << mode << " t " << t << " lamp " << k << " should be dark";
                } else if (k == 0) {
                    EXPECT_GT(c[0], 200) << mode << " t " << t;
                    EXPECT_LT(c[1], 100) << mode << " t " << t;
                } else {
                    EXPECT_GT(c[1], 200) << mode << " t " << t;
                    EXPECT_LT(c[0], 120) << mode << " t " << t;
                }
            }
        }
        return hidden;
    };
    // The first heads with a steady red and a steady green inside the run (away from its ends).
    int tried = 0;
    bool seen = false;
    for (const SignalHead& h : heads) {
        double tRed = -1, tGreen = -1;
        for (double t = tracks->times.front() + 1.0; t < tracks->times.back() - 1.0; t += 0.5) {
            if (tRed < 0 && steady(h.signal, t, LampState::Red)) tRed = t;
            if (tGreen < 0 && steady(h.signal, t, LampState::Green)) tGreen = t;
        }
        if (tRed < 0 || tGreen < 0) continue;
        if (++tried > 8) break;
        const std::string dir = tmp.file("head" + std::to_string(h.signal));
        if (check(h, tRed, tGreen, "full", dir + "_probe", false) != 0) continue;  // behind a tree
        seen = true;
        EXPECT_EQ(check(h, tRed, tGreen, "full", dir + "_full", true), 0u);
        EXPECT_EQ(check(h, tRed, tGreen, "hybrid --near 1", dir + "_hybrid", true), 0u);
        break;
    }
    EXPECT_TRUE(seen) << "every head tried is hidden from 2 m in front of it";
}
