// Effects end to end through the `vista` tool (xvfb): every effect generated,
// rendered by the rasteriser and the ray caster alike (hybrid and raycast vs
// full >= 40 dB), every effect together 1,000 km from the origin, bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <sys/wait.h>

#include <nlohmann/json.hpp>

#include "tests/common/temp_dir.h"

namespace fs = std::filesystem;

namespace {

struct CliResult {
    int code = -1;
    std::string err;
};

CliResult vista(const std::string& args, const std::string& dir) {
    const std::string errFile = dir + "/stderr.txt";
    const std::string cmd = std::string(VISTA_BINARY) + " " + args + " 2>" + errFile + " >/dev/null";
    const int st = std::system(cmd.c_str());
    CliResult r;
    r.code = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    r.err = vista::test::readBytes(errFile);
    return r;
}

nlohmann::json readJson(const std::string& path) {
    std::ifstream in(path);
    nlohmann::json j;
    in >> j;
    return j;
}

bool haveDisplay() {
    const char* d = std::getenv("DISPLAY");
    return d && *d;
}

struct EffectCase {
    const char* name;
    const char* spec;  // --effects of vista gen
    double originX;
};

class EffectRender : public ::testing::TestWithParam<EffectCase> {};

TEST_P(EffectRender, RasterAndRayCasterAgreeWithTheEffectOn) {
    if (!haveDisplay()) GTEST_SKIP() << "needs an X display (run under xvfb-run)";
    const EffectCase& c = GetParam();
    vista::test::TempDir dir("vista_effect");
    const std::string city = dir.file("c.osgb"), stats = dir.file("s.json"), out = dir.file("bench");
    std::string gen = "gen --size 500 --seed 5 -q -o " + city + " --stats " + stats + " --effects '" + c.spec + "'";
    if (c.originX != 0) {
        std::ofstream(dir.file("p.json")) << "{\"origin_x\": " << c.originX << ", \"origin_y\": -" << c.originX << "}";
        gen += " --params " + dir.file("p.json");
    }
    CliResult g = vista(gen, dir.path());
    ASSERT_EQ(g.code, 0) << g.err;
    const auto s = readJson(stats);
    ASSERT_TRUE(s["effects"].is_object());
    EXPECT_FALSE(s["effects"].empty()) << "the stats name the declared effects";
    CliResult b =
        vista("bench " + city + " --seed 2 --frames 4 --modes full,hybrid,raycast --out " + out + " -q", dir.path());
    ASSERT_EQ(b.code, 0) << b.err;
    const auto j = readJson(out + "/summary.json");
    EXPECT_EQ(j["effects"], s["effects"]) << "the bench reads the effects from the scene file";
    for (const char* m : {"full", "hybrid", "raycast"}) {
        const auto& mj = j["modes"][m];
        ASSERT_TRUE(mj["frame_ms_median"].is_number()) << m << ": a non-finite time";
        ASSERT_TRUE(mj["psnr_db_median"].is_number()) << m;
        ASSERT_TRUE(mj["psnr_db_min"].is_number()) << m;
    }
    EXPECT_GE(j["modes"]["hybrid"]["psnr_db_median"].get<double>(), 40.0) << c.name;
    EXPECT_GE(j["modes"]["raycast"]["psnr_db_median"].get<double>(), 40.0) << c.name;
    const std::string spec = c.spec;
    if (spec.find("haze") != std::string::npos) {
        EXPECT_EQ(j["modes"]["hybrid"]["effect_runs"]["haze"], 4) << "haze ran in every frame";
    }
    if (spec.find("glass") != std::string::npos && j["modes"]["full"]["glass_pixels_mean"].get<double>() > 0) {
        EXPECT_GT(j["modes"]["full"]["reflection_rays_mean"].get<double>(), 0.0);
        EXPECT_GT(j["modes"]["hybrid"]["effects_ms"]["glass"].get<double>(), 0.0);
    }
}

INSTANTIATE_TEST_SUITE_P(
    EachEffect, EffectRender,
    ::testing::Values(EffectCase{"sun_shadows", R"({"sun_shadows":{"resolution_m":4}})", 0},
                      EffectCase{"ambient_occlusion", R"({"ambient_occlusion":{"samples":4,"resolution_m":4}})", 0},
                      EffectCase{"haze", R"({"haze":{"visibility_m":300}})", 0}, EffectCase{"glass", "glass", 0},
                      EffectCase{"night", "night", 0}, EffectCase{"materials", "materials", 0},
                      EffectCase{
                          "all_far_away",
                          R"({"sun_shadows":{"resolution_m":4},"ambient_occlusion":{"samples":4,"resolution_m":4},)"
                          R"("haze":{"visibility_m":400},"glass":{},"night":{},"materials":{}})",
                          1e6}),
    [](const ::testing::TestParamInfo<EffectCase>& i) { return std::string(i.param.name); });

TEST(EffectsCli, BadEffectsExitTwoNameTheFieldAndLeaveNoFile) {
    vista::test::TempDir dir("vista_effect_cli");
    const std::string out = dir.file("x.osgb");
    struct Case {
        std::string spec;
        std::vector<std::string> mustSay;
    };
    const Case cases[] = {
        {"fog", {"unknown effect 'fog'", "sun_shadows", "haze"}},
        {R"({"haze":{"visibility_m":5}})", {"'visibility_m'", "[20, 1000000]"}},
        {R"({"glass":{"reflectance":2}})", {"'reflectance'", "[0, 1]"}},
        {"haze,", {"empty effect name"}},
    };
    for (const auto& c : cases) {
        CliResult r = vista("gen --size 300 -q -o " + out + " --effects '" + c.spec + "'", dir.path());
        EXPECT_EQ(r.code, 2) << c.spec << ": " << r.err;
        for (const auto& s : c.mustSay) EXPECT_NE(r.err.find(s), std::string::npos) << c.spec << " -> " << r.err;
        EXPECT_FALSE(fs::exists(out)) << c.spec;
    }
    // The same checks hold in a parameter file.
    std::ofstream(dir.file("p.json")) << R"({"effects": {"night": {"lit_share": -1}}})";
    CliResult r = vista("gen -q -o " + out + " --params " + dir.file("p.json"), dir.path());
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("'lit_share'"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
}

TEST(EffectsCli, NoEffectsIsByteIdenticalAndBenchRejectsUnknownEffects) {
    vista::test::TempDir dir("vista_effect_bytes");
    ASSERT_EQ(vista("gen --size 300 -q -o " + dir.file("a.osgb"), dir.path()).code, 0);
    ASSERT_EQ(vista("gen --size 300 -q --effects none -o " + dir.file("b.osgb"), dir.path()).code, 0);
    EXPECT_EQ(vista::test::readBytes(dir.file("a.osgb")), vista::test::readBytes(dir.file("b.osgb")));
    CliResult r =
        vista("bench " + dir.file("a.osgb") + " --effects smoke --frames 1 --out " + dir.file("o"), dir.path());
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("unknown effect 'smoke'"), std::string::npos) << r.err;
}

}  // namespace
