// Image metrics against hand-built images, PNG I/O.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <unistd.h>

#include "runtime/engine/image.h"
#include "runtime/engine/metrics.h"
#include "cmd/plot.h"

using namespace vista;
namespace {
Image solid(int w, int h, glm::u8vec4 c) {
    Image img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) img.set(x, y, c);
    return img;
}

std::string tmpFile(const std::string& name) {
    return (std::filesystem::temp_directory_path() / ("vista_test_metrics_" + std::to_string(::getpid()) + "_" + name))
        .string();
}

}  // namespace

TEST(Metrics, IdenticalImagesReportTheCap) {
    Image a = solid(32, 16, {10, 200, 30, 255});
    EXPECT_EQ(lumaPsnr(a, a), kPsnrCapDb);
    EXPECT_EQ(kPsnrCapDb, 99.0);
    EXPECT_EQ(fractionDiffering(a, a, 0), 0.0);
}

TEST(Metrics, KnownNoiseGivesKnownPsnr) {
    // Grey noise of known amplitude on all channels: luma difference = noise.
    Image a = solid(64, 48, {120, 120, 120, 255});
    Image b = a;
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> d(-20, 20);
    double sumSq = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) {
            int n = d(rng);
            uint8_t v = uint8_t(120 + n);
            b.set(x, y, {v, v, v, 255});
            sumSq += double(n) * double(n);
        }
    double mse = sumSq / double(a.width * a.height);
    double expected = 10.0 * std::log10(255.0 * 255.0 / mse);
    EXPECT_NEAR(lumaPsnr(a, b), expected, 1e-9);
    EXPECT_NEAR(lumaPsnr(b, a), expected, 1e-9);  // symmetric
    // Constant offset of 5 grey levels: 20 log10(255 / 5).
    Image c = solid(64, 48, {125, 125, 125, 255});
    EXPECT_NEAR(lumaPsnr(a, c), 20.0 * std::log10(255.0 / 5.0), 1e-9);
}

TEST(Metrics, LumaWeights) {
    Image a = solid(8, 8, {100, 100, 100, 255});
    Image r = solid(8, 8, {110, 100, 100, 255});   // +10 red only -> luma +2.99
    Image g = solid(8, 8, {100, 110, 100, 255});   // +10 green -> +5.87
    Image bl = solid(8, 8, {100, 100, 110, 255});  // +10 blue -> +1.14
    EXPECT_NEAR(lumaPsnr(a, r), 20.0 * std::log10(255.0 / 2.99), 1e-9);
    EXPECT_NEAR(lumaPsnr(a, g), 20.0 * std::log10(255.0 / 5.87), 1e-9);
    EXPECT_NEAR(lumaPsnr(a, bl), 20.0 * std::log10(255.0 / 1.14), 1e-9);
    // Alpha is ignored.
    Image alpha = solid(8, 8, {100, 100, 100, 0});
    EXPECT_EQ(lumaPsnr(a, alpha), kPsnrCapDb);
}

TEST(Metrics, FractionDiffering) {
    Image a = solid(10, 10, {50, 50, 50, 255});
    Image b = a;
    for (int i = 0; i < 25; ++i) b.set(i % 10, i / 10, {50, 70, 50, 255});  // 25 pixels, +20 green
    EXPECT_DOUBLE_EQ(fractionDiffering(a, b, 8), 0.25);
    EXPECT_DOUBLE_EQ(fractionDiffering(a, b, 20), 0.0);  // not strictly greater
    EXPECT_DOUBLE_EQ(fractionDiffering(a, b, 19), 0.25);
    Image diff = differenceImage(a, b);
    EXPECT_GT(diff.at(0, 0).x, diff.at(9, 9).x);  // differing pixel shown red
}

TEST(Metrics, DownsampleAndAverage) {
    Image s(4, 2);
    s.set(0, 0, {0, 0, 0, 255});
    s.set(1, 0, {100, 0, 0, 255});
    s.set(0, 1, {200, 0, 0, 255});
    s.set(1, 1, {100, 0, 0, 255});
    for (int x = 2; x < 4; ++x)
        for (int y = 0; y < 2; ++y) s.set(x, y, {9, 9, 9, 255});
    Image d = downsampleBox(s, 2);
    ASSERT_EQ(d.width, 2);
    ASSERT_EQ(d.height, 1);
    EXPECT_EQ(d.at(0, 0).x, 100);
    EXPECT_EQ(d.at(1, 0), glm::u8vec4(9, 9, 9, 255));
    Image avg = averageImages({solid(2, 2, {0, 10, 20, 255}), solid(2, 2, {100, 30, 20, 255})});
    EXPECT_EQ(avg.at(1, 1), glm::u8vec4(50, 20, 20, 255));
}

TEST(Png, RoundTripAndBadFiles) {
    Image a(37, 11);
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            a.set(x, y, {uint8_t(x * 7), uint8_t(y * 20), uint8_t(x + y), uint8_t(255 - x)});
    std::string f = tmpFile("rt.png");
    ASSERT_TRUE(writePng(a, f).isOk());
    auto b = readPng(f);
    ASSERT_TRUE(b.isOk()) << b.status().message();
    EXPECT_EQ(b->width, a.width);
    EXPECT_EQ(b->height, a.height);
    EXPECT_EQ(b->rgba, a.rgba);

    // Truncated file: error, no crash.
    std::string t = tmpFile("trunc.png");
    {
        std::ifstream in(f, std::ios::binary);
        std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        std::ofstream(t, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
    }
    EXPECT_FALSE(readPng(t).isOk());
    std::string junk = tmpFile("junk.png");
    std::ofstream(junk) << "not a png at all";
    EXPECT_FALSE(readPng(junk).isOk());
    EXPECT_FALSE(readPng(tmpFile("missing.png")).isOk());
    EXPECT_FALSE(writePng(a, "/nonexistent-dir-vista/x.png").isOk());
    EXPECT_FALSE(writePng(Image(), tmpFile("empty.png")).isOk());
    for (const auto& p : {f, t, junk}) std::filesystem::remove(p);
}
