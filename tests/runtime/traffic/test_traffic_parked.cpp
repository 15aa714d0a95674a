// Parked cars stand where SUMO's vehicles do not drive: on a generated city
// with its parked cars, the body of every moving vehicle at every step of a
// SUMO run (its front bumper, heading and type size from the FCD) overlaps
// no parked car's footprint.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <map>
#include <utility>
#include <vector>

#include "citygen/blocks.h"
#include "citygen/generate.h"
#include "citygen/opendrive.h"
#include "citygen/parked_cars.h"
#include "foundation/progress.h"
#include "runtime/traffic/traffic_run.h"
#include "runtime/traffic/traffic_tracks.h"
#include "tests/common/sumo_city.h"
#include "tests/common/temp_dir.h"

using namespace vista;
using vista::test::TempDir;

namespace {

using Poly = std::vector<glm::dvec2>;

// Separating-axis test of two convex polygons (any winding).
bool overlap(const Poly& a, const Poly& b) {
    for (const Poly* p : {&a, &b}) {
        for (size_t i = 0; i < p->size(); ++i) {
            const glm::dvec2 e = (*p)[(i + 1) % p->size()] - (*p)[i];
            const glm::dvec2 n(-e.y, e.x);
            double a0 = 1e300, a1 = -1e300, b0 = 1e300, b1 = -1e300;
            for (const auto& v : a) a0 = std::min(a0, glm::dot(n, v)), a1 = std::max(a1, glm::dot(n, v));
            for (const auto& v : b) b0 = std::min(b0, glm::dot(n, v)), b1 = std::max(b1, glm::dot(n, v));
            if (a1 <= b0 || b1 <= a0) return false;
        }
    }
    return true;
}

// A vehicle's body: length behind the front bumper, width across, heading CCW from +x.
Poly body(glm::dvec2 front, double heading, double length, double width) {
    const glm::dvec2 f(std::cos(heading), std::sin(heading)), l(-f.y, f.x);
    const glm::dvec2 rear = front - length * f;
    return {rear - 0.5 * width * l, front - 0.5 * width * l, front + 0.5 * width * l, rear + 0.5 * width * l};
}

}  // namespace

TEST(TrafficParked, NoMovingVehicleDrivesThroughAParkedCar) {
    VISTA_SKIP_WITHOUT_SUMO();
    // The overlap test itself: two bodies side by side touch nothing, nose to tail overlap.
    ASSERT_FALSE(overlap(body({0, 0}, 0.0, 4.0, 2.0), body({0, 2.5}, 0.0, 4.0, 2.0)));
    ASSERT_TRUE(overlap(body({0, 0}, 0.0, 4.0, 2.0), body({3, 0.5}, 0.3, 4.0, 2.0)));
    CityParams params = test::sumoCityParams();
    params.parked_car_share = 0.6;
    auto made = test::xodrCity(params);
    ASSERT_TRUE(made) << made.status().message();
    const City* city = &made->city;
    const std::string* xodr = &made->xodr;
    ASSERT_GT(city->cars.size(), 20u);

    TempDir tmp("vista_traffic_parked");
    TrafficOptions opt;
    opt.demand.vehicles = 80;
    opt.demand.pedestrians = 0;
    opt.demand.durationS = 150.0;
    opt.demand.seed = 3;
    Progress quiet;
    ASSERT_TRUE(makeTraffic(*xodr, opt, tmp.file("t"), quiet, nullptr));
    auto tracks = loadTrafficTracks(tmp.file("t"));
    ASSERT_TRUE(tracks) << tracks.status().message();

    // Parked cars by 10 m grid cell (city frame).
    std::map<std::pair<int, int>, std::vector<Poly>> cells;
    for (const ParkedCar& c : city->cars) {
        const Poly fp = carFootprint(c);
        const auto key = std::make_pair(int(std::floor(c.position.x / 10.0)), int(std::floor(c.position.y / 10.0)));
        for (int dx = -1; dx <= 1; ++dx)
            for (int dy = -1; dy <= 1; ++dy) cells[{key.first + dx, key.second + dy}].push_back(fp);
    }
    size_t checked = 0, hits = 0;
    for (const AgentPose& p : tracks->poses) {
        const AgentTypeInfo& type = agentTypeInfo(tracks->agentTypes[p.agent]);
        const glm::dvec2 front = glm::dvec2(p.x, p.y) - glm::dvec2(params.origin_x, params.origin_y);
        const Poly b = body(front, p.heading, type.length, type.width);
        const glm::dvec2 mid = 0.5 * (b[0] + b[2]);
        auto it = cells.find({int(std::floor(mid.x / 10.0)), int(std::floor(mid.y / 10.0))});
        ++checked;
        if (it == cells.end()) continue;
        for (const Poly& car : it->second)
            if (overlap(b, car)) {
                ++hits;
                break;
            }
    }
    EXPECT_GT(checked, 1000u);
    EXPECT_EQ(hits, 0u) << "of " << checked << " vehicle samples";
}
