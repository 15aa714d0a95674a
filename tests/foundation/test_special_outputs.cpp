// foundation's rules for where outputs go: devices and FIFOs written in place
// and never replaced (atomic_file.h), one writer per output (output_lock.h),
// every path resolved up front (output_paths.h). Device nodes are private
// (mknod in the test's directory), never the system's.
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "foundation/atomic_file.h"
#include "foundation/output_lock.h"
#include "foundation/output_paths.h"
#include "tests/common/special_files.h"
#include "tests/common/temp_dir.h"

using namespace vista;
using vista::test::FifoReader;
using vista::test::isDevice;
using vista::test::isFifo;
using vista::test::kFullMinor;
using vista::test::kNoMknod;
using vista::test::kNullMinor;
using vista::test::listTree;
using vista::test::makeDevice;
using vista::test::readBytes;
using vista::test::TempDir;

namespace {

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// The names in `dir` (not recursive: links that loop are listed, never followed).
std::set<std::string> names(const std::string& dir) {
    std::set<std::string> out;
    std::error_code ec;
    for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
        out.insert(it->path().filename().string());
    return out;
}

bool exists(const std::string& path) {
    struct stat st {};
    return ::lstat(path.c_str(), &st) == 0;
}

}  // namespace

TEST(SpecialOutputs, DevicesAreWrittenInPlaceAndAFullOneIsAnError) {
    TempDir dir;
    const std::string null = dir.file("null"), full = dir.file("full");
    if (!makeDevice(null, kNullMinor) || !makeDevice(full, kFullMinor)) GTEST_SKIP() << kNoMknod;
    EXPECT_TRUE(isSpecialFile(null));
    EXPECT_TRUE(checkWritablePath("-o", null).isOk());
    EXPECT_TRUE(writeFileAtomic(null, "bytes").isOk());
    EXPECT_TRUE(isDevice(null, kNullMinor));
    const Status s = writeFileAtomic(full, "bytes");
    ASSERT_FALSE(s.isOk());
    EXPECT_TRUE(has(s.message(), full) && has(s.message(), "No space left on device")) << s.message();
    EXPECT_TRUE(isDevice(full, kFullMinor));
    // A writer that streams into a temporary: it lives elsewhere and is copied in.
    const std::string tmp = tempPathFor(full);
    EXPECT_NE(tmp.rfind(dir.path(), 0), 0u) << tmp;
    std::ofstream(tmp) << "scene bytes";
    const Status c = commitTempFile(tmp, full);
    EXPECT_TRUE(has(c.message(), "No space left on device")) << c.message();
    EXPECT_FALSE(exists(tmp));
    EXPECT_TRUE(isDevice(full, kFullMinor));
    EXPECT_EQ(listTree(dir.path()), (std::set<std::string>{"full", "null"}));  // nothing staged beside them
}

TEST(SpecialOutputs, ABatchWritesDevicesFirstSoAFullOneLeavesTheFilesAsTheyWere) {
    TempDir dir;
    const std::string null = dir.file("null"), full = dir.file("full"), a = dir.file("a.txt");
    if (!makeDevice(null, kNullMinor) || !makeDevice(full, kFullMinor)) GTEST_SKIP() << kNoMknod;
    std::ofstream(a) << "old";
    {
        OutputBatch batch;
        ASSERT_TRUE(writeFileAtomic(batch.stage(a), "new").isOk());
        ASSERT_TRUE(writeFileAtomic(batch.stage(full), "stats").isOk());
        const Status s = batch.commit();
        ASSERT_FALSE(s.isOk());
        EXPECT_TRUE(has(s.message(), full) && has(s.message(), "No space left on device")) << s.message();
    }
    EXPECT_EQ(readBytes(a), "old");
    EXPECT_TRUE(isDevice(full, kFullMinor));
    {
        OutputBatch batch;
        ASSERT_TRUE(writeFileAtomic(batch.stage(a), "new").isOk());
        ASSERT_TRUE(writeFileAtomic(batch.stage(null), "stats").isOk());
        ASSERT_TRUE(batch.commit().isOk());
    }
    EXPECT_EQ(readBytes(a), "new");
    EXPECT_TRUE(isDevice(null, kNullMinor));
    EXPECT_EQ(listTree(dir.path()), (std::set<std::string>{"a.txt", "full", "null"}));
}

TEST(SpecialOutputs, AFifoReceivesTheBytesAndStaysAFifo) {
    TempDir dir;
    const std::string fifo = dir.file("pipe");
    {
        FifoReader reader(fifo);
        ASSERT_TRUE(reader.made());
        ASSERT_TRUE(writeFileAtomic(fifo, "hello through a pipe").isOk());
        EXPECT_EQ(reader.finish(), "hello through a pipe");
    }
    {
        FifoReader reader(fifo + "2");
        OutputBatch batch;
        ASSERT_TRUE(writeFileAtomic(batch.stage(fifo + "2"), "staged bytes").isOk());
        ASSERT_TRUE(batch.commit().isOk());
        EXPECT_EQ(reader.finish(), "staged bytes");
    }
    EXPECT_TRUE(isFifo(fifo) && isFifo(fifo + "2"));
    // A directory output is never written in place.
    const Status d = checkWritableDirectory("--out", fifo);
    EXPECT_TRUE(has(d.message(), "--out") && has(d.message(), "not a directory")) << d.message();
}

TEST(ResolvedPaths, LoopsDanglingLinksAndUnreachableDirectoriesAreRefused) {
    TempDir dir;
    ASSERT_EQ(::symlink("loop_b", dir.file("loop_a").c_str()), 0);
    ASSERT_EQ(::symlink("loop_a", dir.file("loop_b").c_str()), 0);
    ASSERT_EQ(::symlink("nowhere", dir.file("dangling").c_str()), 0);
    std::ofstream(dir.file("file")) << "x";
    const std::string loop = dir.file("loop_a"), dangling = dir.file("dangling");
    auto refused = [](const Status& s, std::initializer_list<const char*> parts) {
        EXPECT_FALSE(s.isOk());
        for (const char* p : parts) EXPECT_TRUE(has(s.message(), p)) << "'" << p << "' not in: " << s.message();
    };
    refused(checkInputPath("city", loop), {"city", "symbolic link loop"});
    refused(checkInputPath("city", dangling), {"city", "dangling symbolic link", "nowhere"});
    refused(checkInputPath("--path", dir.file("missing")), {"--path", "does not exist"});
    refused(checkInputPath("--path", dir.file("file/x")), {"--path", "cannot be reached"});
    refused(checkWritablePath("-o", loop), {"-o", "symbolic link loop"});
    refused(checkWritablePath("-o", dangling), {"-o", "dangling symbolic link"});
    refused(checkWritablePath("-o", loop + "/x.csv"), {"-o", "symbolic link loop"});
    refused(checkWritablePath("-o", dir.file("file/x.csv")), {"-o", "not a directory"});
    refused(checkWritableDirectory("--out", loop), {"--out", "symbolic link loop"});
    refused(checkWritableDirectory("--out", dangling), {"--out", "dangling symbolic link"});
    refused(checkWritableDirectory("--out", loop + "/deep/er"), {"--out", "symbolic link loop"});
    refused(checkWritableDirectory("--out", dir.file("file/deep")), {"--out", "not a directory"});
    refused(checkWritableDirectory("--out", dir.file("no/out"), true), {"--out", "parent directory", "does not exist"});
    EXPECT_TRUE(checkWritableDirectory("--out", dir.file("no/out")).isOk());
    // CommandFiles resolves every path before anything else, outputs first.
    CommandFiles files;
    refused(files.input("city", loop).output("-o", dangling).check(), {"-o", "dangling"});
    EXPECT_EQ(names(dir.path()), (std::set<std::string>{"dangling", "file", "loop_a", "loop_b"}));
}

TEST(OutputLocks, ASecondWriterIsRefusedNamingTheLockAndNoLockFileStays) {
    TempDir dir;
    const std::string out = dir.file("c.osgb"), lockFile = dir.file("c.osgb.lock");
    {
        auto first = OutputLock::acquire("-o", out, false);
        ASSERT_TRUE(first.isOk()) << first.status().message();
        EXPECT_EQ(first->lockPath(), lockFile);
        auto second = OutputLock::acquire("--stats", out, false);
        ASSERT_FALSE(second.isOk());
        const std::string m = second.status().message();
        EXPECT_TRUE(has(m, "--stats") && has(m, "another vista process") && has(m, lockFile)) << m;
        EXPECT_FALSE(OutputLock::acquire("-o", out, true).isOk());  // shared against exclusive
    }
    EXPECT_FALSE(exists(lockFile));
    {
        // Shards share; an exclusive writer waits for none of them; the last one out removes the file.
        auto a = OutputLock::acquire("-o", out, true);
        auto b = OutputLock::acquire("-o", out, true);
        ASSERT_TRUE(a.isOk() && b.isOk());
        EXPECT_FALSE(OutputLock::acquire("-o", out, false).isOk());
        { OutputLock gone = std::move(*a); }
        EXPECT_TRUE(exists(lockFile));
        EXPECT_FALSE(OutputLock::acquire("-o", out, false).isOk());
    }
    EXPECT_FALSE(exists(lockFile));
    // A stale lock file of a killed run is taken over, then removed.
    std::ofstream(lockFile).close();
    { ASSERT_TRUE(OutputLock::acquire("-o", out, false).isOk()); }
    EXPECT_FALSE(exists(lockFile));
    // A file of that name that is not ours is refused and kept.
    std::ofstream(lockFile) << "user data";
    auto theirs = OutputLock::acquire("-o", out, false);
    ASSERT_FALSE(theirs.isOk());
    EXPECT_TRUE(has(theirs.status().message(), "not a vista lock file")) << theirs.status().message();
    EXPECT_EQ(readBytes(lockFile), "user data");
}

TEST(OutputLocks, CommandFilesHoldTheirLocksAndCreateOnlyWhatTheyRemove) {
    TempDir dir;
    const std::string paged = dir.file("new/deep/city.paged");
    {
        CommandFiles files;
        ASSERT_TRUE(files.outputDirectory("-o", paged).output("--stats", dir.file("s.json")).check().isOk());
        EXPECT_TRUE(exists(paged + ".lock"));
        EXPECT_TRUE(exists(dir.file("s.json.lock")));
        CommandFiles other;
        const Status s = other.outputDirectory("-o", paged + "/").check();
        EXPECT_TRUE(has(s.message(), "another vista process") && has(s.message(), paged + ".lock")) << s.message();
    }
    EXPECT_EQ(listTree(dir.path()), std::set<std::string>{});  // locks and the parents made for them are gone
    // A device output takes no lock: nothing is created beside it.
    if (!makeDevice(dir.file("null"), kNullMinor)) GTEST_SKIP() << kNoMknod;
    {
        CommandFiles files, again;
        ASSERT_TRUE(files.output("-o", dir.file("null")).output("--stats", dir.file("null")).check().isOk());
        ASSERT_TRUE(again.output("-o", dir.file("null")).check().isOk());
        EXPECT_EQ(listTree(dir.path()), std::set<std::string>{"null"});
    }
}
