// Bake: the driver as a library call (progress, resume after interruption).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>

#include <sys/stat.h>
#include <unistd.h>

#include <osg/UserDataContainer>
#include <osgDB/ReaderWriter>
#include <osgDB/Registry>
#include <tbb/global_control.h>

#include "citygen/generate.h"
#include "citygen/polygon.h"
#include "bake/appearance.h"
#include "bake/assembly.h"
#include "bake/bake_cell.h"
#include "bake/cell_result.h"
#include "bake/depth_mesh.h"
#include "bake/far_set.h"
#include "bake/impostor_frame.h"
#include "bake/driver.h"
#include "bake/ldi_sampling.h"
#include "bake/placement.h"
#include "bake/point_removal.h"
#include "bake/sampling_plane.h"
#include "bake/view_cells.h"
#include "foundation/hash.h"
#include "foundation/units.h"
#include "nodes/baked_file.h"
#include "foundation/rng.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_file.h"
#include "nodes/render/mode_impostor.h"
#include "nodes/render/mode_full.h"
#include "nodes/render/mode_lodmesh.h"
#include "runtime/engine/image.h"
#include "runtime/engine/metrics.h"
#include "nodes/render/offscreen.h"

#include "tests/common/temp_dir.h"
#include "tests/bake/bake_fixtures.h"

namespace vista {
namespace {
using test::readBytes;

// Records what the driver reports through Progress (called from one thread).
class RecordingProgress : public Progress {
public:
    void begin(const std::string& stage) override { stages.push_back(stage); }
    void update(double f) override { fractions.push_back(f); }
    void end() override { ++ends; }
    std::vector<std::string> stages;
    std::vector<double> fractions;
    int ends = 0;
};

// The driver as a library call: a run interrupted after some cells (here: a
// run with a cell list that keeps its work directory) resumes in the whole
// job, which bakes only the missing cells and writes the bytes of one run.
TEST(BakeDriver, ResumeAfterInterruptionGivesTheBytesOfOneRun) {
    TempDir dir;
    ASSERT_TRUE(writeCityFile(makeBakeCity(), dir.file("city.osgb")).isOk());
    BakeJob job;
    job.input = dir.file("city.osgb");
    job.params = smallParams();
    job.jobs = 2;
    job.output = dir.file("one.osgb");
    RecordingProgress progress;
    std::vector<std::string> lines;
    auto one = runBakeJob(job, &progress, [&](const std::string& l) { lines.push_back(l); });
    ASSERT_TRUE(one.isOk()) << one.status().message();
    EXPECT_TRUE(one->assembled);
    EXPECT_EQ(one->cells, 2u);
    EXPECT_EQ(one->baked, 2u);
    EXPECT_EQ(one->resumed, 0u);
    EXPECT_EQ(one->skippedEdges, 1u);
    EXPECT_GE(one->impostors, 2u);
    EXPECT_EQ(one->outputBytes, readBytes(job.output).size());
    EXPECT_EQ(progress.stages, std::vector<std::string>{"bake"});
    EXPECT_EQ(progress.ends, 1);
    for (double f : progress.fractions) EXPECT_TRUE(f >= 0.0 && f <= 1.0) << f;
    ASSERT_EQ(lines.size(), 1u);
    EXPECT_NE(lines[0].find("2 cells (2 in this run, 0 already done)"), std::string::npos) << lines[0];
    struct stat st;
    EXPECT_NE(::stat(dir.file("one.osgb.work").c_str(), &st), 0) << "work directory left behind";
    const std::string ref = readBytes(job.output);

    BakeJob part = job;
    part.output = dir.file("part.osgb");
    part.workDir = dir.file("work");
    part.cells = {0};
    part.keepWork = true;
    auto first = runBakeJob(part);
    ASSERT_TRUE(first.isOk()) << first.status().message();
    EXPECT_EQ(first->baked, 1u);
    EXPECT_EQ(::stat(dir.file("work/cell_0.vbc").c_str(), &st), 0);

    BakeJob whole = job;
    whole.output = dir.file("resumed.osgb");
    whole.workDir = dir.file("work");
    auto resumed = runBakeJob(whole);
    ASSERT_TRUE(resumed.isOk()) << resumed.status().message();
    EXPECT_EQ(resumed->resumed, 1u);
    EXPECT_EQ(resumed->baked, 1u);
    EXPECT_EQ(readBytes(whole.output), ref);

    // Errors are returned, naming the option or the file.
    BakeJob bad = job;
    bad.cells = {99};
    auto noCell = runBakeJob(bad);
    ASSERT_FALSE(noCell.isOk());
    EXPECT_NE(noCell.status().message().find("--cells"), std::string::npos);
    bad = job;
    bad.merge = true;
    bad.output = dir.file("merged.osgb");
    auto noResults = runBakeJob(bad);
    ASSERT_FALSE(noResults.isOk());
    EXPECT_NE(noResults.status().message().find("missing"), std::string::npos);
    bad = job;
    bad.params.sampling.maxLayers = 0;
    auto badValue = runBakeJob(bad);
    ASSERT_FALSE(badValue.isOk());
    EXPECT_NE(badValue.status().message().find("--layers"), std::string::npos);
    bad = job;
    bad.input = dir.file("missing.osgb");
    auto noInput = runBakeJob(bad);
    ASSERT_FALSE(noInput.isOk());
    EXPECT_NE(noInput.status().message().find("missing.osgb"), std::string::npos);
}

}  // namespace
}  // namespace vista
