// foundation's rules for user files and numbers: number_text.h (one parser
// for integers and reals), input_file.h (bounded reads), output_paths.h (no
// output aliases another or an input).
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "foundation/input_file.h"
#include "foundation/number_text.h"
#include "foundation/output_paths.h"
#include "tests/common/temp_dir.h"

using namespace vista;
using vista::test::TempDir;

namespace {

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST(NumberText, IntegersNeverWrapAndNameTheRangeAndTheText) {
    auto max = parseUnsignedText("seed", "18446744073709551615", 0, UINT64_MAX);
    ASSERT_TRUE(max.isOk());
    EXPECT_EQ(*max, UINT64_MAX);
    for (const char* bad : {"-1", "18446744073709551616", "99999999999999999999999"}) {
        auto r = parseUnsignedText("option --seed", bad, 0, UINT64_MAX);
        ASSERT_FALSE(r.isOk()) << bad;
        EXPECT_TRUE(has(r.status().message(), std::string("'") + bad + "'")) << r.status().message();
        EXPECT_TRUE(has(r.status().message(), "[0, 18446744073709551615]")) << r.status().message();
    }
    for (const char* bad : {"", "0x10", "1.5", "1e3", "+3", " 3", "3 ", "3abc"}) {
        auto r = parseUnsignedText("n", bad, 0, 100);
        ASSERT_FALSE(r.isOk()) << bad;
        EXPECT_TRUE(has(r.status().message(), "[0, 100]")) << r.status().message();
    }
    EXPECT_EQ(*parseSignedText("n", "-9223372036854775808", INT64_MIN, INT64_MAX), INT64_MIN);
    EXPECT_FALSE(parseSignedText("n", "-9223372036854775809", INT64_MIN, INT64_MAX).isOk());
    EXPECT_FALSE(parseSignedText("n", "9223372036854775808", INT64_MIN, INT64_MAX).isOk());
    EXPECT_FALSE(parseSignedText("n", "4", -3, 3).isOk());
    EXPECT_EQ(*parseSignedText("n", "-3", -3, 3), -3);
}

TEST(NumberText, RealsAreDecimalFiniteAndWhole) {
    EXPECT_DOUBLE_EQ(*parseRealText("x", "-12.5e1", -1e3, 1e3), -125.0);
    for (const char* bad : {"1.5abc", "0x1p3", "inf", "nan", "", "1,5", "+1"}) {
        auto r = parseRealText("field 2 (x_m)", bad, -10, 10);
        ASSERT_FALSE(r.isOk()) << bad;
        EXPECT_TRUE(has(r.status().message(), "field 2 (x_m)")) << r.status().message();
        EXPECT_TRUE(has(r.status().message(), "not a number")) << r.status().message();
    }
    auto big = parseRealText("x", "1e308", -2e7, 2e7);
    ASSERT_FALSE(big.isOk());
    EXPECT_TRUE(has(big.status().message(), "'1e308'")) << big.status().message();
    EXPECT_TRUE(has(big.status().message(), "[-20000000, 20000000]")) << big.status().message();
    EXPECT_FALSE(parseRealText("x", "1e999", -1e300, 1e300).isOk());
}

// An open end excludes its bound, and the message writes the range as it is.
TEST(NumberText, OpenEndsExcludeTheirBound) {
    const RealRange fov = RealRange::open(1, 179), dt = RealRange::openMin(0, 10);
    EXPECT_DOUBLE_EQ(*parseRealText("option --fov", "1.5", fov), 1.5);
    EXPECT_DOUBLE_EQ(*parseRealText("option --dt", "10", dt), 10.0);
    for (const char* bad : {"1", "179", "0.999", "200"}) {
        auto r = parseRealText("option --fov", bad, fov);
        ASSERT_FALSE(r.isOk()) << bad;
        EXPECT_TRUE(has(r.status().message(), "option --fov = '" + std::string(bad) + "' is out of range (1, 179)"))
            << r.status().message();
    }
    auto zero = parseRealText("option --dt", "0", dt);
    ASSERT_FALSE(zero.isOk());
    EXPECT_TRUE(has(zero.status().message(), "(0, 10]")) << zero.status().message();
    EXPECT_EQ(RealRange::openMax(0, 1).text(), "[0, 1)");
    EXPECT_EQ(RealRange::closed(0.05, 4).text(), "[0.05, 4]");
    EXPECT_FALSE(RealRange::closed(0, 1).contains(std::nan("")));
}

TEST(NumberText, EchoedTextAndNumbersStayShort) {
    const std::string key(1 << 20, 'k');
    EXPECT_LE(echoText(key).size(), kMaxEchoChars + 3);
    EXPECT_EQ(echoText("short"), "short");
    // Cut on a character boundary: no half of a two-byte character.
    std::string accents;
    for (int i = 0; i < 100; ++i) accents += "\xC3\xA9";
    const std::string cut = echoText(accents);
    EXPECT_EQ(cut.substr(cut.size() - 3), "\xE2\x80\xA6");
    EXPECT_EQ((cut.size() - 3) % 2, 0u);
    EXPECT_EQ(shortNumber(1e308), "1e+308");
    EXPECT_EQ(shortNumber(2000), "2000");
    EXPECT_EQ(shortNumber(0.1), "0.1");
    EXPECT_EQ(std::stod(shortNumber(1.0 / 3.0)), 1.0 / 3.0);
}

TEST(InputFile, DevicesDirectoriesAndOversizedFilesAreRefused) {
    TempDir dir;
    for (const char* dev : {"/dev/zero", "/dev/urandom"}) {
        auto r = readInputFile("parameter file", dev, kMaxParamsFileBytes);
        ASSERT_FALSE(r.isOk());
        EXPECT_TRUE(has(r.status().message(), "not a regular file")) << r.status().message();
    }
    auto d = readInputFile("parameter file", dir.path(), kMaxParamsFileBytes);
    ASSERT_FALSE(d.isOk());
    EXPECT_TRUE(has(d.status().message(), "is a directory")) << d.status().message();
    ASSERT_EQ(::mkfifo(dir.file("fifo").c_str(), 0600), 0);
    EXPECT_FALSE(readInputFile("path file", dir.file("fifo"), kMaxPathCsvBytes).isOk());  // refused, never blocks
    std::ofstream(dir.file("big")) << std::string(2000, 'x');
    auto big = readInputFile("path file", dir.file("big"), 1024);
    ASSERT_FALSE(big.isOk());
    EXPECT_TRUE(has(big.status().message(), "limit of 1 KiB for a path file")) << big.status().message();
    auto ok = readInputFile("path file", dir.file("big"), 2000);
    ASSERT_TRUE(ok.isOk());
    EXPECT_EQ(ok->size(), 2000u);
    EXPECT_FALSE(checkInputFile("OSM file", dir.file("missing"), 0).isOk());
    EXPECT_EQ(byteLimitText(kMaxParamsFileBytes), "1 MiB");
    EXPECT_EQ(byteLimitText(kMaxOsmFileBytes), "8 GiB");
}

TEST(OutputPaths, SameFileAfterDotDotSymlinksAndHardLinks) {
    TempDir dir;
    ::mkdir(dir.file("sub").c_str(), 0755);
    ASSERT_EQ(::symlink(dir.file("sub").c_str(), dir.file("link").c_str()), 0);
    std::ofstream(dir.file("sub/a")) << "a";
    ASSERT_EQ(::link(dir.file("sub/a").c_str(), dir.file("hard").c_str()), 0);
    EXPECT_TRUE(sameFile(dir.file("sub/../sub/a"), dir.file("sub/a")));
    EXPECT_TRUE(sameFile(dir.file("link/a"), dir.file("sub/a")));
    EXPECT_TRUE(sameFile(dir.file("hard"), dir.file("sub/a")));
    EXPECT_TRUE(sameFile(dir.file("link/new"), dir.file("sub/./new")));  // neither exists yet
    EXPECT_FALSE(sameFile(dir.file("sub/a"), dir.file("sub/b")));
    EXPECT_FALSE(sameFile(dir.file("a"), dir.file("sub/a")));

    CommandFiles a, b, c;
    Status s = a.input("city", dir.file("sub/a")).output("-o", dir.file("link/a")).check();
    ASSERT_FALSE(s.isOk());
    EXPECT_TRUE(has(s.message(), "-o") && has(s.message(), "city")) << s.message();
    s = b.output("-o", dir.file("x")).output("--stats", dir.file("sub/../x")).check();
    ASSERT_FALSE(s.isOk());
    EXPECT_TRUE(has(s.message(), "-o") && has(s.message(), "--stats")) << s.message();
    EXPECT_TRUE(c.input("city", dir.file("sub/a"))
                    .output("-o", dir.file("x"))
                    .output("--stats", dir.file("y"))
                    .output("--gltf", "")
                    .check()
                    .isOk());
}
