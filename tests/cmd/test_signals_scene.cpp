// Signals through the pipeline, on a city with traffic lights, stop and yield
// signs (tests/common/signal_city.h) written as a scene file:
// - `vista render` of a frame looking at a traffic light (full, and hybrid
//   with the light beyond the near distance, so that Embree rays label it)
//   shows pixels of class traffic_light whose instance ids are of kind
//   traffic_light, the light looked at among them; classes.json lists the
//   new class and kinds;
// - the OpenDRIVE file (`vista export --xodr` of the scene file) declares as
//   many <signal>s as the scene has signal instances, signal id i being the
//   instance of index i of the matching kind, at the heights of the meshes.
// Rendering: needs DISPLAY (ctest runs under xvfb-run).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "citygen/generate.h"
#include "citygen/labels.h"
#include "citygen/lanes.h"
#include "citygen/terrain.h"
#include "citygen/traffic_signals.h"
#include "foundation/units.h"
#include "runtime/engine/image.h"
#include "runtime/scene/city_file.h"
#include "tests/common/run_vista.h"
#include "tests/common/signal_city.h"
#include "tests/common/temp_dir.h"

namespace vista {
namespace {

using test::runVista;
using test::TempDir;

constexpr int kW = 160, kH = 120;

class SignalsScene : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        dir = new TempDir("vista_signals");
        cityFile = dir->file("city.osgb");
        GenerateOptions o;
        o.streets = test::signalStreets();
        auto c = generateCity(test::signalCityParams(), o);
        ASSERT_TRUE(c.isOk()) << c.status().message();
        city = new City(std::move(*c));
        ASSERT_TRUE(bool(writeCityFile(*city, cityFile)));
        lanes = new LaneModel(buildLaneModel(city->streets, city->params, &city->blocks));
    }
    static void TearDownTestSuite() {
        delete lanes;
        delete city;
        delete dir;
        lanes = nullptr;
        city = nullptr;
        dir = nullptr;
    }
    static TempDir* dir;
    static std::string cityFile;
    static City* city;
    static LaneModel* lanes;
};
TempDir* SignalsScene::dir = nullptr;
std::string SignalsScene::cityFile;
City* SignalsScene::city = nullptr;
LaneModel* SignalsScene::lanes = nullptr;

// A .npy array of uint32, row-major kH x kW.
std::vector<uint32_t> loadIds(const std::string& path) {
    const std::string b = test::readBytes(path);
    if (b.size() < 10) return {};
    const size_t hl = uint8_t(b[8]) | size_t(uint8_t(b[9])) << 8;
    EXPECT_NE(b.substr(10, hl).find("<u4"), std::string::npos);
    std::vector<uint32_t> v((b.size() - 10 - hl) / 4);
    std::memcpy(v.data(), b.data() + 10 + hl, v.size() * 4);
    return v;
}

TEST_F(SignalsScene, RenderShowsTrafficLightPixelsWithTheirInstances) {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) GTEST_SKIP() << "no DISPLAY: run the tests under xvfb-run -a";
    size_t li = lanes->signals.size();
    for (size_t i = 0; i < lanes->signals.size() && li == lanes->signals.size(); ++i)
        if (lanes->signals[i].kind == SignalPlacement::Kind::TrafficLight) li = i;
    ASSERT_LT(li, lanes->signals.size()) << "the test city has traffic lights";
    const SignalPlacement& s = lanes->signals[li];
    // The eye of a driver on the approach the light controls: 10 m before it
    // along its facing, 3 m toward the carriageway (left of the light as the
    // traffic sees it), 1.6 m above the ground, looking at the housing.
    const glm::dvec2 f = s.facing, right(-f.y, f.x);
    const glm::dvec2 eye = s.position + 10.0 * f - 3.0 * right;
    const double z = terrainHeight(city->params, eye) + 1.6;
    const glm::dvec2 d = s.position - eye;
    const double head = terrainHeight(city->params, s.position) + kTrafficLightBottom + 0.5 * kTrafficLightHeight;
    const double heading = std::atan2(d.x, d.y), pitch = std::atan2(head - z, glm::length(d));
    const std::string pathCsv = dir->file("light.csv");
    {
        std::ofstream o(pathCsv);
        o << "t_s,x_m,y_m,z_m,heading_deg,pitch_deg\n";
        for (double t : {0.0, 0.1}) {
            char line[256];
            std::snprintf(line, sizeof line, "%.3f,%.4f,%.4f,%.4f,%.6f,%.6f\n", t, eye.x + city->params.origin_x,
                          eye.y + city->params.origin_y, z, heading * 180 / kPi, pitch * 180 / kPi);
            o << line;
        }
    }
    const uint32_t want = makeInstanceId(InstanceKind::TrafficLight, li);
    for (const std::string mode : {"full", "hybrid"}) {
        const std::string out = dir->file("render_" + mode);
        // hybrid: a 5 m near distance leaves the light (10 m away) to the far-field rays.
        const auto r =
            runVista("render " + cityFile + " --path " + pathCsv + " --frames 1 --size " + std::to_string(kW) + "x" +
                     std::to_string(kH) + " --mode " + mode + (mode == "hybrid" ? " --near 5" : "") +
                     " --channels semantic,instance -q --out " + out);
        ASSERT_EQ(r.code, 0) << r.err;
        const auto ids = loadIds(out + "/instance/000000.npy");
        auto sem = readPng(out + "/semantic/000000.png");
        ASSERT_TRUE(bool(sem)) << sem.status().message();
        ASSERT_EQ(ids.size(), size_t(kW * kH));
        ASSERT_EQ(sem->rgba.size(), size_t(kW * kH * 4));
        size_t lightPixels = 0, ofWanted = 0;
        for (size_t p = 0; p < ids.size(); ++p) {
            const int cls = sem->rgba[4 * p];
            const bool lightKind = instanceKind(ids[p]) == InstanceKind::TrafficLight;
            EXPECT_EQ(cls == int(SemanticClass::TrafficLight), lightKind) << mode << " pixel " << p;
            if (cls != int(SemanticClass::TrafficLight)) continue;
            ++lightPixels;
            ofWanted += ids[p] == want;
            EXPECT_LT(instanceIndex(ids[p]), lanes->signals.size()) << mode;
            EXPECT_EQ(lanes->signals[instanceIndex(ids[p]) % lanes->signals.size()].kind,
                      SignalPlacement::Kind::TrafficLight);
        }
        // The housing (0.3 x 0.9 m at about 10.4 m) covers about 8 x 24 pixels at 60 degrees over 120 rows.
        EXPECT_GT(ofWanted, 60u) << mode << ": the light looked at";
        EXPECT_GE(lightPixels, ofWanted);
        const auto classes = nlohmann::json::parse(test::readBytes(out + "/classes.json"));
        std::map<int, std::string> names, kinds;
        for (const auto& c : classes["semantic_classes"]) names[c["id"].get<int>()] = c["name"].get<std::string>();
        for (const auto& k : classes["instance_kinds"]) kinds[k["kind"].get<int>()] = k["name"].get<std::string>();
        EXPECT_EQ(names[12], "traffic_light");
        EXPECT_EQ(names[13], "traffic_sign");
        EXPECT_EQ(kinds[8], "traffic_light");
        EXPECT_EQ(kinds[9], "traffic_sign");
        EXPECT_EQ(names[14], "car");
        EXPECT_EQ(kinds[10], "car");
    }
}

// The value of attribute `name` in the tag text `tag` ("" if absent).
std::string attribute(const std::string& tag, const std::string& name) {
    const std::string key = " " + name + "=\"";
    const size_t a = tag.find(key);
    if (a == std::string::npos) return "";
    const size_t b = tag.find('"', a + key.size());
    return tag.substr(a + key.size(), b - a - key.size());
}

TEST_F(SignalsScene, OpenDriveSignalsAreTheSceneSignalInstances) {
    const std::string xodr = dir->file("city.xodr");
    const auto r = runVista("export " + cityFile + " --xodr " + xodr);
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string text = test::readBytes(xodr);
    // <signal> elements (not <signals> or <signalReference>).
    std::map<uint32_t, std::string> declared;  // signal id -> type
    for (size_t at = text.find("<signal "); at != std::string::npos; at = text.find("<signal ", at + 1)) {
        const std::string tag = text.substr(at, text.find('>', at) - at);
        const uint32_t id = uint32_t(std::stoul(attribute(tag, "id")));
        const std::string type = attribute(tag, "type");
        EXPECT_TRUE(declared.emplace(id, type).second) << "signal id " << id << " twice";
        const bool light = type == "1000001";
        EXPECT_TRUE(light || type == "206" || type == "205") << type;
        EXPECT_DOUBLE_EQ(std::stod(attribute(tag, "zOffset")), light ? kTrafficLightBottom : kSignBottom) << id;
        EXPECT_DOUBLE_EQ(std::stod(attribute(tag, "height")), light ? kTrafficLightHeight : kSignSize) << id;
        EXPECT_DOUBLE_EQ(std::stod(attribute(tag, "width")), light ? kTrafficLightWidth : kSignSize) << id;
    }
    // The signal instances of the scene file as loaded (every tile mesh's ids).
    auto model = loadCityFile(cityFile);
    ASSERT_TRUE(bool(model)) << model.status().message();
    std::set<uint32_t> instances;
    for (const auto& m : model->meshes)
        for (uint32_t id : m.ids)
            if (instanceKind(id) == InstanceKind::TrafficLight || instanceKind(id) == InstanceKind::TrafficSign)
                instances.insert(id);
    ASSERT_FALSE(declared.empty());
    EXPECT_EQ(declared.size(), instances.size());
    EXPECT_EQ(declared.size(), lanes->signals.size());
    for (const auto& [id, type] : declared) {
        const InstanceKind k = type == "1000001" ? InstanceKind::TrafficLight : InstanceKind::TrafficSign;
        EXPECT_TRUE(instances.count(makeInstanceId(k, id)))
            << "signal " << id << " (type " << type << ") stands in the scene";
    }
}

}  // namespace
}  // namespace vista
