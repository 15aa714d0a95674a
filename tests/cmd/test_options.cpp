// The command-line value parsers of cmd/options.h: good values parse, bad
// ones are errors naming the flag and the allowed range.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "cmd/options.h"
#include "foundation/shard.h"

using namespace vista;

namespace {

// The error of a failed parse names `flag` and `range`.
template <class R>
void expectBad(const R& r, const std::string& input, const std::string& flag, const std::string& range) {
    ASSERT_FALSE(r.isOk()) << input;
    EXPECT_NE(r.status().message().find(flag), std::string::npos) << input << ": " << r.status().message();
    EXPECT_NE(r.status().message().find(range), std::string::npos) << input << ": " << r.status().message();
}

// Parses `args` as typed (the program name left out) with the options
// `declare` adds; returns the parse error's message, or "" when it parsed.
std::string parseArgs(const std::function<void(CLI::App&)>& declare, std::vector<std::string> args) {
    CLI::App app;
    declare(app);
    std::reverse(args.begin(), args.end());  // CLI11 parses the reversed vector
    try {
        app.parse(args);
    } catch (const CLI::ParseError& e) { return e.what(); }
    return "";
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST(Options, ImageSize) {
    auto s = parseImageSize("640x480");
    ASSERT_TRUE(s.isOk());
    EXPECT_EQ(s->width, 640);
    EXPECT_EQ(s->height, 480);
    EXPECT_EQ(parseImageSize("1X1")->height, 1);
    EXPECT_EQ(parseImageSize("8192x8192")->width, 8192);
    for (const char* bad : {"0x0", "8193x10", "10x8193", "640", "640x", "x480", "-5x4", "640x480x3", "64 0x480", "ax b",
                            "", "99999999999x1", "640x0x1e0", "+640x480", "640x4.8e2"})
        expectBad(parseImageSize(bad), bad, "--size", "8192");
    EXPECT_TRUE(checkImageSize(1, 1).isOk());
    EXPECT_FALSE(checkImageSize(0, 5).isOk());
}

TEST(Options, NearDistanceAndBudgets) {
    EXPECT_LT(parseNearDistance("auto").value(), 0.0);
    EXPECT_DOUBLE_EQ(parseNearDistance("250").value(), 250.0);
    EXPECT_DOUBLE_EQ(parseNearDistance("1").value(), 1.0);
    for (const char* bad : {"-5", "0", "0.5", "100001", "abc", "", "12m", "nan", "inf"})
        expectBad(parseNearDistance(bad), bad, "--near", "100000");
    EXPECT_EQ(parsePixelBudget("unlimited").value(), -1);
    EXPECT_EQ(parsePixelBudget("-1").value(), -1);
    EXPECT_EQ(parsePixelBudget("0").value(), 0);
    EXPECT_EQ(parsePixelBudget("1000000000").value(), 1000000000);
    for (const char* bad : {"-7", "1e3", "x", "", "1000000001", "99999999999999999999"})
        expectBad(parsePixelBudget(bad), bad, "--budget", "1000000000");
    for (const char* bad : {"0x10", "+5", " 5", "1e3"})
        expectBad(parsePixelBudget(bad), bad, "--budget", "[-1, 1000000000]");
    for (const char* bad : {"0x10", "1e999", "+5"}) expectBad(parseNearDistance(bad), bad, "--near", "[1, 100000]");
    ModeFlags f;
    const auto modeFlags = [&f](CLI::App& app) { addModeFlags(app, f); };
    EXPECT_EQ(parseArgs(modeFlags, {"--triangle-budget", "10000000000"}), "");
    EXPECT_EQ(f.triangleBudget, 10000000000u);
    for (const char* bad : {"-1", "1.5", "many", "", "10000000001", "0x10", "1e3"}) {
        const std::string e = parseArgs(modeFlags, {"--triangle-budget", bad});
        EXPECT_TRUE(has(e, "--triangle-budget") && has(e, "[0, 10000000000]")) << bad << ": " << e;
        EXPECT_TRUE(has(e, std::string("'") + bad + "'")) << bad << ": " << e;
    }
}

// Numeric options read by number_text: decimal only, nothing wraps or is
// cut, the error names the option, the text and the range; a value in range
// (also at the bounds) is taken as written.
TEST(Options, NumberOptionsFollowTheNumberTextRules) {
    int frames = 7;
    uint64_t budget = 3;
    size_t count = 5;
    double fov = 60, dt = 1;
    std::optional<int> detail;
    std::optional<double> size;
    const auto declare = [&](CLI::App& app) {
        addNumberOption(app, "--frames", frames, 1, 1000000, "frames");
        addNumberOption(app, "--budget", budget, 0, 100, "budget")->capture_default_str();
        addNumberOption(app, "--count", count, 0, 1000000000, "count");
        addNumberOption(app, "--fov", fov, kFovRange, "fov")->capture_default_str();
        addNumberOption(app, "--dt", dt, RealRange::openMin(0, 10), "dt");
        addNumberOption(app, "--detail", detail, 0, 3, "detail");
        addNumberOption(app, "--size", size, RealRange::closed(100, 64000), "size");
    };
    struct Bad {
        std::vector<std::string> args;
        const char* range;
    };
    const Bad bad[] = {{{"--frames", "0x10"}, "[1, 1000000]"},
                       {{"--frames", "1.5"}, "[1, 1000000]"},
                       {{"--frames", "0b11"}, "[1, 1000000]"},
                       {{"--frames", "1e3"}, "[1, 1000000]"},
                       {{"--frames", "0"}, "[1, 1000000]"},
                       {{"--frames", "1000001"}, "[1, 1000000]"},
                       {{"--frames", "4294967297"}, "[1, 1000000]"},  // 2^32 + 1: would wrap to 1 in an int
                       {{"--frames", "+5"}, "[1, 1000000]"},
                       {{"--frames", ""}, "[1, 1000000]"},
                       {{"--budget", "-1"}, "[0, 100]"},
                       {{"--budget", "101"}, "[0, 100]"},
                       {{"--budget", "18446744073709551617"}, "[0, 100]"},
                       {{"--count", "-1"}, "[0, 1000000000]"},
                       {{"--count", "1000000001"}, "[0, 1000000000]"},
                       {{"--fov", "1"}, "(1, 179)"},
                       {{"--fov", "179"}, "(1, 179)"},
                       {{"--fov", "0x3c"}, "(1, 179)"},
                       {{"--fov", "inf"}, "(1, 179)"},
                       {{"--fov", "nan"}, "(1, 179)"},
                       {{"--fov", "60deg"}, "(1, 179)"},
                       {{"--dt", "0"}, "(0, 10]"},
                       {{"--dt", "10.001"}, "(0, 10]"},
                       {{"--detail", "4"}, "[0, 3]"},
                       {{"--detail", "-1"}, "[0, 3]"},
                       {{"--size", "1e5"}, "[100, 64000]"},
                       {{"--size", "0x100"}, "[100, 64000]"}};
    for (const Bad& b : bad) {
        const std::string e = parseArgs(declare, b.args);
        EXPECT_TRUE(has(e, "option " + b.args[0])) << b.args[0] << " " << b.args[1] << ": " << e;
        EXPECT_TRUE(has(e, b.range)) << b.args[0] << " " << b.args[1] << ": " << e;
        EXPECT_TRUE(has(e, "'" + b.args[1] + "'")) << b.args[0] << " " << b.args[1] << ": " << e;
    }
    EXPECT_EQ(frames, 7) << "a refused value leaves the variable alone";
    EXPECT_EQ(budget, 3u);
    EXPECT_FALSE(detail.has_value());
    ASSERT_EQ(parseArgs(declare, {"--frames", "010", "--budget", "100", "--count", "1000000000", "--fov", "1.5", "--dt",
                                  "10", "--detail", "0", "--size", "1e2"}),
              "");
    EXPECT_EQ(frames, 10) << "leading zeros are decimal, not octal";
    EXPECT_EQ(budget, 100u);
    EXPECT_EQ(count, 1000000000u);
    EXPECT_DOUBLE_EQ(fov, 1.5);
    EXPECT_DOUBLE_EQ(dt, 10.0);
    EXPECT_EQ(detail, 0);
    EXPECT_EQ(size, 100.0);
    // The help keeps CLI11's type names, and the defaults where asked for.
    CLI::App app;
    frames = 120;
    budget = 3;
    fov = 60;
    declare(app);
    const std::string help = app.help();
    for (const char* part :
         {"--frames INT", "--budget UINT=3", "--count UINT", "--fov FLOAT=60", "--detail INT", "--size FLOAT"})
        EXPECT_TRUE(has(help, part)) << part << " not in:\n" << help;
}

TEST(Options, SamplingAndCacheKnobs) {
    EXPECT_EQ(parseSampling("spread").value(), 0);
    EXPECT_EQ(parseSampling("consecutive").value(), 1);
    EXPECT_EQ(parseSampling("runs:8").value(), 8);
    EXPECT_EQ(parseSampling("runs:100000").value(), 100000);
    for (const char* text : {"spread", "consecutive", "runs:8"})
        EXPECT_EQ(samplingName(parseSampling(text).value()), text);
    for (const char* bad :
         {"runs:0", "runs:", "runs:x", "runs:100001", "runs:-3", "every", "", "runs:0x10", "runs:1e3"})
        expectBad(parseSampling(bad), bad, "--sampling", "100000");
    ModeOptions o;
    EXPECT_TRUE(checkModeOptions(o).isOk());
    o.cacheErrorPx = -0.1;
    EXPECT_NE(checkModeOptions(o).message().find("--cache-error"), std::string::npos);
    o.cacheErrorPx = NAN;
    EXPECT_NE(checkModeOptions(o).message().find("0 .. 100"), std::string::npos);
    o.cacheErrorPx = 100;
    EXPECT_TRUE(checkModeOptions(o).isOk());
    o.frameMsTarget = 10001;
    EXPECT_NE(checkModeOptions(o).message().find("--frame-ms"), std::string::npos);
    o.frameMsTarget = 0;
    o.splatSigma = 4.5;
    EXPECT_NE(checkModeOptions(o).message().find("--point-splat"), std::string::npos);
    o.splatSigma = 0;  // off: 1-pixel points
    EXPECT_TRUE(checkModeOptions(o).isOk());
}

TEST(Options, FovReferenceAndModes) {
    EXPECT_TRUE(kFovRange.contains(1.5));
    for (double bad : {1.0, 179.0, 0.0, -60.0, 200.0, double(NAN)}) EXPECT_FALSE(checkFov(bad).isOk()) << bad;
    EXPECT_DOUBLE_EQ(parseSplatSigma("off").value(), 0.0);
    EXPECT_DOUBLE_EQ(parseSplatSigma("0.25").value(), 0.25);
    EXPECT_EQ(formatSplatSigma(0.25), "0.25");
    EXPECT_EQ(formatSplatSigma(0), "off");
    for (const char* bad : {"0.01", "4.5", "-1", "wide", "", "0x1"})
        expectBad(parseSplatSigma(bad), bad, "--point-splat", "[0.05, 4]");
    EXPECT_EQ(parseReference("full").value(), 0);
    EXPECT_EQ(parseReference("ssaa:2").value(), 2);
    EXPECT_EQ(parseReference("ssaa:8").value(), 8);
    for (const char* bad : {"ssaa:1", "ssaa:9", "ssaa:", "ssaa:x", "ssaa:4x", "half", "", "ssaa:0x2", "ssaa:+2"})
        expectBad(parseReference(bad), bad, "--reference", "[2, 8]");
    auto m = parseModeList("full, near,osglod ,hybrid");
    ASSERT_TRUE(m.isOk()) << m.status().message();
    EXPECT_EQ(m.value(), (std::vector<std::string>{"full", "near", "osglod", "hybrid"}));
    expectBad(parseModeList("full,warp"), "full,warp", "--modes",
              "available modes: full, near, raycast, osgimpostor, osglod, hybrid, hybrid-fixed, impostor");
    expectBad(parseModeList("full,full"), "full,full", "--modes", "twice");
    expectBad(parseModeList(","), ",", "--modes", "available modes");
    EXPECT_EQ(parseModeName("raycast").value(), "raycast");
    expectBad(parseModeName("fast"), "fast", "--mode", "available modes");
    EXPECT_EQ(parseSweep("sizes=500,1000").value(), (std::vector<int>{500, 1000}));
    for (const char* bad : {"sizes=50", "sizes=", "500,1000", "sizes=1000,x", "sizes=0x200", "sizes=500.5"})
        EXPECT_FALSE(parseSweep(bad).isOk()) << bad;
    expectBad(parseSweep("sizes=500,16001"), "sizes=500,16001", "--sweep", "[100, 16000]");
}

TEST(Options, ModeFlagsBecomeModeOptions) {
    ModeFlags f;
    f.near = "auto";
    f.triangleBudget = 50000;
    f.budget = "2000";
    f.horizonGrid = 64;
    f.noCache = true;
    f.threads = 2;
    ModeOptions o;
    ASSERT_TRUE(parseModeFlags(f, o).isOk());
    EXPECT_LT(o.nearDistance, 0.0);
    EXPECT_EQ(o.fixedNearDistance(), kDefaultNearDistance);
    EXPECT_EQ(o.triangleBudget, 50000u);
    EXPECT_EQ(o.pixelBudget, 2000);
    EXPECT_EQ(o.horizonGrid, 64);
    EXPECT_FALSE(o.cache);
    EXPECT_EQ(o.threads, 2);
    struct Bad {
        ModeFlags flags;
        const char* flag;
    };
    ModeFlags grid, threads, baked, near;
    grid.horizonGrid = -1;
    threads.threads = 5000;
    baked.baked = "/nonexistent/city.baked.osgb";
    near.near = "-5";
    for (const Bad& b :
         {Bad{grid, "--horizon-grid"}, Bad{threads, "--threads"}, Bad{baked, "--baked"}, Bad{near, "--near"}}) {
        Status s = parseModeFlags(b.flags, o);
        ASSERT_FALSE(s.isOk()) << b.flag;
        EXPECT_NE(s.message().find(b.flag), std::string::npos) << s.message();
    }
}

TEST(Options, PathFlags) {
    PathFlags f;
    f.kind = "walk";
    f.runUp = 0;
    auto po = parsePathFlags(f);
    ASSERT_TRUE(po.isOk()) << po.status().message();
    EXPECT_EQ(po->kind, PathKind::Walk);
    EXPECT_EQ(po->runUp, 0.0);
    EXPECT_LT(po->maxSpeed, 2.0) << "a walk goes at a walker's pace";
    f.kind = "car";
    auto car = parsePathFlags(f);
    ASSERT_TRUE(car.isOk());
    EXPECT_GT(car->maxSpeed, 5.0 * po->maxSpeed);
    f.kind = "boat";
    EXPECT_FALSE(parsePathFlags(f).isOk());
    f.kind = "car";
    f.runUp = 601;
    auto bad = parsePathFlags(f);
    ASSERT_FALSE(bad.isOk());
    EXPECT_NE(bad.status().message().find("run-up"), std::string::npos) << bad.status().message();
}

TEST(Options, BakeCellsShardAndTexels) {
    auto cells = parseCellList("7,3,10-12,3");
    ASSERT_TRUE(cells.isOk());
    EXPECT_EQ(*cells, (std::vector<uint32_t>{3, 7, 10, 11, 12}));
    for (const char* bad : {"", ",", "a", "3-", "-3", "5-2", "1-2-3", "3x", "100000001"})
        expectBad(parseCellList(bad), bad, "--cells", "10-20");

    // Shards (foundation/shard.h, gen and bake alike): K/N, 1-based K.
    auto sh = parseShard("--shard", "2/4");
    ASSERT_TRUE(sh.isOk());
    EXPECT_EQ(sh->k(), 2);
    EXPECT_EQ(sh->index, 1);
    EXPECT_EQ(sh->count, 4);
    ASSERT_TRUE(parseShard("--shard", "100000/100000").isOk());
    for (const char* bad : {"0/4", "5/4", "2/0", "2", "2/", "/4", "2/4x", " 2/4", "+2/4", "a/b", "2\\4", "1/100001",
                            "-1/2", "1/2/3", "", "0x1/2", "1/0x2", "1.0/2"}) {
        auto s = parseShard("--shard", bad);
        ASSERT_FALSE(s.isOk()) << bad;
        EXPECT_NE(s.status().message().find("1 <= K <= N"), std::string::npos) << s.status().message();
        EXPECT_NE(s.status().message().find("--shard"), std::string::npos) << s.status().message();
    }

    int x = 0, y = 0;
    ASSERT_TRUE(parseTexels("8x2", x, y).isOk());
    EXPECT_EQ(x, 8);
    EXPECT_EQ(y, 2);
    ASSERT_TRUE(parseTexels("1", x, y).isOk());
    EXPECT_EQ(x * y, 1);
    ASSERT_TRUE(parseTexels("32X32", x, y).isOk());
    for (const char* bad : {"0x2", "33x1", "8x", "8", "8x2junk", "8*2", ""}) {
        Status s = parseTexels(bad, x, y);
        ASSERT_FALSE(s.isOk()) << bad;
        EXPECT_NE(s.message().find("--texels"), std::string::npos) << s.message();
        EXPECT_NE(s.message().find("32"), std::string::npos) << s.message();
    }
}

// --effects: empty, repeated and oversized values are refused; a baked effect
// cannot be asked for at run time (it is in the scene's colours).
TEST(Options, EffectsOptionRules) {
    const Effects none;
    EXPECT_TRUE(parseEffectsOption("haze,glass", none).isOk());
    for (const char* bad : {"", ",", "haze,", ",haze", "haze,,glass"})
        expectBad(parseEffectsOption(bad, none), bad, "--effects", "empty");
    expectBad(parseEffectsOption("haze,haze", none), "haze,haze", "--effects", "twice");
    expectBad(parseEffectsOption(std::string(100000, 'h'), none), "100000 x h", "--effects", "64 KiB");
    auto longName = parseEffectsOption(std::string(5000, 'h'), none);
    ASSERT_FALSE(longName.isOk());
    EXPECT_LT(longName.status().message().size(), 300u);
    for (const char* baked :
         {"sun_shadows", "ambient_occlusion", "materials", "haze,sun_shadows", "{\"ambient_occlusion\": {}}"}) {
        auto fx = runTimeEffects(std::string(baked), none, true, "vista bench");
        ASSERT_FALSE(fx.isOk()) << baked;
        EXPECT_NE(fx.status().message().find("baked"), std::string::npos) << fx.status().message();
    }
    EXPECT_TRUE(runTimeEffects(std::string("haze,night"), none, true, "vista bench").isOk());
    EXPECT_TRUE(runTimeEffects(std::string("none"), none, true, "vista bench").isOk());
    EXPECT_TRUE(runTimeEffects(std::nullopt, none, true, "vista bench").isOk());
    EXPECT_FALSE(runTimeEffects(std::string(""), none, true, "vista bench").isOk());
}

// The one seed rule on the command line: 0 .. 2^64-1 in decimal, nothing wraps.
TEST(Options, SeedOptionNeverWraps) {
    for (const char* bad : {"-1", "18446744073709551616", "0x10", "1e3"}) {
        CLI::App app;
        uint64_t seed = 7;
        addSeedOption(app, "--seed", seed, "");
        std::vector<std::string> args = {bad, "--seed"};  // CLI11 parses the reversed vector
        EXPECT_THROW(app.parse(args), CLI::ValidationError) << bad;
        EXPECT_EQ(seed, 7u);
    }
    CLI::App app;
    uint64_t seed = 7;
    addSeedOption(app, "--seed", seed, "");
    std::vector<std::string> args = {"18446744073709551615", "--seed"};
    app.parse(args);
    EXPECT_EQ(seed, UINT64_MAX);
}
