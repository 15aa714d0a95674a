// Bake: determinism across thread counts, cell results and their codec.
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

TEST(Bake, DeterministicAcrossThreadCounts) {
    const BakeParams p = smallParams();
    ImpostorResult a = bakeTestImpostor(1, p), b = bakeTestImpostor(2, p);
    ASSERT_GT(a.data.positions.size(), 100u);
    EXPECT_EQ(a.data.positions, b.data.positions);
    EXPECT_EQ(a.data.colors, b.data.colors);
    EXPECT_EQ(a.data.block, b.data.block);
    EXPECT_EQ(a.data.texels, b.data.texels);
    EXPECT_GT(a.stats.points, 0u);
    EXPECT_LT(a.stats.afterRemoval, a.stats.ldiSamples);
}

TEST(Bake, CellResultRoundTripAndCorruption) {
    CellResult cr;
    cr.cell = 3;
    cr.notes = {"end 0: far field small"};
    cr.impostors.push_back(bakeTestImpostor(2, smallParams()));
    cr.impostors[0].cell = 3;
    const std::string bytes = encodeCellResult(cr, 77);
    auto back = decodeCellResult(bytes, 77, "x");
    ASSERT_TRUE(back.isOk()) << back.status().message();
    EXPECT_EQ(back->cell, 3u);
    EXPECT_EQ(back->notes, cr.notes);
    EXPECT_EQ(back->impostors[0].data.positions, cr.impostors[0].data.positions);
    EXPECT_EQ(back->impostors[0].data.texels, cr.impostors[0].data.texels);
    EXPECT_FALSE(decodeCellResult(bytes, 78, "x").isOk());                              // other config
    EXPECT_FALSE(decodeCellResult(bytes.substr(0, bytes.size() / 2), 77, "x").isOk());  // truncated
    std::string bad = bytes;
    bad[bad.size() / 2] ^= 0x5a;
    auto r = decodeCellResult(bad, 77, "x");
    ASSERT_FALSE(r.isOk());
    EXPECT_NE(r.status().message().find("corrupted"), std::string::npos);
    EXPECT_FALSE(decodeCellResult("", 77, "x").isOk());
}

// Size and hash of encodeCellResult(handMadeCellResult(), 0x1234) as the
// VBCELL01 encoder writes it.
constexpr size_t kCellFormatSize = 901;
constexpr uint64_t kCellFormatHash = 10395255239569369693ull;

// A small cell result built by hand (no bake): two impostors, two notes.
CellResult handMadeCellResult() {
    CellResult cr;
    cr.cell = 12;
    cr.bakeMs = 3.5;
    cr.notes = {"end 0: far field small", "x"};
    for (int e = 0; e < 2; ++e) {
        ImpostorResult im;
        im.cell = 12;
        im.end = uint8_t(e);
        im.frame.origin = {100.5, -20.25, 3.0};
        im.frame.x = {e ? 1.0 : -1.0, 0.0};
        im.hiddenTiles = {uint32_t(1 + e), 7};
        im.data.planeOrigin = {1, 2, 3};
        im.data.planeU = {0, 4, 0};
        im.data.planeV = {0, 0, 5};
        im.data.texelsX = 2;
        im.data.texelsY = 1;
        for (int k = 0; k < 5; ++k) {
            im.data.positions.emplace_back(float(k), float(e), 1.5f);
            im.data.colors.emplace_back(uint8_t(10 * k), 20, 30, 255);
            im.data.block.push_back(k == 2 ? 0 : k == 4 ? 1 : -1);
        }
        im.data.texels.assign(4, glm::u8vec4(200, 100, 50, 255));
        im.stats.points = 5;
        im.stats.camW[1] = 64;
        im.stats.requiredStep = 0.001;
        cr.impostors.push_back(im);
    }
    return cr;
}

// The byte format is pinned: cells baked by an earlier build must still decode
// (a change to the field list needs a new magic, "VBCELL02").
TEST(Bake, CellResultFormatIsStable) {
    const std::string bytes = encodeCellResult(handMadeCellResult(), 0x1234);
    EXPECT_EQ(bytes.substr(0, 8), "VBCELL01");
    EXPECT_EQ(bytes.size(), kCellFormatSize);
    EXPECT_EQ(hashBytes64(bytes.data(), bytes.size()), kCellFormatHash);
    auto back = decodeCellResult(bytes, 0x1234, "golden");
    ASSERT_TRUE(back.isOk()) << back.status().message();
    EXPECT_EQ(encodeCellResult(*back, 0x1234), bytes);  // every field survives the round trip
}

// Fuzz-style: truncation and byte flips at every offset are errors naming the
// file, never a crash. With the integrity hash recomputed (as a buggy writer
// would produce), the reader's own bounds checks must still hold.
TEST(Bake, CellResultDecoderRejectsDamageAtEveryOffset) {
    const std::string bytes = encodeCellResult(handMadeCellResult(), 77);
    const size_t body = bytes.size() - 8;
    auto rehash = [](std::string b) {
        uint64_t h = hashBytes64(b.data(), b.size());
        b.append(reinterpret_cast<const char*>(&h), 8);
        return b;
    };
    auto expectError = [](const std::string& b, const char* what, size_t off) {
        auto r = decodeCellResult(b, 77, "dir/cell_12.vbc");
        ASSERT_FALSE(r.isOk()) << what << " at byte " << off << " was accepted";
        EXPECT_NE(r.status().message().find("'dir/cell_12.vbc'"), std::string::npos) << r.status().message();
    };
    size_t structural = 0, accepted = 0;
    for (size_t off = 0; off < bytes.size(); ++off) {
        expectError(bytes.substr(0, off), "truncation", off);
        for (int mask : {0x01, 0x5a, 0x80, 0xff}) {
            std::string flipped = bytes;
            flipped[off] = char(flipped[off] ^ mask);
            expectError(flipped, "a flip", off);
            if (off >= body) continue;
            std::string b = bytes.substr(0, body);
            b[off] = char(b[off] ^ mask);
            auto r = decodeCellResult(rehash(b), 77, "dir/cell_12.vbc");
            if (r.isOk()) {
                ++accepted;  // a flip inside a value (a position, a colour) is a valid file
                EXPECT_GE(off, 16u) << "magic or config hash damaged but accepted";
            } else {
                EXPECT_NE(r.status().message().find("'dir/cell_12.vbc'"), std::string::npos);
                structural += off >= 16 ? 1 : 0;
            }
        }
        if (off >= 16 && off < body) expectError(rehash(bytes.substr(0, off)), "a re-hashed truncation", off);
    }
    EXPECT_GT(structural, 50u) << "the reader's bounds checks were never exercised";
    EXPECT_GT(accepted, 100u);
    // Trailing bytes after a valid body are rejected too.
    expectError(rehash(bytes.substr(0, body) + std::string(4, '\0')), "trailing bytes", body);
}

}  // namespace
}  // namespace vista
