// foundation/: hashing, atomic writes, units, RNG streams, stopwatch.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include <fstream>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "foundation/zeroed_array.h"
#include "foundation/atomic_file.h"
#include "foundation/format.h"
#include "foundation/hash.h"
#include "foundation/rng.h"
#include "foundation/shard.h"
#include "foundation/statistics.h"
#include "foundation/timing.h"
#include "foundation/units.h"
#include "tests/common/temp_dir.h"

namespace vista {
namespace {

TEST(Hash, StreamingEqualsOneShotForEverySplit) {
    std::string data;
    for (int i = 0; i < 97; ++i) data.push_back(char((i * 37 + 11) & 0xFF));
    const uint64_t whole = hashBytes64(data.data(), data.size(), 5);
    for (size_t a = 0; a <= data.size(); a += 7)
        for (size_t b = a; b <= data.size(); b += 5) {
            Hasher64 h(5);
            const auto* p = reinterpret_cast<const unsigned char*>(data.data());
            h.update(p, a);
            h.update(p + a, b - a);
            h.update(p + b, data.size() - b);
            ASSERT_EQ(h.finish(), whole) << a << "," << b;
        }
}

TEST(Hash, SensitiveToEveryByteLengthAndSeed) {
    std::string data(64, 'x');
    const uint64_t base = hashBytes64(data.data(), data.size());
    std::set<uint64_t> seen{base};
    for (size_t i = 0; i < data.size(); ++i) {
        std::string d = data;
        d[i] ^= 1;
        EXPECT_TRUE(seen.insert(hashBytes64(d.data(), d.size())).second) << "byte " << i;
    }
    EXPECT_NE(hashBytes64(data.data(), data.size() - 1), base);  // length counts
    EXPECT_NE(hashBytes64(data.data(), data.size(), 1), base);   // seed counts
    // Zero padding is not the same input: "ab" vs "ab\0".
    const char ab[3] = {'a', 'b', 0};
    EXPECT_NE(hashBytes64(ab, 2), hashBytes64(ab, 3));
}

TEST(Hash, LittleEndianRoundTripAndKnownLayout) {
    unsigned char b[8];
    storeLE64(b, 0x0102030405060708ull);
    EXPECT_EQ(b[0], 0x08);
    EXPECT_EQ(b[7], 0x01);
    EXPECT_EQ(loadLE64(b), 0x0102030405060708ull);
    EXPECT_NE(hashKeys(1, 2, 3), hashKeys(2, 1, 3));  // order matters
}

TEST(AtomicFile, WritesWholeFileAndLeavesNoTemporary) {
    test::TempDir dir("vista_foundation");
    const std::string f = dir.file("out.bin");
    std::string bytes(100000, '\0');
    for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = char(i * 31);
    ASSERT_TRUE(writeFileAtomic(f, bytes).isOk());
    EXPECT_EQ(test::readBytes(f), bytes);
    ASSERT_TRUE(writeFileAtomic(f, "short").isOk());  // replaces
    EXPECT_EQ(test::readBytes(f), "short");
    size_t entries = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir.path())) {
        (void)e;
        ++entries;
    }
    EXPECT_EQ(entries, 1u);
}

// A pid that certainly belongs to no process: a child that has exited and been reaped.
pid_t deadPid() {
    const pid_t p = ::fork();
    if (p == 0) ::_exit(0);
    int st = 0;
    ::waitpid(p, &st, 0);
    return p;
}

TEST(AtomicFile, StaleTemporariesOfKilledRunsAreRemovedAndLiveOnesKept) {
    vista::test::TempDir dir("vista_stale");
    const std::string target = dir.file("city.osgb");
    const std::string dead = target + ".tmp." + std::to_string(deadPid());
    const std::string deadStage = target + ".stage." + std::to_string(deadPid());
    const std::string deadPrev = target + ".prev." + std::to_string(deadPid());  // OutputBatch's kept previous file
    const std::string live = target + ".tmp." + std::to_string(::getppid());     // the parent runs
    const std::string other = dir.file("other.osgb.tmp.1");                      // another file's
    for (const auto& f : {dead, deadStage, deadPrev, live, other}) std::ofstream(f) << "partial";
    ASSERT_TRUE(writeFileAtomic(target, "whole"));
    EXPECT_FALSE(std::filesystem::exists(dead));
    EXPECT_FALSE(std::filesystem::exists(deadStage));
    EXPECT_FALSE(std::filesystem::exists(deadPrev));
    EXPECT_TRUE(std::filesystem::exists(live)) << "a concurrent writer's file is not touched";
    EXPECT_TRUE(std::filesystem::exists(other));
    EXPECT_EQ(vista::test::readBytes(target), "whole");
}

TEST(AtomicFile, OutputBatchCommitsAllOrNothing) {
    vista::test::TempDir dir("vista_batch");
    const std::string a = dir.file("a.osgb"), b = dir.file("b.glb");
    std::ofstream(a) << "old";
    {
        OutputBatch batch;
        ASSERT_TRUE(writeFileAtomic(batch.stage(a), "new a"));
        ASSERT_TRUE(writeFileAtomic(batch.stage(b), "new b"));
        // The command fails before commit(): nothing of it appears.
    }
    EXPECT_EQ(vista::test::readBytes(a), "old");
    EXPECT_FALSE(std::filesystem::exists(b));
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1) << "no staged file left";
    OutputBatch batch;
    ASSERT_TRUE(writeFileAtomic(batch.stage(a), "new a"));
    ASSERT_TRUE(writeFileAtomic(batch.stage(b), "new b"));
    ASSERT_TRUE(batch.commit());
    EXPECT_EQ(vista::test::readBytes(a), "new a");
    EXPECT_EQ(vista::test::readBytes(b), "new b");
    OutputBatch missing;
    missing.stage(dir.file("never_written"));
    EXPECT_FALSE(missing.commit());
}

// A rename that fails in commit() (here: a directory where the second output
// goes) undoes the renames before it: the first output's previous bytes come
// back, an output that did not exist is removed, and no staged file or kept
// previous file is left.
TEST(AtomicFile, OutputBatchUndoesItsRenamesWhenOneFails) {
    vista::test::TempDir dir("vista_batch");
    const std::string a = dir.file("a.osgb"), b = dir.file("b.glb"), c = dir.file("c.json");
    std::ofstream(a) << "old a";
    OutputBatch batch;
    ASSERT_TRUE(writeFileAtomic(batch.stage(a), "new a"));
    ASSERT_TRUE(writeFileAtomic(batch.stage(c), "new c"));
    ASSERT_TRUE(writeFileAtomic(batch.stage(b), "new b"));
    ASSERT_TRUE(std::filesystem::create_directory(b));
    std::ofstream(b + "/in_the_way") << "x";
    const Status s = batch.commit();
    ASSERT_FALSE(s);
    EXPECT_NE(s.message().find("b.glb"), std::string::npos) << s.message();
    EXPECT_EQ(vista::test::readBytes(a), "old a");
    EXPECT_FALSE(std::filesystem::exists(c));
    const std::set<std::string> left = vista::test::listTree(dir.path());
    EXPECT_EQ(left, (std::set<std::string>{"a.osgb", "b.glb", "b.glb/in_the_way"}));
}

// Directories made for outputs go again when a failed run leaves them empty;
// one that holds something stays with its ancestors; keep() keeps them all.
TEST(AtomicFile, CreatedDirectoriesThatStayEmptyAreRemoved) {
    namespace fs = std::filesystem;
    vista::test::TempDir dir("vista_dirs");
    {
        CreatedDirectories made;
        ASSERT_TRUE(made.create("--out", dir.file("x/y/z")));
        ASSERT_TRUE(fs::is_directory(dir.file("x/y/z")));
    }
    EXPECT_FALSE(fs::exists(dir.file("x")));
    {
        CreatedDirectories made;
        ASSERT_TRUE(made.create("--out", dir.file("x/y/z")));
        std::ofstream(dir.file("x/y/whole_result")) << "x";
    }
    EXPECT_EQ(vista::test::listTree(dir.path()), (std::set<std::string>{"x", "x/y", "x/y/whole_result"}));
    {
        CreatedDirectories made;
        ASSERT_TRUE(made.create("--out", dir.file("k/l/")));
        made.keep();
    }
    EXPECT_TRUE(fs::is_directory(dir.file("k/l")));
    std::ofstream(dir.file("afile")) << "x";
    CreatedDirectories made;
    const Status s = made.create("--out", dir.file("afile/sub"));
    ASSERT_FALSE(s);
    EXPECT_NE(s.message().find("--out"), std::string::npos) << s.message();
    EXPECT_NE(s.message().find("afile/sub"), std::string::npos) << s.message();
}

TEST(AtomicFile, FailureNamesThePathAndKeepsTheOldFile) {
    test::TempDir dir("vista_foundation");
    const std::string f = dir.file("keep.txt");
    ASSERT_TRUE(writeFileAtomic(f, "old").isOk());
    Status s = writeFileAtomic(dir.file("missing_dir/x.txt"), "new");
    ASSERT_FALSE(s.isOk());
    EXPECT_NE(s.message().find("missing_dir/x.txt"), std::string::npos) << s.message();
    EXPECT_FALSE(writeFileAtomic("", "x").isOk());
    // A directory in the way of the rename: error, old content untouched.
    std::filesystem::create_directory(dir.file("adir"));
    EXPECT_FALSE(writeFileAtomic(dir.file("adir"), "x").isOk());
    EXPECT_EQ(test::readBytes(f), "old");
    EXPECT_FALSE(std::filesystem::exists(tempPathFor(dir.file("adir"))));
}

TEST(Units, ConversionsAndWrapAgreeWithLibm) {
    EXPECT_DOUBLE_EQ(kPi, std::acos(-1.0));
    EXPECT_DOUBLE_EQ(degToRad(180.0), kPi);
    EXPECT_DOUBLE_EQ(radToDeg(kHalfPi), 90.0);
    for (double a = -20.0; a <= 20.0; a += 0.37) {
        const double w = wrapAngle(a);
        EXPECT_GE(w, -kPi);
        EXPECT_LE(w, kPi);
        EXPECT_NEAR(std::sin(w), std::sin(a), 1e-12);
        EXPECT_NEAR(std::cos(w), std::cos(a), 1e-12);
    }
}

TEST(Rng, StreamsDependOnlyOnTheirKeys) {
    Rng a(7, 42, Stream::Trees), b(7, 42, Stream::Trees), c(7, 43, Stream::Trees), d(7, 42, Stream::Buildings);
    int sameC = 0, sameD = 0;
    for (int i = 0; i < 100; ++i) {
        const uint64_t x = a.next();
        EXPECT_EQ(x, b.next());
        sameC += x == c.next();
        sameD += x == d.next();
    }
    EXPECT_LT(sameC, 2);
    EXPECT_LT(sameD, 2);
    // uniform() stays in [0, 1) and its mean is near 1/2 (binomial bound, 6 sigma).
    Rng u(1, 1, Stream::Paths);
    double sum = 0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
        const double v = u.uniform();
        ASSERT_GE(v, 0.0);
        ASSERT_LT(v, 1.0);
        sum += v;
    }
    EXPECT_NEAR(sum / n, 0.5, 6.0 * std::sqrt(1.0 / 12.0 / n));
}

TEST(Stopwatch, LapsAreNonOverlappingPiecesOfTheTotal) {
    // Ordering only, never a duration: each lap covers real work (> 0 on a
    // monotonic clock), the laps do not overlap (their sum stays within the
    // total), and lap() restarts (a fresh ms() right after it is below the lap).
    Stopwatch total, laps;
    double sum = 0;
    for (int i = 0; i < 3; ++i) {
        volatile double x = 0;
        for (int k = 0; k < 100000; ++k) x = x + std::sqrt(double(k));
        const double lap = laps.lap();
        EXPECT_GT(lap, 0.0) << "lap " << i;
        sum += lap;
    }
    const double t = total.ms();
    EXPECT_LE(sum, t + 1e-6);
    EXPECT_GT(t, 0.0);
}

TEST(Statistics, PercentileInterpolatesBetweenRanksAndIgnoresNonFinite) {
    EXPECT_DOUBLE_EQ(median({3, 1, 2}), 2.0);
    EXPECT_DOUBLE_EQ(median({4, 1, 3, 2}), 2.5);  // even count: mean of the middle two
    EXPECT_DOUBLE_EQ(percentile({1, 2, 3, 4, 5}, 0.95), 4.8);
    EXPECT_DOUBLE_EQ(percentile({1, 2, 3}, 0.0), 1.0);
    EXPECT_DOUBLE_EQ(percentile({1, 2, 3}, 7.0), 3.0);  // p clamped
    const double inf = std::numeric_limits<double>::infinity(), nan = std::nan("");
    EXPECT_DOUBLE_EQ(median({nan, 5, inf, 1}), 3.0);
    EXPECT_TRUE(std::isnan(median({})));
    EXPECT_TRUE(std::isnan(median({nan, -inf})));
}

}  // namespace
}  // namespace vista

TEST(ZeroedArray, StartsZeroAndResetsToZero) {
    vista::ZeroedArray<uint32_t> a(1000);
    ASSERT_EQ(a.size(), 1000u);
    for (uint32_t v : a) EXPECT_EQ(v, 0u);
    a[7] = 42;
    EXPECT_EQ(a[7], 42u);
    a.reset(10);
    EXPECT_EQ(a.size(), 10u);
    for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i], 0u);
    a.reset(0);
    EXPECT_EQ(a.size(), 0u);
    EXPECT_EQ(a.begin(), a.end());
}

// Large arrays (huge-page mappings on Linux): zero everywhere, aligned to
// 2 MiB there, writable at both ends, and zero again after a reset to the same size.
TEST(ZeroedArray, LargeArraysAreZeroAlignedAndReusable) {
    const size_t n = (vista::kHugeBytes / sizeof(uint64_t)) * 3 + 123;  // not a multiple of the huge page
    vista::ZeroedArray<uint64_t> a(n);
    ASSERT_EQ(a.size(), n);
#if defined(__linux__)
    EXPECT_EQ(reinterpret_cast<uintptr_t>(a.begin()) % (uintptr_t(2) << 20), 0u);
#endif
    uint64_t sum = 0;
    for (size_t i = 0; i < n; i += 511) sum += a[i];
    sum += a[n - 1];
    EXPECT_EQ(sum, 0u);
    a[0] = 1;
    a[n - 1] = 2;
    a[n / 2] = 3;
    EXPECT_EQ(a[0] + a[n - 1] + a[n / 2], 6u);
    a.reset(n);
    EXPECT_EQ(a[0] + a[n - 1] + a[n / 2], 0u);
    a.reset(100);  // small again: an ordinary allocation
    EXPECT_EQ(a[99], 0u);
}

// zero(): every element back to zero in the same memory (a restart keeps its pages).
TEST(ZeroedArray, ZeroKeepsTheMemory) {
    const size_t n = (vista::kHugeBytes / sizeof(uint32_t)) + 77;
    vista::ZeroedArray<uint32_t> a(n);
    const uint32_t* before = a.begin();
    for (size_t i = 0; i < n; i += 1000) a[i] = uint32_t(i + 1);
    a[n - 1] = 9;
    a.zero();
    EXPECT_EQ(a.begin(), before);
    EXPECT_EQ(a.size(), n);
    uint64_t sum = 0;
    for (uint32_t v : a) sum += v;
    EXPECT_EQ(sum, 0u);
}

// A printed command pastes back as the same words: safe words unchanged,
// others single-quoted with their quotes escaped, as sh reads them.
TEST(Format, ShellWordQuotesOnlyWhatTheShellWouldSplitOrExpand) {
    EXPECT_EQ(vista::shellWord("/shared/city.paged"), "/shared/city.paged");
    EXPECT_EQ(vista::shellWord("--size=32000,a+b@c%d:e"), "--size=32000,a+b@c%d:e");
    EXPECT_EQ(vista::shellWord(""), "''");
    EXPECT_EQ(vista::shellWord("my city.paged"), "'my city.paged'");
    EXPECT_EQ(vista::shellWord("$HOME*"), "'$HOME*'");
    EXPECT_EQ(vista::shellWord("it's"), "'it'\\''s'");
    // The shell itself reads the quoted word back as the original.
    const std::string word = "a b'c$d\"e\\f";
    const std::string cmd = "printf %s " + vista::shellWord(word);
    FILE* p = ::popen(cmd.c_str(), "r");
    ASSERT_NE(p, nullptr);
    char buf[64] = {};
    const size_t n = std::fread(buf, 1, sizeof buf - 1, p);
    ::pclose(p);
    EXPECT_EQ(std::string(buf, n), word);
}

namespace vista {
// Every item falls into exactly one shard's range, in order, and the shares
// differ by at most one (checked by counting, not by the formula).
TEST(Shard, RangesTileTheItemsInOrderAndBalance) {
    for (size_t total : {size_t(0), size_t(1), size_t(3), size_t(4), size_t(7), size_t(100), size_t(1000003)})
        for (int n : {1, 2, 3, 4, 7, 64}) {
            size_t next = 0, smallest = total, largest = 0;
            for (int k = 0; k < n; ++k) {
                const ShardRange r = shardRange(total, Shard{k, n});
                ASSERT_EQ(r.begin, next) << total << " items, shard " << k + 1 << "/" << n;
                ASSERT_LE(r.begin, r.end);
                next = r.end;
                smallest = std::min(smallest, r.size());
                largest = std::max(largest, r.size());
                if (r.size()) { EXPECT_TRUE(r.contains(r.begin) && !r.contains(r.end)); }
            }
            EXPECT_EQ(next, total) << total << " items in " << n << " shards";
            EXPECT_LE(largest - smallest, 1u) << total << " items in " << n << " shards";
        }
    EXPECT_EQ(shardText(Shard{2, 4}), "3/4");
}
}  // namespace vista
