// `vista view`: every mode shows the picture `vista bench` renders for the
// same camera, stepped and played headless, with haze too. Needs an X display
// (run under `xvfb-run -a`; the tests skip with a message without one).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "nodes/render/render_mode.h"
#include "runtime/engine/image.h"
#include "runtime/engine/metrics.h"
#include "tests/common/run_vista.h"
#include "tests/common/temp_dir.h"
#include "tests/nodes/render/render_fixtures.h"

using namespace vista;
namespace fs = std::filesystem;
using vista::test::TempDir;

namespace {

// One vista run; its stderr (where vista reports) in *output.
int runVista(const std::string& args, std::string* output) {
    const vista::test::CliRun r = vista::test::runVista(args);
    *output = r.err;
    return r.code;
}

}  // namespace

TEST(ViewCli, EveryModeShowsTheBenchPicture) {
    REQUIRE_DISPLAY();
    ASSERT_TRUE(fs::exists(VISTA_BINARY)) << "the vista binary is a build dependency of this test";
    TempDir tmp("vista_view_cli");
    const std::string dir = tmp.path();
    std::string out;
    const std::string city = dir + "/tiny.osgb", baked = dir + "/tiny.baked.osgb", path = dir + "/p.csv";
    const std::string meshes = dir + "/tiny.mesh.osgb";
    ASSERT_EQ(runVista("gen --size 300 --seed 3 -q -o " + city, &out), 0) << out;
    ASSERT_EQ(runVista("bake " + city + " -o " + baked +
                           " --out-size 120 --min-triangles 1 --placement all --max-rays 20000 -q",
                       &out),
              0)
        << out;
    ASSERT_EQ(
        runVista("bake " + city + " -o " + meshes + " --representation mesh --out-size 120 --min-triangles 1 -q", &out),
        0)
        << out;
    ASSERT_EQ(runVista("path " + city + " --seed 4 --duration 10 -o " + path, &out), 0) << out;
    const std::string common =
        " --path " + path + " --size 160x120 --near 30 --budget unlimited --baked " + baked + " --baked-mesh " + meshes;
    std::string all;
    for (const auto& info : renderModes()) all += (all.empty() ? "" : ",") + std::string(info.name);
    ASSERT_EQ(runVista("bench " + city + common + " --frames 1 -q --modes " + all + " --out " + dir + "/b", &out), 0)
        << out;
    for (const auto& info : renderModes()) {
        const std::string mode = info.name, png = dir + "/view_" + mode + ".png";
        ASSERT_EQ(
            runVista("view " + city + common + " --mode " + mode + " --step --frames 1 --no-hud --screenshot " + png,
                     &out),
            0)
            << mode << ": " << out;
        auto view = readPng(png);
        ASSERT_TRUE(view.isOk()) << mode << ": " << view.status().message();
        auto bench = readPng(dir + "/b/images/first_" + mode + ".png");
        ASSERT_TRUE(bench.isOk()) << mode << ": " << bench.status().message();
        ASSERT_EQ(view->width, 160);
        ASSERT_EQ(view->height, 120);
        const double psnr = lumaPsnr(view.value(), bench.value());
        EXPECT_GE(psnr, kPsnrCapDb - 0.5) << mode << ": view and bench differ";
        std::printf("view vs bench, %s: %.2f dB\n", mode.c_str(), psnr);
    }
    // Interactive playback (not --step) of every mode runs headless too, with the HUD.
    for (const auto& info : renderModes()) {
        const std::string png = dir + "/play.png";
        EXPECT_EQ(runVista("view " + city + " --seed 2 --size 160x120 --frames 3 --baked " + baked + " --baked-mesh " +
                               meshes + " --mode " + info.name + " --screenshot " + png,
                           &out),
                  0)
            << info.name << ": " << out;
        EXPECT_TRUE(readPng(png).isOk()) << info.name;
        fs::remove(png);
    }
}

// Haze in hybrid is applied to the read-back pixels (FarFieldOptions::
// hazeCovered) in both faces: the viewer shows the bench's hazed picture, and
// the hazed hybrid picture agrees with full (which hazes in the rasteriser).
TEST(ViewCli, HybridHazeShowsTheBenchPicture) {
    REQUIRE_DISPLAY();
    ASSERT_TRUE(fs::exists(VISTA_BINARY)) << "the vista binary is a build dependency of this test";
    TempDir tmp("vista_view_haze");
    const std::string dir = tmp.path();
    std::string out;
    const std::string city = dir + "/tiny.osgb", path = dir + "/p.csv";
    ASSERT_EQ(runVista("gen --size 300 --seed 5 -q -o " + city, &out), 0) << out;
    ASSERT_EQ(runVista("path " + city + " --seed 2 --duration 10 -o " + path, &out), 0) << out;
    const std::string common =
        " --path " + path + " --size 160x120 --near 40 --effects '{\"haze\":{\"visibility_m\":80}}'";
    ASSERT_EQ(runVista("bench " + city + common + " --frames 1 -q --modes full,hybrid --out " + dir + "/b", &out), 0)
        << out;
    ASSERT_EQ(
        runVista("bench " + city + " --path " + path +
                     " --size 160x120 --near 40 --effects none --frames 1 -q --modes hybrid --out " + dir + "/clear",
                 &out),
        0)
        << out;
    const std::string png = dir + "/view_hybrid.png";
    auto hybrid = readPng(dir + "/b/images/first_hybrid.png"), full = readPng(dir + "/b/images/first_full.png"),
         clear = readPng(dir + "/clear/images/first_hybrid.png");
    ASSERT_TRUE(hybrid.isOk() && full.isOk() && clear.isOk());
    // The viewer's window: under a loaded CI run (ctest -j2, no window
    // manager) the X server has once mapped it at another size than asked
    // before the frame was drawn (one failure in many runs, never reproduced
    // alone). What this test checks is the haze, not window placement: the
    // screenshot is retaken (at most 3 tries) until it has the asked size.
    Result<Image> view = Status::error("no screenshot");
    for (int attempt = 0; attempt < 3; ++attempt) {
        ASSERT_EQ(
            runVista("view " + city + common + " --mode hybrid --step --frames 1 --no-hud --screenshot " + png, &out),
            0)
            << out;
        view = readPng(png);
        ASSERT_TRUE(view.isOk()) << view.status().message();
        if (view.value().width == hybrid.value().width && view.value().height == hybrid.value().height) break;
    }
    ASSERT_EQ(view.value().width, hybrid.value().width) << "the viewer's screenshot is not 160x120";
    ASSERT_EQ(view.value().height, hybrid.value().height) << "the viewer's screenshot is not 160x120";
    EXPECT_GE(lumaPsnr(view.value(), hybrid.value()), kPsnrCapDb - 0.5) << "view and bench differ with haze";
    EXPECT_GE(lumaPsnr(hybrid.value(), full.value()), 40.0) << "hybrid's haze pass and the rasteriser's haze differ";
    EXPECT_LT(lumaPsnr(hybrid.value(), clear.value()), 28.0) << "80 m haze must change the picture";
}
