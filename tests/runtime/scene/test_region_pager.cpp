// The streaming pager of a paged city (runtime/scene/region_pager.h): the
// desired set follows a moving eye, loads ahead of the heading come first,
// regions left behind are dropped, the budget holds (coarse levels first),
// wait mode holds what a synchronous load of the same reach loads, damaged
// files fall back to the coarse level, and no load runs on the caller's thread.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "runtime/scene/paged_load.h"
#include "runtime/scene/region_pager.h"
#include "tests/common/small_paged_city.h"
#include "tests/common/temp_dir.h"

namespace fs = std::filesystem;
using vista::RegionPager;
using vista::RegionPagerOptions;
using vista::test::TempDir;

namespace {

// The shared 1.5 km city in 500 m regions (3 x 3, region 4 in the middle): tests/common/small_paged_city.h.
class Pager : public ::testing::Test {
protected:
    static void SetUpTestSuite() { vista::test::smallPagedCity(); }
    static std::string cityDir() { return vista::test::smallPagedCity().dir; }
    void SetUp() override {
        auto m = vista::readPagedManifest(cityDir());
        ASSERT_TRUE(m.isOk()) << m.status().message();
        manifest = *m;
        ASSERT_EQ(manifest.regions.size(), 9u);
        ASSERT_EQ(manifest.nonEmpty(), 9);
    }
    // The centre of region i's grid cell (world metres).
    glm::dvec3 centre(int i) const {
        const auto& r = manifest.regions[size_t(i)];
        const double half = 0.5 * manifest.params.size_m, s = manifest.regionSizeM;
        return glm::dvec3(manifest.params.origin_x - half + (r.ix + 0.5) * s,
                          manifest.params.origin_y - half + (r.iy + 0.5) * s, 1.7);
    }
    // Applies a delta to `held` (region -> level) as a consumer does; checks the loader threads.
    void apply(vista::RegionPagerDelta& d, std::map<int, int>& held) {
        for (const auto& x : d.dropped) {
            ASSERT_EQ(held.count(x.region), 1u) << "drop of a region not held: " << x.region;
            ASSERT_EQ(held[x.region], x.coarse ? 1 : 2);
            held.erase(x.region);
        }
        for (const auto& a : d.arrived) {
            EXPECT_NE(a.loader, std::this_thread::get_id())
                << "region " << a.region << " loaded on the caller's thread";
            EXPECT_FALSE(a.model.tiles.empty());
            if (held.count(a.region)) {
                ADD_FAILURE() << "region " << a.region << " arrived while another level is held";
            }
            held[a.region] = a.coarse ? 1 : 2;
        }
    }
    static std::map<int, int> asMap(const std::vector<uint8_t>& levels) {
        std::map<int, int> m;
        for (size_t i = 0; i < levels.size(); ++i)
            if (levels[i]) m[int(i)] = levels[i];
        return m;
    }
    vista::PagedManifest manifest;
};

}  // namespace

TEST_F(Pager, TheResidentSetFollowsAMovingEyeAndUnloadsBehindIt) {
    RegionPagerOptions o;
    o.radius = 0;
    o.far = 0;
    o.prefetchS = 0;
    o.wait = true;
    RegionPager pager(manifest, o);
    std::map<int, int> held;
    for (int step : {0, 1, 2, 5, 8}) {
        pager.update(centre(step), glm::dvec3(0.0));
        auto d = pager.collect();
        apply(d, held);
        EXPECT_EQ(held, (std::map<int, int>{{step, 2}})) << "eye in region " << step;
        EXPECT_EQ(asMap(pager.held()), held);
    }
    const auto s = pager.stats();
    EXPECT_EQ(s.loads, 5);
    EXPECT_EQ(s.unloads, 4);
    EXPECT_EQ(s.residentFull, 1);
    EXPECT_EQ(s.residentBytes, manifest.regions[8].bytes);
    EXPECT_GT(s.framesWaited, 0);
    uint64_t read = 0;
    for (int i : {0, 1, 2, 5, 8}) read += manifest.regions[size_t(i)].bytes;
    EXPECT_EQ(s.bytesRead, read);
}

TEST_F(Pager, WaitModeHoldsWhatASynchronousLoadLoads) {
    for (double radius : {0.0, 200.0, 600.0}) {
        RegionPagerOptions o;
        o.radius = radius;
        o.far = 5000;
        o.prefetchS = 0;
        o.wait = true;
        o.workers = 2;
        RegionPager pager(manifest, o);
        // A point off the grid's symmetry: inside region 0, towards region 1.
        const glm::dvec3 eye = centre(0) + glm::dvec3(180.0, 40.0, 0.0);
        pager.update(eye, glm::dvec3(3.0, 1.0, 0.0));  // prefetch 0: the velocity does not matter
        auto d = pager.collect();
        std::map<int, int> held;
        apply(d, held);
        const std::vector<int> full = vista::selectPagedRegions(manifest, {glm::dvec2(eye)}, radius);
        const std::vector<int> coarse = vista::selectCoarseRegions(manifest, {glm::dvec2(eye)}, o.far, full);
        std::map<int, int> expect;
        for (int i : full) expect[i] = 2;
        for (int i : coarse) expect[i] = 1;
        EXPECT_EQ(held, expect) << "radius " << radius;
        // The same triangles as the merged synchronous load of that set.
        auto merged = vista::loadPagedCity(manifest, full, radius, nullptr, coarse);
        ASSERT_TRUE(merged.isOk()) << merged.status().message();
        size_t tris = 0;
        for (const auto& a : d.arrived) tris += a.model.triangles;
        EXPECT_EQ(tris, merged->triangles);
        // Arrivals come sorted (full first, by region), whatever the load order.
        for (size_t k = 1; k < d.arrived.size(); ++k) {
            const auto &a = d.arrived[k - 1], &b = d.arrived[k];
            EXPECT_TRUE(a.coarse < b.coarse || (a.coarse == b.coarse && a.region < b.region));
        }
    }
}

TEST_F(Pager, PrefetchLoadsAheadOfTheHeadingFirst) {
    RegionPagerOptions o;
    o.radius = 260;  // from the middle of region 4: itself and its four edge neighbours
    o.far = 0;
    o.prefetchS = 30;  // 10 m/s east: 300 m ahead
    o.workers = 1;
    RegionPager pager(manifest, o);
    pager.update(centre(4), glm::dvec3(10.0, 0.0, 0.0));
    // Grid: region = iy * 3 + ix; east of 4 is 5, west is 3, north-east 8, north-west 6.
    const auto& want = pager.desired();
    for (int i : {1, 3, 4, 5, 7}) EXPECT_EQ(want[size_t(i)], 2) << "region " << i;
    // The corner regions' nearest corners are 354 m from the eye: within 260 m of the 300 m the
    // camera can go in the lookahead, whichever way it turns.
    for (int i : {0, 2, 6, 8}) EXPECT_EQ(want[size_t(i)], 2) << "corner region " << i << ": within reach";
    std::map<int, uint64_t> seq;
    std::map<int, int> held;
    for (int tries = 0; tries < 20000 && seq.size() < 9; ++tries) {
        auto d = pager.collect();
        for (const auto& a : d.arrived) seq[a.region] = a.sequence;
        apply(d, held);
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    ASSERT_EQ(seq.size(), 9u);
    EXPECT_EQ(seq[4], 1u) << "the eye's own region first";
    EXPECT_LT(seq[5], seq[3]) << "ahead (east) before behind (west)";
    EXPECT_LT(seq[5], seq[1]);
    EXPECT_LT(seq[5], seq[7]);
    EXPECT_LT(seq[3], seq[2]) << "regions within reach of the eye before those wanted for the lookahead only";
    EXPECT_LT(seq[3], seq[8]);
    EXPECT_LT(seq[2], seq[0]) << "south-east (ahead) before south-west (behind)";
    EXPECT_LT(seq[8], seq[6]) << "north-east (ahead) before north-west (behind)";
    EXPECT_EQ(pager.stats().framesWaited, 0);
}

// Slow loads lengthen the lookahead (at least kLookaheadLoads times the longest recent full load),
// so regions come within reach of it early enough; wait mode keeps --paged-prefetch.
TEST_F(Pager, SlowLoadsLengthenTheLookahead) {
    const double sleepS = 0.1;
    for (bool wait : {false, true}) {
        RegionPagerOptions o;
        o.radius = 260;  // from the middle of region 4: itself and its four edge neighbours
        o.far = 0;
        o.prefetchS = 0.01;  // 1000 m/s east: 10 m ahead, short of the corner regions 2 and 8
        o.workers = 1;
        o.wait = wait;
        o.prepare = [&](vista::SceneModel&, const vista::RegionLoad&) -> std::shared_ptr<void> {
            std::this_thread::sleep_for(std::chrono::duration<double>(sleepS));
            return nullptr;
        };
        RegionPager pager(manifest, o);
        const glm::dvec3 v(1000.0, 0.0, 0.0);
        pager.update(centre(4), v);
        EXPECT_EQ(pager.desired()[8], 0) << "wait " << wait << ": no load measured yet";
        EXPECT_EQ(pager.desired()[2], 0) << "wait " << wait;
        std::map<int, int> held;
        for (int tries = 0; tries < 20000 && !held.count(4); ++tries) {
            auto d = pager.collect();
            apply(d, held);
            if (!held.count(4)) std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
        ASSERT_EQ(held.count(4), 1u);
        pager.update(centre(4), v);
        const auto s = pager.stats();
        if (wait) {
            EXPECT_DOUBLE_EQ(s.lookaheadS, o.prefetchS);
            EXPECT_EQ(pager.desired()[8], 0);
        } else {
            // The corner of region 8 is (250, 250) m from the eye: within 260 m of the lookahead's
            // end once it reaches 179 m, which 2 x 0.1 s at 1000 m/s (200 m) does.
            EXPECT_GE(s.fullLoadSMax, sleepS);
            EXPECT_GE(s.lookaheadS, vista::kLookaheadLoads * sleepS);
            EXPECT_LE(s.lookaheadS, vista::kMaxPagedPrefetchS);
            EXPECT_EQ(pager.desired()[8], 2) << "north-east: within reach of the longer lookahead";
            EXPECT_EQ(pager.desired()[2], 2) << "south-east: within reach of the longer lookahead";
        }
        EXPECT_GE(s.peakLookaheadS, s.lookaheadS);
    }
}

TEST_F(Pager, TheBudgetHoldsCoarseLevelsFirstThenTheRadiusShrinks) {
    // Coarse first: the middle region at full detail, the others coarse, the budget short of two coarse levels.
    {
        uint64_t total = manifest.regions[4].bytes;
        for (int i = 0; i < 9; ++i)
            if (i != 4) total += manifest.regions[size_t(i)].coarseBytes;
        RegionPagerOptions o;
        o.radius = 0;
        o.far = 5000;
        o.prefetchS = 0;
        o.wait = true;
        o.budgetBytes = total - manifest.regions[0].coarseBytes / 2;
        RegionPager pager(manifest, o);
        pager.update(centre(4), glm::dvec3(0.0));
        auto d = pager.collect();
        std::map<int, int> held;
        apply(d, held);
        EXPECT_EQ(held[4], 2) << "the full region stays";
        int coarse = 0;
        for (const auto& [r, level] : held) coarse += level == 1 ? 1 : 0;
        EXPECT_LT(coarse, 8) << "a coarse level went";
        EXPECT_GE(coarse, 6);
        EXPECT_LE(pager.stats().peakResidentBytes, o.budgetBytes);
        EXPECT_GT(pager.stats().budgetLimited, 0);
    }
    // Then the radius: five full regions wanted, the budget one byte short of them; moving on keeps it.
    {
        uint64_t five = 0;
        for (int i : {1, 3, 4, 5, 7}) five += manifest.regions[size_t(i)].bytes;
        RegionPagerOptions o;
        o.radius = 260;
        o.far = 5000;
        o.prefetchS = 0;
        o.wait = true;
        o.budgetBytes = five - 1;
        RegionPager pager(manifest, o);
        std::map<int, int> held;
        for (int step : {4, 5, 2, 1, 0}) {
            pager.update(centre(step), glm::dvec3(0.0));
            auto d = pager.collect();
            apply(d, held);
            EXPECT_EQ(held[step], 2) << "the eye's region stays, step " << step;
            uint64_t bytes = 0;
            for (const auto& [r, level] : held)
                bytes += level == 2 ? manifest.regions[size_t(r)].bytes : manifest.regions[size_t(r)].coarseBytes;
            EXPECT_LE(bytes, o.budgetBytes);
            EXPECT_LE(pager.stats().peakResidentBytes, o.budgetBytes) << "step " << step;
        }
        EXPECT_GT(pager.stats().unloads, 0);
    }
}

// The budget weighs each kind of load by the resident bytes the caller makes of a file byte
// (RegionCost): what is held, priced here from the manifest's sizes, stays within it and is what
// the pager reports as its cost; the same budget with unit weights (file bytes) holds it all; room
// for a load being prepared is held back from it.
TEST_F(Pager, TheBudgetWeighsEachKindOfLoad) {
    struct Held {
        std::map<int, int> levels;
        std::set<int> parts;
        uint64_t fileBytes = 0, weighted = 0;
        vista::RegionPagerStats stats;
    };
    auto run = [&](const vista::RegionCost& cost, uint64_t budget) {
        RegionPagerOptions o;
        o.radius = 260;
        o.chunkRadius = 260;
        o.far = 5000;
        o.prefetchS = 0;
        o.wait = true;
        o.cost = cost;
        o.budgetBytes = budget;
        RegionPager pager(manifest, o);
        pager.update(centre(4), glm::dvec3(0.0));
        auto d = pager.collect();
        Held h;
        for (const auto& a : d.arrived) {
            if (a.chunks) h.parts.insert(a.region);
            else h.levels[a.region] = a.coarse ? 1 : 2;
        }
        for (const auto& x : d.dropped) {
            if (x.chunks) h.parts.erase(x.region);
            else h.levels.erase(x.region);
        }
        for (const auto& [r, level] : h.levels) {
            const auto& e = manifest.regions[size_t(r)];
            const uint64_t b = level == 2 ? e.bytes : e.coarseBytes;
            h.fileBytes += b;
            h.weighted += uint64_t(std::llround(double(b) * (level == 2 ? cost.full : cost.coarse)));
        }
        for (int r : h.parts) {
            h.fileBytes += manifest.regions[size_t(r)].bytes;
            h.weighted += uint64_t(std::llround(double(manifest.regions[size_t(r)].bytes) * cost.chunks));
        }
        h.stats = pager.stats();
        return h;
    };
    const vista::RegionCost weights{3.0, 1.5, 3.0};
    const Held all = run(weights, 0);
    ASSERT_EQ(all.parts.size(), 5u) << "a chunk part for each full region in the band";
    EXPECT_EQ(all.stats.residentCost, all.weighted);
    const uint64_t budget = all.weighted / 2;
    const Held cut = run(weights, budget);
    EXPECT_EQ(cut.levels.at(4), 2) << "the eye's region stays at full detail";
    EXPECT_EQ(cut.parts.count(4), 1u) << "with its chunks: the near field outranks the far city";
    EXPECT_LE(cut.weighted, budget);
    EXPECT_EQ(cut.stats.residentCost, cut.weighted);
    EXPECT_LE(cut.stats.peakResidentCost, budget);
    EXPECT_GT(cut.stats.budgetLimited, 0);
    const Held unit = run(vista::RegionCost{}, budget);
    EXPECT_EQ(unit.stats.budgetLimited, 0) << "in file bytes the same budget holds everything";
    EXPECT_EQ(unit.fileBytes, all.fileBytes);
    EXPECT_GT(unit.fileBytes, cut.fileBytes);
    // Room for a load being prepared (the largest full file times `loading`, one worker) is held back.
    vista::RegionCost withLoading = weights;
    withLoading.loading = 0.5;
    const Held reserved = run(withLoading, budget);
    uint64_t largest = 0;
    for (const auto& e : manifest.regions)
        if (!e.empty) largest = std::max(largest, e.bytes);
    EXPECT_EQ(reserved.stats.loadingReserve, uint64_t(std::llround(double(largest) * 0.5)));
    EXPECT_LE(reserved.weighted, budget - reserved.stats.loadingReserve);
    EXPECT_LE(reserved.stats.peakResidentCost, budget - reserved.stats.loadingReserve);
    EXPECT_EQ(reserved.levels.at(4), 2) << "the eye's region stays at full detail";
}

// A budget set between updates (a caller following the process's measured memory) takes effect at
// the next update: what is held then fits it. The pager is idle only once nothing is queued,
// loading or waiting to be collected.
TEST_F(Pager, ANewBudgetTakesEffectAtTheNextUpdate) {
    RegionPagerOptions o;
    o.radius = 260;
    o.far = 5000;
    o.prefetchS = 0;
    o.budgetBytes = 1ull << 40;
    RegionPager pager(manifest, o);
    EXPECT_TRUE(pager.idle());
    pager.update(centre(4), glm::dvec3(0.0));
    EXPECT_FALSE(pager.idle()) << "loads are queued until collected";
    pager.collect(true);
    EXPECT_TRUE(pager.idle());
    const uint64_t all = pager.stats().heldCost;
    EXPECT_EQ(all, pager.stats().residentCost);
    EXPECT_EQ(pager.stats().budgetLimited, 0);
    pager.setBudget(all / 2);
    pager.update(centre(4), glm::dvec3(0.0));
    pager.collect(true);
    EXPECT_GT(pager.stats().budgetLimited, 0);
    EXPECT_LE(pager.stats().heldCost, all / 2);
    EXPECT_EQ(pager.held()[4], 2) << "the eye's region stays at full detail";
}

TEST_F(Pager, ADamagedRegionFileFallsBackToItsCoarseLevel) {
    TempDir tmp("vista_pager_damaged");
    const std::string dir = tmp.file("city.paged");
    fs::copy(cityDir(), dir, fs::copy_options::recursive);
    auto m = vista::readPagedManifest(dir);
    ASSERT_TRUE(m.isOk()) << m.status().message();
    const std::string bad = (fs::path(dir) / m->regions[4].file).string();
    fs::resize_file(bad, m->regions[4].bytes / 2);
    RegionPagerOptions o;
    o.radius = 0;
    o.far = 0;
    o.prefetchS = 0;
    o.wait = true;
    RegionPager pager(*m, o);
    pager.update(centre(4), glm::dvec3(0.0));
    auto d = pager.collect();
    ASSERT_EQ(d.damaged.size(), 1u);
    EXPECT_NE(d.damaged[0].find(m->regions[4].file), std::string::npos) << d.damaged[0];
    std::map<int, int> held;
    apply(d, held);
    EXPECT_EQ(held, (std::map<int, int>{{4, 1}}));
    EXPECT_EQ(pager.belowDetail(), 1) << "the eye's region is drawn at its coarse level, full detail asked";
    pager.update(centre(4) + glm::dvec3(1.0, 0.0, 0.0), glm::dvec3(0.0));
    auto again = pager.collect();
    EXPECT_TRUE(again.damaged.empty());
    EXPECT_TRUE(again.arrived.empty());
    EXPECT_EQ(pager.stats().failed, 1);
}

// The regions at the camera (those whose bounds hold the eye): a budget that cannot hold even
// their coarse levels says so with what they need; one that holds exactly that does not; a waiting
// pager without a budget holds nothing below the detail each region's distance asks for.
TEST_F(Pager, ABudgetThatCannotHoldTheRegionsAtTheCameraSaysWhatTheyNeed) {
    const glm::dvec3 eye = centre(4);
    std::set<int> atEye;
    uint64_t coarse = 0, full = 0;
    for (size_t i = 0; i < manifest.regions.size(); ++i) {
        const auto& r = manifest.regions[i];
        if (eye.x >= r.lo.x && eye.x <= r.hi.x && eye.y >= r.lo.y && eye.y <= r.hi.y) {
            atEye.insert(int(i));
            coarse += r.coarseBytes;
            full += r.bytes;
        }
    }
    ASSERT_EQ(atEye.count(4), 1u);
    RegionPagerOptions o;
    o.radius = 0;
    o.far = 0;
    o.prefetchS = 0;
    o.wait = true;
    o.budgetBytes = coarse - 1;
    {
        RegionPager pager(manifest, o);
        pager.update(eye, glm::dvec3(0.0));
        const vista::RegionShortfall sf = pager.cameraShortfall();
        EXPECT_TRUE(sf.starved);
        EXPECT_EQ(std::set<int>(sf.regions.begin(), sf.regions.end()), atEye);
        EXPECT_EQ(sf.needCoarse, coarse);
        EXPECT_EQ(sf.needFull, full);
    }
    o.budgetBytes = coarse;
    {
        RegionPager pager(manifest, o);
        pager.update(eye, glm::dvec3(0.0));
        EXPECT_FALSE(pager.cameraShortfall().starved);
        pager.collect();
        EXPECT_EQ(pager.belowDetail(), int(atEye.size())) << "every region at the eye drawn coarse";
    }
    o.budgetBytes = 0;
    o.far = 5000;
    {
        RegionPager pager(manifest, o);
        pager.update(eye, glm::dvec3(0.0));
        EXPECT_FALSE(pager.cameraShortfall().starved);
        pager.collect();
        EXPECT_EQ(pager.belowDetail(), 0);
    }
}

// Chunk parts (RegionPagerOptions::chunkRadius): a full level loads without its chunks, and the
// full regions whose bounds come within the band of the eye get a chunk part of their own; a part
// leaves when its region leaves the band. The band is checked against the manifest bounds here.
TEST_F(Pager, ChunkPartsFollowTheBandAndLeaveWithIt) {
    RegionPagerOptions o;
    o.radius = 600;
    o.far = 5000;
    o.prefetchS = 0;
    o.wait = true;
    o.chunkRadius = 100;
    std::mutex m;
    std::vector<vista::RegionLoad> loads;
    o.prepare = [&](vista::SceneModel&, const vista::RegionLoad& load) -> std::shared_ptr<void> {
        std::lock_guard<std::mutex> lock(m);
        loads.push_back(load);
        return nullptr;
    };
    RegionPager pager(manifest, o);
    auto band = [&](const glm::dvec3& eye) {
        std::set<int> out;
        for (int i : vista::selectPagedRegions(manifest, {glm::dvec2(eye)}, o.radius)) {
            const auto& r = manifest.regions[size_t(i)];
            const double dx = std::max({r.lo.x - eye.x, 0.0, eye.x - r.hi.x});
            const double dy = std::max({r.lo.y - eye.y, 0.0, eye.y - r.hi.y});
            if (std::hypot(dx, dy) <= o.chunkRadius) out.insert(i);
        }
        return out;
    };
    std::set<int> parts;
    int partsLoaded = 0;
    // From the middle of region 4 to 50 m short of its east edge, then into region 5's middle.
    const double half = 0.5 * manifest.regionSizeM;
    for (const glm::dvec3& eye : {centre(4), centre(4) + glm::dvec3(half - 50.0, 0.0, 0.0), centre(5)}) {
        pager.update(eye, glm::dvec3(0.0));
        auto d = pager.collect();
        for (const auto& x : d.dropped)
            if (x.chunks) {
                EXPECT_FALSE(x.coarse);
                EXPECT_EQ(parts.erase(x.region), 1u) << "drop of a chunk part not held: " << x.region;
            }
        for (const auto& a : d.arrived)
            if (a.chunks) {
                EXPECT_FALSE(a.coarse);
                EXPECT_TRUE(parts.insert(a.region).second) << "chunk part " << a.region << " arrived twice";
                ++partsLoaded;
            }
        const std::set<int> expect = band(eye);
        ASSERT_FALSE(expect.empty());
        EXPECT_EQ(parts, expect) << "eye at " << eye.x << ", " << eye.y;
        EXPECT_EQ(pager.stats().residentChunks, int(expect.size()));
    }
    // Every level loaded without chunks; every part is a full file prepared for its chunks alone.
    std::lock_guard<std::mutex> lock(m);
    int levelLoads = 0;
    for (const auto& l : loads) {
        if (l.level) {
            EXPECT_FALSE(l.chunks) << "region " << l.region << ": a level with its chunks";
            ++levelLoads;
        } else {
            EXPECT_TRUE(l.chunks);
            EXPECT_FALSE(l.coarse);
        }
    }
    EXPECT_EQ(int(loads.size()) - levelLoads, partsLoaded);
    EXPECT_EQ(pager.stats().loads, int(loads.size()));
}
