// The file rules of every command, end to end: outputs never alias each other
// or an input (exit 2 naming both options, the file system as it was), reads
// of user files are bounded and refuse non-regular files, numbers are parsed
// by one set of rules, and user text echoed in messages is cut short.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <string>

#include "tests/bake/bake_fixtures.h"
#include "runtime/scene/city_file.h"
#include "tests/common/run_vista.h"
#include "tests/common/temp_dir.h"

namespace fs = std::filesystem;
using vista::test::CliRun;
using vista::test::readBytes;
using vista::test::runVista;
using vista::test::TempDir;

namespace {

// Every entry under `dir` with its bytes (directories as "<dir>").
std::map<std::string, std::string> snapshot(const std::string& dir) {
    std::map<std::string, std::string> out;
    for (auto it = fs::recursive_directory_iterator(dir); it != fs::recursive_directory_iterator(); ++it) {
        const std::string rel = fs::relative(it->path(), dir).string();
        out[rel] = it->is_directory() ? "<dir>" : it->is_symlink() ? "<link>" : readBytes(it->path().string());
    }
    return out;
}

void write(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Runs `args` in `dir` and expects a refusal: exit 2, every part in the
// message, the directory unchanged (old outputs intact, nothing new, no temporary).
void expectRefusedUnchanged(const TempDir& dir, const std::string& args, std::initializer_list<std::string> parts) {
    const auto before = snapshot(dir.path());
    const CliRun r = runVista(args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.err;
    for (const std::string& p : parts) EXPECT_TRUE(has(r.err, p)) << args << ": '" << p << "' not in: " << r.err;
    EXPECT_EQ(snapshot(dir.path()), before) << args;
}

}  // namespace

TEST(OutputRule, GenOutputsThatNameOneFileAreRefusedAndNothingChanges) {
    TempDir dir;
    const std::string c = dir.file("c.osgb"), x = dir.file("x.glb");
    write(c, "old city bytes");
    ::mkdir(dir.file("sub").c_str(), 0755);
    ASSERT_EQ(::symlink(dir.path().c_str(), dir.file("link").c_str()), 0);
    const std::string gen = "gen --size 300 -q ";
    expectRefusedUnchanged(dir, gen + "-o " + c + " --stats " + c, {"-o", "--stats", "same file"});
    expectRefusedUnchanged(dir, gen + "-o " + c + " --geojson " + c, {"-o", "--geojson", "same file"});
    expectRefusedUnchanged(dir, gen + "-o " + c + " --geojson " + x + " --gltf " + x, {"--geojson", "--gltf"});
    // After ".." and through a symlinked directory; a new file and an existing one.
    expectRefusedUnchanged(dir, gen + "-o " + dir.file("sub/../n.osgb") + " --stats " + dir.file("n.osgb"),
                           {"-o", "--stats"});
    expectRefusedUnchanged(dir, gen + "-o " + dir.file("link/c.osgb") + " --xodr " + dir.file("c.osgb"),
                           {"-o", "--xodr"});
    // An output that is an input.
    write(dir.file("p.json"), R"({"size_m": 300})");
    expectRefusedUnchanged(dir, gen + "--params " + dir.file("p.json") + " -o " + c + " --stats " + dir.file("p.json"),
                           {"--stats", "--params"});
}

TEST(OutputRule, BakePathExportBenchAndViewNeverWriteOverTheirInput) {
    TempDir dir;
    // The rule is checked before the input is read: junk inputs show the refusal is the rule's.
    const std::string c = dir.file("c.osgb"), b = dir.file("b.osgb");
    write(c, "old city bytes");
    expectRefusedUnchanged(dir, "bake -q " + c + " -o " + c, {"--output", "city", "same file"});
    expectRefusedUnchanged(dir, "bake -q " + c + " -o " + b + " --stats " + b, {"--output", "--stats"});
    expectRefusedUnchanged(dir, "bake -q " + c + " -o " + b + " --stats " + c, {"--stats", "city"});
    expectRefusedUnchanged(dir, "path " + c + " -o " + c, {"-o", "city"});
    expectRefusedUnchanged(dir, "path " + c + " -o " + b + " --xodr-positions " + b, {"-o", "--xodr-positions"});
    write(dir.file("r.xodr"), "old roads");
    expectRefusedUnchanged(dir, "export " + dir.file("r.xodr") + " --xodr " + dir.file("r.xodr"), {"--xodr", "city"});
    expectRefusedUnchanged(dir, "bench " + c + " --out " + c, {"--out", "city"});
    expectRefusedUnchanged(dir, "view " + c + " --frames 1 --screenshot " + c, {"--screenshot", "city"});
    write(dir.file("p.csv"), "t_s,x_m,y_m,z_m,heading_deg,pitch_deg\n0,0,0,1,0,0\n");
    expectRefusedUnchanged(
        dir,
        "bench " + c + " --path " + dir.file("p.csv") + " --out " + dir.file("o") + " --dump-rays " + dir.file("o"),
        {"--out", "--dump-rays"});
}

TEST(OutputRule, BakeCommitsTheBakedFileAndItsStatsTogether) {
    TempDir dir;
    ASSERT_TRUE(vista::writeCityFile(vista::makeBakeCity(), dir.file("city.osgb")).isOk());
    const std::string bake = "bake " + dir.file("city.osgb") + " --out-size 120 --min-triangles 1 -q --placement all ";
    ASSERT_EQ(runVista(bake + "-o " + dir.file("b.osgb") + " --stats " + dir.file("s.json")).code, 0);
    EXPECT_TRUE(fs::exists(dir.file("b.osgb")));
    EXPECT_TRUE(
        has(readBytes(dir.file("s.json")), "\"output_bytes\": " + std::to_string(fs::file_size(dir.file("b.osgb")))));
    // A cell that does not exist: the range is that of the city's edges (0..2 for 3 edges).
    const CliRun r = runVista(bake + "-o " + dir.file("e.osgb") + " --cells 3");
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(has(r.err, "0..2,")) << r.err;
    EXPECT_FALSE(fs::exists(dir.file("e.osgb")));
    // An empty cell list is an error, not "every cell".
    expectRefusedUnchanged(dir, bake + "-o " + dir.file("e.osgb") + " --cells ''", {"--cells"});
}

TEST(BoundedReads, DevicesDirectoriesAndOversizedFilesAreRefused) {
    TempDir dir;
    const std::string out = " -q -o " + dir.file("c.osgb");
    for (const char* dev : {"/dev/zero", "/dev/urandom"})
        expectRefusedUnchanged(dir, std::string("gen --params ") + dev + out, {"--params", "not a regular file"});
    ::mkdir(dir.file("d").c_str(), 0755);
    expectRefusedUnchanged(dir, "gen --params " + dir.file("d") + out, {"is a directory"});
    write(dir.file("big.json"), "{\"_comment\": \"" + std::string(2 << 20, 'x') + "\"}");
    expectRefusedUnchanged(dir, "gen --params " + dir.file("big.json") + out, {"limit of 1 MiB", "parameter file"});
    // bench --path /dev/zero: refused before the output folder is made.
    write(dir.file("c.osgb"), "junk city");
    expectRefusedUnchanged(dir, "bench " + dir.file("c.osgb") + " --path /dev/zero --out " + dir.file("o/deep"),
                           {"--path", "path file", "not a regular file"});
    EXPECT_FALSE(fs::exists(dir.file("o")));
}

TEST(NumbersAsWritten, SeedsOutsideTheRangeAreRefusedWithTheTextAsWritten) {
    TempDir dir;
    write(dir.file("c.osgb"), "junk city");
    for (const char* seed : {"-1", "18446744073709551616", "0x10", "1.5"}) {
        expectRefusedUnchanged(dir, std::string("gen -q --size 300 --seed ") + seed + " -o " + dir.file("n.osgb"),
                               {"--seed", seed});
        expectRefusedUnchanged(
            dir, std::string("path ") + dir.file("c.osgb") + " --seed " + seed + " -o " + dir.file("p.csv"),
            {"--seed", seed});
    }
    write(dir.file("p.json"), R"({"seed": 18446744073709551616})");
    const CliRun r = runVista("gen -q --params " + dir.file("p.json") + " -o " + dir.file("n.osgb"));
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(has(r.err, "18446744073709551616")) << r.err;
    EXPECT_TRUE(has(r.err, "18446744073709551615]")) << r.err;
    EXPECT_FALSE(has(r.err, "e+19")) << r.err;
    // A megabyte key is not echoed whole.
    write(dir.file("k.json"), "{\"" + std::string(1 << 20, 'k') + "\": 1}");
    const CliRun k = runVista("gen -q --params " + dir.file("k.json") + " -o " + dir.file("n.osgb"));
    EXPECT_EQ(k.code, 2);
    EXPECT_LT(k.err.size(), 2000u) << k.err.substr(0, 300);
}

// Every numeric option of every command reads its value by the one rule
// (cmd/options.h addNumberOption, foundation/number_text.h): hex, a fraction
// for an integer, '-' where the range has no negatives and a value past the
// range are refused with exit code 2 before anything is read or written,
// naming the option, the text as written and the range.
TEST(NumbersAsWritten, NumericOptionsOfEveryCommandFollowOneRule) {
    TempDir dir;
    write(dir.file("c.osgb"), "junk city");
    const std::string c = dir.file("c.osgb");
    const std::string bench = "bench " + c + " -q --out " + dir.file("o") + " ",
                      render = "render " + c + " -q --out " + dir.file("r") + " ", view = "view " + c + " ",
                      gen = "gen -q -o " + dir.file("n.osgb") + " ",
                      path = "path " + c + " -o " + dir.file("p.csv") + " ",
                      bake = "bake " + c + " -q -o " + dir.file("b.osgb") + " ";
    struct Case {
        std::string command, option, text, range;
    };
    const Case cases[] = {{bench, "--frames", "0x10", "[1, 1000000]"},
                          {bench, "--frames", "1.5", "[1, 1000000]"},
                          {bench, "--frames", "1000001", "[1, 1000000]"},
                          {bench, "--triangle-budget", "-1", "[0, 10000000000]"},
                          {bench, "--fov", "179", "(1, 179)"},
                          {bench, "--fov", "0x3c", "(1, 179)"},
                          {bench, "--diff-threshold", "0x8", "[0, 255]"},
                          {bench, "--threads", "1025", "[0, 1024]"},
                          {bench, "--memory-budget", "0", "(0, 65536]"},
                          {bench, "--paged-radius", "1e6", "[0, 100000]"},
                          {bench, "--budget", "1.5", "[-1, 1000000000]"},
                          {bench, "--near", "0x10", "[1, 100000]"},
                          {bench, "--sampling", "runs:0x10", "[1, 100000]"},
                          {bench, "--size", "640x0x1e0", "[1, 8192]"},
                          {render, "--frames", "-1", "[1, 1000000]"},
                          {render, "--run-up", "0x10", "[0, 600]"},
                          {render, "--far-step", "3", "[1, 2]"},
                          {view, "--frames", "-1", "[0, 100000000]"},
                          {view, "--horizon-grid", "1.5", "[0, 8192]"},
                          {view, "--cache-error", "101", "[0, 100]"},
                          {gen, "--detail", "4", "[0, 3]"},
                          {gen, "--threads", "0x2", "[0, 256]"},
                          {gen, "--size", "0x100", "[100, 64000]"},
                          {gen, "--region-size", "-1", "[250, 16000]"},
                          {path, "--dt", "0", "(0, 10]"},
                          {path, "--fly-pitch", "-90", "(-90, 90)"},
                          {path, "--duration", "0x3c", "(0, 86400]"},
                          {path, "--yaw-rate", "721", "(0, 720]"},
                          {bake, "--jobs", "0x10", "[0, 1024]"},
                          {bake, "--min-triangles", "-1", "[0, 1000000000]"},
                          {bake, "--max-rays", "1e6", "[1, 1000000000]"},
                          {bake, "--mc-max", "1.5", "[1, 65536]"},
                          {bake, "--layers", "65", "[1, 64]"},
                          {bake, "--triangle-ns", "0", "(0, 1000000000)"},
                          {bake, "--texels", "8x0x2", "[1, 32]"},
                          {bake, "--shard", "0x1/2", "1 <= K <= N"}};
    for (const Case& k : cases)
        expectRefusedUnchanged(dir, k.command + k.option + " " + k.text,
                               {"option " + k.option, "'" + k.text + "'", k.range});
    // In range (at the bounds, leading zeros decimal): the generation and the
    // path run; the other commands get past their options to the junk city.
    CliRun r = runVista("gen -q --size 300 --detail 0 --threads 256 --seed 010 -o " + dir.file("g.osgb"));
    ASSERT_EQ(r.code, 0) << r.err;
    r = runVista("path " + dir.file("g.osgb") + " --duration 5 --dt 10 --speed 1000 --yaw-rate 720 --run-up 0 -o " +
                 dir.file("p.csv"));
    ASSERT_EQ(r.code, 0) << r.err;
    for (const std::string& args :
         {bench + "--frames 1000000 --fov 1.5 --threads 1024 --triangle-budget 10000000000 --memory-budget 65536 "
                  "--budget -1 --near 100000 --size 8192x1",
          render + "--frames 1 --far-step 2 --run-up 600", view + "--frames 0 --horizon-grid 8192 --cache-error 0",
          bake + "--jobs 1024 --min-triangles 0 --mc-max 65536 --layers 64 --max-rays 1000000000"}) {
        r = runVista(args);
        EXPECT_EQ(r.code, 2) << args << ": " << r.err;
        EXPECT_FALSE(has(r.err, "option --")) << args << ": " << r.err;
        EXPECT_TRUE(has(r.err, "c.osgb")) << args << ": the city is refused, not an option: " << r.err;
    }
}

TEST(EffectsOption, EmptyDuplicateAndDeepValuesAreRefused) {
    TempDir dir;
    const std::string gen = "gen -q --size 300 -o " + dir.file("c.osgb") + " --effects ";
    expectRefusedUnchanged(dir, gen + "''", {"--effects", "empty"});
    expectRefusedUnchanged(dir, gen + "haze,haze", {"--effects", "haze", "twice"});
    expectRefusedUnchanged(dir, gen + "'{\"haze\":{},\"haze\":{}}'", {"haze", "appears twice"});
    std::string deep = "{\"haze\":" + std::string(40, '[') + std::string(40, ']') + "}";
    expectRefusedUnchanged(dir, gen + "'" + deep + "'", {"nested deeper than"});
}

// Each baked-file flag takes one representation: the wrong one is bad input (exit 2), refused before drawing.
TEST(BakedFlags, APointsBakeAsBakedMeshAndAMeshBakeAsBakedAreRefused) {
    TempDir dir;
    ASSERT_TRUE(vista::writeCityFile(vista::makeBakeCity(), dir.file("city.osgb")).isOk());
    const std::string bake = "bake " + dir.file("city.osgb") + " --out-size 120 --min-triangles 1 -q --placement all ";
    ASSERT_EQ(runVista(bake + "-o " + dir.file("p.osgb")).code, 0);
    ASSERT_EQ(runVista(bake + "-o " + dir.file("m.osgb") + " --representation mesh --mesh-image 256").code, 0);
    const std::string bench = "bench " + dir.file("city.osgb") + " -q --frames 1 --size 80x60 --out " + dir.file("o");
    CliRun r = runVista(bench + " --baked-mesh " + dir.file("p.osgb") + " --modes lodmesh");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_TRUE(has(r.err, "--baked-mesh") && has(r.err, "point impostors")) << r.err;
    r = runVista(bench + " --baked " + dir.file("m.osgb") + " --modes impostor");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_TRUE(has(r.err, "--baked") && has(r.err, "textured depth meshes")) << r.err;
    EXPECT_FALSE(fs::exists(dir.file("o")));
}

// An OSM extract larger than --size: the city's own seeded path stays in the city square (render's check).
TEST(OsmLargerThanTheCity, SeededPathsStayInsideTheCitySquare) {
    TempDir dir;
    const std::string city = dir.file("c.osgb");
    CliRun r = runVista("gen -q --osm " + std::string(VISTA_SOURCE_DIR) +
                        "/tests/data/osm/town.osm --osm-buildings off --size 300 -o " + city);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(has(r.err, "clipped")) << r.err;
    for (const char* seed : {"1", "3", "7"}) {
        r = runVista("path " + city + " --seed " + seed + " -o " + dir.file("p.csv"));
        ASSERT_EQ(r.code, 0) << r.err;
        std::istringstream csv(readBytes(dir.file("p.csv")));
        std::string line;
        std::getline(csv, line);  // header
        size_t samples = 0;
        while (std::getline(csv, line)) {
            double t = 0, x = 0, y = 0;
            ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf", &t, &x, &y), 3) << line;
            EXPECT_LE(std::max(std::abs(x), std::abs(y)), 150.0 + 50.0) << "seed " << seed << ": " << line;
            ++samples;
        }
        EXPECT_GT(samples, 100u);
    }
}
