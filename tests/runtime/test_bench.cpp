// Offscreen renderer, bench modes and the `vista bench` command.
// Rendering tests need an X display: run under `xvfb-run -a` (they skip
// with a message when DISPLAY is unset).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include <osg/Geode>
#include <osg/Geometry>
#include <osg/MatrixTransform>
#include <nlohmann/json.hpp>

#include "citygen/lighting.h"
#include "foundation/units.h"
#include "cmd/bench.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_graph.h"
#include "runtime/engine/metrics.h"
#include "nodes/render/offscreen.h"
#include "runtime/scene/paths.h"
#include "runtime/engine/ray_scene.h"

using namespace vista;
namespace fs = std::filesystem;

namespace {


#define REQUIRE_DISPLAY()                                                                        \
    do {                                                                                         \
        const char* d = std::getenv("DISPLAY");                                                  \
        if (!d || !*d) GTEST_SKIP() << "no X display: run the rendering tests under xvfb-run -a"; \
    } while (0)

// Axis-aligned box (5 faces, no bottom) as a SceneMesh in a local frame.
void addBox(SceneMesh& m, glm::vec3 lo, glm::vec3 hi, glm::u8vec4 c) {
    glm::vec3 p[8];
    for (int i = 0; i < 8; ++i) p[i] = {i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z};
    const int faces[5][4] = {{0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}, {4, 5, 7, 6}};
    for (const auto& f : faces) {
        uint32_t base = uint32_t(m.positions.size());
        for (int k = 0; k < 4; ++k) {
            m.positions.push_back(p[f[k]]);
            m.colors.push_back(c);
        }
        for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
    }
}
void addQuad(SceneMesh& m, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, glm::u8vec4 col) {
    uint32_t base = uint32_t(m.positions.size());
    for (auto v : {a, b, c, d}) {
        m.positions.push_back(v);
        m.colors.push_back(col);
    }
    for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
}

// The OSG scene of a set of meshes, structured like a city file (tiles as
// double MatrixTransforms, prelit colours, lighting off).
osg::ref_ptr<osg::Group> sceneOf(const std::vector<SceneMesh>& meshes) {
    osg::ref_ptr<osg::Group> root = new osg::Group;
    root->getOrCreateStateSet()->setMode(GL_LIGHTING, osg::StateAttribute::OFF);
    for (const auto& m : meshes) {
        osg::ref_ptr<osg::Geometry> g = new osg::Geometry;
        osg::ref_ptr<osg::Vec3Array> v = new osg::Vec3Array;
        osg::ref_ptr<osg::Vec4ubArray> c = new osg::Vec4ubArray;
        for (size_t i = 0; i < m.positions.size(); ++i) {
            v->push_back({m.positions[i].x, m.positions[i].y, m.positions[i].z});
            c->push_back({m.colors[i].x, m.colors[i].y, m.colors[i].z, m.colors[i].w});
        }
        c->setNormalize(true);
        g->setVertexArray(v.get());
        g->setColorArray(c.get(), osg::Array::BIND_PER_VERTEX);
        osg::ref_ptr<osg::DrawElementsUInt> de = new osg::DrawElementsUInt(GL_TRIANGLES);
        for (uint32_t i : m.indices) de->push_back(i);
        g->addPrimitiveSet(de.get());
        g->setUseDisplayList(false);
        g->setUseVertexBufferObjects(true);
        osg::ref_ptr<osg::Geode> geode = new osg::Geode;
        geode->addDrawable(g.get());
        osg::ref_ptr<osg::MatrixTransform> mt = new osg::MatrixTransform(osg::Matrixd::translate(m.origin.x, m.origin.y, m.origin.z));
        mt->addChild(geode.get());
        root->addChild(mt.get());
    }
    return root;
}

// A little "city": ground and a few coloured blocks, far from the world origin.
const glm::dvec3 kWorld(1.0e6, 2.0e6, 0.0);
SceneModel tinyCity() {
    SceneModel c;
    SceneMesh ground;
    ground.origin = kWorld;
    addQuad(ground, {-400, -400, 0}, {400, -400, 0}, {400, 400, 0}, {-400, 400, 0}, {90, 110, 80, 255});
    c.meshes.push_back(ground);
    SceneMesh blocks;
    blocks.origin = kWorld + glm::dvec3(0, 100, 0);
    addBox(blocks, {-60, -20, 0}, {-20, 20, 30}, {200, 80, 60, 255});
    addBox(blocks, {10, -10, 0}, {40, 30, 55}, {60, 90, 200, 255});
    addBox(blocks, {-15, 80, 0}, {25, 120, 90}, {220, 210, 170, 255});
    c.meshes.push_back(blocks);
    for (const auto& m : c.meshes) c.triangles += m.indices.size() / 3;
    setSceneRoot(c, sceneOf(c.meshes));
    return c;
}

Camera testCamera(int w = 96, int h = 72) {
    Camera c;
    c.width = w;
    c.height = h;
    c.fovY = 60.0 * kPi / 180.0;
    c.eye = kWorld + glm::dvec3(0, 0, 1.7);
    return c;
}

std::string tmpDir(const std::string& name) {
    fs::path p = fs::temp_directory_path() / ("vista_test_bench_" + std::to_string(::getpid()) + "_" + name);
    fs::create_directories(p);
    return p.string();
}

int runVista(const std::string& args, std::string* output = nullptr) {
    std::string log = tmpDir("cli") + "/out.txt";
    int rc = std::system((std::string(VISTA_BINARY) + " " + args + " > " + log + " 2>&1").c_str());
    if (output) {
        std::ifstream f(log);
        std::stringstream ss;
        ss << f.rdbuf();
        *output = ss.str();
    }
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

}  // namespace

TEST(Offscreen, SkyBackgroundMatchesTheCpuSkyExactly) {
    REQUIRE_DISPLAY();
    auto r = OffscreenRenderer::create(96, 72);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    osg::ref_ptr<osg::Group> empty = new osg::Group;
    Camera cam = testCamera();
    cam.pitch = 0.15;  // horizon below the centre: rows differ top to bottom
    Image img, sky;
    FrameStats st;
    ASSERT_TRUE(r.value()->render(empty.get(), cam, 0.0, &img, nullptr, st).isOk());
    renderSky(cam, sky);
    EXPECT_EQ(lumaPsnr(img, sky), kPsnrCapDb);
    EXPECT_NE(img.at(0, 0), img.at(0, 71));  // the gradient is there, row 0 at the top
    EXPECT_EQ(st.triangles, 0u);              // the background is not counted
}

TEST(Offscreen, ColourDepthOrientationAndCounts) {
    REQUIRE_DISPLAY();
    auto r = OffscreenRenderer::create(96, 72);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    // A red wall 50 m ahead (north) covering the upper half of a level view
    // (from eye height up), in a tile far from the world origin.
    SceneMesh wall;
    wall.origin = kWorld + glm::dvec3(0, 50, 0);
    addQuad(wall, {-500, 0, 1.7f}, {500, 0, 1.7f}, {500, 0, 900}, {-500, 0, 900}, {255, 0, 0, 255});
    auto scene = sceneOf({wall});
    Camera cam = testCamera();
    Image img;
    std::vector<float> depth;
    FrameStats st;
    ASSERT_TRUE(r.value()->render(scene.get(), cam, 0.0, &img, &depth, st).isOk());
    EXPECT_EQ(img.at(48, 0), glm::u8vec4(255, 0, 0, 255));   // top: wall
    EXPECT_EQ(img.at(48, 71), skyColor(std::asin(cam.rayDirection(48.5, 71.5).z)));  // bottom: sky
    ASSERT_EQ(depth.size(), size_t(96 * 72));
    // Infinite far plane: window depth = 1 - zNear / distance.
    double d0 = depth[size_t(0 * 96 + 48)];
    double dist = 50.0 / glm::dot(cam.rayDirection(48.5, 0.5), cam.forward()) * glm::dot(cam.rayDirection(48.5, 0.5), cam.forward());
    EXPECT_NEAR(d0, 1.0 - cam.zNear / dist, 1e-5);
    EXPECT_EQ(depth[size_t(71 * 96 + 48)], 1.0f);
    EXPECT_EQ(st.triangles, 2u);
    EXPECT_EQ(st.drawCalls, 1u);
    EXPECT_GT(st.frameMs, 0.0);

    // Near plane at 40 m: the wall at 50 m is gone.
    ASSERT_TRUE(r.value()->render(scene.get(), cam, 40.0, &img, nullptr, st).isOk());
    EXPECT_EQ(img.at(48, 0), skyColor(std::asin(cam.rayDirection(48.5, 0.5).z)));
    // A small object wholly beyond the near plane is culled, not just clipped.
    SceneMesh far;
    far.origin = kWorld + glm::dvec3(0, 200, 0);
    addQuad(far, {-5, 0, 0}, {5, 0, 0}, {5, 0, 10}, {-5, 0, 10}, {0, 255, 0, 255});
    auto farScene = sceneOf({far});
    ASSERT_TRUE(r.value()->render(farScene.get(), cam, 40.0, &img, nullptr, st).isOk());
    EXPECT_EQ(st.triangles, 0u);
    ASSERT_TRUE(r.value()->render(farScene.get(), cam, 0.0, &img, nullptr, st).isOk());
    EXPECT_EQ(st.triangles, 2u);
}

TEST(Offscreen, BadSizesAndMismatchedCameras) {
    EXPECT_FALSE(OffscreenRenderer::create(0, 0).isOk());
    REQUIRE_DISPLAY();
    auto r = OffscreenRenderer::create(32, 24);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    Image img;
    FrameStats st;
    osg::ref_ptr<osg::Group> empty = new osg::Group;
    EXPECT_FALSE(r.value()->render(empty.get(), testCamera(64, 48), 0.0, &img, nullptr, st).isOk());
}

TEST(Bench, ModeTableAndParsing) {
    auto m = parseModeList("full,near,raycast,osgimpostor");
    ASSERT_TRUE(m.isOk());
    EXPECT_EQ(m->size(), 4u);
    auto bad = parseModeList("full,warp");
    ASSERT_FALSE(bad.isOk());
    EXPECT_NE(bad.status().message().find("available modes: full, near, raycast, osgimpostor"), std::string::npos)
        << bad.status().message();
    EXPECT_FALSE(parseModeList("full,full").isOk());
    BenchContext ctx;
    EXPECT_FALSE(makeMode("nope", ctx).isOk());
    BenchConfig c;
    c.frames = 0;
    EXPECT_FALSE(validateBenchConfig(c).isOk());
    c.frames = 1;
    c.width = 0;
    EXPECT_FALSE(validateBenchConfig(c).isOk());
    EXPECT_DOUBLE_EQ(percentile({3, 1, 2}, 0.5), 2.0);
    EXPECT_DOUBLE_EQ(percentile({1, 2, 3, 4, 5}, 0.95), 4.8);
}

TEST(Bench, SyntheticSceneSmokeRun) {
    REQUIRE_DISPLAY();
    SceneModel city = tinyCity();
    Path path;
    for (int i = 0; i < 4; ++i) {
        PathSample s;
        s.t = i;
        s.position = kWorld + glm::dvec3(0, -30.0 + 5 * i, 1.7);
        s.heading = 0.1 * i;
        path.samples.push_back(s);
    }
    BenchConfig cfg;
    cfg.width = 96;
    cfg.height = 72;
    cfg.frames = 3;
    cfg.modes = {"near", "osgimpostor"};  // full is added as the reference
    cfg.options.nearDistance = 120;
    cfg.outDir = tmpDir("smoke");
    cfg.quiet = true;
    auto r = runBenchmark(nullptr, sceneRoot(city), path, cfg);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    ASSERT_EQ(r->modes.size(), 3u);
    EXPECT_EQ(r->modes[0].mode, "full");
    EXPECT_EQ(r->modes[0].psnrDbMin, kPsnrCapDb);
    EXPECT_DOUBLE_EQ(r->modes[0].speedupVsFullMedian, 1.0);
    EXPECT_GT(r->modes[0].trianglesMedian, 0.0);
    EXPECT_LE(r->modes[1].trianglesMedian, r->modes[0].trianglesMedian);

    std::ifstream f(cfg.outDir + "/summary.json");
    ASSERT_TRUE(f.good());
    auto j = nlohmann::json::parse(f);
    for (const char* mode : {"full", "near", "osgimpostor"})
        for (const char* key : {"frame_ms_median", "frame_ms_p95", "speedup_vs_full_median", "psnr_db_median",
                                "psnr_db_min", "triangles_median"}) {
            ASSERT_TRUE(j["modes"].contains(mode)) << mode;
            EXPECT_TRUE(j["modes"][mode].contains(key)) << mode << "." << key;
            EXPECT_TRUE(j["modes"][mode][key].is_number()) << mode << "." << key;
        }
    std::ifstream csv(cfg.outDir + "/frames.csv");
    int lines = 0;
    for (std::string l; std::getline(csv, l);) ++lines;
    EXPECT_EQ(lines, 1 + 3 * 3);
    for (const char* file : {"frame_time.png", "quality.png", "images/first_full.png"})
        EXPECT_TRUE(fs::exists(cfg.outDir + "/" + file)) << file;
    fs::remove_all(cfg.outDir);
}

TEST(Bench, SupersampledReferenceIsCloserToItselfThanAliasedFrames) {
    REQUIRE_DISPLAY();
    SceneModel city = tinyCity();
    Path path;
    PathSample s;
    s.position = kWorld + glm::dvec3(0, -20, 1.7);
    path.samples.push_back(s);
    BenchConfig cfg;
    cfg.width = 64;
    cfg.height = 48;
    cfg.frames = 1;
    cfg.modes = {"full"};
    cfg.referenceSsaa = 3;
    cfg.quiet = true;
    auto r = runBenchmark(nullptr, sceneRoot(city), path, cfg);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    // The aliased full frame differs from the 3x3 supersampled reference
    // (edges), but stays close to it.
    EXPECT_LT(r->modes[0].psnrDbMin, kPsnrCapDb);
    EXPECT_GT(r->modes[0].psnrDbMin, 20.0);
}

// Ray casting and rasterising the same prelit scene agree: on a still frame
// luma PSNR >= 30 dB (differences only along edges, where pixel centres fall
// on different sides of a triangle edge).
TEST(Bench, RaycastAgreesWithFull) {
    REQUIRE_DISPLAY();
    SceneModel city = tinyCity();
    auto rs = RayScene::build(city);
    ASSERT_TRUE(rs.isOk()) << rs.status().message();
    auto r = OffscreenRenderer::create(160, 120);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    BenchContext ctx;
    ctx.city = &city;
    ctx.scene = sceneRoot(city);
    ctx.renderer = r.value().get();
    ctx.rays = rs.value().get();
    auto full = makeMode("full", ctx), ray = makeMode("raycast", ctx);
    ASSERT_TRUE(full.isOk());
    ASSERT_TRUE(ray.isOk()) << ray.status().message();
    Camera cam = testCamera(160, 120);
    cam.eye = kWorld + glm::dvec3(-10, -40, 1.7);
    cam.heading = 0.15;
    Image a, b;
    FrameStats sa, sb;
    ASSERT_TRUE(full.value()->renderFrame(cam, a, sa).isOk());
    ASSERT_TRUE(ray.value()->renderFrame(cam, b, sb).isOk());
    double psnr = lumaPsnr(a, b);
    EXPECT_GE(psnr, 30.0) << "raycast vs full";
    std::printf("raycast vs full on a still frame: %.2f dB, %.4f of pixels differ by > 8\n", psnr, fractionDiffering(a, b, 8));
    EXPECT_GT(sb.pixels.rayHit, 0u);
    EXPECT_GT(sb.pixels.rayMiss, 0u);
    EXPECT_EQ(sb.pixels.rayHit + sb.pixels.rayMiss, uint64_t(160 * 120));
}

TEST(BenchCli, BadInputExitsWithTwo) {
    ASSERT_TRUE(fs::exists(VISTA_BINARY)) << "the vista binary is a build dependency of this test";
    std::string dir = tmpDir("badcli"), out;
    std::string dummy = dir + "/dummy.osgb";
    std::ofstream(dummy) << "x";
    EXPECT_EQ(runVista("bench " + dir + "/missing.osgb --out " + dir + "/o", &out), 2) << out;
    EXPECT_NE(out.find("missing.osgb"), std::string::npos) << out;
    EXPECT_EQ(runVista("bench " + dummy + " --modes full,warp --out " + dir + "/o", &out), 2) << out;
    EXPECT_NE(out.find("available modes"), std::string::npos) << out;
    EXPECT_EQ(runVista("bench " + dummy + " --size 0x0 --out " + dir + "/o", &out), 2) << out;
    EXPECT_NE(out.find("--size"), std::string::npos) << out;
    EXPECT_EQ(runVista("bench " + dummy + " --frames 0 --out " + dir + "/o", &out), 2) << out;
    EXPECT_NE(out.find("--frames"), std::string::npos) << out;
    EXPECT_EQ(runVista("path " + dir + "/missing.osgb -o " + dir + "/p.csv", &out), 2) << out;
    EXPECT_EQ(runVista("bench " + dummy + " --reference ssaa:99 --out " + dir + "/o", &out), 2) << out;
    fs::remove_all(dir);
}

// End to end on a generated tiny city: gen -> path -> bench (all modes).
TEST(BenchCli, TinyGeneratedCity) {
    REQUIRE_DISPLAY();
    ASSERT_TRUE(fs::exists(VISTA_BINARY)) << "the vista binary is a build dependency of this test";
    std::string dir = tmpDir("e2e"), out;
    std::string city = dir + "/tiny.osgb";
    ASSERT_EQ(runVista("gen --size 300 --seed 3 -q -o " + city, &out), 0) << out;
    auto loaded = loadCityFile(city);
    ASSERT_TRUE(loaded.isOk()) << loaded.status().message();
    ASSERT_EQ(runVista("path " + city + " --seed 4 --duration 10 -o " + dir + "/p.csv", &out), 0) << out;
    {  // the path drives on the generated city's streets
        auto p = loadPathCsv(dir + "/p.csv");
        ASSERT_TRUE(p.isOk()) << p.status().message();
        const auto& L = loaded.value();
        glm::dvec2 origin(L.params.origin_x, L.params.origin_y);
        for (const auto& s : p->samples) {
            int e = -1;
            double d = distanceToStreets(L.streets, glm::dvec2(s.position) - origin, &e);
            ASSERT_GE(e, 0);
            EXPECT_LE(d, 0.5 * L.streets.edges[size_t(e)].width + 0.5) << "t = " << s.t;
        }
    }
    std::string modes = "full,near,osgimpostor";
    if (RayScene::build(loaded.value()).isOk()) modes += ",raycast";
    ASSERT_EQ(runVista("bench " + city + " --path " + dir + "/p.csv --frames 3 --size 96x72 -q --modes " + modes +
                           " --out " + dir + "/bench",
                       &out),
              0)
        << out;
    std::ifstream f(dir + "/bench/summary.json");
    auto j = nlohmann::json::parse(f);
    EXPECT_EQ(j["modes"].size(), size_t(std::count(modes.begin(), modes.end(), ',') + 1));
    EXPECT_TRUE(j["modes"]["full"]["frame_ms_median"].is_number());
    EXPECT_TRUE(fs::exists(dir + "/bench/frame_time.png"));

    // The viewer runs headless for a few frames and writes a screenshot.
    ASSERT_EQ(runVista("view " + city + " --seed 2 --size 160x120 --frames 3 --screenshot " + dir + "/shot.png", &out), 0)
        << out;
    auto shot = readPng(dir + "/shot.png");
    ASSERT_TRUE(shot.isOk()) << shot.status().message();
    EXPECT_EQ(shot->width, 160);
    EXPECT_EQ(shot->height, 120);
    EXPECT_EQ(runVista("view " + dir + "/missing.osgb --frames 1", &out), 2) << out;
    fs::remove_all(dir);
}

TEST(Bench, FarFieldOptionParsing) {
    auto n = parseNearDistance("auto");
    ASSERT_TRUE(n.isOk());
    EXPECT_LT(n.value(), 0.0);
    EXPECT_DOUBLE_EQ(parseNearDistance("250").value(), 250.0);
    for (const char* bad : {"-5", "0", "0.5", "100001", "abc", "", "12m", "nan"}) {
        auto r = parseNearDistance(bad);
        ASSERT_FALSE(r.isOk()) << bad;
        EXPECT_NE(r.status().message().find("--near"), std::string::npos) << r.status().message();
    }
    EXPECT_EQ(parsePixelBudget("unlimited").value(), -1);
    EXPECT_EQ(parsePixelBudget("-1").value(), -1);
    EXPECT_EQ(parsePixelBudget("0").value(), 0);
    EXPECT_EQ(parsePixelBudget("1000").value(), 1000);
    for (const char* bad : {"-7", "1e3", "x", "", "1000000001"}) {
        auto r = parsePixelBudget(bad);
        ASSERT_FALSE(r.isOk()) << bad;
        EXPECT_NE(r.status().message().find("--budget"), std::string::npos) << r.status().message();
    }
    BenchConfig c;
    c.options.horizonGrid = 0;
    auto s = validateBenchConfig(c);
    ASSERT_FALSE(s.isOk());
    EXPECT_NE(s.message().find("--horizon-grid"), std::string::npos) << s.message();
    c.options.horizonGrid = 8192;
    c.options.nearDistance = -1;  // auto
    EXPECT_TRUE(validateBenchConfig(c).isOk());
    c.options.nearDistance = 0.5;
    EXPECT_FALSE(validateBenchConfig(c).isOk());
}

TEST(BenchCli, FarFieldFlagsRejectBadValues) {
    ASSERT_TRUE(fs::exists(VISTA_BINARY)) << "the vista binary is a build dependency of this test";
    std::string dir = tmpDir("badff"), out;
    std::string dummy = dir + "/dummy.osgb";
    std::ofstream(dummy) << "x";
    const std::pair<const char*, const char*> bad[] = {
        {"--near -5", "--near"}, {"--near abc", "--near"}, {"--horizon-grid 0", "--horizon-grid"},
        {"--budget -7", "--budget"}, {"--horizon-grid 9000", "--horizon-grid"}};
    for (const auto& [args, flag] : bad) {
        EXPECT_EQ(runVista("bench " + dummy + " " + args + " --out " + dir + "/o", &out), 2) << args << ": " << out;
        EXPECT_NE(out.find(flag), std::string::npos) << args << ": " << out;
    }
    fs::remove_all(dir);
}

// Hybrid on a generated tiny city: per-mode pixel classes and stage times in
// summary.json; the far-field flags are accepted and recorded.
TEST(BenchCli, HybridPixelClassesAndOptions) {
    REQUIRE_DISPLAY();
    ASSERT_TRUE(fs::exists(VISTA_BINARY)) << "the vista binary is a build dependency of this test";
    std::string dir = tmpDir("hybrid"), out;
    std::string city = dir + "/tiny.osgb";
    ASSERT_EQ(runVista("gen --size 300 --seed 3 -q -o " + city, &out), 0) << out;
    struct Run {
        std::string flags;
        nlohmann::json near, budget;
        int grid;
        bool cache;
    };
    const Run runs[] = {
        {"--near auto --budget 1000 --no-cache --horizon-grid 64", "auto", 1000, 64, false},
        {"--near 60 --budget unlimited", 60.0, "unlimited", 512, true},
    };
    for (size_t i = 0; i < 2; ++i) {
        const Run& r = runs[i];
        std::string o = dir + "/b" + std::to_string(i);
        ASSERT_EQ(runVista("bench " + city + " --seed 4 --duration 10 --frames 3 --size 160x120 -q --modes full,hybrid " +
                               r.flags + " --out " + o,
                           &out),
                  0)
            << r.flags << ": " << out;
        std::ifstream f(o + "/summary.json");
        ASSERT_TRUE(f.good()) << r.flags;
        auto j = nlohmann::json::parse(f);
        const auto& opt = j["options"];
        EXPECT_EQ(opt["near_m"], r.near) << r.flags;
        EXPECT_EQ(opt["pixel_budget"], r.budget) << r.flags;
        EXPECT_EQ(opt["horizon_grid"], r.grid) << r.flags;
        EXPECT_EQ(opt["cache"], r.cache) << r.flags;
        ASSERT_TRUE(j["modes"]["hybrid"].contains("pixels")) << j["modes"]["hybrid"].dump();
        const auto& px = j["modes"]["hybrid"]["pixels"];
        double sum = 0;
        for (const char* cls : {"covered", "horizon_culled", "cache", "ray_hit", "ray_miss"}) {
            ASSERT_TRUE(px.contains(cls)) << cls;
            for (const char* k : {"min_pct", "mean_pct", "max_pct", "mean_count"})
                ASSERT_TRUE(px[cls][k].is_number()) << cls << "." << k;
            EXPECT_LE(px[cls]["min_pct"].get<double>(), px[cls]["mean_pct"].get<double>() + 1e-9) << cls;
            EXPECT_LE(px[cls]["mean_pct"].get<double>(), px[cls]["max_pct"].get<double>() + 1e-9) << cls;
            EXPECT_NEAR(px[cls]["mean_count"].get<double>(), px[cls]["mean_pct"].get<double>() / 100.0 * 160 * 120, 1e-6);
            sum += px[cls]["mean_pct"].get<double>();
        }
        EXPECT_NEAR(sum, 100.0, 0.1) << px.dump();
        if (!r.cache) {
            EXPECT_EQ(px["cache"]["max_pct"].get<double>(), 0.0);
        }
        // Stage times: every stage that ran has a mean and a run count within the frame count.
        const auto& stages = j["modes"]["hybrid"]["stages_ms"];
        ASSERT_TRUE(stages.contains("opacity")) << stages.dump();
        for (auto it = stages.begin(); it != stages.end(); ++it) {
            EXPECT_GE(it.value().get<double>(), 0.0) << it.key();
            int runsN = j["modes"]["hybrid"]["stage_runs"][it.key()].get<int>();
            EXPECT_GE(runsN, 1) << it.key();
            EXPECT_LE(runsN, 3) << it.key();
        }
        EXPECT_FALSE(j["modes"]["full"].contains("pixels"));  // full classifies nothing (documented)
    }

    // The viewer's hybrid mode: from the (static) street start position it
    // shows the same picture as full below the HUD text.
    Image shots[2];
    const char* viewModes[2] = {"full", "hybrid"};
    for (int i = 0; i < 2; ++i) {
        std::string png = dir + "/view_" + viewModes[i] + ".png";
        ASSERT_EQ(runVista("view " + city + " --mode " + viewModes[i] + " --size 320x240 --frames 3 --screenshot " + png, &out), 0)
            << out;
        auto img = readPng(png);
        ASSERT_TRUE(img.isOk()) << img.status().message();
        ASSERT_EQ(img->width, 320);
        ASSERT_EQ(img->height, 240);
        Image crop(320, 100);  // rows 140 .. 239: below the HUD lines
        for (int y = 0; y < 100; ++y)
            for (int x = 0; x < 320; ++x) crop.set(x, y, img->at(x, 140 + y));
        shots[i] = crop;
    }
    const double viewPsnr = lumaPsnr(shots[1], shots[0]);
    EXPECT_GE(viewPsnr, 30.0) << "view hybrid vs full";
    std::printf("vista view hybrid vs full (rows below the HUD): %.2f dB\n", viewPsnr);
    fs::remove_all(dir);
}
