// Bake: textured LOD meshes (Chen et al. 2003) and the lodmesh mode.
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

// A perspective image (width x height, vertical field of view fovY, row 0 at
// the top) from `eye` looking along +x of the impostor frame; `shade` gives
// the colour of a pixel's ray (unit direction) or nothing (black).
Image frameImage(int width, int height, double fovY, const glm::vec3& eye,
                 const std::function<glm::u8vec4(const glm::vec3&)>& shade) {
    Image img(width, height);
    const double f = std::tan(0.5 * fovY), aspect = double(width) / height;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const double sx = ((x + 0.5) / width * 2 - 1) * f * aspect, sy = (1 - (y + 0.5) / height * 2) * f;
            img.set(x, y, shade(glm::normalize(glm::vec3(1.0f, float(-sx), float(sy)))));
        }
    (void)eye;
    return img;
}

// The mesh ray-cast on the CPU (an independent check of geometry and
// projective texture): the hit's texture coordinate interpolated as the GPU
// does (s q, t q, q linear on the triangle, then divided), the image sampled
// bilinearly, alpha tested at 0.5 as the node does.
struct MeshCaster {
    explicit MeshCaster(const TexturedDepthMeshData& d) : mesh(d) {
        TriangleSoup soup;
        soup.positions = d.positions;
        soup.colors.assign(d.positions.size(), glm::u8vec4(255));
        soup.indices = d.indices;
        auto s = RayScene::build(soup);
        EXPECT_TRUE(s.isOk());
        if (s) scene = std::move(*s);
    }
    glm::u8vec4 shade(const glm::vec3& eye, const glm::vec3& dir) const {
        const RayHit h = scene->intersect(eye, dir);
        if (!h.hit) return glm::u8vec4(0, 0, 0, 255);
        const uint32_t* t = &mesh.indices[size_t(h.primId) * 3];
        const glm::vec4 tc =
            (1 - h.u - h.v) * mesh.texcoords[t[0]] + h.u * mesh.texcoords[t[1]] + h.v * mesh.texcoords[t[2]];
        const double s = tc.x / tc.w * mesh.width - 0.5, r = tc.y / tc.w * mesh.height - 0.5;
        const int i0 = std::clamp(int(std::floor(s)), 0, mesh.width - 1),
                  j0 = std::clamp(int(std::floor(r)), 0, mesh.height - 1);
        const int i1 = std::min(i0 + 1, mesh.width - 1), j1 = std::min(j0 + 1, mesh.height - 1);
        const double a = std::clamp(s - i0, 0.0, 1.0), b = std::clamp(r - j0, 0.0, 1.0);
        auto at = [&](int i, int j) { return glm::dvec4(mesh.image[size_t(j) * size_t(mesh.width) + size_t(i)]); };
        const glm::dvec4 c =
            (1 - b) * ((1 - a) * at(i0, j0) + a * at(i1, j0)) + b * ((1 - a) * at(i0, j1) + a * at(i1, j1));
        if (c.w <= 127.5) return glm::u8vec4(0, 0, 0, 255);
        return glm::u8vec4(uint8_t(c.x + 0.5), uint8_t(c.y + 0.5), uint8_t(c.z + 0.5), 255);
    }
    const TexturedDepthMeshData& mesh;
    std::unique_ptr<RayScene> scene;
};

TEST(LodMesh, OneMeshPerStreetEndWithinTheBudgetReproducingTheRayCastFarField) {
    TempDir dir;
    ASSERT_TRUE(writeCityFile(makeBakeCity(), dir.file("city.osgb")).isOk());
    auto city = loadCityFile(dir.file("city.osgb"));
    ASSERT_TRUE(city.isOk());
    const BakeParams p = meshParams();
    BakeInput in = prepareBake(*city, p);
    const ViewCell& cell = in.cells[0];
    CellResult cr = bakeCell(in, cell, p);
    EXPECT_TRUE(cr.impostors.empty());
    ASSERT_EQ(cr.meshes.size(), 2u) << (cr.notes.empty() ? "" : cr.notes[0]);
    size_t total = 0;
    for (const MeshResult& m : cr.meshes) {
        total += m.mesh.triangleCount();
        EXPECT_GT(m.mesh.triangleCount(), 10u);
        EXPECT_LE(m.mesh.triangleCount(), size_t(p.mesh.maxTriangles / 2));
        ASSERT_EQ(m.hiddenTiles.size(), 1u);  // the same far set as the point bake
        EXPECT_NE(m.hiddenTiles[0], in.tiles[0].child);
        // PSNR against the Embree image of the same far field from the same eye
        // (the viewpoint the mesh was made for), and from 30 m down the street
        // (parallax the mesh approximates).
        FarSet fs = selectFarSet(*city, in.tiles, cell, m.end, p.far);
        SoupSceneOptions so;
        so.cullBackFaces = true;
        auto far = RayScene::build(fs.soup, so);
        ASSERT_TRUE(far.isOk());
        MeshCaster mc(m.mesh);
        const glm::vec3 centre = glm::vec3(cellInFrame(cell, m.frame).center());
        EXPECT_NEAR(glm::length(centre - m.mesh.eye), 0.0f, 1e-3f);
        for (float ahead : {0.0f, 30.0f}) {
            const glm::vec3 eye = centre + glm::vec3(ahead, 0, 0);
            auto ref = frameImage(160, 120, 60 * kPi / 180, eye, [&](const glm::vec3& d) {
                const RayHit h = (*far)->intersect(eye, d);
                return h.hit ? glm::u8vec4(h.color.x, h.color.y, h.color.z, 255) : glm::u8vec4(0, 0, 0, 255);
            });
            auto got = frameImage(160, 120, 60 * kPi / 180, eye, [&](const glm::vec3& d) { return mc.shade(eye, d); });
            const double psnr = lumaPsnr(got, ref);
            std::printf("mesh cell 0 end %d, eye %.0f m ahead: %zu triangles, luma PSNR %.1f dB\n", int(m.end), ahead,
                        m.mesh.triangleCount(), psnr);
            EXPECT_GT(psnr, ahead == 0 ? 28.0 : 26.0) << "end " << int(m.end) << ", eye " << ahead << " m ahead";
        }
    }
    EXPECT_LE(total, size_t(p.mesh.maxTriangles));
    // Deterministic: the same cell twice gives the same mesh.
    CellResult again = bakeCell(in, cell, p);
    ASSERT_EQ(again.meshes.size(), 2u);
    EXPECT_EQ(again.meshes[0].mesh.positions, cr.meshes[0].mesh.positions);
    EXPECT_EQ(again.meshes[0].mesh.indices, cr.meshes[0].mesh.indices);
    EXPECT_EQ(again.meshes[1].mesh.image, cr.meshes[1].mesh.image);

    // Codec: round trip, its own magic, damage is an error.
    const std::string bytes = encodeCellResult(cr, 42);
    EXPECT_EQ(bytes.substr(0, 8), "VBCMESH1");
    auto back = decodeCellResult(bytes, 42, "c");
    ASSERT_TRUE(back.isOk()) << back.status().message();
    ASSERT_EQ(back->meshes.size(), 2u);
    EXPECT_EQ(back->meshes[1].mesh.texcoords, cr.meshes[1].mesh.texcoords);
    EXPECT_EQ(encodeCellResult(*back, 42), bytes);
    EXPECT_FALSE(decodeCellResult(bytes, 43, "c").isOk());
    for (size_t at : {size_t(20), bytes.size() / 2, bytes.size() - 9}) {
        std::string bad = bytes;
        bad[at] ^= 0x20;
        EXPECT_FALSE(decodeCellResult(bad, 42, "c").isOk()) << at;
    }
    EXPECT_FALSE(decodeCellResult(bytes.substr(0, bytes.size() / 2), 42, "c").isOk());

    // Assembled file: loads as a mesh bake; truncation is an error.
    auto root = assembleBakedScene(*city, in.cells, {cr}, p.canonical(), p.representation);
    ASSERT_TRUE(writeSceneFile(*root, dir.file("city.mesh.osgb")).isOk());
    auto bf = loadBakedFile(dir.file("city.mesh.osgb"));
    ASSERT_TRUE(bf.isOk()) << bf.status().message();
    EXPECT_TRUE(bf->meshes);
    EXPECT_EQ(bf->meshCount, 2u);
    EXPECT_EQ(bf->meshTriangles, total);
    EXPECT_EQ(bf->root->impostorsOf(0).size(), 2u);
    const std::string file = readBytes(dir.file("city.mesh.osgb"));
    {
        std::ofstream o(dir.file("trunc.osgb"), std::ios::binary);
        o << file.substr(0, file.size() * 3 / 4);
    }
    auto tr = loadBakedFile(dir.file("trunc.osgb"));
    ASSERT_FALSE(tr.isOk());
    EXPECT_NE(tr.status().message().find("trunc.osgb"), std::string::npos);
}

// Greedy refinement on a synthetic depth image: a near box in front of a far
// wall. The step between them is not bridged by any triangle (no skin), and
// the budget holds.
TEST(LodMesh, NoSkinAcrossADepthDiscontinuityAndTheBudgetHolds) {
    TriangleSoup soup;
    addBox(soup, {300, -100, -2}, {301, 100, 60}, constantColor);                                          // far wall
    addBox(soup, {150, -10, -2}, {160, 10, 20}, [](glm::vec3) { return glm::u8vec4(200, 40, 40, 255); });  // near box
    SoupSceneOptions so;
    so.cullBackFaces = true;
    auto scene = RayScene::build(soup, so);
    ASSERT_TRUE(scene.isOk());
    const glm::dvec3 eye(0, 0, 1.6);
    for (int budget : {512, 4096}) {
        const DepthView view = chooseDepthView(soup, eye, 0.002, 256, budget);
        const FarImage img = renderFarImage(**scene, view);
        DepthMeshStats st;
        TexturedDepthMeshData m = buildDepthMesh(img, 50.0, budget, 0.5, st);
        EXPECT_LE(m.triangleCount(), size_t(budget));
        EXPECT_GT(st.droppedTriangles, 0u);
        // Opaque vertices (a hit sample, alpha 255): misses only carry the
        // transparent part of the texture.
        auto opaque = [&](uint32_t v) {
            const glm::vec4 tc = m.texcoords[v];
            const int i = int(std::lround(tc.x / tc.w * m.width - 0.5)),
                      j = int(std::lround(tc.y / tc.w * m.height - 0.5));
            return m.image[size_t(j) * size_t(m.width) + size_t(i)].w == 255;
        };
        for (size_t t = 0; t < m.triangleCount(); ++t) {
            float lo = 1e9f, hi = 0;
            bool allOpaque = true;
            for (int k = 0; k < 3; ++k) allOpaque = allOpaque && opaque(m.indices[3 * t + size_t(k)]);
            if (!allOpaque) continue;
            for (int k = 0; k < 3; ++k) {
                const float x = m.positions[m.indices[3 * t + size_t(k)]].x;
                lo = std::min(lo, x);
                hi = std::max(hi, x);
            }
            // Every vertex lies on the box front (x = 150) or on the wall (x = 300) or the ground; none bridges both.
            EXPECT_FALSE(lo < 170 && hi > 280)
                << "triangle " << t << " spans " << lo << " .. " << hi << " (budget " << budget << ")";
        }
    }
}

// The lodmesh mode through OpenGL (run under xvfb-run -a): in the cell it draws
// the meshes instead of the far tiles and looks like the geometry; outside every
// cell it uses the nearest cell.
TEST(LodMeshMode, DrawsTheCellMeshesAndResemblesTheGeometry) {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) GTEST_SKIP() << "no X display (run under xvfb-run -a)";
    auto renderer = OffscreenRenderer::create(160, 120);
    ASSERT_TRUE(renderer.isOk()) << "DISPLAY is set but the renderer failed: " << renderer.status().message();
    TempDir dir;
    ASSERT_TRUE(writeCityFile(makeBakeCity(), dir.file("city.osgb")).isOk());
    auto city = loadCityFile(dir.file("city.osgb"));
    ASSERT_TRUE(city.isOk());
    const BakeParams p = meshParams();
    BakeInput in = prepareBake(*city, p);
    CellResult cr = bakeCell(in, in.cells[0], p);
    ASSERT_EQ(cr.meshes.size(), 2u);
    auto root = assembleBakedScene(*city, in.cells, {cr}, p.canonical(), p.representation);
    ModeContext ctx;
    ctx.scene = root.get();
    ctx.renderer = renderer->get();
    auto mode = makeLodMeshMode(ctx);
    ASSERT_TRUE(mode.isOk()) << mode.status().message();
    Camera cam;
    cam.eye = {50, 0, 1.6};
    cam.heading = kHalfPi;  // east, towards the far tile at x = 300
    cam.fovY = 60 * kPi / 180;
    cam.width = 160;
    cam.height = 120;
    Image withMesh, plain, noFar;
    FrameStats st;
    ASSERT_TRUE((*mode)->renderFrame(cam, withMesh, st).isOk());
    ASSERT_FALSE(st.notes.empty());
    EXPECT_EQ(st.notes.back(), "cell 0 (2 meshes)");
    root->setForcedCell(-1);
    FrameStats st2;
    ASSERT_TRUE((*renderer)->render(root.get(), cam, 0.0, &plain, nullptr, st2).isOk());
    // The cell's near field alone: the tiles the meshes do not replace.
    osg::ref_ptr<osg::Group> nearOnly = new osg::Group;
    nearOnly->setStateSet(root->getStateSet());
    const std::vector<uint32_t> hidden = root->hiddenOf(0);
    for (unsigned i = 0; i < root->getTileCount(); ++i)
        if (std::find(hidden.begin(), hidden.end(), i) == hidden.end()) nearOnly->addChild(root->getChild(i));
    FrameStats st3;
    ASSERT_TRUE((*renderer)->render(nearOnly.get(), cam, 0.0, &noFar, nullptr, st3).isOk());
    root->setForcedCell(-2);
    const double psnr = lumaPsnr(withMesh, plain), without = lumaPsnr(noFar, plain);
    std::printf("lodmesh vs full: %.1f dB; the cell's near field without the meshes vs full: %.1f dB\n", psnr, without);
    EXPECT_LT(psnr, kPsnrCapDb) << "the mesh was not drawn (identical to the plain city)";
    EXPECT_GT(psnr, 25.0) << "the mesh does not resemble the geometry it replaces";
    EXPECT_GT(psnr, without + 3.0) << "the mesh adds little over leaving the far field out";
    // Outside every cell: the nearest one (cell 0 is nearest to y = 30).
    cam.eye = {50, 30, 1.6};
    FrameStats st4;
    ASSERT_TRUE((*mode)->renderFrame(cam, withMesh, st4).isOk());
    EXPECT_EQ(st4.notes.back(), "cell 0 (2 meshes)");
    // Without a mesh bake the mode says what is missing.
    ModeContext none;
    none.renderer = renderer->get();
    auto bad = makeLodMeshMode(none);
    ASSERT_FALSE(bad.isOk());
    EXPECT_NE(bad.status().message().find("--representation mesh"), std::string::npos);
}

}  // namespace
}  // namespace vista
