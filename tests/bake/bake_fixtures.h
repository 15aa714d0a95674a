// Helpers shared by the bake tests (tests/bake/, tests/cmd/test_bake_cli.cpp): test scenes,
// small bake parameters, a hand-made cell result, the CLI runner.
#pragma once

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

namespace vista {
class TempDir : public test::TempDir {
public:
    TempDir() : test::TempDir("vista_bake_test") {}
};

// Box triangles (outward faces) appended to a soup, one colour per vertex from `color`.
inline void addBox(TriangleSoup& s, glm::vec3 lo, glm::vec3 hi, const std::function<glm::u8vec4(glm::vec3)>& color) {
    const uint32_t base = uint32_t(s.positions.size());
    for (int i = 0; i < 8; ++i) {
        glm::vec3 p((i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z);
        s.positions.push_back(p);
        s.colors.push_back(color(p));
    }
    const uint32_t f[] = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                          2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
    for (uint32_t i : f) s.indices.push_back(base + i);
}

inline glm::u8vec4 constantColor(glm::vec3) { return {100, 150, 200, 255}; }

// A far field: a building with a window pattern on ground, in an impostor frame.
inline TriangleSoup testFarField(bool constant) {
    TriangleSoup s;
    auto facade = [&](glm::vec3 p) -> glm::u8vec4 {
        if (constant) return constantColor(p);
        const int w = (int(std::floor(p.y / 3.0)) + int(std::floor(p.z / 3.0))) & 1;
        return w ? glm::u8vec4(60, 70, 90, 255) : glm::u8vec4(200, 180, 150, 255);
    };
    addBox(
        s, {150, -40, -1}, {210, 40, 0},
        constant ? constantColor : [](glm::vec3) { return glm::u8vec4(90, 120, 80, 255); });
    // Side walls seen at a slant (left- and right-facing): sampled better by one camera.
    addBox(s, {172, -39, 0}, {208, -37, 18}, [](glm::vec3) { return glm::u8vec4(150, 90, 60, 255); });
    addBox(s, {172, 37, 0}, {208, 39, 18}, [](glm::vec3) { return glm::u8vec4(60, 90, 150, 255); });
    // Facade made of 3 m strips so the colour changes across it.
    for (int i = 0; i < 10; ++i)
        for (int j = 0; j < 8; ++j) {
            const glm::vec3 lo(160, -30 + 6 * i, 3 * j), hi(170, -24 + 6 * i, 3 * j + 3);
            glm::u8vec4 c = facade(glm::vec3(0, float(i), float(j)));
            addBox(s, lo, hi, [c](glm::vec3) { return c; });
        }
    return s;
}

// ------------------------------------------------------ determinism, encoding
inline ImpostorResult bakeTestImpostor(int threads, const BakeParams& p) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, size_t(threads));
    TriangleSoup soup = testFarField(false);
    ImpostorResult r;
    Status st = bakeImpostor(soup, Box3{{-100, -5, 1.2}, {0, 5, 2.0}}, p, 11, r);
    EXPECT_TRUE(st.isOk()) << st.message();
    return r;
}

inline BakeParams smallParams() {
    BakeParams p;
    p.sampling.outHeight = 120;
    p.sampling.outWidth = 160;
    p.far.minTriangles = 1;
    return p;
}

// ---------------------------------------------------- whole pipeline, CLI
inline Mesh boxMesh(glm::vec3 lo, glm::vec3 hi, glm::u8vec4 c0, glm::u8vec4 c1) {
    Mesh m;
    for (int i = 0; i < 8; ++i) {
        m.positions.push_back({(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z});
        m.normals.push_back(glm::normalize(glm::vec3((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1)));
        m.colors.push_back((i & 4) ? c1 : c0);
    }
    const uint32_t f[] = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                          2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
    m.indices.assign(std::begin(f), std::end(f));
    return m;
}

// A street along x (edge 0), a zero-length and a very short edge, a near tile
// around the street and two far tiles with buildings beyond both street ends.
inline City makeBakeCity() {
    City c;
    c.params.size_m = 1000;
    c.params.tile_size_m = 250;
    c.params.seed = 5;
    c.params.hills_amplitude_m = 0;
    c.streets.nodes = {{0, 0}, {100, 0}, {100, 0}, {0, 0.8}};
    c.streets.edges = {
        {0, 1, RoadClass::Local, 10.0f, 2}, {1, 2, RoadClass::Local, 8.0f, 2}, {0, 3, RoadClass::Local, 8.0f, 2}};
    Tile near;
    near.origin = {50, 0, 0};
    near.meshes[size_t(Material::Ground)] =
        boxMesh({-60, -40, -1}, {60, 40, 0}, {90, 90, 90, 255}, {100, 100, 100, 255});
    c.tiles.push_back(near);
    for (int side = 0; side < 2; ++side) {
        Tile t;
        t.ix = side + 1;
        t.origin = {side ? 300.0 : -200.0, 0, 0};
        Mesh walls;
        for (int i = 0; i < 6; ++i)
            walls.append(boxMesh({-15, -30.0f + 10 * i, 0}, {15, -22.0f + 10 * i, 12.0f + 4 * i},
                                 {uint8_t(60 + 30 * i), 80, 120, 255}, {200, uint8_t(40 * i), 90, 255}));
        t.meshes[size_t(Material::Wall)] = walls;
        t.meshes[size_t(Material::Ground)] =
            boxMesh({-30, -40, -1}, {30, 40, 0}, {70, 110, 60, 255}, {80, 120, 70, 255});
        c.tiles.push_back(t);
    }
    return c;
}

inline int run(const std::string& args) {
    const std::string cmd = std::string(VISTA_BINARY) + " bake " + args + " > /dev/null 2>&1";
    const int rc = std::system(cmd.c_str());
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

// ------------------------------------------ textured LOD meshes (Chen et al. 2003)
inline BakeParams meshParams() {
    BakeParams p = smallParams();
    p.representation = BakeRepresentation::Mesh;
    p.mesh.maxTriangles = 2048;
    p.mesh.imageSize = 256;
    return p;
}

}  // namespace vista
