// Faults of `vista bake`: a kill -9 at several points of a bake
// leaves the old output or the whole new one, never a partial file, and the
// next run resumes to the bytes of an uninterrupted bake; a full disk gives
// the cause and no partial output; an unwritable --output, --work or --stats
// is refused before the input is read.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <regex>
#include <string>
#include <thread>

#include "tests/common/run_vista.h"
#include "tests/common/temp_dir.h"
#include "tests/common/tmpfs_mount.h"

namespace vista {
namespace {

namespace fs = std::filesystem;
using test::CliRun;
using test::listTree;
using test::readBytes;
using test::runVista;

// Whole cell results ("cell_ID.vbc") in a work directory; 0 when it does not exist.
size_t countCells(const std::string& workDir) {
    static const std::regex cell("cell_[0-9]+\\.vbc");
    size_t n = 0;
    std::error_code ec;
    for (fs::directory_iterator it(workDir, ec), end; !ec && it != end; it.increment(ec))
        if (std::regex_match(it->path().filename().string(), cell)) ++n;
    return n;
}

// A small, quick bake of a 300 m city (36 cells, 8 impostors, about 1 s on one core).
const char* const kParams = " --out-size 80 --min-triangles 1 --placement all";

std::string makeCity(const test::TempDir& dir) {
    const std::string city = dir.file("city.osgb");
    const CliRun r = runVista("gen --size 300 --seed 3 -q -o " + city);
    EXPECT_EQ(r.code, 0) << r.err;
    return city;
}

// One kill point: when `due` (given the child's pid, the cell results in the
// work directory when it started and the milliseconds since) first holds.
struct KillPoint {
    const char* what;
    std::function<bool(pid_t, size_t, double)> due;
};

TEST(BakeFaults, KillNineLeavesTheOldOutputOrTheWholeNewOneAndTheNextRunResumes) {
    test::TempDir dir("vista_bake_faults");
    const std::string city = makeCity(dir), out = dir.file("out.osgb"), work = out + ".work";
    const std::string bake = "bake " + city + kParams + " -q";
    // The bake is deterministic (what the resume check below relies on): the
    // same bytes with one and with two threads.
    CliRun r = runVista(bake + " --jobs 2 -o " + dir.file("ref.osgb"));
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string ref = readBytes(dir.file("ref.osgb"));
    ASSERT_GT(ref.size(), 1000u);
    r = runVista(bake + " --jobs 1 -o " + dir.file("ref1.osgb"));
    ASSERT_EQ(r.code, 0) << r.err;
    ASSERT_TRUE(readBytes(dir.file("ref1.osgb")) == ref) << "the bake is not deterministic";
    // The old output: a complete earlier bake of one cell (other bytes).
    r = runVista(bake + " --cells 0 -o " + out);
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string old = readBytes(out);
    ASSERT_FALSE(old.empty());
    ASSERT_FALSE(old == ref);
    ASSERT_FALSE(fs::exists(work));

    // Spread over the run: while the city loads, at the first cell result,
    // ten cell results later, and while the output file is being written.
    // Each run resumes from the cell results the killed runs left.
    const std::vector<KillPoint> points = {
        {"while loading (100 ms)", [](pid_t, size_t, double ms) { return ms >= 100; }},
        {"at the first cell result", [&](pid_t, size_t before, double) { return countCells(work) > before; }},
        {"ten cell results later", [&](pid_t, size_t before, double) { return countCells(work) >= before + 10; }},
        // (a temporary or the staged output exists, or the output itself changes, as it would under a
        // writer that is not atomic)
        {"while writing the output",
         [&](pid_t pid, size_t, double) {
             std::error_code ec;
             const std::string p = std::to_string(pid);
             return fs::exists(out + ".tmp." + p) || fs::exists(out + ".stage." + p + ".tmp." + p) ||
                    fs::exists(out + ".stage." + p) || fs::file_size(out, ec) != old.size();
         }},
    };
    int killed = 0;
    bool lastKilled = false;
    for (const KillPoint& k : points) {
        const size_t before = countCells(work);
        const auto start = std::chrono::steady_clock::now();
        const pid_t pid = test::startVista({"bake", city, "--out-size", "80", "--min-triangles", "1", "--placement",
                                            "all", "-q", "--jobs", "2", "-o", out});
        ASSERT_GT(pid, 0);
        int st = 0;
        bool exited = false;
        while (!(exited = ::waitpid(pid, &st, WNOHANG) == pid)) {
            const double ms =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
            if (k.due(pid, before, ms)) {
                ::kill(pid, SIGKILL);
                break;
            }
            std::this_thread::sleep_for(std::chrono::microseconds(300));
        }
        if (!exited) { ASSERT_EQ(::waitpid(pid, &st, 0), pid); }
        const std::string now = readBytes(out);
        lastKilled = WIFSIGNALED(st) && WTERMSIG(st) == SIGKILL;
        std::printf("kill point '%s': %s, %zu cell results\n", k.what, lastKilled ? "killed" : "finished first",
                    countCells(work));
        if (lastKilled) {
            ++killed;
            EXPECT_TRUE(now == old) << "killed " << k.what << ": the old output changed (" << now.size()
                                    << " bytes, old " << old.size() << ")";
            // The work directory holds cell results and temporaries of the killed run only.
            const std::regex cellFile("cell_[0-9]+\\.vbc(\\.tmp\\." + std::to_string(pid) + ")?");
            for (const std::string& n : listTree(work))
                EXPECT_TRUE(std::regex_match(n, cellFile)) << k.what << ": " << n;
        } else {
            ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << k.what << ": status " << st;
            EXPECT_TRUE(now == ref) << "a run that was not killed (" << k.what << ") must leave the whole new output";
            std::ofstream(out, std::ios::binary | std::ios::trunc) << old;  // the old output again, for the next kill
        }
        // Next to the output: only its work directory and the killed run's temporary or staged output,
        // and its lock files (empty; the next run takes them over and removes them).
        const std::string p = std::to_string(pid);
        for (const auto& e : fs::directory_iterator(dir.path())) {
            const std::string n = e.path().filename().string();
            const bool killedRunsFile = n == "out.osgb.tmp." + p || n == "out.osgb.stage." + p ||
                                        n == "out.osgb.stage." + p + ".tmp." + p || n == "out.osgb.lock" ||
                                        n == "out.osgb.work.lock";
            const bool expected = n == "city.osgb" || n == "ref.osgb" || n == "ref1.osgb" || n == "out.osgb" ||
                                  n == "out.osgb.work" || (lastKilled && killedRunsFile);
            EXPECT_TRUE(expected) << k.what << ": " << n;
        }
    }
    EXPECT_GE(killed, 3) << "the kills should land while the bake runs";

    // The next complete run resumes: it reuses every cell result the killed
    // runs left (all of them whole), writes the bytes of an uninterrupted
    // bake, and removes the temporaries and the work directory.
    const size_t done = countCells(work);
    if (lastKilled) { EXPECT_GT(done, 0u) << "the last kill came after cell results were written"; }
    r = runVista("bake " + city + kParams + " --jobs 2 -o " + out);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find(std::to_string(done) + " already done"), std::string::npos) << r.err;
    EXPECT_TRUE(readBytes(out) == ref) << "the resumed bake differs from an uninterrupted one";
    EXPECT_FALSE(fs::exists(work));
    for (const std::string& n : listTree(dir.path())) {
        EXPECT_EQ(n.find(".tmp."), std::string::npos) << n;
        EXPECT_EQ(n.find(".stage."), std::string::npos) << n;
        EXPECT_EQ(n.find(".lock"), std::string::npos) << n;  // the killed runs' locks taken over and removed
    }
}

TEST(BakeFaults, DiskFullGivesTheCauseAndLeavesNoPartialOutput) {
    test::TempDir dir("vista_bake_faults");
    const std::string small = dir.file("small");
    ASSERT_TRUE(fs::create_directory(small));
    test::TmpfsMount disk(small, "size=2m");
    if (!disk.mounted()) GTEST_SKIP() << "disk full not tested: " << disk.why();
    const std::string city = makeCity(dir);
    std::ofstream(small + "/b.osgb") << "old output";

    // The output does not fit (the cell results go elsewhere): the cause, the
    // old output untouched, no temporary; the next run reuses the cell results.
    CliRun r = runVista("bake " + city + kParams + " --cells 0-3 -o " + small + "/b.osgb --work " + dir.file("work"));
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("b.osgb"), std::string::npos) << r.err;
    EXPECT_EQ(readBytes(small + "/b.osgb"), "old output");
    EXPECT_EQ(listTree(small), std::set<std::string>{"b.osgb"});
    EXPECT_EQ(countCells(dir.file("work")), 4u);
    r = runVista("bake " + city + kParams + " --cells 0-3 -o " + dir.file("b.osgb") + " --work " + dir.file("work"));
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("4 already done"), std::string::npos) << r.err;

    // The cell results do not fit (the default work directory, next to the
    // output): the cause, no output, no temporary; whole cell results stay
    // for the next run.
    r = runVista("bake " + city + kParams + " -q -o " + small + "/c.osgb");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(small + "/c.osgb"));
    const std::regex allowed("b\\.osgb|c\\.osgb\\.work|c\\.osgb\\.work/cell_[0-9]+\\.vbc");
    for (const std::string& n : listTree(small)) EXPECT_TRUE(std::regex_match(n, allowed)) << n;
}

// The input is a file that is not a scene; the output, work or stats path cannot be written.
void expectRefusedBeforeTheInput(const test::TempDir& dir, const std::string& junk, const std::string& args,
                                 const std::string& option, const std::string& reason) {
    test::expectRefusedBeforeTheInput(dir.path(), "bake " + junk + " -q " + args, junk, option, reason);
}

TEST(BakeFaults, UnwritableOutputWorkOrStatsIsRefusedBeforeTheInputIsRead) {
    test::TempDir dir("vista_bake_faults");
    const std::string junk = dir.file("junk.osgb"), aFile = dir.file("afile");
    std::ofstream(junk) << "not a scene file";
    std::ofstream(aFile) << "a file";
    std::ofstream(dir.file("d.osgb.work")) << "a file where the default work directory goes";
    // With writable paths the junk input is what fails (so the checks below can fail).
    const CliRun r = runVista("bake " + junk + " -q -o " + dir.file("b.osgb"));
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("junk.osgb"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir.file("b.osgb.work")));

    expectRefusedBeforeTheInput(dir, junk, "-o " + dir.file("no/such/b.osgb"), "--output", "does not exist");
    expectRefusedBeforeTheInput(dir, junk, "-o " + aFile + "/b.osgb", "--output", "does not exist");
    expectRefusedBeforeTheInput(dir, junk, "-o " + dir.path(), "--output", "is a directory");
    expectRefusedBeforeTheInput(dir, junk, "-o " + dir.file("b.osgb") + " --work " + aFile, "--work",
                                "not a directory");
    expectRefusedBeforeTheInput(dir, junk, "-o " + dir.file("b.osgb") + " --work " + aFile + "/w", "--work",
                                "not a directory");
    expectRefusedBeforeTheInput(dir, junk, "-o " + dir.file("d.osgb"), "--work", "not a directory");
    expectRefusedBeforeTheInput(dir, junk, "-o " + dir.file("b.osgb") + " --stats " + dir.file("no/s.json"), "--stats",
                                "does not exist");
}

TEST(BakeFaults, ReadOnlyDirectoryIsRefusedBeforeTheInputIsRead) {
    test::TempDir dir("vista_bake_faults");
    const std::string junk = dir.file("junk.osgb"), ro = dir.file("ro");
    std::ofstream(junk) << "not a scene file";
    ASSERT_TRUE(fs::create_directory(ro));
    test::ReadOnlyDir readOnly(ro);
    if (!readOnly.ready()) GTEST_SKIP() << "no read-only directory: " << readOnly.why();
    expectRefusedBeforeTheInput(dir, junk, "-o " + ro + "/b.osgb", "--output", "not writable");
    expectRefusedBeforeTheInput(dir, junk, "-o " + dir.file("b.osgb") + " --work " + ro, "--work", "not writable");
    expectRefusedBeforeTheInput(dir, junk, "-o " + dir.file("b.osgb") + " --work " + ro + "/w", "--work",
                                "not writable");
}

}  // namespace
}  // namespace vista
