#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "citygen/effects.h"
#include "citygen/params.h"

using namespace vista;

TEST(Params, DefaultsAreValid) { EXPECT_TRUE(validateParams(CityParams()).isOk()); }

// Malformed files a new user might write: each must be refused cleanly (no
// crash, no uncaught exception, no silent acceptance) or accepted when valid.
TEST(Params, HostileJsonIsRefusedCleanlyAndTheFullSeedRangeAccepted) {
    const std::pair<std::string, std::string> bad[] = {
        {R"({"seed": 1e999})", "number overflow"},
        {"{\"size_m\": 1" + std::string(400, '0') + "}", "number overflow"},
        {R"({"seed": 1, "seed": 2})", "key 'seed' appears twice"},
        {R"({"effects": {"haze": {}, "haze": {"visibility_m": 30}}})", "key 'haze' appears twice"},
        {"{\"_c\": " + std::string(100000, '[') + std::string(100000, ']') + "}", "nested deeper than 16"},
        {R"({"seed": -1})", "out of range"},
        // Integers from the text as written: 2^64 is out of range (not a double near 1.8e19), 2.5 is no integer.
        {R"({"seed": 18446744073709551616})",
         "'seed' = 18446744073709551616 is out of range [0, 18446744073709551615]"},
        {R"({"detail": 2.5})", "'detail' must be an integer, got 2.5"},
        {R"({"detail": 99999999999999999999})", "'detail' = 99999999999999999999 is out of range [0, 3]"},
    };
    for (const auto& [text, says] : bad) {
        auto r = parseParamsJson(text, "p.json");
        ASSERT_FALSE(r.isOk()) << text.substr(0, 60);
        EXPECT_NE(r.status().message().find(says), std::string::npos) << r.status().message();
        EXPECT_LT(r.status().message().size(), 300u) << "messages stay short";
    }
    // A megabyte key is named, cut short (the message lists the known parameters besides).
    auto key = parseParamsJson("{\"" + std::string(1 << 20, 'k') + "\": 1}", "p.json");
    ASSERT_FALSE(key.isOk());
    EXPECT_NE(key.status().message().find("unknown parameter 'kkkk"), std::string::npos);
    EXPECT_LT(key.status().message().size(), 1000u);
    auto top = parseParamsJson(R"({"seed": 18446744073709551615})", "p.json");
    ASSERT_TRUE(top.isOk()) << top.status().message();
    EXPECT_EQ(top->seed, 18446744073709551615ull);
    auto mid = parseParamsJson(R"({"seed": 9223372036854775808})", "p.json");
    ASSERT_TRUE(mid.isOk()) << mid.status().message();
    EXPECT_EQ(mid->seed, 9223372036854775808ull);
    // The --effects JSON follows the same rules as a parameter file.
    for (const auto& [text, says] : std::vector<std::pair<std::string, std::string>>{
             {R"({"haze": {}, "haze": {}})", "key 'haze' appears twice"},
             {R"({"haze": {"visibility_m": 100, "visibility_m": 200}})", "key 'visibility_m' appears twice"},
             {"{\"haze\": " + std::string(40, '[') + std::string(40, ']') + "}", "nested deeper than 16"},
             {"{\"" + std::string(1 << 20, 'e') + "\": {}}", "unknown effect 'eeee"}}) {
        auto r = parseEffectsJson(text, "option --effects");
        ASSERT_FALSE(r.isOk()) << text.substr(0, 60);
        EXPECT_NE(r.status().message().find(says), std::string::npos) << r.status().message().substr(0, 300);
        EXPECT_LT(r.status().message().size(), 300u) << "messages stay short";
    }
    // Strings may hold brackets: they do not count as nesting.
    EXPECT_TRUE(parseParamsJson("{\"_c\": \"" + std::string(100, '[') + "\"}", "p.json").isOk());
}

TEST(Params, SizeZeroRejectedWithRange) {
    CityParams p;
    p.size_m = 0;
    Status s = validateParams(p);
    ASSERT_FALSE(s.isOk());
    EXPECT_NE(s.message().find("size_m"), std::string::npos);
    EXPECT_NE(s.message().find("[100, 64000]"), std::string::npos);
}

TEST(Params, TinyAndHugeSizesRejected) {
    for (double v : {1.0, 99.9, 64000.1, 1e9, -5.0}) {
        CityParams p;
        p.size_m = v;
        EXPECT_FALSE(validateParams(p).isOk()) << v;
    }
}

TEST(Params, SingleFileCapNamesThePagedAlternative) {
    CityParams p;
    p.size_m = 16000;
    EXPECT_TRUE(validateParams(p).isOk());
    EXPECT_TRUE(checkSingleFileSize(p).isOk());
    p.size_m = 16000.5;
    EXPECT_TRUE(validateParams(p).isOk());
    const Status s = checkSingleFileSize(p);
    ASSERT_FALSE(s.isOk());
    EXPECT_NE(s.message().find("'size_m' = 16000.5"), std::string::npos) << s.message();
    EXPECT_NE(s.message().find("[100, 16000]"), std::string::npos) << s.message();
    EXPECT_NE(s.message().find(".paged"), std::string::npos) << s.message();
}

TEST(Params, NanRejected) {
    CityParams p;
    p.sun_elevation_deg = std::nan("");
    EXPECT_FALSE(validateParams(p).isOk());
}

TEST(Params, JsonOverridesBase) {
    auto r = parseParamsJson(R"({"size_m": 500, "seed": 7, "detail": 0})", "x.json");
    ASSERT_TRUE(r.isOk()) << r.status().message();
    EXPECT_EQ(r->size_m, 500);
    EXPECT_EQ(r->seed, 7u);
    EXPECT_EQ(r->detail, 0);
    EXPECT_EQ(r->tile_size_m, CityParams().tile_size_m);
}

TEST(Params, UnknownKeyNamed) {
    auto r = parseParamsJson(R"({"sise_m": 500})", "x.json");
    ASSERT_FALSE(r.isOk());
    EXPECT_NE(r.status().message().find("'sise_m'"), std::string::npos);
}

TEST(Params, MalformedJsonReportsLineAndColumn) {
    auto r = parseParamsJson("{\n  \"size_m\": 500,\n  \"seed\": ,\n}", "bad.json");
    ASSERT_FALSE(r.isOk());
    EXPECT_NE(r.status().message().find("bad.json:3:"), std::string::npos) << r.status().message();
}

TEST(Params, WrongTypes) {
    EXPECT_FALSE(parseParamsJson(R"({"size_m": "big"})", "x").isOk());
    EXPECT_FALSE(parseParamsJson(R"({"detail": 1.5})", "x").isOk());
    EXPECT_FALSE(parseParamsJson(R"({"seed": -1})", "x").isOk());
    EXPECT_FALSE(parseParamsJson(R"([1,2])", "x").isOk());
}

TEST(Params, CanonicalJsonRoundTripsAndOmitsThreads) {
    CityParams p;
    p.seed = 42;
    p.size_m = 1234.5;
    p.threads = 3;
    std::string j = paramsToJson(p);
    EXPECT_EQ(j.find("threads"), std::string::npos);
    auto r = parseParamsJson(j, "canon");
    ASSERT_TRUE(r.isOk()) << r.status().message();
    EXPECT_EQ(r->seed, 42u);
    EXPECT_EQ(r->size_m, 1234.5);
    EXPECT_EQ(paramsToJson(*r), j);
}

TEST(Params, ExampleFilesParse) {
    for (const char* f : {"village", "town", "downtown", "metropolis", "default"}) {
        auto r = loadParamsFile(std::string(VISTA_SOURCE_DIR) + "/data/" + f + ".json");
        EXPECT_TRUE(r.isOk()) << f << ": " << r.status().message();
    }
}
