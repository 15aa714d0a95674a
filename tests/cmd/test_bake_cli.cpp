// `vista bake` and the baked file through the tool: resume, shards, jobs, placement,
// lodmesh, view and bench of baked files, refusal of mismatched or truncated files.
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

TEST(BakeCli, ResumeShardsAndJobsGiveIdenticalBytes) {
    TempDir dir;
    ASSERT_TRUE(writeCityFile(makeBakeCity(), dir.file("city.osgb")).isOk());
    const std::string common = dir.file("city.osgb") + " --out-size 120 --min-triangles 1 -q  --placement all ";
    ASSERT_EQ(run(common + "-o " + dir.file("a.osgb") + " --jobs 2"), 0);
    const std::string ref = readBytes(dir.file("a.osgb"));
    ASSERT_GT(ref.size(), 1000u);
    struct stat st;
    EXPECT_NE(::stat(dir.file("a.osgb.work").c_str(), &st), 0) << "work directory left behind";
    // One job: same bytes.
    ASSERT_EQ(run(common + "-o " + dir.file("b.osgb") + " --jobs 1"), 0);
    EXPECT_EQ(readBytes(dir.file("b.osgb")), ref);
    // Interrupted bake: keep the work dir, remove one cell result, truncate the
    // other (as a kill -9 between write and rename cannot, but a disk error could).
    ASSERT_EQ(run(common + "-o " + dir.file("c.osgb") + " --keep-work"), 0);
    std::remove(dir.file("c.osgb").c_str());
    std::remove(dir.file("c.osgb.work/cell_0.vbc").c_str());
    {
        const std::string part = readBytes(dir.file("c.osgb.work/cell_2.vbc"));
        std::ofstream o(dir.file("c.osgb.work/cell_2.vbc"), std::ios::binary | std::ios::trunc);
        o << part.substr(0, part.size() / 2);
    }
    ASSERT_EQ(run(common + "-o " + dir.file("c.osgb")), 0);
    EXPECT_EQ(readBytes(dir.file("c.osgb")), ref);
    // A real kill -9 at an arbitrary moment (before, during or after the cell
    // writes): the rerun must produce the same bytes whenever the kill landed.
    {
        const std::string bg =
            "(" + std::string(VISTA_BINARY) + " bake " + common + "-o " + dir.file("k.osgb") +
            " > /dev/null 2>&1 & p=$!; sleep 0.6; kill -9 $p 2>/dev/null; wait $p 2>/dev/null) ; true";
        ASSERT_EQ(std::system(bg.c_str()), 0);
        ASSERT_EQ(run(common + "-o " + dir.file("k.osgb")), 0);
        EXPECT_EQ(readBytes(dir.file("k.osgb")), ref);
    }
    // Shards baked separately, then merged.
    ASSERT_EQ(run(common + "-o " + dir.file("d.osgb") + " --shard 1/2"), 0);
    EXPECT_NE(::stat(dir.file("d.osgb").c_str(), &st), 0) << "a shard must not write the output";
    EXPECT_EQ(run(common + "-o " + dir.file("d.osgb") + " --merge"), 2) << "merge with a shard missing must fail";
    ASSERT_EQ(run(common + "-o " + dir.file("d.osgb") + " --shard 2/2"), 0);
    ASSERT_EQ(run(common + "-o " + dir.file("d.osgb") + " --merge"), 0);
    EXPECT_EQ(readBytes(dir.file("d.osgb")), ref);
    // Bad input is exit code 2.
    EXPECT_EQ(run(common + "-o " + dir.file("e.osgb") + " --shard 3/2"), 2);
    EXPECT_EQ(run(common + "-o " + dir.file("e.osgb") + " --cells 99"), 2);
    EXPECT_EQ(run(common + "-o " + dir.file("e.osgb") + " --texels 3"), 2);
    EXPECT_EQ(run(dir.file("missing.osgb") + " -o " + dir.file("e.osgb")), 2);
    EXPECT_EQ(run(dir.file("a.osgb") + " -o " + dir.file("e.osgb")), 2);  // already baked
}

// Placement by cost (the default of `vista bake`) stays byte-identical across
// thread counts, shards + merge and a resume with a damaged cell result; bad
// placement values are refused with exit 2.
TEST(BakeCli, PlacementByCostIsDeterministicAcrossJobsShardsAndResume) {
    TempDir dir;
    City occ = makeBakeCity();
    occ.tiles[0].meshes[size_t(Material::Wall)] =
        boxMesh({52, -40, 0}, {58, 8, 40}, {90, 90, 90, 255}, {100, 100, 100, 255});
    ASSERT_TRUE(writeCityFile(occ, dir.file("city.osgb")).isOk());
    // Cheap points: both ends are placed (and culled by the from-region visibility).
    const std::string common = dir.file("city.osgb") + " --out-size 120 --min-triangles 1 -q --point-ns 0.000001 ";
    ASSERT_EQ(run(common + "-o " + dir.file("a.osgb") + " --jobs 2 --stats " + dir.file("a.json")), 0);
    const std::string ref = readBytes(dir.file("a.osgb"));
    ASSERT_GT(ref.size(), 1000u);
    const std::string stats = readBytes(dir.file("a.json"));
    EXPECT_NE(stats.find("place=cost"), std::string::npos) << "the default placement is by cost";
    EXPECT_NE(stats.find("end 1: placed: saves"), std::string::npos) << stats.substr(0, 400);
    ASSERT_EQ(run(common + "-o " + dir.file("b.osgb") + " --jobs 1"), 0);
    EXPECT_EQ(readBytes(dir.file("b.osgb")), ref);
    ASSERT_EQ(run(common + "-o " + dir.file("c.osgb") + " --shard 1/2"), 0);
    ASSERT_EQ(run(common + "-o " + dir.file("c.osgb") + " --shard 2/2"), 0);
    ASSERT_EQ(run(common + "-o " + dir.file("c.osgb") + " --merge --keep-work"), 0);
    EXPECT_EQ(readBytes(dir.file("c.osgb")), ref);
    std::remove(dir.file("c.osgb").c_str());
    {
        const std::string part = readBytes(dir.file("c.osgb.work/cell_0.vbc"));
        ASSERT_FALSE(part.empty());
        std::ofstream o(dir.file("c.osgb.work/cell_0.vbc"), std::ios::binary | std::ios::trunc);
        o << part.substr(0, part.size() / 2);
    }
    ASSERT_EQ(run(common + "-o " + dir.file("c.osgb")), 0);
    EXPECT_EQ(readBytes(dir.file("c.osgb")), ref) << "a damaged cell result was trusted";
    // The default (real) costs: a few walls are cheaper as triangles, nothing is placed.
    ASSERT_EQ(run(dir.file("city.osgb") + " --out-size 120 --min-triangles 1 -q -o " + dir.file("d.osgb") +
                  " --stats " + dir.file("d.json")),
              0);
    EXPECT_NE(readBytes(dir.file("d.json")).find("not placed: saves"), std::string::npos);
    // A budget that holds at most one of the two ends: the other is passed
    // over with a note, and the placed ends' predicted MB fit in the budget.
    ASSERT_EQ(run(common + "-o " + dir.file("f.osgb") + " --storage-budget 0.01 --stats " + dir.file("f.json")), 0);
    {
        const nlohmann::json fj = nlohmann::json::parse(readBytes(dir.file("f.json")));
        size_t placed = 0, over = 0;
        double placedMb = 0;
        for (const auto& n : fj["notes"]) {
            const std::string t = n.get<std::string>();
            if (t.find("over the storage budget") != std::string::npos) ++over;
            if (t.find(": placed: ") != std::string::npos) {
                ++placed;
                placedMb += std::stod(t.substr(t.rfind("; ") + 2));
            }
        }
        EXPECT_GE(over, 1u) << fj["notes"].dump();
        EXPECT_EQ(fj["impostors"].get<size_t>(), placed);
        EXPECT_LE(placedMb, 0.01 + 1e-3) << fj["notes"].dump();
        EXPECT_DOUBLE_EQ(fj["storage_budget_mb"].get<double>(), 0.01);
        EXPECT_NE(fj["params"].get<std::string>().find("budget=0.01"), std::string::npos);
    }
    ASSERT_EQ(run(common + "-o " + dir.file("g.osgb") + " --storage-budget off --visibility rays --stats " +
                  dir.file("g.json")),
              0);
    EXPECT_EQ(readBytes(dir.file("g.json")).find("budget="), std::string::npos) << "off: no budget in the parameters";
    EXPECT_EQ(run(common + "-o " + dir.file("e.osgb") + " --storage-budget 0"), 2);
    EXPECT_EQ(run(common + "-o " + dir.file("e.osgb") + " --storage-budget lots"), 2);
    EXPECT_EQ(run(common + "-o " + dir.file("e.osgb") + " --visibility maybe"), 2);
    EXPECT_EQ(run(common + "-o " + dir.file("e.osgb") + " --placement some"), 2);
    EXPECT_EQ(run(common + "-o " + dir.file("e.osgb") + " --triangle-ns 0"), 2);
}

// `vista view` opens a baked file and offers the impostor mode (needs a display).
TEST(BakeCli, ViewOpensTheBakedFileInImpostorMode) {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) GTEST_SKIP() << "no X display (run under xvfb-run -a)";
    TempDir dir;
    ASSERT_TRUE(writeCityFile(makeBakeCity(), dir.file("city.osgb")).isOk());
    ASSERT_EQ(
        run(dir.file("city.osgb") + " --out-size 120 --min-triangles 1 -q  --placement all -o " + dir.file("a.osgb")),
        0);
    auto view = [&](const std::string& args) {
        const std::string cmd = std::string(VISTA_BINARY) + " view " + args + " > /dev/null 2>&1";
        const int rc = std::system(cmd.c_str());
        return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
    };
    const std::string png = dir.file("shot.png");
    ASSERT_EQ(view(dir.file("a.osgb") + " --mode impostor --size 160x120 --frames 3 --screenshot " + png), 0);
    EXPECT_TRUE(readPng(png).isOk());
    // The plain city has no impostor mode: a clear error, exit 2.
    EXPECT_EQ(view(dir.file("city.osgb") + " --mode impostor --size 160x120 --frames 3"), 2);
}

TEST(LodMeshCli, ResumeShardsCorruptCellAndBadValues) {
    TempDir dir;
    ASSERT_TRUE(writeCityFile(makeBakeCity(), dir.file("city.osgb")).isOk());
    const std::string common =
        dir.file("city.osgb") +
        " --out-size 120 --min-triangles 1 -q  --placement all --representation mesh --mesh-image 256 ";
    ASSERT_EQ(run(common + "-o " + dir.file("a.osgb") + " --jobs 2 --stats " + dir.file("a.json")), 0);
    const std::string ref = readBytes(dir.file("a.osgb"));
    ASSERT_GT(ref.size(), 1000u);
    auto bf = loadBakedFile(dir.file("a.osgb"));
    ASSERT_TRUE(bf.isOk()) << bf.status().message();
    EXPECT_TRUE(bf->meshes);
    EXPECT_GE(bf->meshCount, 2u);
    // One job: same bytes.
    ASSERT_EQ(run(common + "-o " + dir.file("b.osgb") + " --jobs 1"), 0);
    EXPECT_EQ(readBytes(dir.file("b.osgb")), ref);
    // Resume: one cell result missing, the other corrupted (a flipped byte) -> re-baked.
    ASSERT_EQ(run(common + "-o " + dir.file("c.osgb") + " --keep-work"), 0);
    std::remove(dir.file("c.osgb").c_str());
    std::remove(dir.file("c.osgb.work/cell_2.vbc").c_str());  // the short street: no mesh
    {
        std::string part = readBytes(dir.file("c.osgb.work/cell_0.vbc"));
        ASSERT_EQ(part.substr(0, 8), "VBCMESH1");
        part[part.size() / 2] ^= 0x40;
        std::ofstream o(dir.file("c.osgb.work/cell_0.vbc"), std::ios::binary | std::ios::trunc);
        o << part;
    }
    ASSERT_EQ(run(common + "-o " + dir.file("c.osgb")), 0);
    EXPECT_EQ(readBytes(dir.file("c.osgb")), ref);
    // kill -9 at an arbitrary moment, then a rerun: the bytes of one run.
    {
        const std::string bg =
            "(" + std::string(VISTA_BINARY) + " bake " + common + "-o " + dir.file("k.osgb") +
            " > /dev/null 2>&1 & p=$!; sleep 0.3; kill -9 $p 2>/dev/null; wait $p 2>/dev/null) ; true";
        ASSERT_EQ(std::system(bg.c_str()), 0);
        ASSERT_EQ(run(common + "-o " + dir.file("k.osgb")), 0);
        EXPECT_EQ(readBytes(dir.file("k.osgb")), ref);
    }
    // Shards + merge.
    ASSERT_EQ(run(common + "-o " + dir.file("d.osgb") + " --shard 1/2"), 0);
    ASSERT_EQ(run(common + "-o " + dir.file("d.osgb") + " --shard 2/2"), 0);
    ASSERT_EQ(run(common + "-o " + dir.file("d.osgb") + " --merge"), 0);
    EXPECT_EQ(readBytes(dir.file("d.osgb")), ref);
    // The representation is in the config hash: point results in the same work
    // directory are not reused for a mesh bake (and the other way round).
    const std::string points = dir.file("city.osgb") + " --out-size 120 --min-triangles 1 -q  --placement all ";
    ASSERT_EQ(run(points + "-o " + dir.file("p.osgb") + " --keep-work --work " + dir.file("w")), 0);
    ASSERT_EQ(run(common + "-o " + dir.file("m.osgb") + " --work " + dir.file("w")), 0);
    EXPECT_EQ(readBytes(dir.file("m.osgb")), ref);
    auto pf = loadBakedFile(dir.file("p.osgb"));
    ASSERT_TRUE(pf.isOk());
    EXPECT_FALSE(pf->meshes);
    // Bad values: exit 2.
    EXPECT_EQ(run(dir.file("city.osgb") + " -q -o " + dir.file("e.osgb") + " --representation voxels"), 2);
    EXPECT_EQ(run(common + "-o " + dir.file("e.osgb") + " --mesh-triangles 10"), 2);
    EXPECT_EQ(run(common + "-o " + dir.file("e.osgb") + " --mesh-image 5"), 2);
    EXPECT_EQ(run(common + "-o " + dir.file("e.osgb") + " --mesh-error -1"), 2);
}

// `vista bench --modes lodmesh` and `vista view --mode lodmesh` on a mesh bake (needs a display).
TEST(LodMeshCli, BenchAndViewRunTheLodMeshMode) {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) GTEST_SKIP() << "no X display (run under xvfb-run -a)";
    TempDir dir;
    ASSERT_TRUE(writeCityFile(makeBakeCity(), dir.file("city.osgb")).isOk());
    const std::string common = dir.file("city.osgb") + " --out-size 120 --min-triangles 1 -q  --placement all ";
    ASSERT_EQ(run(common + "-o " + dir.file("m.osgb") + " --representation mesh --mesh-image 256"), 0);
    ASSERT_EQ(run(common + "-o " + dir.file("p.osgb")), 0);
    auto tool = [&](const std::string& args) {
        const std::string cmd = std::string(VISTA_BINARY) + " " + args + " > " + dir.file("log.txt") + " 2>&1";
        const int rc = std::system(cmd.c_str());
        return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
    };
    ASSERT_EQ(tool("bench " + dir.file("m.osgb") + " --baked " + dir.file("p.osgb") +
                   " --modes full,impostor,lodmesh --frames 2 --size 80x60 --seed 1 --out " + dir.file("bench")),
              0)
        << readBytes(dir.file("log.txt"));
    const std::string csv = readBytes(dir.file("bench/frames.csv"));
    EXPECT_NE(csv.find(",lodmesh,"), std::string::npos) << csv;
    EXPECT_NE(csv.find(",impostor,"), std::string::npos) << csv;
    const std::string png = dir.file("shot.png");
    ASSERT_EQ(tool("view " + dir.file("m.osgb") + " --mode lodmesh --size 160x120 --frames 3 --screenshot " + png), 0)
        << readBytes(dir.file("log.txt"));
    EXPECT_TRUE(readPng(png).isOk());
    // A point bake has no lodmesh mode: a clear error, exit 2.
    EXPECT_EQ(tool("view " + dir.file("p.osgb") + " --mode lodmesh --size 160x120 --frames 3"), 2);
}

// A baked file records its source city's content hash
// (vista.source_city_hash); bench and view refuse a baked file of another city
// and a truncated one (exit 2, both representations), warn about a file without
// the hash, and run with a matching pair.
TEST(BakeCli, BakedFileOfAnotherCityOrTruncatedIsRefusedWithExit2) {
    TempDir dir;
    City other = makeBakeCity();
    other.tiles[1].meshes[size_t(Material::Wall)].positions[0].z += 1.0f;  // one vertex moved: another city
    ASSERT_TRUE(writeCityFile(makeBakeCity(), dir.file("city.osgb")).isOk());
    ASSERT_TRUE(writeCityFile(other, dir.file("other.osgb")).isOk());
    const std::string common = dir.file("city.osgb") + " --out-size 120 --min-triangles 1 -q  --placement all ";
    ASSERT_EQ(run(common + "-o " + dir.file("p.osgb")), 0);
    ASSERT_EQ(run(common + "-o " + dir.file("m.osgb") + " --representation mesh --mesh-image 256"), 0);

    // The recorded hash is the hash64 of the city file's payload (everything but the 32-byte trailer), computed here
    // independently.
    const std::string cityBytes = readBytes(dir.file("city.osgb"));
    ASSERT_GT(cityBytes.size(), kSceneTrailerSize);
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx",
                  static_cast<unsigned long long>(hashBytes64(reinterpret_cast<const unsigned char*>(cityBytes.data()),
                                                              cityBytes.size() - kSceneTrailerSize)));
    auto cityHash = sceneFileContentHash(dir.file("city.osgb"));
    ASSERT_TRUE(cityHash.isOk()) << cityHash.status().message();
    EXPECT_EQ(*cityHash, std::string(hex));
    auto otherHash = sceneFileContentHash(dir.file("other.osgb"));
    ASSERT_TRUE(otherHash.isOk());
    EXPECT_NE(*otherHash, *cityHash);
    for (const char* f : {"p.osgb", "m.osgb"}) {
        auto bf = loadBakedFile(dir.file(f));
        ASSERT_TRUE(bf.isOk()) << bf.status().message();
        EXPECT_EQ(bf->sourceCityHash, *cityHash) << f;
        EXPECT_TRUE(checkBakedFromCity(dir.file(f), *bf, dir.file("city.osgb"), nullptr).isOk());
        EXPECT_FALSE(checkBakedFromCity(dir.file(f), *bf, dir.file("other.osgb"), nullptr).isOk());
    }

    auto tool = [&](const std::string& args) {
        const std::string cmd = std::string(VISTA_BINARY) + " " + args + " > " + dir.file("log.txt") + " 2>&1";
        const int rc = std::system(cmd.c_str());
        return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
    };
    const std::string bench = " --frames 2 --size 80x60 --seed 1 --out " + dir.file("bench");
    // Another city: exit 2, a message naming both files and both hashes (before any drawing: no display needed).
    EXPECT_EQ(tool("bench " + dir.file("other.osgb") + " --baked " + dir.file("p.osgb") + " --modes impostor" + bench),
              2);
    std::string log = readBytes(dir.file("log.txt"));
    EXPECT_NE(log.find("baked from another city"), std::string::npos) << log;
    EXPECT_NE(log.find(dir.file("p.osgb")), std::string::npos) << log;
    EXPECT_NE(log.find(dir.file("other.osgb")), std::string::npos) << log;
    EXPECT_NE(log.find(*cityHash), std::string::npos) << log;
    EXPECT_NE(log.find(*otherHash), std::string::npos) << log;
    EXPECT_FALSE(std::filesystem::exists(dir.file("bench/summary.json")));
    EXPECT_EQ(
        tool("bench " + dir.file("other.osgb") + " --baked-mesh " + dir.file("m.osgb") + " --modes lodmesh" + bench),
        2);
    log = readBytes(dir.file("log.txt"));
    EXPECT_NE(log.find("baked from another city"), std::string::npos) << log;
    EXPECT_NE(log.find("--representation mesh"), std::string::npos) << log;
    EXPECT_EQ(tool("view " + dir.file("other.osgb") + " --baked " + dir.file("p.osgb") + " --mode impostor --frames 1"),
              2);
    EXPECT_NE(readBytes(dir.file("log.txt")).find("baked from another city"), std::string::npos);
    EXPECT_EQ(
        tool("view " + dir.file("other.osgb") + " --baked-mesh " + dir.file("m.osgb") + " --mode lodmesh --frames 1"),
        2);
    // A baked city file opened as the city stands for its source city: a mesh bake of `city` with a point bake of
    // `city` pairs, with a point bake of `other` it does not.
    ASSERT_EQ(
        run(dir.file("other.osgb") + " --out-size 120 --min-triangles 1 -q  --placement all -o " + dir.file("po.osgb")),
        0);
    EXPECT_EQ(tool("bench " + dir.file("m.osgb") + " --baked " + dir.file("po.osgb") + " --modes impostor" + bench), 2);
    EXPECT_NE(readBytes(dir.file("log.txt")).find("baked from another city"), std::string::npos);

    // Truncated baked files, both representations: exit 2 naming the file.
    for (const char* f : {"p.osgb", "m.osgb"}) {
        const std::string bytes = readBytes(dir.file(f));
        const std::string cut = dir.file(std::string("cut_") + f);
        {
            std::ofstream o(cut, std::ios::binary | std::ios::trunc);
            o << bytes.substr(0, bytes.size() * 2 / 3);
        }
        const bool mesh = std::string(f) == "m.osgb";
        EXPECT_EQ(tool("bench " + dir.file("city.osgb") + (mesh ? " --baked-mesh " : " --baked ") + cut +
                       (mesh ? " --modes lodmesh" : " --modes impostor") + bench),
                  2)
            << f;
        log = readBytes(dir.file("log.txt"));
        EXPECT_NE(log.find("truncated"), std::string::npos) << log;
        EXPECT_NE(log.find(cut), std::string::npos) << log;
        EXPECT_EQ(tool("view " + dir.file("city.osgb") + (mesh ? " --baked-mesh " : " --baked ") + cut + " --frames 1"),
                  2)
            << f;
    }
    // Unknown representation: exit 2, the option and the value named.
    EXPECT_EQ(tool("bake " + common + "-o " + dir.file("e.osgb") + " --representation voxels"), 2);
    log = readBytes(dir.file("log.txt"));
    EXPECT_NE(log.find("--representation"), std::string::npos) << log;
    EXPECT_NE(log.find("voxels"), std::string::npos) << log;
    EXPECT_FALSE(std::filesystem::exists(dir.file("e.osgb")));

    // A file baked before the hash existed: readable, a warning naming it (it cannot be checked).
    {
        auto node = readSceneFile(dir.file("p.osgb"));
        ASSERT_TRUE(node.isOk());
        osg::UserDataContainer* udc = (*node)->getUserDataContainer();
        ASSERT_NE(udc, nullptr);
        const unsigned i = udc->getUserObjectIndex("vista.source_city_hash");
        ASSERT_LT(i, udc->getNumUserObjects());
        udc->removeUserObject(i);
        ASSERT_TRUE(writeSceneFile(**node, dir.file("old.osgb")).isOk());
        auto bf = loadBakedFile(dir.file("old.osgb"));
        ASSERT_TRUE(bf.isOk()) << bf.status().message();
        EXPECT_TRUE(bf->sourceCityHash.empty());
        std::string warning;
        EXPECT_TRUE(checkBakedFromCity(dir.file("old.osgb"), *bf, dir.file("other.osgb"), nullptr, &warning).isOk());
        EXPECT_NE(warning.find(dir.file("old.osgb")), std::string::npos) << warning;
    }

    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) GTEST_SKIP() << "no X display (run under xvfb-run -a): the runs that draw are skipped";
    // Matching city: both representations run.
    ASSERT_EQ(tool("bench " + dir.file("city.osgb") + " --baked " + dir.file("p.osgb") + " --baked-mesh " +
                   dir.file("m.osgb") + " --modes full,impostor,lodmesh" + bench),
              0)
        << readBytes(dir.file("log.txt"));
    EXPECT_TRUE(std::filesystem::exists(dir.file("bench/summary.json")));
    EXPECT_EQ(readBytes(dir.file("log.txt")).find("warning"), std::string::npos) << readBytes(dir.file("log.txt"));
    // The old file: runs, with the warning.
    ASSERT_EQ(tool("bench " + dir.file("city.osgb") + " --baked " + dir.file("old.osgb") + " --modes impostor" + bench),
              0)
        << readBytes(dir.file("log.txt"));
    log = readBytes(dir.file("log.txt"));
    EXPECT_NE(log.find("warning"), std::string::npos) << log;
    EXPECT_NE(log.find(dir.file("old.osgb")), std::string::npos) << log;
}

}  // namespace
}  // namespace vista
