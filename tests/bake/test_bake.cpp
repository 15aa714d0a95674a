// Bake end to end: a cell baked at both street ends and assembled into a valid baked file,
// the impostor mode drawing it, and the baked modes drawing the near field in chunks.
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

TEST(Bake, CellBakesBothEndsAndAssemblesAValidFile) {
    TempDir dir;
    ASSERT_TRUE(writeCityFile(makeBakeCity(), dir.file("city.osgb")).isOk());
    auto city = loadCityFile(dir.file("city.osgb"));
    ASSERT_TRUE(city.isOk()) << city.status().message();
    BakeParams p = smallParams();
    BakeInput in = prepareBake(*city, p);
    ASSERT_EQ(in.cells.size(), 2u);  // the zero-length edge has no cell, the 0.8 m one has
    ASSERT_EQ(in.skipped.size(), 1u);
    EXPECT_EQ(in.skipped[0].edge, 1u);
    ASSERT_EQ(in.tiles.size(), 3u);
    CellResult cr = bakeCell(in, in.cells[0], p);
    ASSERT_EQ(cr.impostors.size(), 2u) << (cr.notes.empty() ? "" : cr.notes[0]);
    for (const auto& im : cr.impostors) {
        ASSERT_EQ(im.hiddenTiles.size(), 1u);
        EXPECT_NE(im.hiddenTiles[0], in.tiles[0].child);  // the near tile stays
        EXPECT_GT(im.stats.points, 100u);
        EXPECT_GT(im.stats.screenPixels, 0u);
    }
    EXPECT_NE(cr.impostors[0].hiddenTiles, cr.impostors[1].hiddenTiles);
    CellResult cr1 =
        bakeCell(in, in.cells[1], p);  // the 0.8 m street: far fields too close/small are skipped, not errors
    auto root = assembleBakedScene(*city, in.cells, {cr, cr1}, p.canonical());
    ASSERT_TRUE(writeSceneFile(*root, dir.file("city.baked.osgb")).isOk());
    auto bf = loadBakedFile(dir.file("city.baked.osgb"));
    ASSERT_TRUE(bf.isOk()) << bf.status().message();
    EXPECT_EQ(bf->impostors, cr.impostors.size() + cr1.impostors.size());
    EXPECT_EQ(bf->city.meshes.size(), city->meshes.size());  // the city part loads as a city
    EXPECT_EQ(bf->root->cellAt({50, 0, 1.6}), 0);
    EXPECT_EQ(bf->root->cellAt({50, 0, 3.0}), -1);
    EXPECT_EQ(bf->root->impostorsOf(0).size(), 2u);
    // Errors: a plain city, truncation, corruption.
    auto plain = loadBakedFile(dir.file("city.osgb"));
    ASSERT_FALSE(plain.isOk());
    EXPECT_NE(plain.status().message().find("not a vista baked file"), std::string::npos);
    const std::string bytes = readBytes(dir.file("city.baked.osgb"));
    {
        std::ofstream o(dir.file("trunc.osgb"), std::ios::binary);
        o << bytes.substr(0, bytes.size() * 2 / 3);
    }
    auto tr = loadBakedFile(dir.file("trunc.osgb"));
    ASSERT_FALSE(tr.isOk());
    EXPECT_NE(tr.status().message().find("trunc.osgb"), std::string::npos);
    std::string bad = bytes;
    bad[bad.size() / 3] ^= 0x11;
    {
        std::ofstream o(dir.file("bad.osgb"), std::ios::binary);
        o << bad;
    }
    EXPECT_FALSE(loadBakedFile(dir.file("bad.osgb")).isOk());
    EXPECT_FALSE(loadBakedFile(dir.file("missing.osgb")).isOk());
}

// The impostor bench mode through OpenGL (skipped without a display, fails if
// the renderer does not start although one is set; run under xvfb-run -a).
TEST(ImpostorMode, DrawsImpostorsInTheCellAndResemblesTheGeometry) {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) GTEST_SKIP() << "no X display (run under xvfb-run -a)";
    auto renderer = OffscreenRenderer::create(160, 120);
    ASSERT_TRUE(renderer.isOk()) << "DISPLAY is set but the renderer failed: " << renderer.status().message();
    TempDir dir;
    ASSERT_TRUE(writeCityFile(makeBakeCity(), dir.file("city.osgb")).isOk());
    auto city = loadCityFile(dir.file("city.osgb"));
    ASSERT_TRUE(city.isOk());
    BakeParams p = smallParams();
    BakeInput in = prepareBake(*city, p);
    CellResult cr = bakeCell(in, in.cells[0], p);
    ASSERT_EQ(cr.impostors.size(), 2u);
    auto root = assembleBakedScene(*city, in.cells, {cr}, p.canonical());
    ModeContext ctx;
    ctx.scene = root.get();
    ctx.renderer = renderer->get();
    auto mode = makeImpostorMode(ctx);
    ASSERT_TRUE(mode.isOk()) << mode.status().message();
    Camera cam;
    cam.eye = {50, 0, 1.6};
    cam.heading = kHalfPi;  // east, towards the far tile at x = 300
    cam.fovY = 60 * 3.14159265358979 / 180;
    cam.width = 160;
    cam.height = 120;
    Image withImp, plain;
    FrameStats st;
    ASSERT_TRUE((*mode)->renderFrame(cam, withImp, st).isOk());
    ASSERT_FALSE(st.notes.empty());
    EXPECT_EQ(st.notes.back(), "cell 0 (2 impostors)");
    root->setForcedCell(-1);
    FrameStats st2;
    ASSERT_TRUE((*renderer)->render(root.get(), cam, 0.0, &plain, nullptr, st2).isOk());
    const double psnr = lumaPsnr(withImp, plain);
    EXPECT_LT(psnr, kPsnrCapDb) << "the impostor was not drawn (identical to the plain city)";
    EXPECT_GT(psnr, 25.0) << "the impostor does not resemble the geometry it replaces";
    // Without a baked scene or file, the mode explains what is missing.
    ModeContext none;
    none.renderer = renderer->get();
    auto bad = makeImpostorMode(none);
    ASSERT_FALSE(bad.isOk());
    EXPECT_NE(bad.status().message().find("--baked"), std::string::npos);
}

// The baked modes draw the near field in the 40 m chunks of
// `full`/`hybrid` (view_cell_switch.h). On a small generated city, from inside
// a baked cell looking down its street: the baked modes draw no more
// triangles than `full` (a subset of its chunks, plus the few mesh triangles
// or points), fewer than the whole 250 m tiles they drew before, and the
// picture stays within a stated PSNR of `full`.
TEST(BakedChunks, BakedModesDrawNoMoreTrianglesThanFullAndMatchIt) {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) GTEST_SKIP() << "no X display (run under xvfb-run -a)";
    const int W = 160, H = 120;
    auto renderer = OffscreenRenderer::create(W, H);
    ASSERT_TRUE(renderer.isOk()) << "DISPLAY is set but the renderer failed: " << renderer.status().message();
    CityParams cp;
    cp.size_m = 700;
    cp.tile_size_m = 100;  // small tiles: far fields fit in a small city
    cp.seed = 3;
    auto gen = generateCity(cp);
    ASSERT_TRUE(gen.isOk()) << gen.status().message();
    TempDir dir;
    ASSERT_TRUE(writeCityFile(*gen, dir.file("city.osgb")).isOk());
    auto city = loadCityFile(dir.file("city.osgb"));
    ASSERT_TRUE(city.isOk()) << city.status().message();
    const BakeParams p = meshParams();
    BakeInput in = prepareBake(*city, p);
    ASSERT_FALSE(in.cells.empty());
    // The longest cells first: the first with a mesh at both ends.
    std::vector<size_t> order(in.cells.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t a, size_t b) { return in.cells[a].box.halfLength > in.cells[b].box.halfLength; });
    CellResult cr;
    for (size_t k = 0; k < order.size() && k < 12; ++k) {
        cr = bakeCell(in, in.cells[order[k]], p);
        if (cr.meshes.size() == 2) break;
    }
    ASSERT_FALSE(cr.meshes.empty()) << "no cell of the test city has a far field";
    const ViewCell& cell = in.cells[cr.cell];
    auto root = assembleBakedScene(*city, in.cells, {cr}, p.canonical(), p.representation);
    ModeContext ctx;
    ctx.scene = root.get();
    ctx.renderer = renderer->get();
    auto lod = makeLodMeshMode(ctx);
    auto full = makeFullMode(ctx);
    ASSERT_TRUE(lod.isOk() && full.isOk());
    ASSERT_TRUE(root->hasNearChunks());
    EXPECT_EQ(root->nearChunkDistance(), kDefaultNearDistance) << "the near distance of hybrid";
    const ViewCellBox& b = cell.box;
    int views = 0;
    double worstPsnr = 1e9;
    for (int dir01 = 0; dir01 < 2; ++dir01) {
        const double sgn = dir01 ? -1.0 : 1.0;
        Camera cam;
        cam.eye =
            b.center + glm::dvec3(-sgn * b.axis.x * b.halfLength * 0.5, -sgn * b.axis.y * b.halfLength * 0.5, 0.0);
        cam.eye.z = cell.groundMax + 1.7;
        if (!b.contains(cam.eye)) cam.eye.z = b.center.z;
        cam.heading = std::atan2(sgn * b.axis.x, sgn * b.axis.y);
        cam.fovY = 60 * kPi / 180;
        cam.width = W;
        cam.height = H;
        Image baked, ref, whole;
        FrameStats sb, sf, sw;
        ASSERT_TRUE((*lod)->renderFrame(cam, baked, sb).isOk());
        ASSERT_EQ(root->lastCell(), int(cr.cell));
        ASSERT_TRUE((*full)->renderFrame(cam, ref, sf).isOk());
        // The same frame with the whole tiles (as before the chunking).
        root->setNearChunks(NearFieldScene(), 0.0);
        ASSERT_TRUE((*renderer)->render(root.get(), cam, 0.0, &whole, nullptr, sw).isOk());
        root->setNearChunks(ctx.nearField(), kDefaultNearDistance);
        const double psnr = lumaPsnr(baked, ref);
        std::printf("cell %u view %d: triangles lodmesh %llu, full %llu, whole tiles %llu; lodmesh vs full %.1f dB\n",
                    cr.cell, dir01, (unsigned long long)sb.triangles, (unsigned long long)sf.triangles,
                    (unsigned long long)sw.triangles, psnr);
        EXPECT_GT(sf.triangles, 0u);
        EXPECT_LE(sb.triangles, sf.triangles) << "the baked mode draws more than full";
        EXPECT_LT(sb.triangles, sw.triangles) << "chunking saved nothing over the whole tiles";
        EXPECT_GT(psnr, 30.0) << "the baked frame does not match full";
        worstPsnr = std::min(worstPsnr, psnr);
        ++views;
    }
    EXPECT_EQ(views, 2);
    // Outside every cell the chunked baked root is exactly full's frame.
    root->setForcedCell(-1);
    Camera out;
    out.eye = b.center + glm::dvec3(0, 0, 40.0);
    out.heading = 0.3;
    out.pitch = -0.3;
    out.fovY = 60 * kPi / 180;
    out.width = W;
    out.height = H;
    Image a, c;
    FrameStats s1, s2;
    ASSERT_TRUE((*lod)->renderFrame(out, a, s1).isOk());
    ASSERT_TRUE((*full)->renderFrame(out, c, s2).isOk());
    EXPECT_EQ(s1.triangles, s2.triangles);
    EXPECT_EQ(lumaPsnr(a, c), kPsnrCapDb) << "without a cell the chunked baked root is full";
    root->setForcedCell(-2);
}

}  // namespace
}  // namespace vista
