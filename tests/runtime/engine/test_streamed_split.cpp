// What a streamed city's near field and horizon rest on, without OSG:
// SplitIndex blocks (added and removed per region) select exactly what a
// linear scan over the resident objects selects, and a query visits the same
// blocks and objects whether 4 or 100 regions are resident; HeightGrid
// patches spliced in and out give the cells of one patch of the models present.
#include <gtest/gtest.h>

#include <limits>
#include <map>
#include <memory>
#include <random>
#include <vector>

#include "runtime/engine/adaptive_split.h"
#include "runtime/engine/horizon.h"
#include "tests/runtime/engine/fixtures.h"

using namespace vista;
using vista::test::splitBox;

namespace {

constexpr double kRegion = 400.0;  // metres a region side
constexpr double kChunk = 40.0;

// The objects of region (rx, ry): 40 m chunks of varying heights, one wider "large" chunk.
std::vector<SplitObject> regionObjects(int rx, int ry) {
    std::vector<SplitObject> out;
    const glm::dvec3 o(rx * kRegion, ry * kRegion, 0.0);
    for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 10; ++x)
            out.push_back(splitBox(o + glm::dvec3(x * kChunk, y * kChunk, 0.0),
                                   o + glm::dvec3((x + 1) * kChunk, (y + 1) * kChunk, 5.0 + (x * 7 + y * 3) % 40),
                                   uint64_t(100 + x + 10 * y)));
    out.push_back(splitBox(o + glm::dvec3(-5.0, 100.0, 0.0), o + glm::dvec3(kRegion + 5.0, 130.0, 1.0), 7));
    return out;
}

// A streamed object list as the near field keeps it: regions take runs of slots.
struct Streamed {
    std::vector<SplitObject> objects;
    SplitIndex index{objects, kRegion, nullptr};
    std::map<uint64_t, uint32_t> first;
    void add(int rx, int ry) {
        const std::vector<SplitObject> objs = regionObjects(rx, ry);
        const uint64_t key = uint64_t(ry) * 1000 + uint64_t(rx);
        const uint32_t at = uint32_t(objects.size());
        objects.insert(objects.end(), objs.begin(), objs.end());
        first[key] = at;
        index.addBlock(key, at, SplitIndex::makeBlock(objs.data(), objs.size()));
    }
    void remove(int rx, int ry) {
        const uint64_t key = uint64_t(ry) * 1000 + uint64_t(rx);
        index.removeBlock(key);
        SplitObject none = splitBox(glm::dvec3(std::numeric_limits<double>::infinity()),
                                    glm::dvec3(std::numeric_limits<double>::infinity()), 0);
        for (uint32_t i = first[key]; i < first[key] + 101; ++i) objects[i] = none;  // a free run
        first.erase(key);
    }
    // The linear scan over the resident objects, in block order.
    std::vector<uint32_t> linear(const glm::dvec3& eye, double d) const {
        std::vector<uint32_t> out;
        for (const auto& [key, at] : first)
            for (uint32_t i = at; i < at + 101; ++i)
                if (boxDistance(objects[i], eye) <= d) out.push_back(i);
        return out;
    }
};

}  // namespace

TEST(SplitIndexBlocks, SelectWhatALinearScanOfTheResidentRegionsSelects) {
    Streamed s;
    s.objects.reserve(200 * 101);
    for (int ry = 0; ry < 6; ++ry)
        for (int rx = 0; rx < 6; ++rx) s.add(rx, ry);
    s.remove(2, 2);
    s.remove(0, 5);
    s.add(7, 7);
    EXPECT_EQ(s.index.blockCount(), 35u);
    EXPECT_EQ(s.index.size(), 35u * 101u);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> xy(-300.0, 3300.0);
    for (int e = 0; e < 30; ++e) {
        const glm::dvec3 eye(xy(rng), xy(rng), e % 4 == 0 ? 200.0 : 1.7);
        for (double d : {0.0, 15.0, 100.0, 450.0, 2000.0, std::numeric_limits<double>::infinity()}) {
            ASSERT_EQ(s.index.within(eye, d), s.linear(eye, d)) << "eye " << e << " d " << d;
            // By budget: the nearest resident objects, as the linear selection over them picks.
            for (uint64_t budget : {uint64_t(1), uint64_t(5000), uint64_t(100000000)}) {
                std::vector<SplitObject> resident;
                std::vector<uint32_t> slot;
                for (const auto& [key, at] : s.first)
                    for (uint32_t i = at; i < at + 101; ++i) {
                        resident.push_back(s.objects[i]);
                        slot.push_back(i);
                    }
                std::vector<uint32_t> want;
                for (uint32_t k : selectNearFieldByBudget(resident, eye, budget)) want.push_back(slot[k]);
                std::vector<uint32_t> got = selectNearFieldByBudget(s.index, eye, budget);
                std::sort(want.begin(), want.end());
                std::sort(got.begin(), got.end());
                ASSERT_EQ(got, want) << "eye " << e << " budget " << budget;
            }
        }
    }
    uint64_t total = 0;
    for (const auto& [key, at] : s.first)
        for (uint32_t i = at; i < at + 101; ++i) total += s.objects[i].triangles;
    EXPECT_EQ(s.index.totalTriangles(), total);
    // The static index is one block: ascending, as before.
    const std::vector<SplitObject> one = regionObjects(0, 0);
    EXPECT_EQ(SplitIndex(one).within(glm::dvec3(200, 200, 2), 60.0), selectNearField(one, {200, 200, 2}, 60.0));
}

TEST(SplitIndexBlocks, ASelectionVisitsTheSameWorkWhateverIsResident) {
    // The same eye and near distance with the 3 x 3 regions around it resident, then with 100
    // more far away: the query visits the same objects and tests no more blocks than those
    // around the eye (counted, not timed).
    Streamed few, many;
    many.objects.reserve(120 * 101);
    for (int ry = 0; ry < 3; ++ry)
        for (int rx = 0; rx < 3; ++rx) {
            few.add(rx, ry);
            many.add(rx, ry);
        }
    for (int ry = 10; ry < 20; ++ry)
        for (int rx = 10; rx < 20; ++rx) many.add(rx, ry);
    EXPECT_EQ(many.index.blockCount(), 109u);
    const glm::dvec3 eye(600.0, 610.0, 1.7);
    for (double d : {15.0, 100.0, 300.0, 800.0}) {
        const SplitIndex::VisitCost a = few.index.cost(eye, d), b = many.index.cost(eye, d);
        EXPECT_EQ(a.objects, b.objects) << d;
        EXPECT_LE(a.blocks, 9u);
        EXPECT_LE(b.blocks, 9u) << d;
        if (d <= 300) { EXPECT_LT(a.objects, 9u * 101u) << "only the cells within reach"; }
        EXPECT_EQ(few.index.within(eye, d), many.index.within(eye, d));
    }
    // Everything (+inf) does visit every block.
    EXPECT_EQ(many.index.cost(eye, std::numeric_limits<double>::infinity()).blocks, 109u);
}

namespace {

void addBox(SceneMesh& m, glm::vec3 lo, glm::vec3 hi) {
    const uint32_t b = uint32_t(m.positions.size());
    for (int c = 0; c < 8; ++c)
        m.positions.push_back({(c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z});
    m.colors.resize(m.positions.size(), glm::u8vec4(200));
    const uint32_t f[12][3] = {{0, 1, 3}, {0, 3, 2}, {4, 6, 7}, {4, 7, 5}, {0, 4, 5}, {0, 5, 1},
                               {2, 3, 7}, {2, 7, 6}, {0, 2, 6}, {0, 6, 4}, {1, 5, 7}, {1, 7, 3}};
    for (const auto& t : f)
        for (uint32_t k : t) m.indices.push_back(b + k);
}

// Region (rx, ry) of a 3 x 3 city of 400 m regions: a few buildings, one reaching into the next region.
SceneModel regionModel(int rx, int ry) {
    SceneModel r;
    SceneMesh m;
    m.origin = glm::dvec3(rx * kRegion, ry * kRegion, 0.0);
    for (int k = 0; k < 6; ++k) {
        const float x = float(30 + 60 * k), y = float(40 + 50 * ((k + rx + ry) % 5));
        addBox(m, {x, y, 0}, {x + 20, y + 25, float(10 + 9 * ((k * 5 + rx * 3 + ry) % 7))});
    }
    addBox(m, {380, 180, 0}, {430, 200, float(15 + rx + ry)});  // crosses into the region east
    r.meshes.push_back(m);
    return r;
}

void expectSameCells(const HeightGrid& a, const HeightGrid& b) {
    ASSERT_EQ(a.cells(), b.cells());
    EXPECT_EQ(a.empty(), b.empty());
    if (!a.empty()) {
        EXPECT_EQ(a.boundsMin(), b.boundsMin());
        EXPECT_EQ(a.boundsMax(), b.boundsMax());
    }
    size_t differ = 0;
    for (int y = 0; y < a.cells(); ++y)
        for (int x = 0; x < a.cells(); ++x)
            differ += a.maxZ(x, y) != b.maxZ(x, y) || a.minZ(x, y) != b.minZ(x, y) ? 1 : 0;
    EXPECT_EQ(differ, 0u);
    // The horizon over both: the same values (blocks included).
    for (double az = 0.0; az < 6.28; az += 0.37) {
        const glm::dvec3 eye(500.0, 520.0, 1.7);
        EXPECT_EQ(a.traceRay(eye, az, 30.0), b.traceRay(eye, az, 30.0)) << az;
    }
}

}  // namespace

TEST(HeightGridPatches, SplicedRegionsGiveTheCellsOfTheirMergedModel) {
    const glm::dvec3 origin(600.0, 600.0, 0.0);
    const HeightGrid lattice = HeightGrid::lattice({0.0, 0.0}, {1200.0, 1200.0}, origin, 0);
    EXPECT_TRUE(lattice.empty());
    EXPECT_EQ(lattice.cells(), HeightGrid::autoCells(1200.0 + 4 * HeightGrid::kCellMargin));
    std::map<int, SceneModel> regions;
    for (int k = 0; k < 9; ++k) regions[k] = regionModel(k % 3, k / 3);
    auto merged = [&](const std::vector<int>& keys) {
        SceneModel m;
        for (int k : keys) m.meshes.push_back(regions[k].meshes[0]);
        HeightGrid g = lattice;
        g.addPatch(0, std::make_shared<const HeightPatch>(g.patch(m)));
        return g;
    };
    HeightGrid streamed = lattice;
    for (int k : {4, 0, 8, 1, 3, 5, 2, 6, 7})
        streamed.addPatch(uint64_t(k), std::make_shared<const HeightPatch>(streamed.patch(regions[k])));
    expectSameCells(streamed, merged({0, 1, 2, 3, 4, 5, 6, 7, 8}));
    // Regions leave (their cells are those of the others again, the shared border included) and come back.
    streamed.removePatch(4);
    streamed.removePatch(3);
    streamed.removePatch(42);  // unknown: nothing
    expectSameCells(streamed, merged({0, 1, 2, 5, 6, 7, 8}));
    streamed.addPatch(3, std::make_shared<const HeightPatch>(streamed.patch(regions[3])));
    expectSameCells(streamed, merged({0, 1, 2, 3, 5, 6, 7, 8}));
    for (int k : {0, 1, 2, 3, 5, 6, 7, 8}) streamed.removePatch(uint64_t(k));
    EXPECT_TRUE(streamed.empty());
    EXPECT_EQ(streamed.patchCount(), 0u);
}
