// `vista render` (ground truth per frame) on a small generated city and a
// short path: depth and semantic class against independent Embree rays in
// full and hybrid, instance ids byte-identical across runs, every pixel
// classified, cameras.json projecting a depth-hit point back to its pixel,
// and bad input (path outside the city, unknown channel, unwritable --out)
// refused with exit code 2 and nothing left behind; interrupted runs (killed
// with SIGKILL) resume to the bytes of an uninterrupted run (full; hybrid with
// its cache rebuilt; a sensor rig), a work directory of other parameters is refused (exit 2,
// the field named) or discarded with --restart. Rendering: needs DISPLAY
// (ctest runs under xvfb-run).
#include <gtest/gtest.h>

#include <functional>

#include <sys/wait.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>
#include <osg/UserDataContainer>

#include "citygen/labels.h"
#include "runtime/engine/far_field_rays.h"
#include "runtime/engine/image.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_file.h"
#include "runtime/scene/scene_graph.h"
#include "runtime/scene/paths.h"
#include "tests/common/run_vista.h"
#include "tests/common/temp_dir.h"

namespace vista {
namespace {

namespace fs = std::filesystem;
using test::runVista;
using test::TempDir;

constexpr int kW = 160, kH = 120;

// A .npy array of 4-byte elements (header checked), row-major kH x kW.
template <class T>
std::vector<T> loadNpy(const std::string& path, const char* descr) {
    const std::string b = test::readBytes(path);
    EXPECT_GT(b.size(), 10u) << path;
    if (b.size() < 10) return {};
    const size_t hl = uint8_t(b[8]) | size_t(uint8_t(b[9])) << 8;
    const std::string header = b.substr(10, hl);
    EXPECT_NE(header.find(descr), std::string::npos) << header;
    EXPECT_NE(header.find("(" + std::to_string(kH) + ", " + std::to_string(kW) + ")"), std::string::npos) << header;
    std::vector<T> v((b.size() - 10 - hl) / 4);
    std::memcpy(v.data(), b.data() + 10 + hl, v.size() * 4);
    EXPECT_EQ(v.size(), size_t(kW * kH));
    return v;
}

// The 8-bit grey PNG of a semantic frame (readPng expands grey to r = g = b).
std::vector<uint8_t> loadSemantic(const std::string& path) {
    auto img = readPng(path);
    EXPECT_TRUE(bool(img)) << img.status().message();
    std::vector<uint8_t> out;
    if (!img) return out;
    for (size_t i = 0; i < img->rgba.size(); i += 4) out.push_back(img->rgba[i]);
    return out;
}

class GroundTruth : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        const char* display = std::getenv("DISPLAY");
        if (!display || !*display) return;
        dir = new TempDir("vista_gt");
        city = dir->file("city.osgb");
        pathCsv = dir->file("path.csv");
        ASSERT_EQ(runVista("gen --size 400 --seed 11 -q -o " + city).code, 0);
        ASSERT_EQ(runVista("path " + city + " --seed 2 --duration 3 -o " + pathCsv).code, 0);
    }
    static void TearDownTestSuite() {
        delete dir;
        dir = nullptr;
    }
    void SetUp() override {
        const char* display = std::getenv("DISPLAY");
        if (!display || !*display) GTEST_SKIP() << "no DISPLAY: run the tests under xvfb-run -a";
    }
    static std::string render(const std::string& mode, const std::string& out, const std::string& extra = "") {
        const auto r = runVista("render " + city + " --path " + pathCsv + " --frames 3 --size " + std::to_string(kW) +
                                "x" + std::to_string(kH) + " --mode " + mode + " -q --out " + out + " " + extra);
        EXPECT_EQ(r.code, 0) << r.err;
        return out;
    }
    static TempDir* dir;
    static std::string city, pathCsv;
};
TempDir* GroundTruth::dir = nullptr;
std::string GroundTruth::city, GroundTruth::pathCsv;

// Depth and class of every sampled pixel against an independent ray through
// its centre (RayScene of the loaded city; class from the hit mesh's
// material or the tree prototype's part). Depth: within 1 cm wherever the
// pixel is not on a silhouette or crease (its 4-neighbours hit the same
// entity and depth varies by < 5 cm per pixel there: a sub-pixel sample
// shift cannot move the hit by more than a few mm).
void checkAgainstRays(const std::string& cityFile, const std::string& out, const char* mode) {
    auto model = loadCityFile(cityFile);
    ASSERT_TRUE(bool(model)) << model.status().message();
    auto rays = RayScene::build(*model);
    ASSERT_TRUE(bool(rays));
    const auto cams = nlohmann::json::parse(test::readBytes(out + "/cameras.json"));
    const double fovY = 2.0 * std::atan(0.5 * kH / cams["fy"].get<double>());
    int checkedDepth = 0, checkedClass = 0, classAgree = 0;
    for (size_t f = 0; f < cams["frames"].size(); ++f) {
        const auto& fr = cams["frames"][f];
        const std::string name = fr["name"];
        const auto depth = loadNpy<float>(out + "/depth/" + name + ".npy", "<f4");
        const auto ids = loadNpy<uint32_t>(out + "/instance/" + name + ".npy", "<u4");
        const auto cls = loadSemantic(out + "/semantic/" + name + ".png");
        ASSERT_EQ(cls.size(), size_t(kW * kH));
        for (size_t p = 0; p < cls.size(); ++p) {  // every pixel: sky or a surface class, depth +inf iff sky
            ASSERT_LT(cls[p], kSemanticClassCount) << "pixel " << p << " without a class";
            ASSERT_EQ(cls[p] == 0, std::isinf(depth[p])) << "pixel " << p;
            if (cls[p] == 0) { ASSERT_EQ(ids[p], 0u); }
        }
        Camera cam;
        cam.width = kW;
        cam.height = kH;
        cam.fovY = fovY;
        cam.eye = {fr["eye_world"][0].get<double>(), fr["eye_world"][1].get<double>(),
                   fr["eye_world"][2].get<double>()};
        cam.heading = fr["heading_deg"].get<double>() * M_PI / 180.0;
        cam.pitch = fr["pitch_deg"].get<double>() * M_PI / 180.0;
        const PixelRays gen(cam);
        const glm::vec3 org(cam.eye - (*rays)->frameOrigin());
        for (int y = 1; y < kH - 1; y += 3)
            for (int x = 1; x < kW - 1; x += 3) {
                const size_t p = size_t(y) * kW + size_t(x);
                ASSERT_LT(cls[p], kSemanticClassCount) << "pixel without a class";
                const glm::dvec3 d = gen.dir(x, y);
                const double c = glm::dot(d, cam.forward());
                const RayHit h = (*rays)->intersect(org, glm::vec3(d), float(cam.zNear / c));
                if (!h.hit) {
                    EXPECT_TRUE(std::isinf(depth[p]) || cls[p] != 0);  // an edge pixel may see what the ray misses
                    continue;
                }
                const HitSource src = (*rays)->source(h);
                int rayClass = -1;
                if (src.mesh >= 0) rayClass = int(semanticClass(model->meshes[size_t(src.mesh)].material));
                if (src.instance >= 0) {
                    const SceneInstance& in = model->instances[size_t(src.instance)];
                    const SceneMesh& pm = model->prototypes[in.prototype];
                    rayClass = int(semanticClass(Material(pm.ids[pm.indices[3 * h.primId]])));
                }
                ++checkedClass;
                classAgree += rayClass == int(cls[p]) ? 1 : 0;
                const double zRay = double(h.t) * c;
                bool smooth = true;
                for (size_t q : {p - 1, p + 1, p - kW, p + kW})
                    smooth = smooth && ids[q] == ids[p] && cls[q] == cls[p] && std::abs(depth[q] - depth[p]) < 0.05f;
                if (!smooth || !(zRay < 300.0)) continue;
                ++checkedDepth;
                EXPECT_NEAR(depth[p], zRay, 0.01) << mode << " frame " << f << " pixel " << x << "," << y;
            }
    }
    EXPECT_GT(checkedDepth, 300) << mode;
    // Classes agree except where coplanar-ish layers tie (a lane marking 1 cm
    // above the road far away) or a silhouette pixel's centre is on the edge.
    EXPECT_GT(checkedClass, 600) << mode;
    EXPECT_GE(classAgree, int(0.98 * checkedClass)) << mode << ": " << classAgree << " of " << checkedClass;
}

TEST_F(GroundTruth, FullDepthAndClassesAgreeWithRays) {
    const std::string out = render("full", dir->file("full"));
    checkAgainstRays(city, out, "full");
    for (const char* f : {"classes.json", "summary.json", "rgb/000000.png", "rgb/000002.png"})
        EXPECT_TRUE(fs::exists(out + "/" + f)) << f;
}

TEST_F(GroundTruth, HybridDepthAndClassesAgreeWithRays) {
    // A 40 m near distance: a good part of every frame comes from the far-field rays.
    const std::string out = render("hybrid", dir->file("hybrid"), "--near 40");
    checkAgainstRays(city, out, "hybrid");
    const auto summary = nlohmann::json::parse(test::readBytes(out + "/summary.json"));
    EXPECT_GT(summary["median_far_label_pixels"].get<double>(), 0.0);
}

TEST_F(GroundTruth, InstanceIdsAreStableAcrossRuns) {
    const std::string a = render("full", dir->file("run_a"), "--channels instance,semantic");
    const std::string b = render("full", dir->file("run_b"), "--channels instance,semantic");
    for (const char* f : {"instance/000000.npy", "instance/000001.npy", "instance/000002.npy", "semantic/000001.png"}) {
        const std::string x = test::readBytes(a + "/" + f), y = test::readBytes(b + "/" + f);
        EXPECT_FALSE(x.empty()) << f;
        EXPECT_EQ(x, y) << f;
    }
    EXPECT_FALSE(fs::exists(a + "/rgb")) << "only the channels asked for";
    // Several entity kinds are seen (buildings, trees, roads) and ids decode.
    const auto ids = loadNpy<uint32_t>(a + "/instance/000001.npy", "<u4");
    std::set<uint32_t> kinds;
    for (uint32_t id : ids) kinds.insert(uint32_t(instanceKind(id)));
    EXPECT_TRUE(kinds.count(uint32_t(InstanceKind::Road))) << "road";
    EXPECT_GE(kinds.size(), 3u);
}

TEST_F(GroundTruth, CamerasProjectDepthPointsBack) {
    const std::string out = render("full", dir->file("cams"), "--channels depth");
    const auto cams = nlohmann::json::parse(test::readBytes(out + "/cameras.json"));
    const double fx = cams["fx"], fy = cams["fy"], cx = cams["cx"], cy = cams["cy"];
    const glm::dvec3 off(cams["world_offset"][0].get<double>(), cams["world_offset"][1].get<double>(), 0.0);
    for (size_t f = 0; f < cams["frames"].size(); ++f) {
        const auto& fr = cams["frames"][f];
        const auto depth = loadNpy<float>(out + "/depth/" + fr["name"].get<std::string>() + ".npy", "<f4");
        Camera cam;
        cam.width = kW;
        cam.height = kH;
        cam.fovY = 2.0 * std::atan(0.5 * kH / fy);
        cam.eye = {fr["eye_world"][0].get<double>(), fr["eye_world"][1].get<double>(),
                   fr["eye_world"][2].get<double>()};
        cam.heading = fr["heading_deg"].get<double>() * M_PI / 180.0;
        cam.pitch = fr["pitch_deg"].get<double>() * M_PI / 180.0;
        const auto& M = fr["camera_from_world"];
        int n = 0;
        for (int y = 5; y < kH; y += 17)
            for (int x = 3; x < kW; x += 13) {
                const float z = depth[size_t(y) * kW + size_t(x)];
                if (!std::isfinite(z)) continue;
                // The world point the pixel's depth names (independent of cameras.json: the path's camera).
                const glm::dvec3 d = cam.rayDirection(x + 0.5, y + 0.5);
                const glm::dvec3 P = cam.eye + d * (double(z) / glm::dot(d, cam.forward())) - off;
                double c[3];
                for (int r = 0; r < 3; ++r)
                    c[r] = M[r][0].get<double>() * P.x + M[r][1].get<double>() * P.y + M[r][2].get<double>() * P.z +
                           M[r][3].get<double>();
                EXPECT_NEAR(c[2], z, 1e-3 * std::max(1.0, double(z)));
                EXPECT_NEAR(fx * c[0] / c[2] + cx, x, 1e-3);
                EXPECT_NEAR(fy * c[1] / c[2] + cy, y, 1e-3);
                ++n;
            }
        EXPECT_GT(n, 10);
    }
}

TEST_F(GroundTruth, BadInputExitsTwoAndLeavesNothing) {
    TempDir t("vista_gt_bad");
    // A path outside the city square.
    const std::string far = t.file("far.csv");
    {
        std::ofstream o(far);
        o << "t_s,x_m,y_m,z_m,heading_deg,pitch_deg\n0,5000,5000,2,0,0\n0.1,5001,5000,2,0,0\n";
    }
    auto r = runVista("render " + city + " --path " + far + " --frames 2 --size 64x48 -q --out " + t.file("o1"));
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("outside the city"), std::string::npos) << r.err;
    // An unknown channel.
    r = runVista("render " + city + " --path " + pathCsv + " --channels rgb,normals -q --out " + t.file("o2"));
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("normals"), std::string::npos) << r.err;
    // An unwritable --out (its parent is a regular file).
    const std::string file = t.file("plain");
    { std::ofstream(file) << "x"; }
    r = runVista("render " + city + " --path " + pathCsv + " -q --out " + file + "/sub");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("--out"), std::string::npos) << r.err;
    // Nothing partial anywhere: only the two inputs made here.
    std::set<std::string> left;
    for (const auto& e : fs::directory_iterator(t.path())) left.insert(e.path().filename().string());
    EXPECT_EQ(left, (std::set<std::string>{"far.csv", "plain"}));
}

TEST_F(GroundTruth, OldFileWithoutLabelsAsksToRegenerate) {
    // The same city without the vista.labels marker: a file of an older version.
    auto model = loadCityFile(city);
    ASSERT_TRUE(bool(model));
    osg::Node* root = sceneRoot(*model);
    osg::UserDataContainer* udc = root->getUserDataContainer();
    ASSERT_NE(udc, nullptr);
    const unsigned i = udc->getUserObjectIndex("vista.labels");
    ASSERT_LT(i, udc->getNumUserObjects());
    udc->removeUserObject(i);
    const std::string old = dir->file("old.osgb");
    ASSERT_TRUE(bool(writeSceneFile(*root, old)));
    auto r =
        runVista("render " + old + " --path " + pathCsv + " --frames 1 --size 64x48 -q --out " + dir->file("old_sem"));
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("regenerate the city"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir->file("old_sem")));
    // rgb and depth need no labels.
    r = runVista("render " + old + " --path " + pathCsv + " --frames 1 --size 64x48 --channels rgb,depth -q --out " +
                 dir->file("old_rgb"));
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(dir->file("old_rgb/depth/000000.npy")));
}

// Every file under `dir` (relative path -> bytes) but summary.json (timings, command).
std::map<std::string, std::string> outputFiles(const std::string& dir) {
    std::map<std::string, std::string> m;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.is_regular_file() && e.path().filename() != "summary.json")
            m[fs::relative(e.path(), dir).string()] = test::readBytes(e.path().string());
    return m;
}

// A run killed (SIGKILL, through the documented test hook) after `killAfter`
// frames, then rerun with the same arguments: the result equals an
// uninterrupted run byte for byte (all but summary.json's timings).
// `removeAfterKill`: a file of the killed run's output (under DIR.partial/out) removed before
// the resume; its frame is rendered again. `damage` (if set): called with DIR.partial/out
// before the resume; it damages `damagedFrames` finished frames' files, which are rendered again.
void expectResumeEqualsUninterrupted(const std::string& city, const std::string& args, const std::string& ref,
                                     const std::string& out, int killAfter, int frames,
                                     const std::string& removeAfterKill = "",
                                     const std::function<void(const std::string&)>& damage = nullptr,
                                     int damagedFrames = 0) {
    auto r = runVista("render " + city + " " + args + " -q --out " + ref);
    ASSERT_EQ(r.code, 0) << r.err;
    r = runVista("render " + city + " " + args + " -q --out " + out,
                 "VISTA_RENDER_KILL_AFTER_FRAMES=" + std::to_string(killAfter));
    ASSERT_TRUE(r.code == -1 || r.code == 128 + SIGKILL) << "the hook kills the run: " << r.code << " " << r.err;
    EXPECT_FALSE(fs::exists(out)) << "no output before every frame is written";
    int records = 0;
    for (const auto& e : fs::directory_iterator(out + ".partial/done")) records += e.path().extension() == ".json";
    EXPECT_EQ(records, killAfter);
    if (!removeAfterKill.empty()) {
        EXPECT_TRUE(fs::remove(out + ".partial/out/" + removeAfterKill)) << removeAfterKill;
    }
    if (damage) damage(out + ".partial/out");
    r = runVista("render " + city + " " + args + " -q --out " + out);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_FALSE(fs::exists(out + ".partial")) << "the work directory is gone after the final rename";
    const auto a = outputFiles(ref), b = outputFiles(out);
    EXPECT_EQ(a.size(), b.size());
    for (const auto& [name, bytes] : a) {
        auto it = b.find(name);
        ASSERT_NE(it, b.end()) << name;
        EXPECT_TRUE(it->second == bytes) << name << " differs after resuming";
    }
    const auto summary = nlohmann::json::parse(test::readBytes(out + "/summary.json"));
    EXPECT_EQ(summary["frames"].get<int>(), frames);
    EXPECT_EQ(summary["frames_resumed"].get<int>(), killAfter - (removeAfterKill.empty() ? 0 : 1) - damagedFrames);
    if (summary.contains("median_ms")) {
        EXPECT_FALSE(summary["median_ms"]["labels_total"].is_null()) << "timings cover the resumed frames too";
    } else {  // a rig run: every sensor's timings
        for (const auto& [name, sensor] : summary["sensors"].items())
            EXPECT_FALSE(sensor["median_ms"].is_null()) << name << ": timings cover the resumed frames too";
    }
}

TEST_F(GroundTruth, FullResumesAfterKillByteIdentical) {
    expectResumeEqualsUninterrupted(city, "--path " + pathCsv + " --frames 5 --size 160x120", dir->file("res_full_ref"),
                                    dir->file("res_full"), 2, 5);
}

// A resume checks each finished frame's files against its record's sizes and hashes: a truncated
// PNG and a depth file with one byte changed (same size) are rendered again, not shipped.
TEST_F(GroundTruth, AResumeRendersDamagedFramesAgain) {
    auto damage = [](const std::string& partialOut) {
        const std::string png = partialOut + "/rgb/000000.png";
        ASSERT_TRUE(fs::exists(png));
        fs::resize_file(png, fs::file_size(png) / 2);
        const std::string npy = partialOut + "/depth/000001.npy";
        std::string bytes = test::readBytes(npy);
        ASSERT_GT(bytes.size(), 200u);
        bytes[bytes.size() - 3] = char(bytes[bytes.size() - 3] ^ 0x5a);
        std::ofstream(npy, std::ios::binary | std::ios::trunc) << bytes;
    };
    expectResumeEqualsUninterrupted(city, "--path " + pathCsv + " --frames 4 --size 160x120", dir->file("res_dmg_ref"),
                                    dir->file("res_dmg"), 3, 4, "", damage, 2);
}

TEST_F(GroundTruth, HybridResumesAfterKillByteIdentical) {
    // Consecutive frames and a small ray budget: most far pixels come from the
    // panoramic cache, so frame k depends on frames before it (without the
    // warm-up of the resumed run, frames 3 and 4 differ in rgb).
    expectResumeEqualsUninterrupted(
        city,
        "--path " + pathCsv + " --frames 5 --sampling consecutive --size 160x120 --mode hybrid --near 40 --budget 500",
        dir->file("res_hyb_ref"), dir->file("res_hyb"), 3, 5);
}

TEST_F(GroundTruth, RigResumesAfterKillByteIdentical) {
    // A rig (pinhole with flow and boxes, fisheye with boxes, LiDAR at its own
    // rate): the sensors that fired in the killed run's frames and the frames'
    // 3D boxes are kept, the rest cast again.
    const std::string rig = dir->file("resume_rig.json");
    std::ofstream(rig) << R"({"sensors": [
        {"name": "front", "type": "pinhole", "rate_hz": 15, "intrinsics": {"width": 64, "height": 48, "fx": 50,
         "fy": 50, "cx": 31.5, "cy": 23.5}, "channels": ["rgb", "depth", "semantic", "instance", "flow", "boxes"]},
        {"name": "side", "type": "fisheye", "pose": {"yaw_deg": 90}, "intrinsics": {"width": 48, "height": 48,
         "fx": 15, "fy": 15, "cx": 23.5, "cy": 23.5, "max_fov_deg": 180}, "channels": ["rgb", "depth", "flow", "boxes"]},
        {"name": "top", "type": "lidar", "pose": {"z": 0.5}, "beams": {"count": 8, "min_deg": -15, "max_deg": 5},
         "columns": 180}]})";
    expectResumeEqualsUninterrupted(city, "--path " + pathCsv + " --frames 6 --sampling consecutive --rig " + rig,
                                    dir->file("res_rig_ref"), dir->file("res_rig"), 4, 6, "boxes_3d/000001.json");
}

TEST_F(GroundTruth, ExternalKillThenResume) {
    // A real SIGKILL from outside once two frames are finished.
    const std::string ref = dir->file("kill_ref"), out = dir->file("kill");
    const std::vector<std::string> args = {"render", city,         "--path",    pathCsv, "--frames", "24", "--size",
                                           "96x72",  "--channels", "rgb,depth", "-q",    "--out",    out};
    const pid_t pid = test::startVista(args);
    ASSERT_GT(pid, 0);
    bool killed = false;
    for (int i = 0; i < 60000 && !killed; ++i) {
        std::error_code ec;
        size_t n = 0;
        for (fs::directory_iterator it(out + ".partial/done", ec), end; !ec && it != end; it.increment(ec)) ++n;
        if (n >= 2) killed = ::kill(pid, SIGKILL) == 0;
        else std::this_thread::sleep_for(std::chrono::milliseconds(2));
        int st = 0;
        if (!killed && ::waitpid(pid, &st, WNOHANG) == pid) break;  // ended on its own (should not happen)
    }
    int st = 0;
    if (killed) ::waitpid(pid, &st, 0);
    ASSERT_TRUE(killed) << "the run ended before two frames were seen";
    EXPECT_FALSE(fs::exists(out));
    std::string rerun;
    for (const auto& w : args) rerun += w + " ";
    auto r = runVista(rerun);
    ASSERT_EQ(r.code, 0) << r.err;
    r = runVista("render " + city + " --path " + pathCsv + " --frames 24 --size 96x72 --channels rgb,depth -q --out " +
                 ref);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(outputFiles(ref) == outputFiles(out));
    EXPECT_FALSE(fs::exists(out + ".partial"));
    for (const auto& e : fs::recursive_directory_iterator(out))
        EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path();
}

TEST_F(GroundTruth, ResumeWithOtherParametersIsRefusedOrRestarted) {
    const std::string out = dir->file("res_other"), ref = dir->file("res_other_ref");
    const std::string base =
        "render " + city + " --path " + pathCsv + " --frames 3 --channels semantic -q --out " + out;
    auto r = runVista(base + " --size 64x48", "VISTA_RENDER_KILL_AFTER_FRAMES=1");
    ASSERT_TRUE(r.code == -1 || r.code == 128 + SIGKILL) << r.code << " " << r.err;
    const std::set<std::string> before = test::listTree(out + ".partial");
    r = runVista(base + " --size 80x60");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("size: 64x48 in the work directory, 80x60 now"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--restart"), std::string::npos) << r.err;
    EXPECT_EQ(test::listTree(out + ".partial"), before) << "refused: the work directory is untouched";
    EXPECT_FALSE(fs::exists(out));
    // Another city file (other bytes) is refused too.
    const std::string other = dir->file("other_city.osgb");
    ASSERT_EQ(runVista("gen --size 300 --seed 12 -q -o " + other).code, 0);
    r = runVista("render " + other + " --path " + pathCsv + " --frames 3 --channels semantic -q --out " + out +
                 " --size 64x48");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("city_"), std::string::npos) << r.err;  // city_bytes or city_hash
    // --restart discards it and renders the new parameters.
    r = runVista(base + " --size 80x60 --restart");
    ASSERT_EQ(r.code, 0) << r.err;
    r = runVista("render " + city + " --path " + pathCsv + " --frames 3 --channels semantic -q --size 80x60 --out " +
                 ref);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(outputFiles(ref) == outputFiles(out));
    EXPECT_FALSE(fs::exists(out + ".partial"));
}

TEST_F(GroundTruth, MissingOutParentIsNamed) {
    TempDir t("vista_gt_parent");
    const std::string out = t.file("no/such/dir");
    auto r = runVista("render " + city + " --path " + pathCsv + " --frames 1 --size 32x24 -q --out " + out);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("parent directory '" + t.file("no/such") + "' does not exist"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::is_empty(t.path()));
}

TEST(GroundTruthLabels, InstanceIdEncodingRoundTrips) {
    const uint32_t id = makeInstanceId(InstanceKind::Tree, 123456);
    EXPECT_EQ(instanceKind(id), InstanceKind::Tree);
    EXPECT_EQ(instanceIndex(id), 123456u);
    EXPECT_EQ(makeInstanceId(InstanceKind::None, 0), 0u);
    EXPECT_EQ(makeInstanceId(InstanceKind::StreetLight, kInstanceIndexMask) >> 28, 7u);
    for (int m = 0; m < kMaterialCount; ++m) EXPECT_LT(int(semanticClass(Material(m))), kSemanticClassCount);
    EXPECT_STREQ(semanticClassName(SemanticClass::Sky), "sky");
}

}  // namespace
}  // namespace vista
