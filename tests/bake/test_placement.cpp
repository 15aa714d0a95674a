// Bake: impostor placement (from-region visibility, cost rule, storage budget).
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

// From-region visibility of the baked points through the
// whole city, and the cost estimate that decides where an impostor goes.
TEST(Placement, PointsBehindAnOccluderAreDroppedAndTheCostRuleHolds) {
    TempDir dir;
    ASSERT_TRUE(writeCityFile(makeBakeCity(), dir.file("city.osgb")).isOk());
    auto city = loadCityFile(dir.file("city.osgb"));
    ASSERT_TRUE(city.isOk());
    BakeParams p = smallParams();
    p.placement.byCost = true;
    BakeInput in = prepareBake(*city, p);
    ASSERT_TRUE(in.cityRays) << "placement by cost builds the city's ray scene";
    const ViewCell& cell = in.cells[0];
    const FarSet fs = selectFarSet(*city, in.tiles, cell, 1, p.far);  // end 1: towards x = 100, far tile at x = 300
    ASSERT_FALSE(fs.tiles.empty());
    ASSERT_GT(fs.soup.triangleCount(), 0u);
    // The far tile's first wall spans world x 285..315, y -30..-22, 12 m high.
    const glm::vec3 front(fs.frame.toLocal(glm::dvec3(284.9, -26, 5)));   // on its face towards the cell
    const glm::vec3 behind(fs.frame.toLocal(glm::dvec3(316.5, -26, 5)));  // behind it, seen from nowhere in the cell
    const glm::vec3 above(
        fs.frame.toLocal(glm::dvec3(300, -26, 12.05)));  // on its roof: seen over it from eye height? no
    const std::vector<uint8_t> vis = visibleFromCell(*in.cityRays, cell, fs.frame, {front, behind, above},
                                                     outputPixelAngle(p.sampling), p.placement);
    ASSERT_EQ(vis.size(), 3u);
    EXPECT_EQ(vis[0], 1) << "a point on the face towards the cell is visible";
    EXPECT_EQ(vis[1], 0) << "a point behind the wall is occluded from every viewpoint";
    EXPECT_EQ(vis[2], 0) << "a roof 12 m up is not seen from eye height";
    // The packet occlusion test agrees with the single-ray one (rays from the
    // cell centre to points on a grid through the far tile, some behind walls,
    // some in the open, one with an empty interval).
    {
        const glm::vec3 o(glm::dvec3(cell.box.center) - in.cityRays->frameOrigin());
        std::vector<glm::vec3> org, dirs;
        std::vector<float> tfars;
        for (int i = 0; i < 21; ++i) {
            const glm::vec3 q(glm::dvec3(270 + 3 * i, -35 + 3.3 * i, 4) - in.cityRays->frameOrigin());
            org.push_back(o);
            dirs.push_back(glm::normalize(q - o));
            tfars.push_back(i == 20 ? -1.0f : glm::length(q - o));
        }
        std::vector<uint8_t> many(org.size(), 7);
        in.cityRays->occludedMany(org.data(), dirs.data(), int(org.size()), tfars.data(), many.data());
        size_t blocked = 0;
        for (size_t i = 0; i < org.size(); ++i) {
            EXPECT_EQ(many[i] != 0, in.cityRays->occluded(org[i], dirs[i], 0.0f, tfars[i])) << "ray " << i;
            blocked += many[i];
        }
        EXPECT_GT(blocked, 0u);
        EXPECT_LT(blocked, org.size());
        EXPECT_EQ(many.back(), 0) << "an empty interval is not occluded";
    }
    // The depth-image prefilter (the default) against one ray per point and
    // viewpoint: a grid of points through the far tile (inside walls, on
    // faces, in the open) — what the image keeps is confirmed by rays, so it
    // is a subset; it may lose only points seen through sub-pixel gaps.
    {
        std::vector<glm::vec3> grid;
        for (int i = 0; i < 40; ++i)
            for (int j = 0; j < 30; ++j)
                for (int k = 0; k < 8; ++k)
                    grid.push_back(
                        glm::vec3(fs.frame.toLocal(glm::dvec3(270 + 1.55 * i, -45 + 1.9 * j, 0.3 + 1.9 * k))));
        PlacementParams byRays = p.placement;
        byRays.visByImage = false;
        ASSERT_TRUE(p.placement.visByImage) << "the image prefilter is the default";
        const std::vector<uint8_t> img =
            visibleFromCell(*in.cityRays, cell, fs.frame, grid, outputPixelAngle(p.sampling), p.placement);
        const std::vector<uint8_t> ray =
            visibleFromCell(*in.cityRays, cell, fs.frame, grid, outputPixelAngle(p.sampling), byRays);
        ASSERT_EQ(img.size(), grid.size());
        size_t seenByRays = 0, seenByImage = 0, onlyImage = 0;
        for (size_t i = 0; i < grid.size(); ++i) {
            seenByRays += ray[i];
            seenByImage += img[i];
            onlyImage += img[i] && !ray[i];
        }
        EXPECT_EQ(onlyImage, 0u) << "the image keeps a point that no viewpoint's ray sees";
        EXPECT_GT(seenByRays, grid.size() / 20) << "some of the grid is in plain view";
        EXPECT_LT(seenByRays, grid.size() - grid.size() / 20) << "some of the grid is behind or inside walls";
        EXPECT_GE(double(seenByImage), 0.98 * double(seenByRays)) << seenByImage << " of " << seenByRays;
    }
    // The estimate: rays reach the far walls; saved/cost follow the stated formula.
    PlacementEstimate e = estimatePlacement(*in.cityRays, in.tileLookup, cell, fs, p.sampling, p.placement);
    EXPECT_GT(e.rays, 0);
    EXPECT_GT(e.farHits, 0) << "the far walls are in plain view down the street";
    EXPECT_GT(e.farPixels, 0.0);
    EXPECT_LE(e.farPixels, e.maxFarPixels);
    EXPECT_NEAR(e.savedMs, double(fs.soup.triangleCount()) * p.placement.triangleNs * 1e-6, 1e-9);
    EXPECT_NEAR(e.costMs, p.placement.pointsPerFarPixel * e.farPixels * p.placement.pointNs * 1e-6, 1e-9);
    EXPECT_EQ(e.place, e.savedMs > e.costMs);
    // A few walls (120 triangles) seen over hundreds of pixels: points cost more than the triangles.
    EXPECT_FALSE(e.place) << e.describe();
    PlacementParams cheapPoints = p.placement;
    cheapPoints.pointNs = 1e-6;
    EXPECT_TRUE(estimatePlacement(*in.cityRays, in.tileLookup, cell, fs, p.sampling, cheapPoints).place);
    // The whole cell: the ends are not placed, each with a note saying why.
    CellResult cr = bakeCell(in, cell, p);
    EXPECT_TRUE(cr.impostors.empty());
    size_t notPlaced = 0;
    for (const auto& n : cr.notes) notPlaced += n.find("not placed: saves") != std::string::npos;
    EXPECT_EQ(notPlaced, 2u);
    // With cheap points both ends are placed; a wall just beyond end 1 (world
    // x 102..108, y -40..8, 40 m high) hides the far tile's walls at y < 0
    // from the whole cell: their points are dropped, the open part stays.
    City occ = makeBakeCity();
    occ.tiles[0].meshes[size_t(Material::Wall)] =
        boxMesh({52, -40, 0}, {58, 8, 40}, {90, 90, 90, 255}, {100, 100, 100, 255});
    ASSERT_TRUE(writeCityFile(occ, dir.file("occ.osgb")).isOk());
    auto occCity = loadCityFile(dir.file("occ.osgb"));
    ASSERT_TRUE(occCity.isOk());
    p.placement = cheapPoints;
    BakeParams all = smallParams();
    BakeInput occIn = prepareBake(*occCity, p);
    CellResult placed = bakeCell(occIn, occIn.cells[0], p), every = bakeCell(occIn, occIn.cells[0], all);
    ASSERT_EQ(placed.impostors.size(), 2u);
    ASSERT_EQ(every.impostors.size(), 2u);
    for (size_t k = 0; k < 2; ++k) {
        const ImpostorResult &a = placed.impostors[k], &b = every.impostors[k];
        EXPECT_EQ(a.hiddenTiles, b.hiddenTiles);
        EXPECT_GT(a.stats.points, 0u);
        if (a.end == 1) {
            EXPECT_LT(double(a.stats.points), 0.8 * double(b.stats.points)) << "the occluded points were kept";
            size_t behindWall = 0;
            for (const auto& q : a.data.positions) behindWall += a.frame.toWorld(glm::dvec3(q)).y < -3.0;
            EXPECT_EQ(behindWall, 0u) << "points hidden by the wall from the whole cell survived";
        } else {
            EXPECT_EQ(a.stats.points, b.stats.points) << "nothing occludes end 0's far field";
        }
    }
    EXPECT_NE(p.canonical(), all.canonical()) << "placement changes the config hash";
}

// The storage budget: paying ends ranked by (saved - cost) ms per predicted
// MB, taken while they fit; an end that does not fit is passed over and a
// smaller one after it may still fit; an end that does not pay never counts.
TEST(Placement, StorageBudgetTakesTheMostMillisecondsPerMegabyteThatFit) {
    auto end = [](uint32_t cell, int e, double saved, double cost, double mb) {
        PlannedEnd p;
        p.cell = cell;
        p.end = uint8_t(e);
        p.estimate.savedMs = saved;
        p.estimate.costMs = cost;
        p.estimate.place = saved > cost;
        p.predictedMb = mb;
        return p;
    };
    // Values (ms per MB): (1,0) 8, (1,1) does not pay, (2,0) 7.5, (3,0) 8
    // (a tie with (1,0): the lower cell first), (4,1) 5 with 50 MB, (5,0) 4.
    const std::vector<PlannedEnd> ends = {end(5, 0, 3, 1, 0.5), end(4, 1, 250, 0, 50), end(3, 0, 9, 1, 1),
                                          end(2, 0, 30, 0, 4),  end(1, 1, 5, 6, 0.1),  end(1, 0, 10, 2, 1)};
    const PlacementPlan plan = rankPlacement(ends, 6.6);
    ASSERT_EQ(plan.ends.size(), ends.size());
    for (size_t i = 1; i < plan.ends.size(); ++i)
        EXPECT_LT(std::make_pair(plan.ends[i - 1].cell, plan.ends[i - 1].end),
                  std::make_pair(plan.ends[i].cell, plan.ends[i].end));
    auto at = [&](uint32_t c, int e) {
        const PlannedEnd* p = plan.find(c, e);
        EXPECT_NE(p, nullptr) << c << "," << e;
        return p ? *p : PlannedEnd();
    };
    EXPECT_EQ(plan.find(9, 0), nullptr);
    EXPECT_EQ(at(1, 0).rank, 0);
    EXPECT_EQ(at(3, 0).rank, 1);
    EXPECT_EQ(at(2, 0).rank, 2);
    EXPECT_EQ(at(4, 1).rank, 3);
    EXPECT_EQ(at(5, 0).rank, 4);
    EXPECT_EQ(at(1, 1).rank, -1);
    // 1 + 1 + 4 = 6 MB; 50 MB does not fit in what is left; 0.5 MB does.
    EXPECT_TRUE(at(1, 0).inBudget && at(3, 0).inBudget && at(2, 0).inBudget && at(5, 0).inBudget);
    EXPECT_FALSE(at(4, 1).inBudget);
    EXPECT_FALSE(at(1, 1).inBudget) << "an end that does not pay is never chosen";
    EXPECT_EQ(plan.chosen, 4u);
    EXPECT_EQ(plan.paying, 5u);
    EXPECT_NEAR(plan.chosenMb, 6.5, 1e-12);
    EXPECT_NEAR(plan.payingMb, 56.5, 1e-12);
    EXPECT_NE(at(4, 1).describe().find("over the storage budget"), std::string::npos) << at(4, 1).describe();
    EXPECT_EQ(at(2, 0).describe().rfind("placed: ", 0), 0u) << at(2, 0).describe();
    EXPECT_EQ(at(1, 1).describe().rfind("not placed: saves", 0), 0u) << at(1, 1).describe();
    // A budget below the smallest paying end chooses nothing; a large one every paying end.
    EXPECT_EQ(rankPlacement(ends, 0.4).chosen, 0u);
    EXPECT_EQ(rankPlacement(ends, 1e9).chosen, 5u);
    // The predicted size follows its stated formula.
    PlacementEstimate e;
    e.farPixels = 1000;
    PlacementParams pp;
    EXPECT_NEAR(predictedMb(e, pp), pp.pointsPerFarPixel * 1000 * pp.bytesPerPoint / 1048576.0, 1e-12);
}

}  // namespace
}  // namespace vista
