// Faults of `vista gen` and `vista bench`: a full disk gives the
// cause, leaves the old output intact and no partial output or temporary;
// an --out that bench cannot write is refused before the scene is loaded.
// (kill -9 of `vista gen`: test_gen_cli.cpp.)
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

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

TEST(GenFaults, DiskFullGivesTheCauseAndLeavesTheOldOutputAndNoTemporary) {
    test::TempDir dir("vista_gen_faults");
    const std::string small = dir.file("small");
    ASSERT_TRUE(fs::create_directory(small));
    test::TmpfsMount disk(small, "size=2m");
    if (!disk.mounted()) GTEST_SKIP() << "disk full not tested: " << disk.why();
    std::ofstream(small + "/c.osgb") << "old city";

    // The city (about 10 MB) does not fit in 2 MB.
    CliRun r = runVista("gen --size 300 -q -o " + small + "/c.osgb");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("c.osgb"), std::string::npos) << r.err;
    EXPECT_EQ(readBytes(small + "/c.osgb"), "old city");
    EXPECT_EQ(listTree(small), std::set<std::string>{"c.osgb"});

    // Several outputs: the city and the GeoJSON fit elsewhere, the glTF does
    // not; none of them appears (they are committed together).
    r = runVista("gen --size 300 -q -o " + dir.file("d.osgb") + " --geojson " + dir.file("d.geojson") + " --gltf " +
                 small + "/d.glb");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("d.glb"), std::string::npos) << r.err;
    EXPECT_EQ(listTree(small), std::set<std::string>{"c.osgb"});
    EXPECT_EQ(listTree(dir.path()), (std::set<std::string>{"small", "small/c.osgb"}));
}

// The scene is a file that is not a scene; --out cannot be written.
void expectOutRefused(const test::TempDir& dir, const std::string& junk, const std::string& out,
                      const std::string& reason) {
    test::expectRefusedBeforeTheInput(dir.path(), "bench " + junk + " --frames 1 -q --out " + out, junk, "--out",
                                      reason);
}

TEST(BenchFaults, UnwritableOutIsRefusedBeforeTheSceneIsLoaded) {
    test::TempDir dir("vista_bench_faults");
    const std::string junk = dir.file("junk.osgb"), aFile = dir.file("afile");
    std::ofstream(junk) << "not a scene file";
    std::ofstream(aFile) << "a file";
    // With a writable --out the junk scene is what fails, and the directories
    // of --out that the run created are gone again.
    const CliRun r = runVista("bench " + junk + " --frames 1 -q --out " + dir.file("new/deeper"));
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("junk.osgb"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir.file("new")));

    expectOutRefused(dir, junk, aFile, "not a directory");
    expectOutRefused(dir, junk, aFile + "/sub", "not a directory");
}

TEST(BenchFaults, ReadOnlyOutIsRefusedBeforeTheSceneIsLoaded) {
    test::TempDir dir("vista_bench_faults");
    const std::string junk = dir.file("junk.osgb"), ro = dir.file("ro");
    std::ofstream(junk) << "not a scene file";
    ASSERT_TRUE(fs::create_directory(ro));
    test::ReadOnlyDir readOnly(ro);
    if (!readOnly.ready()) GTEST_SKIP() << "no read-only directory: " << readOnly.why();
    expectOutRefused(dir, junk, ro, "not writable");
    expectOutRefused(dir, junk, ro + "/sub", "not writable");
}

}  // namespace
}  // namespace vista
