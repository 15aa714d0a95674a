// The dataset manifest (runtime/scene/dataset_manifest.h): a good manifest
// expands into every (city, path, rig) drive in order with names from the
// files or the entries; every malformed field (wrong type, unknown key, empty
// list, bad or repeated name, a generation field beside a path file, a
// camera field beside a rig file, frames out of range, a file that does not
// exist) is refused with a message naming the field.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "runtime/scene/dataset_manifest.h"
#include "tests/common/temp_dir.h"

namespace vista {
namespace {

const char* const kGood = R"({
  "cities": ["a.osgb", {"name": "b", "file": "sub/b.paged"}],
  "paths": [{"name": "p1", "seed": 2, "duration": 3}, {"file": "drive.csv"}],
  "rigs": [{"name": "cam", "size": "160x120", "fov": 60, "mode": "hybrid", "channels": "rgb"}, {"file": "kitti.json"}],
  "options": {"frames": 3, "sampling": "consecutive", "allow_repeated_frames": true}})";

TEST(DatasetManifest, ExpandsEveryCityPathAndRigInOrder) {
    auto m = parseDatasetManifest(kGood, "m.json", "/data");
    ASSERT_TRUE(bool(m)) << m.status().message();
    ASSERT_EQ(m->cities.size(), 2u);
    EXPECT_EQ(m->cities[0].name, "a");
    EXPECT_EQ(m->cities[0].file, "/data/a.osgb");
    EXPECT_EQ(m->cities[1].file, "/data/sub/b.paged");
    EXPECT_EQ(m->paths[1].name, "drive");
    EXPECT_EQ(m->paths[1].file, "/data/drive.csv");
    EXPECT_EQ(*m->paths[0].seed, 2u);
    EXPECT_DOUBLE_EQ(*m->paths[0].duration, 3.0);
    EXPECT_EQ(*m->rigs[0].mode, "hybrid");
    EXPECT_EQ(m->rigs[1].name, "kitti");
    EXPECT_EQ(*m->options.frames, 3);
    EXPECT_TRUE(m->options.allowRepeatedFrames);
    const auto d = m->drives();
    ASSERT_EQ(d.size(), 8u);
    std::vector<std::string> names;
    for (const auto& c : {"a", "b"})
        for (const auto& p : {"p1", "drive"})
            for (const auto& r : {"cam", "kitti"}) names.push_back(std::string(c) + "/" + p + "/" + r);
    for (size_t i = 0; i < d.size(); ++i) {
        EXPECT_EQ(d[i].name, names[i]);
        EXPECT_EQ(d[i].name, m->cities[d[i].city].name + "/" + m->paths[d[i].path].name + "/" + m->rigs[d[i].rig].name);
    }
}

TEST(DatasetManifest, BadFieldsAreNamed) {
    const std::string paths = R"("paths": [{"name": "p"}])", rigs = R"("rigs": [{"name": "r"}])";
    const std::string cities = R"("cities": ["c.osgb"])";
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"[1, 2]", "expected a JSON object"},
        {"{\"cities\": ", "not valid JSON"},
        {"{" + paths + "," + rigs + "}", "cities: missing"},
        {R"({"cities": [], )" + paths + "," + rigs + "}", "cities: expected a non-empty list"},
        {R"({"cities": [7], )" + paths + "," + rigs + "}", "cities[0]: expected a file name"},
        {R"({"cities": [{"name": "x"}], )" + paths + "," + rigs + "}", "cities[0].file: missing"},
        {R"({"cities": ["a/c.osgb", "b/c.osgb"], )" + paths + "," + rigs + "}", "cities[1].file: name 'c' used twice"},
        {R"({"cities": [{"file": "c.osgb", "name": "a b"}], )" + paths + "," + rigs + "}",
         "cities[0].name: name 'a b'"},
        {R"({"cities": [{"file": "c.osgb", "name": ".."}], )" + paths + "," + rigs + "}", "cities[0].name: name '..'"},
        {"{" + cities + "," + rigs + R"(, "paths": [{"seed": 1}]})", "paths[0].name: missing"},
        {"{" + cities + "," + rigs + R"(, "paths": [{"name": "p", "seed": -1}]})", "paths[0].seed: -1 out of range"},
        {"{" + cities + "," + rigs + R"(, "paths": [{"name": "p", "seed": 1.5}]})", "paths[0].seed: expected a whole"},
        {"{" + cities + "," + rigs + R"(, "paths": [{"name": "p", "duration": "3"}]})",
         "paths[0].duration: expected a"},
        {"{" + cities + "," + rigs + R"(, "paths": [{"name": "p", "lht": 1}]})", "paths[0].lht: expected true"},
        {"{" + cities + "," + rigs + R"(, "paths": [{"file": "p.csv", "seed": 1}]})", "paths[0].seed: does not apply"},
        {"{" + cities + "," + rigs + R"(, "paths": [{"name": "p", "speed": 1}]})", "paths[0].speed: unknown key"},
        {"{" + cities + "," + paths + R"(, "rigs": [{"file": "r.json", "fov": 50}]})", "rigs[0].fov: does not apply"},
        {"{" + cities + "," + paths + R"(, "rigs": [{"name": "r", "size": ""}]})",
         "rigs[0].size: expected a non-empty"},
        {"{" + cities + "," + paths + R"(, "rigs": {"name": "r"}})", "rigs: expected a non-empty list"},
        {"{" + cities + "," + paths + "," + rigs + R"(, "options": {"frames": 0}})", "options.frames: 0 out of range"},
        {"{" + cities + "," + paths + "," + rigs + R"(, "options": {"threads": 2}})", "options.threads: unknown key"},
        {"{" + cities + "," + paths + "," + rigs + R"(, "option": {}})", "option: unknown key"},
    };
    for (const auto& [text, expected] : cases) {
        auto m = parseDatasetManifest(text, "m.json", "");
        ASSERT_FALSE(bool(m)) << text;
        EXPECT_NE(m.status().message().find("dataset 'm.json': " + expected), std::string::npos)
            << text << "\n -> " << m.status().message();
    }
}

TEST(DatasetManifest, LoadNamesAMissingFile) {
    test::TempDir dir("vista_dataset");
    std::ofstream(dir.file("c.osgb")) << "x";
    const std::string manifest = dir.file("m.json");
    std::ofstream(manifest) << R"({"cities": ["c.osgb"], "paths": [{"name": "p"}], "rigs": [{"file": "none.json"}]})";
    auto m = loadDatasetManifest(manifest);
    ASSERT_FALSE(bool(m));
    EXPECT_NE(m.status().message().find("rigs[0].file: '" + dir.file("none.json") + "' is not a file"),
              std::string::npos)
        << m.status().message();
    std::ofstream(dir.file("none.json")) << "{}";
    m = loadDatasetManifest(manifest);
    EXPECT_TRUE(bool(m)) << m.status().message();
    m = loadDatasetManifest(dir.file("absent.json"));
    ASSERT_FALSE(bool(m));
    EXPECT_NE(m.status().message().find("--dataset"), std::string::npos) << m.status().message();
}

}  // namespace
}  // namespace vista
