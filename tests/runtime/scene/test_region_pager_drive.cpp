// A paced drive through a streamed paged city (runtime/scene/region_pager.h)
// never draws a region below the detail its distance asks for when every load
// finishes within the lookahead: not on a straight road across region
// boundaries, and not where the road turns back towards a region it left by
// a few metres (the camera turns at a corner just past the full-detail
// radius). Loads take a fixed number of frames here: each one waits on the
// worker until the drive has gone that many frames on, so what the frames see
// does not depend on how fast the machine loads.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "runtime/scene/paged_load.h"
#include "runtime/scene/region_pager.h"
#include "tests/common/small_paged_city.h"

using vista::RegionPager;
using vista::RegionPagerOptions;

namespace {

constexpr double kFrameS = 1.0 / 30.0;  // the drive's frame rate: 30 frames a path second
constexpr int kLoadFrames = 30;         // every load takes one path second
constexpr double kPrefetchS = 2.0;      // the lookahead: twice a load

// Loads that take kLoadFrames frames: a load started at frame f (on the worker, in prepare) is
// handed back once the drive reaches frame f + kLoadFrames. Off (open) until the drive starts.
class FrameGate {
public:
    void prepare() {
        std::unique_lock<std::mutex> lock(_m);
        if (!_on) return;
        _due = _frame + kLoadFrames;
        _blocked = true;
        _cv.wait(lock, [this] { return _stop || _frame >= _due; });
        _blocked = false;
    }
    void start() {
        set([this] { _on = true; });
    }
    void frame(int f) {
        set([this, f] { _frame = f; });
    }
    void stop() {
        set([this] { _stop = true; });
    }
    // True when the worker waits on a load that is not due yet.
    bool holding() const {
        std::lock_guard<std::mutex> lock(_m);
        return _blocked && _frame < _due;
    }

private:
    template <class F>
    void set(F f) {
        {
            std::lock_guard<std::mutex> lock(_m);
            f();
        }
        _cv.notify_all();
    }
    mutable std::mutex _m;
    std::condition_variable _cv;
    bool _on = false, _stop = false, _blocked = false;
    int _frame = 0, _due = 0;
};

// Releases a gated worker before the pager joins it.
struct GateStop {
    FrameGate& gate;
    ~GateStop() { gate.stop(); }
};

double pointRect(const glm::dvec2& p, const vista::PagedRegionEntry& r) {
    const double dx = std::max({r.lo.x - p.x, 0.0, p.x - r.hi.x});
    const double dy = std::max({r.lo.y - p.y, 0.0, p.y - r.hi.y});
    return std::hypot(dx, dy);
}

// A path through `corners` at `speed` m/s, one sample per frame.
std::vector<glm::dvec3> drivePath(const std::vector<glm::dvec2>& corners, double speed) {
    std::vector<glm::dvec3> out;
    glm::dvec2 at = corners.front();
    out.emplace_back(at, 1.7);
    for (size_t k = 1; k < corners.size(); ++k) {
        for (;;) {
            const glm::dvec2 to = corners[k] - at;
            const double step = speed * kFrameS;
            if (glm::length(to) <= step) break;
            at += to / glm::length(to) * step;
            out.emplace_back(at, 1.7);
        }
    }
    return out;
}

struct DriveResult {
    int frames = 0, framesBelow = 0, arrivals = 0;
    std::string below;  // the first frames below detail: "frame f: region r held at level l"
};

class PagerDrive : public ::testing::Test {
protected:
    void SetUp() override {
        // The shared small paged city (1.5 km in 500 m regions: 3 x 3, region 4 in the middle), read in place.
        auto m = vista::readPagedManifest(vista::test::smallPagedCity().dir);
        ASSERT_TRUE(m.isOk()) << m.status().message();
        manifest = *m;
        ASSERT_EQ(manifest.regions.size(), 9u);
        ASSERT_EQ(manifest.nonEmpty(), 9);
    }

    // Drives `path` frame by frame as the bench's paced drive does (update, collect, count),
    // full detail within `radius`, coarse everywhere else, loads of kLoadFrames frames. The
    // frames below detail are counted from the levels the deltas handed over and the regions'
    // manifest bounds, and checked against RegionPager::belowDetail().
    DriveResult drive(const std::vector<glm::dvec3>& path, double radius) {
        DriveResult out;
        FrameGate gate;
        RegionPagerOptions o;
        o.radius = radius;
        o.far = 5000;
        o.prefetchS = kPrefetchS;
        o.workers = 1;
        o.prepare = [&gate](vista::SceneModel&, const vista::RegionLoad&) -> std::shared_ptr<void> {
            gate.prepare();
            return nullptr;
        };
        RegionPager pager(manifest, o);
        GateStop release{gate};
        std::map<int, int> held;  // region -> 1 coarse, 2 full
        auto apply = [&](const vista::RegionPagerDelta& d) {
            for (const auto& x : d.dropped) held.erase(x.region);
            for (const auto& a : d.arrived) held[a.region] = a.coarse ? 1 : 2;
            out.arrivals += int(d.arrived.size());
        };
        for (size_t f = 0; f < path.size(); ++f) {
            const size_t a = f + 1 < path.size() ? f : f - 1;
            const glm::dvec3 velocity = (path[a + 1] - path[a]) / kFrameS;
            gate.frame(int(f));
            pager.update(path[f], velocity);
            if (f == 0) {
                apply(pager.collect(true));  // the first frame waits for the regions at the start
                gate.start();
                continue;
            }
            // Every load due by this frame is collected; one not due yet holds the worker.
            for (int tries = 0;; ++tries) {
                apply(pager.collect());
                if (pager.idle() || gate.holding()) break;
                if (tries > 100000) {
                    ADD_FAILURE() << "frame " << f << ": the pager does not settle";
                    return out;
                }
                std::this_thread::sleep_for(std::chrono::microseconds(200));
            }
            int below = 0;
            for (size_t i = 0; i < manifest.regions.size(); ++i) {
                const double d = pointRect(glm::dvec2(path[f]), manifest.regions[i]);
                const int want = d <= radius ? 2 : 1;
                const int level = held.count(int(i)) ? held[int(i)] : 0;
                if (level >= want) continue;
                ++below;
                if (out.below.size() < 400)
                    out.below += "frame " + std::to_string(f) + ": region " + std::to_string(i) + " held at level " +
                                 std::to_string(level) + " (" + std::to_string(radius - d) + " m within the radius); ";
            }
            EXPECT_EQ(pager.belowDetail(), below) << "frame " << f;
            out.framesBelow += below > 0 ? 1 : 0;
            ++out.frames;
        }
        return out;
    }

    vista::PagedManifest manifest;
};

}  // namespace

// A straight road from the middle of region 3 through region 4 to the middle of region 5 at
// 20 m/s: each region comes within the radius of the heading's lookahead (2 s, 40 m) before the
// eye's, and its full level (1 s to load) is there when the eye arrives.
TEST_F(PagerDrive, AStraightRoadAcrossRegionBoundariesNeverDrawsBelowDetail) {
    const auto& r3 = manifest.regions[3];
    const auto& r5 = manifest.regions[5];
    const double y = 0.5 * (manifest.regions[4].lo.y + manifest.regions[4].hi.y);
    const auto path = drivePath({{0.5 * (r3.lo.x + r3.hi.x), y}, {0.5 * (r5.lo.x + r5.hi.x), y}}, 20.0);
    const DriveResult r = drive(path, 100.0);
    EXPECT_GE(r.arrivals, 4) << "full levels arrive on the way (regions 4 and 5) and coarse ones behind";
    EXPECT_EQ(r.framesBelow, 0) << r.below;
}

// At 5 m/s east out of region 4's full-detail radius by 3 m, north along it for 3 s (its coarse
// level arrives, the full one goes), then west back into it: the turn brings the region back
// within the radius 0.6 s after it faces it, sooner than a load. Within reach of the lookahead
// (2 s: 10 m at that speed) whichever way the camera turns, the region keeps its full level.
TEST_F(PagerDrive, TurningBackAtACornerJustPastTheRadiusNeverDrawsBelowDetail) {
    const double radius = 100.0;
    const auto& r4 = manifest.regions[4];
    const double y = 0.5 * (r4.lo.y + r4.hi.y);
    const double out = r4.hi.x + radius + 3.0;  // 3 m past the radius, east of region 4
    const auto path = drivePath({{out - 20.0, y}, {out, y}, {out, y + 15.0}, {out - 20.0, y + 15.0}}, 5.0);
    // The path leaves the radius (for more than a load's time) and comes back within it.
    int outside = 0;
    for (const glm::dvec3& p : path) outside += pointRect(glm::dvec2(p), r4) > radius ? 1 : 0;
    EXPECT_GT(outside, 2 * kLoadFrames);
    EXPECT_LT(pointRect(glm::dvec2(path.back()), r4), radius - 10.0);
    const DriveResult r = drive(path, radius);
    EXPECT_EQ(r.framesBelow, 0) << r.below;
}
